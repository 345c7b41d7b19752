// SPDX-License-Identifier: BSD-3-Clause
#include "IsosurfaceRendererGL.h"

#include "GLObjects.h"
#include "HistoPyramidGL.h"
#include "Lighting.h"
#include "Matrix4.h"
#include "MedisoShaders.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <climits>
#include <cmath>
#include <sstream>
#include <string>

namespace mediso
{
namespace
{
using namespace glcore;
using matrix4::Matrix;

// Whether point sprites cover every cell this frame (see the vertex stage):
// the index box [0, cells] lies wholly beyond the near plane, and no cell can
// project to more than maxPointSize - 3 pixels. The bound on a cell's
// projected extent: with d >= dmin the depth of every point of the volume and
// L the longest cell diagonal in view space, two points of a cell differ in
// x/d by at most L/dmin (1 + |x/d|), and |x/d| <= (1 + |P02|)/|P00| on screen
// (NDC x = P00 x/d - P02 in perspective; NDC x = P00 x + P03 in parallel).
bool PointsCoverCells(const Matrix& indexToView, const Matrix& projection, const int cells[3],
  double nearPlane, bool parallel, const int viewport[4], float maxPointSize)
{
  double dmin = HUGE_VAL;
  for (int i = 0; i < 8; ++i)
  {
    const double p[4] = { (i & 1) ? double(cells[0]) : 0.0, (i & 2) ? double(cells[1]) : 0.0,
      (i & 4) ? double(cells[2]) : 0.0, 1.0 };
    dmin = std::min(dmin, -matrix4::Transform(indexToView, p)[2]); // the camera looks down -z
  }
  if (!(dmin > nearPlane * 1.0001 && dmin > 0.0))
  {
    return false;
  }
  double diagonal = 0.0;
  for (int i = 0; i < 4; ++i)
  {
    const double d[3] = { (i & 1) ? -1.0 : 1.0, (i & 2) ? -1.0 : 1.0, 1.0 };
    double length = 0.0;
    for (int r = 0; r < 3; ++r)
    {
      const double v =
        indexToView[4 * r] * d[0] + indexToView[4 * r + 1] * d[1] + indexToView[4 * r + 2] * d[2];
      length += v * v;
    }
    diagonal = std::max(diagonal, std::sqrt(length));
  }
  const double p00 = std::abs(projection[0]);
  const double p11 = std::abs(projection[5]);
  double ndcX, ndcY; // largest NDC extent of a cell
  if (parallel)
  {
    ndcX = diagonal * p00;
    ndcY = diagonal * p11;
  }
  else
  {
    ndcX = diagonal / dmin * (p00 + 1.0 + std::abs(projection[2]));
    ndcY = diagonal / dmin * (p11 + 1.0 + std::abs(projection[6]));
  }
  const double pixels = std::max(0.5 * ndcX * viewport[2], 0.5 * ndcY * viewport[3]);
  return pixels + 3.0 <= maxPointSize;
}

// The window pixels the volume can cover: the bounding rectangle of the
// index box [0, cells]'s 8 projected corners (x, y, width, height), widened by
// a pixel on every side and cut to the viewport (at least 1x1). Only for a box
// wholly in front of the eye (as point footprints require).
void ProjectedRectangle(const Matrix& indexToClip, const int cells[3], const int viewport[4], int rect[4])
{
  double lo[2] = { HUGE_VAL, HUGE_VAL };
  double hi[2] = { -HUGE_VAL, -HUGE_VAL };
  for (int i = 0; i < 8; ++i)
  {
    const double p[4] = { (i & 1) ? double(cells[0]) : 0.0, (i & 2) ? double(cells[1]) : 0.0,
      (i & 4) ? double(cells[2]) : 0.0, 1.0 };
    const auto clip = matrix4::Transform(indexToClip, p);
    for (int a = 0; a < 2; ++a)
    {
      const double window = viewport[a] + 0.5 * (clip[a] / clip[3] + 1.0) * viewport[2 + a];
      lo[a] = std::min(lo[a], window);
      hi[a] = std::max(hi[a], window);
    }
  }
  for (int a = 0; a < 2; ++a)
  {
    const double first = std::max(std::floor(lo[a]) - 1.0, double(viewport[a]));
    const double last = std::min(std::ceil(hi[a]) + 1.0, double(viewport[a] + viewport[2 + a]));
    const int begin = std::min(static_cast<int>(first), viewport[a] + viewport[2 + a] - 1);
    rect[a] = begin;
    rect[2 + a] = std::max(static_cast<int>(last) - begin, 1);
  }
}

// Whether the index box [0, cells] lies wholly inside the clip volume (all 8
// corners): then no cell is off screen and the vertex stage skips its test.
bool BoxInsideClipVolume(const Matrix& indexToClip, const int cells[3])
{
  for (int i = 0; i < 8; ++i)
  {
    const double p[4] = { (i & 1) ? double(cells[0]) : 0.0, (i & 2) ? double(cells[1]) : 0.0,
      (i & 4) ? double(cells[2]) : 0.0, 1.0 };
    const auto c = matrix4::Transform(indexToClip, p);
    if (!(c[3] > 0.0) || std::fabs(c[0]) > c[3] || std::fabs(c[1]) > c[3] || std::fabs(c[2]) > c[3])
    {
      return false;
    }
  }
  return true;
}

// The transpose of the inverse of m's upper 3x3 (normals to view space).
void NormalMatrix(const Matrix& m, double out[9])
{
  const double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9], i = m[10];
  const double A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
  const double D = -(b * i - c * h), E = a * i - c * g, F = -(a * h - b * g);
  const double G = b * f - c * e, H = -(a * f - c * d), I = a * e - b * d;
  const double det = a * A + b * B + c * C;
  const double s = det != 0.0 ? 1.0 / det : 0.0;
  // inverse = adjugate / det, adjugate = cofactor^T; its transpose is cofactor / det.
  const double cof[9] = { A, B, C, D, E, F, G, H, I };
  for (int k = 0; k < 9; ++k)
  {
    out[k] = cof[k] * s;
  }
}

// What one frame draws and how, chosen from the frame and the pyramid before
// any GL call: the isovalues' uniforms, the matrices, the footprint, the
// first-hit pass (turned off again when its buffers cannot be made) and the
// culling of cells off screen.
struct FrameVariant
{
  std::uint64_t Total = 0;
  int Cells[3] = { 0, 0, 0 };
  int Counted = 0; // isovalues the pyramid counts
  float IsoValues[MaximumIsovalues] = { 0 };
  float IsoColors[4 * MaximumIsovalues] = { 0 };
  bool Translucent = false;
  Matrix IndexToView, Projection, IndexToClip, ClipToIndex;
  float EyeIndex[4] = { 0, 0, 0, 0 };
  double GradientToView[9] = { 0 };
  bool Points = false;
  bool FirstHit = false;
  bool HitCull = false; // the first-hit pass in ranges, hidden points dropped
  bool Cull = false;
  // The clipping planes that cut the volume (index space); Clipped: one of
  // them removes all of it.
  int ClipPlanes = 0;
  float ClipPlaneValues[4 * MaximumClipPlanes] = { 0 };
  bool Clipped = false;

  // Several opaque isovalues in the first-hit pass: one primitive per cell
  // whose fragments take the nearest hit of the cell's isovalues.
  bool Nearest() const { return this->FirstHit && this->Counted > 1; }
  // Each cell drawn once, with all its isovalues.
  bool OneRankPerCell() const { return this->Translucent || this->Nearest(); }
};

// The frame's clipping planes that cut the index box [0, cells] (one that
// keeps all 8 corners costs nothing and is left out, so a cropping box at the
// volume's bounds compiles no clipping at all). "" or why they are unusable.
std::string ChooseClipPlanes(const IsosurfaceFrame& frame, FrameVariant& v)
{
  if (frame.ClipPlanes.size() > static_cast<std::size_t>(MaximumClipPlanes))
  {
    return "more than " + std::to_string(MaximumClipPlanes) + " clipping planes";
  }
  for (const auto& plane : frame.ClipPlanes)
  {
    if (!std::isfinite(plane[0]) || !std::isfinite(plane[1]) || !std::isfinite(plane[2]) ||
      !std::isfinite(plane[3]) || (plane[0] == 0.0 && plane[1] == 0.0 && plane[2] == 0.0))
    {
      return "a clipping plane has no normal or a value that is not finite";
    }
    int kept = 0;
    for (int i = 0; i < 8; ++i)
    {
      const double x = (i & 1) ? v.Cells[0] : 0.0, y = (i & 2) ? v.Cells[1] : 0.0,
                   z = (i & 4) ? v.Cells[2] : 0.0;
      kept += plane[0] * x + plane[1] * y + plane[2] * z + plane[3] >= 0.0 ? 1 : 0;
    }
    if (kept == 0)
    {
      v.Clipped = true;
    }
    else if (kept < 8)
    {
      for (int c = 0; c < 4; ++c)
      {
        v.ClipPlaneValues[4 * v.ClipPlanes + c] = static_cast<float>(plane[c]);
      }
      ++v.ClipPlanes;
    }
  }
  return "";
}

// Step 1: the variant. "" or why the frame cannot be drawn.
std::string ChooseVariant(
  const HistoPyramidGL& pyramid, const IsosurfaceFrame& frame, float maxPointSize, FrameVariant& v)
{
  // Isovalues in the pyramid's threshold order, their colours.
  const std::vector<int>& counted = pyramid.GetCountedIsovalues();
  v.Total = pyramid.GetTotal();
  v.Counted = static_cast<int>(counted.size());
  for (std::size_t t = 0; t < counted.size(); ++t)
  {
    if (counted[t] < 0 || counted[t] >= static_cast<int>(frame.Surfaces.size()))
    {
      return "the frame's surfaces are not those the pyramid was built for";
    }
    const IsosurfaceLook& s = frame.Surfaces[static_cast<std::size_t>(counted[t])];
    v.IsoValues[t] = static_cast<float>(s.Value);
    for (int c = 0; c < 3; ++c)
    {
      v.IsoColors[4 * t + c] = s.Color[c];
    }
    v.IsoColors[4 * t + 3] = s.Opacity;
    v.Translucent = v.Translucent || s.Opacity < 1.0f;
  }

  // Matrices: cell-index space to view and clip, the eye in index space.
  v.IndexToView = matrix4::FromArray(frame.IndexToView);
  v.Projection = matrix4::FromArray(frame.Projection);
  v.IndexToClip = matrix4::Multiply(v.Projection, v.IndexToView);
  Matrix viewToIndex;
  if (!matrix4::Invert(v.IndexToView, viewToIndex) ||
    !matrix4::Invert(v.IndexToClip, v.ClipToIndex))
  {
    return "the volume's transformation to the view is singular";
  }
  const double eyeView[4] = { 0.0, 0.0, frame.Parallel ? 1.0 : 0.0, frame.Parallel ? 0.0 : 1.0 };
  const auto eye = matrix4::Transform(viewToIndex, eyeView);
  for (int a = 0; a < 4; ++a)
  {
    v.EyeIndex[a] = static_cast<float>(eye[a]);
  }
  NormalMatrix(v.IndexToView, v.GradientToView);

  // The footprint (points where they provably cover every cell) and the
  // first-hit pass (opaque frames with points).
  const auto cells = pyramid.GetDrawnCells(); // a brick pool's: the volume's
  std::copy(cells.begin(), cells.end(), v.Cells);
  v.Points = frame.AllowPointFootprint &&
    PointsCoverCells(v.IndexToView, v.Projection, v.Cells, frame.NearPlane, frame.Parallel,
      frame.Viewport, maxPointSize);
  v.FirstHit = frame.FirstHitPass && v.Points && !v.Translucent;
  // Cells off screen are dropped in the vertex stage only where part of the
  // volume is: in a whole-volume view the test is not compiled in at all (a
  // uniform branch still costs a software rasteriser its instructions).
  v.Cull = !BoxInsideClipVolume(v.IndexToClip, v.Cells);
  return ChooseClipPlanes(frame, v);
}

// The state of a surface pass, drawn into the host's framebuffer with its
// depth test: no culling (cells are drawn as they come), no scissor, stencil
// or discard, every colour channel, and the pass's blending. Both the surface
// and the hits composited after it are drawn in it.
void SetSurfacePassState(const GLApi& gl, bool translucent)
{
  const GLApi::Functions& f = gl.F();
  f.Enable(GL_DEPTH_TEST);
  f.Disable(GL_CULL_FACE);
  f.Disable(GL_SCISSOR_TEST);
  f.Disable(GL_STENCIL_TEST);
  f.Disable(GL_RASTERIZER_DISCARD);
  f.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  SetSurfacePassBlending(gl, translucent);
}

// Whether `frame` is drawn into a reduced target (an image sample distance above 1 that leaves
// fewer pixels), and that target's size: ceil(viewport / distance), at least 1.
bool ReducedTarget(const IsosurfaceFrame& frame, int& width, int& height)
{
  if (!(frame.SampleDistance > 1.0f) || !std::isfinite(frame.SampleDistance))
  {
    return false;
  }
  width = std::max(1,
    static_cast<int>(std::ceil(static_cast<double>(frame.Viewport[2]) / frame.SampleDistance)));
  height = std::max(1,
    static_cast<int>(std::ceil(static_cast<double>(frame.Viewport[3]) / frame.SampleDistance)));
  return width < frame.Viewport[2] || height < frame.Viewport[3];
}
} // namespace

struct IsosurfaceRendererGL::Internals
{
  std::shared_ptr<const GLApi> GL;
  ProgramCache Programs;
  Name VertexArray; // empty: the draws take no attributes

  // First-hit pass: buffers over the volume's projected rectangle (HitRect).
  Name HitFBO, HitColor, HitDepth, HitFlag;
  int HitSize[2] = { 0, 0 };
  int HitRect[4] = { 0, 0, 0, 0 };
  // Set while the pieces of a volume kept as bricks go through one first-hit
  // pass: the buffers over all their rectangles are ready and cleared, each
  // piece only draws its cells into them, and the hits are composited once.
  bool SharedHit = false;
  HitCull Mode = HitCull::Auto;

  // The first-hit pass's coverage pyramid (HistoPyramidCoverage_fs.glsl):
  // level l over blocks of 2^(l + 1) hit-buffer pixels, one framebuffer per level.
  Name Coverage;
  std::vector<Name> CoverageFBOs;
  std::vector<std::array<int, 2>> CoverageSizes;

  void ReleaseCoverage()
  {
    this->CoverageFBOs.clear();
    this->CoverageSizes.clear();
    this->Coverage.Reset();
  }

  // The pyramid over the hit buffers (HitSize). "" when ready, else why not.
  std::string PrepareCoverage()
  {
    const int w = std::max(1, (this->HitSize[0] + 1) / 2);
    const int h = std::max(1, (this->HitSize[1] + 1) / 2);
    if (this->Coverage && !this->CoverageSizes.empty() && this->CoverageSizes[0][0] == w &&
      this->CoverageSizes[0][1] == h)
    {
      return "";
    }
    this->ReleaseCoverage();
    const GLApi& gl = *this->GL;
    const GLApi::Functions& f = gl.F();
    gl.TakeErrors();
    this->Coverage = Name(gl, NameKind::Texture);
    BindTextureUnit(gl, 0, GL_TEXTURE_2D, this->Coverage.Get());
    for (int lw = w, lh = h;; lw = std::max(1, lw / 2), lh = std::max(1, lh / 2))
    {
      this->CoverageSizes.push_back({ { lw, lh } });
      if (lw == 1 && lh == 1)
      {
        break;
      }
    }
    const int levels = static_cast<int>(this->CoverageSizes.size());
    for (int l = 0; l < levels; ++l)
    {
      f.TexImage2D(GL_TEXTURE_2D, l, GL_R8, this->CoverageSizes[l][0], this->CoverageSizes[l][1], 0,
        GL_RED, GL_UNSIGNED_BYTE, nullptr);
    }
    f.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    f.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    f.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    f.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    f.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    f.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, levels - 1);
    std::string problem;
    for (int l = 0; l < levels && problem.empty(); ++l)
    {
      this->CoverageFBOs.emplace_back(gl, NameKind::Framebuffer);
      f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, this->CoverageFBOs.back().Get());
      f.FramebufferTexture2D(
        GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, this->Coverage.Get(), l);
      problem = FramebufferProblem(gl);
    }
    const std::string errors = gl.TakeErrors();
    if (problem.empty() && !errors.empty())
    {
      problem = errors;
    }
    if (!problem.empty())
    {
      this->ReleaseCoverage();
    }
    return problem;
  }

  // The pyramid of the hits drawn so far, level by level, each from the one
  // below (the first from the hit colour's alpha). While a level is drawn
  // the texture's base and maximum level are the level read, so that no
  // level is read and drawn at once (WebGL reports that as a feedback loop
  // even where the levels differ); then all levels again, for the vertex
  // stage. Leaves its program, framebuffer, viewport and unit 0 bound, and
  // the counting passes' state set. "" or why not.
  std::string BuildCoverage()
  {
    const GLApi& gl = *this->GL;
    const GLApi::Functions& f = gl.F();
    std::string error;
    Program* reduce = this->Programs.Get(
      gl, "", shaders::HistoPyramidFullScreen_vs, shaders::HistoPyramidCoverage_fs, error);
    if (!reduce)
    {
      return "the coverage shader does not build: " + error;
    }
    SetCountingPassState(gl); // inside RenderPiece()'s ScopedGLState, as the whole pass
    reduce->Use();
    reduce->Set("source", 0);
    const int levels = static_cast<int>(this->CoverageSizes.size());
    for (int l = 0; l < levels; ++l)
    {
      if (l == 0)
      {
        BindTextureUnit(gl, 0, GL_TEXTURE_2D, this->HitColor.Get());
        reduce->Set2i("sourceSize", this->HitSize[0], this->HitSize[1]);
      }
      else
      {
        BindTextureUnit(gl, 0, GL_TEXTURE_2D, this->Coverage.Get());
        f.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, l - 1);
        f.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, l - 1);
        reduce->Set2i("sourceSize", this->CoverageSizes[l - 1][0], this->CoverageSizes[l - 1][1]);
      }
      reduce->Set("fromHits", l == 0 ? 1 : 0);
      f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, this->CoverageFBOs[l].Get());
      f.Viewport(0, 0, this->CoverageSizes[l][0], this->CoverageSizes[l][1]);
      f.DrawArrays(GL_TRIANGLES, 0, 3);
    }
    BindTextureUnit(gl, 0, GL_TEXTURE_2D, this->Coverage.Get());
    f.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    f.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, levels - 1);
    return "";
  }

  // Reduced target of frames drawn at an image sample distance above 1.
  Name ReducedFBO, ReducedColor, ReducedDepth;
  int ReducedSize[2] = { 0, 0 };
  // Set around the reduced pass: translucent surfaces there write the depth
  // of their nearest hit (the cells come back to front, so the last write of
  // a pixel is its nearest hit), which the second pass tests with.
  bool WriteTranslucentDepth = false;
  bool LastTranslucent = false;

  void ReleaseReduced()
  {
    this->ReducedFBO.Reset();
    this->ReducedColor.Reset();
    this->ReducedDepth.Reset();
    this->ReducedSize[0] = this->ReducedSize[1] = 0;
  }

  // The reduced target at exactly width x height. "" when ready, else why not.
  std::string PrepareReduced(int width, int height)
  {
    if (this->ReducedFBO && this->ReducedSize[0] == width && this->ReducedSize[1] == height)
    {
      return "";
    }
    this->ReleaseReduced();
    const GLApi& gl = *this->GL;
    const GLApi::Functions& f = gl.F();
    gl.TakeErrors();
    this->ReducedColor = Name(gl, NameKind::Texture);
    BindTextureUnit(gl, 0, GL_TEXTURE_2D, this->ReducedColor.Get());
    SetNearest(gl, GL_TEXTURE_2D);
    f.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    this->ReducedDepth = Name(gl, NameKind::Texture);
    BindTextureUnit(gl, 0, GL_TEXTURE_2D, this->ReducedDepth.Get());
    SetNearest(gl, GL_TEXTURE_2D);
    f.TexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, width, height, 0, GL_DEPTH_COMPONENT,
      GL_FLOAT, nullptr);
    this->ReducedFBO = Name(gl, NameKind::Framebuffer);
    f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, this->ReducedFBO.Get());
    f.FramebufferTexture2D(
      GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, this->ReducedColor.Get(), 0);
    f.FramebufferTexture2D(
      GL_DRAW_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, this->ReducedDepth.Get(), 0);
    const GLenum buffers[1] = { GL_COLOR_ATTACHMENT0 };
    f.DrawBuffers(1, buffers);
    std::string problem = FramebufferProblem(gl);
    const std::string errors = gl.TakeErrors();
    if (problem.empty() && !errors.empty())
    {
      problem = errors;
    }
    if (!problem.empty())
    {
      this->ReleaseReduced();
      return problem;
    }
    this->ReducedSize[0] = width;
    this->ReducedSize[1] = height;
    return "";
  }

  void ReleaseHitBuffers()
  {
    this->HitFBO.Reset();
    this->HitColor.Reset();
    this->HitDepth.Reset();
    this->HitFlag.Reset();
    this->HitSize[0] = this->HitSize[1] = 0;
  }

  // Buffers for the volume's projection, not the whole viewport: rounded up
  // to 64 pixels (at most the viewport's size), kept while the projection
  // fits in them, made again when it outgrows them or shrinks to less than a
  // quarter of their area. "" when ready, else why not.
  std::string PrepareFirstHit(int rectWidth, int rectHeight, const int viewport[4])
  {
    const GLApi& gl = *this->GL;
    const GLApi::Functions& f = gl.F();
    const int rounded[2] = { std::max(std::min((rectWidth + 63) / 64 * 64, viewport[2]), rectWidth),
      std::max(std::min((rectHeight + 63) / 64 * 64, viewport[3]), rectHeight) };
    if (this->HitFBO && this->HitSize[0] >= rectWidth && this->HitSize[1] >= rectHeight &&
      static_cast<double>(this->HitSize[0]) * this->HitSize[1] <=
        4.0 * static_cast<double>(rounded[0]) * rounded[1])
    {
      return "";
    }
    this->ReleaseHitBuffers();
    const int w = rounded[0], h = rounded[1];
    gl.TakeErrors();
    this->HitColor = Name(gl, NameKind::Texture);
    BindTextureUnit(gl, 0, GL_TEXTURE_2D, this->HitColor.Get());
    SetNearest(gl, GL_TEXTURE_2D);
    f.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    this->HitDepth = Name(gl, NameKind::Texture);
    BindTextureUnit(gl, 0, GL_TEXTURE_2D, this->HitDepth.Get());
    SetNearest(gl, GL_TEXTURE_2D);
    // The exact depth: a float on desktop OpenGL, its bits on GL ES (see the fragment stage).
    if (gl.IsES())
    {
      f.TexImage2D(GL_TEXTURE_2D, 0, GL_R32UI, w, h, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    }
    else
    {
      f.TexImage2D(GL_TEXTURE_2D, 0, GL_R32F, w, h, 0, GL_RED, GL_FLOAT, nullptr);
    }
    this->HitFlag = Name(gl, NameKind::Renderbuffer);
    f.BindRenderbuffer(GL_RENDERBUFFER, this->HitFlag.Get());
    f.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT16, w, h);
    this->HitFBO = Name(gl, NameKind::Framebuffer);
    f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, this->HitFBO.Get());
    f.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, this->HitColor.Get(), 0);
    f.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, this->HitDepth.Get(), 0);
    f.FramebufferRenderbuffer(GL_DRAW_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, this->HitFlag.Get());
    const GLenum buffers[2] = { GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1 };
    f.DrawBuffers(2, buffers);
    std::string problem = FramebufferProblem(gl);
    const std::string errors = gl.TakeErrors();
    if (problem.empty() && !errors.empty())
    {
      problem = errors;
    }
    if (!problem.empty())
    {
      this->ReleaseHitBuffers();
      return problem;
    }
    this->HitSize[0] = w;
    this->HitSize[1] = h;
    return "";
  }

  Program* ComposeProgram(const HistoPyramidWalk& walk, const IsosurfaceFrame& frame,
    const FrameVariant& v, std::string& error);
  // The program's defines and composed sources, which are also its ProgramCache key.
  void ProgramSources(const HistoPyramidWalk& walk, const IsosurfaceFrame& frame,
    const FrameVariant& v, std::string& defines, std::string& vertex, std::string& fragment) const;
  void SetUniforms(Program& program, const HistoPyramidGL& pyramid, const IsosurfaceFrame& frame,
    const FrameVariant& v);
  std::string DrawFirstHit(Program& program, const HistoPyramidGL& pyramid,
    const IsosurfaceFrame& frame, const FrameVariant& v, int coverageUnit, GLuint hostFramebuffer,
    const ScopedGLState& saved);
  void ClearHits();
  std::string CompositeHits();

  void DrawCells(bool points, std::uint64_t total)
  {
    const GLApi::Functions& f = this->GL->F();
    if (points)
    {
      f.DrawArrays(GL_POINTS, 0, static_cast<GLsizei>(total));
    }
    else
    {
      f.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(total));
    }
  }
};

IsosurfaceRendererGL::IsosurfaceRendererGL(std::shared_ptr<const GLApi> gl)
  : Impl(new Internals)
{
  this->Impl->GL = std::move(gl);
}

IsosurfaceRendererGL::~IsosurfaceRendererGL() = default;

std::uint64_t IsosurfaceRendererGL::GetProgramBuilds() const
{
  return this->Impl->Programs.GetBuilds();
}

int IsosurfaceRendererGL::ProgramsToBuild(
  const HistoPyramidGL& pyramid, const IsosurfaceFrame& frame) const
{
  const Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  if (pyramid.GetTotal() == 0)
  {
    return 0; // an empty picture draws nothing
  }
  const auto missing = [&impl](const char* vertex, const char* fragment)
  { return impl.Programs.Has("", vertex, fragment) ? 0 : 1; };
  int programs = 0;
  // An image sample distance that leaves fewer pixels: drawn into the reduced target (a
  // viewport of that size), then up to the viewport (RenderReduced).
  IsosurfaceFrame drawn = frame;
  int width = 0, height = 0;
  if (ReducedTarget(frame, width, height))
  {
    drawn.Viewport[0] = 0;
    drawn.Viewport[1] = 0;
    drawn.Viewport[2] = width;
    drawn.Viewport[3] = height;
    drawn.SampleDistance = 1.0f;
    programs += missing(shaders::HistoPyramidFullScreen_vs, shaders::HistoPyramidUpsample_fs);
  }
  FrameVariant v;
  if (!ChooseVariant(pyramid, drawn, gl.GetMaxPointSize(), v).empty() || v.Clipped)
  {
    return 0; // Render() draws nothing, or fails, without a program
  }
  // Render() keeps the first-hit pass and the hidden-point cull where their buffers can be made,
  // which is taken as given here (a context that cannot make them compiles the one-pass variant).
  const HistoPyramidWalk walk = pyramid.GetWalk();
  if (v.FirstHit && !impl.SharedHit)
  {
    const bool cullWanted = impl.Mode == HitCull::On ||
      (impl.Mode == HitCull::Auto && IsosurfaceRendererGL::HitCullPays(gl));
    v.HitCull = cullWanted && walk.TextureUnits + 1 <= gl.GetMaxVertexTextureUnits();
  }
  if (v.FirstHit)
  {
    programs += missing(shaders::HistoPyramidFullScreen_vs, shaders::HistoPyramidComposite_fs);
  }
  if (v.HitCull)
  {
    programs += missing(shaders::HistoPyramidFullScreen_vs, shaders::HistoPyramidCoverage_fs);
  }
  std::string defines, vertex, fragment;
  impl.ProgramSources(walk, drawn, v, defines, vertex, fragment);
  return programs + (impl.Programs.Has(defines, vertex, fragment) ? 0 : 1);
}

void IsosurfaceRendererGL::Release()
{
  this->Impl->ReleaseHitBuffers();
  this->Impl->ReleaseCoverage();
  this->Impl->ReleaseReduced();
  this->Impl->Programs.Clear();
  this->Impl->VertexArray.Reset();
}

std::uint64_t IsosurfaceRendererGL::GetFrameBufferBytes() const
{
  // First hit: RGBA8 colour, 32-bit depth (R32F or R32UI), 16-bit depth
  // buffer. Reduced target: RGBA8 colour, 32-bit float depth.
  // The coverage pyramid of hidden points: R8 levels.
  std::uint64_t bytes =
    static_cast<std::uint64_t>(this->Impl->HitSize[0]) * this->Impl->HitSize[1] * 10u +
    static_cast<std::uint64_t>(this->Impl->ReducedSize[0]) * this->Impl->ReducedSize[1] * 8u;
  for (const auto& size : this->Impl->CoverageSizes)
  {
    bytes += static_cast<std::uint64_t>(size[0]) * size[1];
  }
  return bytes;
}

void IsosurfaceRendererGL::SetHitCull(HitCull mode)
{
  this->Impl->Mode = mode;
}

HitCull IsosurfaceRendererGL::GetHitCull() const
{
  return this->Impl->Mode;
}

bool IsosurfaceRendererGL::HitCullPays(const GLApi& gl)
{
  // The browser hides the device behind "WebKit WebGL" unless asked, and the
  // page has not been measured with it: a WebGL context counts as unknown.
  auto lower = [](std::string text)
  {
    std::transform(text.begin(), text.end(), text.begin(),
      [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return text;
  };
  const std::string renderer = lower(gl.GetRenderer());
  const std::string version = lower(gl.GetVersion());
  for (const char* software : { "llvmpipe", "softpipe", "swiftshader", "software" })
  {
    if (renderer.find(software) != std::string::npos)
    {
      return false;
    }
  }
  return version.find("webgl") == std::string::npos;
}

//------------------------------------------------------------------------------
// Step 3: the program of this variant and pyramid walk.
void IsosurfaceRendererGL::Internals::ProgramSources(const HistoPyramidWalk& walk,
  const IsosurfaceFrame& frame, const FrameVariant& v, std::string& definesText,
  std::string& vertex, std::string& fragment) const
{
  const GLApi& gl = *this->GL;
  std::ostringstream defines;
  if (v.Points)
  {
    defines << "#define MEDISO_POINT_FOOTPRINT 1\n";
  }
  if (v.Translucent)
  {
    defines << "#define MEDISO_TRANSLUCENT 1\n";
  }
  if (v.FirstHit)
  {
    defines << "#define MEDISO_FIRST_HIT 1\n";
  }
  if (v.HitCull)
  {
    defines << "#define MEDISO_HIT_CULL 1\n";
  }
  if (v.Nearest())
  {
    defines << "#define MEDISO_NEAREST 1\n";
  }
  if (v.Cull)
  {
    defines << "#define MEDISO_CULL_CELLS 1\n";
  }
  if (v.ClipPlanes > 0)
  {
    defines << "#define MEDISO_CLIP_PLANES " << v.ClipPlanes << "\n";
  }
  defines << "#define MEDISO_LIGHTS " << frame.LightsUsed() << "\n";
  defines << "#define MEDISO_ISOVALUES " << (v.OneRankPerCell() ? v.Counted : MaximumIsovalues)
          << "\n";
  defines << walk.Defines;
  const bool conservative = !gl.IsES() && gl.HasConservativeDepth() && !v.FirstHit;
  const Hooks fragmentHooks = { { "FragmentExtensions",
    conservative ? "#extension GL_ARB_conservative_depth : require\nlayout(depth_greater) out "
                   "float gl_FragDepth;"
                 : "" } };
  definesText = defines.str();
  vertex = Compose(shaders::HistoPyramidIso_vs, walk.Hooks);
  fragment = Compose(shaders::HistoPyramidIso_fs, fragmentHooks);
}

Program* IsosurfaceRendererGL::Internals::ComposeProgram(const HistoPyramidWalk& walk,
  const IsosurfaceFrame& frame, const FrameVariant& v, std::string& error)
{
  std::string defines, vertex, fragment;
  this->ProgramSources(walk, frame, v, defines, vertex, fragment);
  Program* program = this->Programs.Get(*this->GL, defines, vertex, fragment, error);
  if (!program)
  {
    error = "the isosurface shaders do not build: " + error;
  }
  return program;
}

// Step 4: the pass's state, textures and uniforms (the walk's on units 0..),
// the vertex array and the viewport the cells are drawn in.
void IsosurfaceRendererGL::Internals::SetUniforms(Program& program, const HistoPyramidGL& pyramid,
  const IsosurfaceFrame& frame, const FrameVariant& v)
{
  const GLApi& gl = *this->GL;
  const GLApi::Functions& f = gl.F();
  SetSurfacePassState(gl, v.Translucent);
  if (v.Points && !gl.IsES())
  {
    f.Enable(GL_PROGRAM_POINT_SIZE); // gl_PointSize (always honoured on GL ES)
  }
  program.Use();
  pyramid.BindWalk(program, 0);
  program.Set4f("eyeIndex", v.EyeIndex);
  program.Set("backToFront", v.Translucent ? 1 : 0);
  program.Set("oneRankPerCell", v.OneRankPerCell() ? 1 : 0);
  program.Set("parallelProjection", frame.Parallel ? 1 : 0);
  program.SetMatrix4("indexToClip", v.IndexToClip.data());
  program.SetMatrix4("indexToView", v.IndexToView.data());
  program.SetMatrix4("clipToIndex", v.ClipToIndex.data());
  program.SetMatrix3("gradientToView", v.GradientToView);
  program.Set1fv("isovalues", MaximumIsovalues, v.IsoValues);
  program.Set4fv("isoColors", MaximumIsovalues, v.IsoColors);
  SetLightingUniforms(program, frame);
  if (v.ClipPlanes > 0)
  {
    program.Set4fv("clipPlanes", v.ClipPlanes, v.ClipPlaneValues);
  }
  // Where the cells are drawn: the viewport, or in the first-hit pass the
  // same viewport in buffers whose pixel (0, 0) is window pixel HitRect.xy.
  const int* viewport = frame.Viewport;
  const int drawOrigin[2] = { v.FirstHit ? viewport[0] - this->HitRect[0] : viewport[0],
    v.FirstHit ? viewport[1] - this->HitRect[1] : viewport[1] };
  program.Set2f("viewportSize", static_cast<float>(viewport[2]), static_cast<float>(viewport[3]));
  const float viewportF[4] = { static_cast<float>(drawOrigin[0]), static_cast<float>(drawOrigin[1]),
    static_cast<float>(viewport[2]), static_cast<float>(viewport[3]) };
  program.Set4f("viewport", viewportF);
  program.Set("maxPointSize", gl.GetMaxPointSize());
  // Pixels whose centres lie on a footprint's edges stay covered whatever the
  // tie rule, and a point size rounded down to the granularity still covers.
  program.Set("pointMargin", 0.1f + gl.GetPointSizeGranularity());
  if (!this->VertexArray)
  {
    this->VertexArray = Name(gl, NameKind::VertexArray);
  }
  f.BindVertexArray(this->VertexArray.Get());
  f.Viewport(drawOrigin[0], drawOrigin[1], viewport[2], viewport[3]);
}

// Step 5 (first-hit pass): the cells into the buffers, then their hits into
// the host's framebuffer. "" or why not.
std::string IsosurfaceRendererGL::Internals::DrawFirstHit(Program& program,
  const HistoPyramidGL& pyramid, const IsosurfaceFrame& frame, const FrameVariant& v,
  int coverageUnit, GLuint hostFramebuffer, const ScopedGLState& saved)
{
  const GLApi& gl = *this->GL;
  const GLApi::Functions& f = gl.F();
  // Pass 1: into the buffers, cleared to no hit; every primitive has the
  // same depth and the test is GL_LESS, so each pixel keeps its first hit
  // in drawing order (front to back: the nearest), and the test runs
  // before the fragment stage.
  f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, this->HitFBO.Get());
  if (!this->SharedHit)
  {
    this->ClearHits();
  }
  f.DepthFunc(GL_LESS);
  if (!v.HitCull)
  {
    this->DrawCells(v.Points, v.Total);
  }
  else
  {
    // In ranges, front to back. Before each range but the first, the hits
    // drawn so far make the coverage pyramid (which leaves its own program,
    // framebuffer and unit 0 bound), and the range's points whose pixels all
    // hold a hit already are clipped in the vertex stage: the depth test
    // would have rejected all their fragments, so the image is the same.
    program.Set("hitCoverage", coverageUnit);
    program.Set("coverageLevels", static_cast<int>(this->CoverageSizes.size()));
    program.Set2f("coverageOrigin", static_cast<float>(frame.Viewport[0] - this->HitRect[0]),
      static_cast<float>(frame.Viewport[1] - this->HitRect[1]));
    const int ranges = IsosurfaceRendererGL::HitCullRanges;
    std::uint64_t begin = 0;
    for (int r = 1; r <= ranges; ++r)
    {
      const std::uint64_t end = v.Total * static_cast<std::uint64_t>(r) / ranges;
      if (end <= begin)
      {
        continue;
      }
      if (begin > 0)
      {
        const std::string problem = this->BuildCoverage();
        if (!problem.empty())
        {
          return problem;
        }
        this->SetUniforms(program, pyramid, frame, v);
        f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, this->HitFBO.Get());
        f.DepthFunc(GL_LESS);
      }
      BindTextureUnit(gl, coverageUnit, GL_TEXTURE_2D, this->Coverage.Get());
      program.Set("cullHidden", begin > 0 ? 1 : 0);
      f.DrawArrays(GL_POINTS, static_cast<GLint>(begin), static_cast<GLsizei>(end - begin));
      begin = end;
    }
  }
  f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, hostFramebuffer);
  saved.RestoreDepthFunc();
  return this->SharedHit ? "" : this->CompositeHits();
}

// The bound hit buffers cleared to no hit.
void IsosurfaceRendererGL::Internals::ClearHits()
{
  const GLApi::Functions& f = this->GL->F();
  const GLfloat clearColor[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
  const GLfloat one = 1.0f;
  f.ClearBufferfv(GL_COLOR, 0, clearColor);
  f.ClearBufferfv(GL_DEPTH, 0, &one);
  // (Attachment 1 needs no clear: its texels are read only where a hit wrote them.)
}

// Pass 2: the hits into the bound (host's) framebuffer over HitRect, with the
// depth test as it is set. "" or why not.
std::string IsosurfaceRendererGL::Internals::CompositeHits()
{
  const GLApi& gl = *this->GL;
  const GLApi::Functions& f = gl.F();
  std::string error;
  Program* composite = this->Programs.Get(
    gl, "", shaders::HistoPyramidFullScreen_vs, shaders::HistoPyramidComposite_fs, error);
  if (!composite)
  {
    return "the first-hit composite shader does not build: " + error;
  }
  composite->Use();
  BindTextureUnit(gl, 0, GL_TEXTURE_2D, this->HitColor.Get());
  BindTextureUnit(gl, 1, GL_TEXTURE_2D, this->HitDepth.Get());
  composite->Set("hitColor", 0);
  composite->Set("hitDepth", 1);
  composite->Set2i("hitOrigin", this->HitRect[0], this->HitRect[1]);
  f.Viewport(this->HitRect[0], this->HitRect[1], this->HitRect[2], this->HitRect[3]);
  f.DrawArrays(GL_TRIANGLES, 0, 3);
  return "";
}

//------------------------------------------------------------------------------
namespace
{
// `frame` in the index space of a piece whose cell (0, 0, 0) is cell `offset`
// of the volume: its points move by -offset, so IndexToView gains the
// translation and every clipping plane's constant its value at the offset.
IsosurfaceFrame PieceFrame(const IsosurfaceFrame& frame, const int offset[3])
{
  IsosurfaceFrame local = frame;
  for (int r = 0; r < 4; ++r)
  {
    local.IndexToView[4 * r + 3] += frame.IndexToView[4 * r] * offset[0] +
      frame.IndexToView[4 * r + 1] * offset[1] + frame.IndexToView[4 * r + 2] * offset[2];
  }
  for (auto& plane : local.ClipPlanes)
  {
    plane[3] += plane[0] * offset[0] + plane[1] * offset[1] + plane[2] * offset[2];
  }
  return local;
}
} // namespace

bool IsosurfaceRendererGL::Render(const HistoPyramidGL& pyramid, const IsosurfaceFrame& frame,
  IsosurfaceFrameStats& stats, std::string& error)
{
  IsosurfacePiece piece;
  piece.Pyramid = &pyramid;
  return this->Render(std::vector<IsosurfacePiece>{ piece }, frame, stats, error);
}

bool IsosurfaceRendererGL::Render(const std::vector<IsosurfacePiece>& pieces,
  const IsosurfaceFrame& frame, IsosurfaceFrameStats& stats, std::string& error)
{
  Internals& impl = *this->Impl;
  stats = IsosurfaceFrameStats();
  bool ready = true;
  std::uint64_t total = 0;
  for (const IsosurfacePiece& piece : pieces)
  {
    if (!piece.Pyramid)
    {
      error = "a piece of the volume has no pyramid";
      return false;
    }
    ready = ready && piece.Pyramid->IsBuilt() && piece.Pyramid->GetGLApi() == impl.GL.get();
    total += piece.Pyramid->GetTotal();
  }
  // An image sample distance above 1 that leaves fewer pixels: the reduced
  // target, then up to the viewport.
  int width = 0, height = 0;
  if (ready && total > 0 && ReducedTarget(frame, width, height))
  {
    return this->RenderReduced(pieces, frame, width, height, stats, error);
  }
  // One volume: drawn as it is. Bricks: each in its own index space, in one pass.
  if (pieces.size() == 1 && pieces[0].Offset[0] == 0 && pieces[0].Offset[1] == 0 &&
    pieces[0].Offset[2] == 0)
  {
    return this->RenderPiece(*pieces[0].Pyramid, frame, stats, error);
  }
  // The pieces that take the first-hit pass (opaque, points: wholly beyond
  // the near plane) share one: buffers over the union of their projected
  // rectangles, cleared once, their cells drawn in the pieces' order (front
  // to back, so each pixel's first hit is still the nearest), composited
  // once. Any other piece draws in one pass; the depth test joins both.
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  int rect[4] = { 0, 0, 0, 0 };
  bool shared = false;
  if (frame.FirstHitPass && ready)
  {
    int lo[2] = { INT_MAX, INT_MAX }, hi[2] = { INT_MIN, INT_MIN };
    for (const IsosurfacePiece& piece : pieces)
    {
      FrameVariant v;
      if (piece.Pyramid->GetTotal() == 0 ||
        !ChooseVariant(*piece.Pyramid, PieceFrame(frame, piece.Offset), gl.GetMaxPointSize(), v)
           .empty() ||
        !v.FirstHit || v.Clipped)
      {
        continue;
      }
      int r[4];
      ProjectedRectangle(v.IndexToClip, v.Cells, frame.Viewport, r);
      for (int a = 0; a < 2; ++a)
      {
        lo[a] = std::min(lo[a], r[a]);
        hi[a] = std::max(hi[a], r[a] + r[2 + a]);
      }
      shared = true;
    }
    rect[0] = lo[0];
    rect[1] = lo[1];
    rect[2] = hi[0] - lo[0];
    rect[3] = hi[1] - lo[1];
  }
  ScopedGLState saved(gl, 2);
  GLint hostFramebuffer = 0;
  f.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &hostFramebuffer);
  if (shared)
  {
    gl.TakeErrors();
    std::copy(rect, rect + 4, impl.HitRect);
    shared = impl.PrepareFirstHit(rect[2], rect[3], frame.Viewport).empty();
    if (shared)
    {
      f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, impl.HitFBO.Get());
      impl.ClearHits();
    }
    f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(hostFramebuffer));
  }
  impl.SharedHit = shared;
  bool drawn = true;
  for (const IsosurfacePiece& piece : pieces)
  {
    if (piece.Pyramid->IsBuilt() && piece.Pyramid->GetTotal() == 0)
    {
      continue; // nothing crosses in this brick
    }
    IsosurfaceFrame local = PieceFrame(frame, piece.Offset);
    local.FirstHitPass = shared;
    IsosurfaceFrameStats pieceStats;
    drawn = this->RenderPiece(*piece.Pyramid, local, pieceStats, error);
    if (!drawn)
    {
      break;
    }
    stats.Primitives += pieceStats.Primitives;
    stats.PointFootprint = stats.PointFootprint || pieceStats.PointFootprint;
    stats.FirstHit = stats.FirstHit || pieceStats.FirstHit;
    stats.HitCull = stats.HitCull || pieceStats.HitCull;
  }
  impl.SharedHit = false;
  if (drawn && stats.FirstHit)
  {
    // The hits into the host's framebuffer, in the state of an opaque surface pass.
    SetSurfacePassState(gl, false);
    if (!impl.VertexArray)
    {
      impl.VertexArray = Name(gl, NameKind::VertexArray);
    }
    f.BindVertexArray(impl.VertexArray.Get());
    const std::string problem = impl.CompositeHits();
    const std::string errors = gl.TakeErrors();
    if (!problem.empty() || !errors.empty())
    {
      error = problem.empty() ? "drawing the isosurfaces failed: " + errors : problem;
      return false;
    }
  }
  return drawn;
}

bool IsosurfaceRendererGL::RenderPiece(const HistoPyramidGL& pyramid, const IsosurfaceFrame& frame,
  IsosurfaceFrameStats& stats, std::string& error)
{
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  stats = IsosurfaceFrameStats();
  if (!pyramid.IsBuilt())
  {
    error = "the pyramid is not built";
    return false;
  }
  if (pyramid.GetGLApi() != impl.GL.get())
  {
    error = "the pyramid belongs to another context";
    return false;
  }
  const std::uint64_t total = pyramid.GetTotal();
  stats.Primitives = total;
  if (total == 0)
  {
    return true; // nothing crosses: an empty, correct picture
  }
  if (total > static_cast<std::uint64_t>(INT_MAX))
  {
    error = "more active cells than one draw call can take";
    return false;
  }
  // The stored levels the vertex stage reads, and the volume.
  const HistoPyramidWalk walk = pyramid.GetWalk();
  if (walk.TextureUnits > gl.GetMaxVertexTextureUnits())
  {
    error = "the pyramid needs " + std::to_string(walk.TextureUnits) +
      " vertex texture units, the context has " + std::to_string(gl.GetMaxVertexTextureUnits());
    return false;
  }

  // 1. Choose the variant.
  FrameVariant v;
  const std::string unusable = ChooseVariant(pyramid, frame, gl.GetMaxPointSize(), v);
  if (!unusable.empty())
  {
    error = unusable;
    return false;
  }
  if (v.Clipped)
  {
    stats.Primitives = 0;
    return true; // a clipping plane removes the whole volume
  }

  // 2. The first-hit pass's buffers, made before the program is chosen, so
  //    that a context that cannot make them draws in one pass instead (the
  //    same image).
  ScopedGLState saved(gl, std::max(walk.TextureUnits + 1, 2));
  gl.TakeErrors();
  GLint hostFramebuffer = 0;
  f.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &hostFramebuffer);
  if (v.FirstHit && !impl.SharedHit)
  {
    ProjectedRectangle(v.IndexToClip, v.Cells, frame.Viewport, impl.HitRect);
    const std::string problem =
      impl.PrepareFirstHit(impl.HitRect[2], impl.HitRect[3], frame.Viewport);
    f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(hostFramebuffer));
    v.FirstHit = problem.empty();
  }
  // Hidden points dropped in the first-hit pass of a volume drawn alone
  // (pieces sharing one pass draw theirs in one range each), where it is
  // wanted, a vertex texture unit is left for the coverage pyramid, and the
  // pyramid can be made (else the same image in one range).
  const bool cullWanted = impl.Mode == HitCull::On ||
    (impl.Mode == HitCull::Auto && IsosurfaceRendererGL::HitCullPays(gl));
  if (v.FirstHit && !impl.SharedHit && cullWanted &&
    walk.TextureUnits + 1 <= gl.GetMaxVertexTextureUnits())
  {
    v.HitCull = impl.PrepareCoverage().empty();
    f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(hostFramebuffer));
  }

  // 3. Compose the program, 4. set its state and uniforms.
  Program* program = impl.ComposeProgram(walk, frame, v, error);
  if (!program)
  {
    return false;
  }
  impl.SetUniforms(*program, pyramid, frame, v);
  impl.LastTranslucent = v.Translucent;
  if (v.Translucent && impl.WriteTranslucentDepth)
  {
    f.DepthMask(GL_TRUE);
    f.DepthFunc(GL_ALWAYS);
  }

  // 5. Draw the cells, through the first-hit pass or in one.
  if (v.FirstHit)
  {
    const std::string problem = impl.DrawFirstHit(
      *program, pyramid, frame, v, walk.TextureUnits, static_cast<GLuint>(hostFramebuffer), saved);
    if (!problem.empty())
    {
      error = problem;
      return false;
    }
  }
  else
  {
    impl.DrawCells(v.Points, total);
  }
  const std::string errors = gl.TakeErrors();
  if (!errors.empty())
  {
    error = "drawing the isosurfaces failed: " + errors;
    return false;
  }
  stats.PointFootprint = v.Points;
  stats.FirstHit = v.FirstHit;
  stats.HitCull = v.HitCull;
  return true;
}

//------------------------------------------------------------------------------
bool IsosurfaceRendererGL::RenderReduced(const std::vector<IsosurfacePiece>& pieces,
  const IsosurfaceFrame& frame, int width, int height, IsosurfaceFrameStats& stats,
  std::string& error)
{
  Internals& impl = *this->Impl;
  const GLApi& gl = *impl.GL;
  const GLApi::Functions& f = gl.F();
  ScopedGLState saved(gl, 2);
  GLint hostFramebuffer = 0;
  f.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &hostFramebuffer);
  gl.TakeErrors();
  const std::string problem = impl.PrepareReduced(width, height);
  f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(hostFramebuffer));
  IsosurfaceFrame reduced = frame;
  reduced.SampleDistance = 1.0f;
  if (!problem.empty())
  {
    return this->Render(pieces, reduced, stats, error); // every pixel: the same surfaces
  }

  // Pass 1: the whole frame into the reduced target, cleared to no surface,
  // as into a host's framebuffer of that size with GL_LESS.
  f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, impl.ReducedFBO.Get());
  f.Disable(GL_SCISSOR_TEST);
  f.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  f.DepthMask(GL_TRUE);
  const GLfloat clearColor[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
  const GLfloat one = 1.0f;
  f.ClearBufferfv(GL_COLOR, 0, clearColor);
  f.ClearBufferfv(GL_DEPTH, 0, &one);
  f.DepthFunc(GL_LESS);
  reduced.Viewport[0] = 0;
  reduced.Viewport[1] = 0;
  reduced.Viewport[2] = width;
  reduced.Viewport[3] = height;
  impl.WriteTranslucentDepth = true;
  const bool drawn = this->Render(pieces, reduced, stats, error);
  impl.WriteTranslucentDepth = false;
  f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(hostFramebuffer));
  if (!drawn)
  {
    return false;
  }

  // Pass 2: up to the host's viewport with the host's depth test.
  saved.RestoreDepthFunc();
  Program* upsample = impl.Programs.Get(
    gl, "", shaders::HistoPyramidFullScreen_vs, shaders::HistoPyramidUpsample_fs, error);
  if (!upsample)
  {
    error = "the sample-distance shader does not build: " + error;
    return false;
  }
  f.Enable(GL_DEPTH_TEST);
  SetSurfacePassBlending(gl, impl.LastTranslucent);
  upsample->Use();
  BindTextureUnit(gl, 0, GL_TEXTURE_2D, impl.ReducedColor.Get());
  BindTextureUnit(gl, 1, GL_TEXTURE_2D, impl.ReducedDepth.Get());
  upsample->Set("reducedColor", 0);
  upsample->Set("reducedDepth", 1);
  const float viewport[4] = { static_cast<float>(frame.Viewport[0]),
    static_cast<float>(frame.Viewport[1]), static_cast<float>(frame.Viewport[2]),
    static_cast<float>(frame.Viewport[3]) };
  upsample->Set4f("viewport", viewport);
  upsample->Set2i("reducedSize", width, height);
  if (!impl.VertexArray)
  {
    impl.VertexArray = Name(gl, NameKind::VertexArray);
  }
  f.BindVertexArray(impl.VertexArray.Get());
  f.Viewport(frame.Viewport[0], frame.Viewport[1], frame.Viewport[2], frame.Viewport[3]);
  f.DrawArrays(GL_TRIANGLES, 0, 3);
  const std::string errors = gl.TakeErrors();
  if (!errors.empty())
  {
    error = "drawing the isosurfaces at a sample distance failed: " + errors;
    return false;
  }
  stats.SampleDistance = frame.SampleDistance;
  return true;
}

} // namespace mediso
