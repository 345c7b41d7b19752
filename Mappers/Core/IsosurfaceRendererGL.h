// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file IsosurfaceRendererGL.h
 * @brief Draws the exact isosurfaces of a HistoPyramidGL by cell rasterisation (no VTK).
 *
 * The drawing half of the GPU path (Liu, Clapworthy & Dong, "Fast
 * isosurface rendering on a GPU by cell rasterization", 2009; section 4.1 of
 * "Hardware Accelerated Medical Data Visualisation on the Web"), on the
 * common subset of OpenGL 3.2 core and OpenGL ES 3.0 / WebGL2:
 *
 * -# One draw call with no vertex attributes draws every active
 *    (cell, isovalue) pair. The vertex stage (HistoPyramidIso_vs.glsl)
 *    walks down the pyramid to its cell, visiting children nearest-first
 *    for the current eye, so the primitives come out front to back with no
 *    sort (back to front for translucency), and makes the cell's footprint:
 *    a point sprite over the projected box that holds the surface in the
 *    cell where points provably cover every cell (the volume beyond the
 *    near plane, no cell wider than the largest point), otherwise a quad
 *    (an instanced strip of 4 vertices) over that box cut by the near plane.
 * -# The fragment stage (HistoPyramidIso_fs.glsl) finds the first root of
 *    the cubic the trilinear interpolant makes along the ray, shades it with
 *    Phong (the frame's lights and material) and writes its depth, so the
 *    surfaces composite exactly with other geometry.
 * -# Opaque frames draw each primitive's one isovalue, front to back, with
 *    depth writes. With point footprints they go through the first-hit pass
 *    (IsosurfaceFrame::FirstHitPass): the cells into the renderer's own
 *    buffers, where a constant-depth test keeps each pixel's first hit in
 *    drawing order (the nearest) before any ray is cast, then that colour and
 *    depth into the host's framebuffer. Translucent frames draw each cell
 *    once, back to front, compositing all its isovalues' hits in depth order.
 * -# Clipping planes (IsosurfaceFrame::ClipPlanes, a cropping box among
 *    them) cut each fragment's ray before its root is sought: the part of
 *    the volume they keep is convex, so the ray keeps one interval of its
 *    piece in the cell, and the first root in that interval is the first
 *    visible hit. A surface behind a clipped one is therefore seen through
 *    the cut, in the first-hit pass (only fragments that hit write) and in
 *    translucent compositing alike; cut faces are left open. The vertex
 *    stage skips cells wholly on a removed side, and planes that keep the
 *    whole volume are not compiled in.
 * -# Programs are compiled per variant (footprint, opaque or translucent,
 *    first hit, lights, isovalues, clipping planes, the pyramid's layout): a software
 *    rasteriser runs every branch of a shader under SIMD masks, so one
 *    mode's code must not sit in another's program.
 *
 * Render() runs in named steps, as vtkVolumeShaderComposer.h names its
 * ReplaceShader* steps: choose the variant (isovalues in the pyramid's
 * order, matrices, footprint, first hit, culling), make the first-hit
 * buffers, compose the program (the variant's defines and the pyramid's
 * walk, HistoPyramidGL::GetWalk(): the renderer knows nothing of the
 * pyramid's textures), set its state and uniforms (the walk's bound by
 * HistoPyramidGL::BindWalk()), draw the cells (through the first-hit pass
 * or in one).
 *
 * A frame with an image sample distance above 1
 * (IsosurfaceFrame::SampleDistance, a host's interactive frames) runs all of
 * this into the renderer's reduced target (the viewport divided by the
 * distance, colour and a depth texture), then draws that up to the viewport
 * (HistoPyramidUpsample_fs.glsl: each window pixel takes its reduced pixel's
 * colour and depth, with the host's depth test; premultiplied "over" for
 * translucent surfaces, whose reduced pass keeps the nearest hit's depth).
 * The still frame (distance 1) does not touch the reduced target. Where
 * the target cannot be made, the frame is drawn at every pixel instead.
 *
 * A volume kept as bricks in a pool (IsosurfaceScene's default) is one
 * pyramid and is drawn as a whole volume: its walk places each cell in the
 * volume (HistoPyramidGL::GetDrawnCells() gives the box the footprint and
 * culling tests use). Bricks the pool cannot hold (IsosurfaceScene over a
 * texture limit or a GPU budget) are drawn as pieces: one pyramid per
 * brick, each over its own sub-volume and counting only the cells the
 * brick owns, placed by its
 * offset in the volume's cell-index space. Each piece is drawn as above
 * with the frame moved into the piece's index space (its matrices and
 * clipping planes shifted by the offset), in the order given (the scene
 * passes a visibility order: nearest first, back to front for translucent
 * surfaces). Opaque pieces drawn with points share one first-hit pass:
 * buffers over the union of their projected rectangles, cleared once, every
 * piece's cells drawn into them in that order (so each pixel's first hit is
 * still the nearest), composited once; other pieces draw in one pass, and
 * the depth test joins both.
 *
 * Hidden points (SetHitCull()): the first-hit pass of a volume drawn as one
 * pyramid draws its primitives in HitCullRanges ranges, front to back.
 * After each range but the last, a coverage pyramid of the hit buffer is
 * made (HistoPyramidCoverage_fs.glsl: level l is 1 over a block of
 * 2^(l + 1) pixels that all hold a hit), and the vertex stage of the next
 * ranges clips a point whose pixels all hold a hit already, before its
 * setup, binning and fragments. The depth test would have rejected every
 * fragment of such a point (a pixel's first hit rejects every later one), so
 * the image is exactly that of one range (and the primitives drawn are
 * still counted as the pyramid's total). It pays where
 * points' setup and fragments cost the hardware (a GPU); a software
 * rasteriser measured no gain (the ranges' flushes and pyramids cost what
 * was saved), so it is on by default only on hardware renderers. Pieces
 * sharing one first-hit pass (bricks the pool cannot hold) are drawn
 * without it.
 *
 * Hosts do not call the renderer: IsosurfaceScene does.
 *
 * The renderer draws into the framebuffer bound when Render() is called,
 * with the depth function the host has set, and restores every piece of
 * state it changes.
 */
#ifndef MedicalIsosurfaces_IsosurfaceRendererGL_h
#define MedicalIsosurfaces_IsosurfaceRendererGL_h

#include "IsosurfaceFrame.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace mediso
{
class GLApi;
class HistoPyramidGL;

namespace glcore
{
class Program;
}

/// What a frame did.
struct IsosurfaceFrameStats
{
  std::uint64_t Primitives = 0;
  bool PointFootprint = false; ///< points (else quads over the box)
  bool FirstHit = false;       ///< drawn through the first-hit pass
  bool HitCull = false;        ///< the first-hit pass dropped hidden points
  float SampleDistance = 1.0f; ///< image sample distance drawn at (1: every pixel)
};

/// One pyramid of a volume kept as bricks, and where its cell (0, 0, 0) lies in the volume.
struct IsosurfacePiece
{
  const HistoPyramidGL* Pyramid = nullptr;
  int Offset[3] = { 0, 0, 0 };
};

class IsosurfaceRendererGL
{
public:
  /**
   * The ranges a first-hit pass with hidden points dropped is drawn in: 4,
   * the fastest of 4, 16 and 64 on a GPU (docs/histopyramid.md, "Hidden
   * points in the first-hit pass"): each range after the first costs a
   * pyramid and a wait for the hits before it, and the first quarter of
   * the primitives (the nearest, roughly) already hides much of the rest.
   */
  static constexpr int HitCullRanges = 4;

  explicit IsosurfaceRendererGL(std::shared_ptr<const GLApi> gl);
  ~IsosurfaceRendererGL();
  IsosurfaceRendererGL(const IsosurfaceRendererGL&) = delete;
  IsosurfaceRendererGL& operator=(const IsosurfaceRendererGL&) = delete;

  /**
   * Draw the isosurfaces of `pyramid` (built, with the same GLApi) for
   * `frame` into the bound draw framebuffer. False, with the reason in
   * @a error, when a program does not build, the context lacks what the
   * frame needs, or a GL call fails.
   */
  bool Render(const HistoPyramidGL& pyramid, const IsosurfaceFrame& frame,
    IsosurfaceFrameStats& stats, std::string& error);

  /**
   * Draw the pieces of a volume kept as bricks (each built, with the same
   * GLApi and isovalues), in the order given. Primitives is their sum.
   */
  bool Render(const std::vector<IsosurfacePiece>& pieces, const IsosurfaceFrame& frame,
    IsosurfaceFrameStats& stats, std::string& error);

  /**
   * Whether the first-hit pass drops hidden points (default HitCull::Auto:
   * on hardware renderers only; see the class's documentation). The image
   * is the same either way.
   */
  void SetHitCull(HitCull mode);
  HitCull GetHitCull() const;

  /// Whether HitCull::Auto drops hidden points on `gl`'s context: not where its renderer is
  /// a software one (Mesa's llvmpipe or softpipe, SwiftShader) or hidden (WebGL).
  static bool HitCullPays(const GLApi& gl);

  /// Bytes of the first-hit pass's buffers and the reduced target (0 until one is drawn).
  std::uint64_t GetFrameBufferBytes() const;

  /// Frees every GL object (the context must be current).
  void Release();

  /// Programs this renderer has compiled so far (each variant of the isosurface shaders and of
  /// its passes, on its first use): what a frame compiled is the difference across it.
  std::uint64_t GetProgramBuilds() const;

  /**
   * The programs Render() of `pyramid` (built, drawn alone) for `frame` would compile: the
   * isosurface shaders' variant it would choose (footprint, translucency, first-hit pass,
   * isovalues counted, clipping, lights, the pyramid's walk) and the passes' own (the first-hit
   * composite, the hidden-point cull's coverage, the sample distance's upsampling), looked up in
   * the compiled ones without compiling anything. A host that predicts a frame's one-off work
   * asks this rather than keep its own key of what was compiled: a key of level and
   * translucency missed that a skin over a bone needs another variant than a skin alone (issue
   * 30: a drag's first frame predicted at 86 ms compiled for 0.6 s). The first-hit pass and the
   * cull are taken as made where the frame asks for them. 0 where Render() would draw nothing
   * (no active pair, clipped away) or fail.
   */
  int ProgramsToBuild(const HistoPyramidGL& pyramid, const IsosurfaceFrame& frame) const;

private:
  // The frame drawn into the reduced target of width x height, then up to its viewport.
  bool RenderReduced(const std::vector<IsosurfacePiece>& pieces, const IsosurfaceFrame& frame,
    int width, int height, IsosurfaceFrameStats& stats, std::string& error);
  // One piece at full resolution into the bound framebuffer.
  bool RenderPiece(const HistoPyramidGL& pyramid, const IsosurfaceFrame& frame,
    IsosurfaceFrameStats& stats, std::string& error);

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

} // namespace mediso

#endif
