// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file mediso-render.cxx
 * @brief mediso-render: exact GPU isosurfaces of a MetaImage volume, headless (EGL, no X, no VTK).
 *
 * The GPU core (mediso::IsosurfaceScene, the same code the ParaView mapper
 * and the web page run) on a context of its own: it renders one
 * image, or runs the paper's protocol (360 one-degree rotations; the sweep of
 * 95 equidistant isovalues) and prints a table. The scene follows the
 * ParaView mapper's conventions (VTK's camera, a headlight, the volume's
 * spacing, origin and direction), so its images compare with ParaView's.
 * Run with --help for the options.
 *
 * Exit status: 0 done; 2 bad options; 3 the volume cannot be read or is not
 * usable; 4 no usable OpenGL (no EGL display, too old a context, the bricks
 * the isovalues cross over the GPU budget); 1 anything else that failed.
 * A --sweep goes on past isovalues whose crossed bricks are over the GPU
 * budget, says how many in one line and times the others (exit 0); it exits
 * 4 only where no isovalue of the sweep fits.
 */
#include "Camera.h"
#include "GLApiFunctions.h"
#include "GLProbe.h"
#include "HeadlessContext.h"
#include "IsosurfaceScene.h"
#include "MetaImage.h"
#include "PngWriter.h"
#include "SceneView.h"
#include "ThreadedFor.h"
#include "VolumeSources.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <new>
#include <sstream>
#include <string>
#include <vector>

namespace
{
using namespace mediso;
using Clock = std::chrono::steady_clock;

const char* const Usage = R"(usage: mediso-render VOLUME.mha|VOLUME.mhd|phantom:N [options]

Renders the isosurfaces of an uncompressed MetaImage volume on the GPU (cell
rasterisation over a HistoPyramid), with no window and no X display (EGL).

Volume:
  phantom:N             in place of a file: the MedicalPhantom head on N^3
                        points (int16 HU, spacing 240/(N-1) mm, no noise)
  --resample WxHxD      resample the volume (trilinear) to WxHxD points over
                        the same bounds, e.g. the head CT to 512x512x216
  --write-volume F.mha  write the volume used (after --resample)

Scene:
  --iso V[:R,G,B[,A]]   an isosurface: value, colour (0..1) and opacity
                        (default colour 0.93,0.85,0.75, opacity 1); up to 8
  --size WxH            image size in pixels (default 1024x768)
  --azimuth DEG         camera rotation about the view up (default 0)
  --elevation DEG       camera rotation about the view's horizontal axis (default 0)
  --zoom F              zoom factor (default 1)
  --parallel            parallel projection (default perspective)
  --background R,G,B    background colour (default 0.1,0.12,0.16)
  --material A,D,S,P    ambient, diffuse, specular, specular power
                        (default 0.15,0.8,0.25,30)
  --no-points           never draw point footprints (always quads)
  --no-first-hit        draw opaque frames in one pass
  --hit-cull auto|on|off
                        drop hidden points in the first-hit pass (drawn in 4
                        ranges, each culled against the hits before it; the same
                        image); auto (default): on hardware renderers only, off
                        on software ones (llvmpipe, softpipe, SwiftShader)
  --clip A,B,C,D        keep the part of the volume where A x + B y + C z + D >= 0
                        (world coordinates, as VTK's clipping planes); up to 6
  --crop I0,I1,J0,J1,K0,K1
                        keep the box of point indices I0..I1, J0..J1, K0..K1
                        (cropping); cut faces are left open
  --sample-distance D   image sample distance (>= 1, default 1): draw into a target of
                        size / D pixels, then up to the image (interactive frames)
The camera is VTK's: reset to the volume's bounds (view angle 30 degrees,
looking down -z), then azimuth, elevation, orthogonalised view up, zoom.

Output:
  --output FILE.png     write the image
  --stats               print one JSON line: primitives, build/draw/frame ms,
                        GPU bytes, the GL renderer
  --frames N            draw the image N times (timing; default 1)

The paper's protocol (prints a table):
  --rotate [N]          N one-degree rotations (azimuth), default 360
  --sweep [N]           N equidistant isovalues strictly inside the data
                        range (default 95), each built and drawn; those whose
                        crossed bricks exceed the GPU budget are counted in one
                        line and left out of the row (exit 0; 4 if all are)

Context:
  --api es|gl           OpenGL ES 3.0 (the WebGL2 subset; default) or OpenGL 3.2 core
  --max-texture-size N  use 3D textures of at most N texels a side (default: the
                        context's GL_MAX_3D_TEXTURE_SIZE); a volume over it is kept
                        as bricks, only those the isovalues cross on the GPU
  --gpu-budget-mb M     GPU memory for the volume's textures and pyramids, in MB
                        (default: half the device's memory where OpenGL tells it,
                        GL_NVX_gpu_memory_info or GL_ATI_meminfo, else 1 GiB);
                        MB are 10^6 bytes, as in ParaView; a volume over it is kept as bricks
  --no-brick-pool       keep each resident brick as its own texture and pyramid
                        (default: the bricks in one pool texture with one pyramid,
                        where it takes at most 3x their own pyramids' GPU memory;
                        --stats's pool_reason says why not)
MEDISO_EGL_PLATFORM=surfaceless|device|default picks the EGL display.
)";

struct Options
{
  std::string Input;
  std::vector<IsosurfaceLook> Surfaces;
  int Width = 1024, Height = 768;
  double Azimuth = 0.0, Elevation = 0.0, Zoom = 1.0;
  bool Parallel = false;
  double Background[3] = { 0.1, 0.12, 0.16 };
  double Material[4] = { 0.15, 0.8, 0.25, 30.0 };
  bool Points = true, FirstHit = true;
  std::vector<std::array<double, 4>> ClipPlanes; // world
  bool Crop = false;
  double CropBox[6] = { 0, 0, 0, 0, 0, 0 }; // point indices
  double SampleDistance = 1.0;
  std::string Output;
  int Resample[3] = { 0, 0, 0 };
  std::string WriteVolume;
  bool Stats = false;
  int Frames = 1;
  int Rotate = 0;
  int Sweep = 0;
  bool ES = true;
  int MaxTextureSize = 0;      // 0: the context's
  std::uint64_t GPUBudget = 0; // bytes; 0: the scene's default
  bool BrickPool = true;
  HitCull Cull = HitCull::Auto;
};

struct UsageError
{
  std::string Text;
};

std::vector<double> Numbers(const std::string& text, char separator, const std::string& what)
{
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, separator))
  {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(v))
    {
      throw UsageError{ what + ": \"" + item + "\" is not a finite number" };
    }
    values.push_back(v);
  }
  return values;
}

double Number(const std::string& text, const std::string& what)
{
  const std::vector<double> v = Numbers(text, ',', what);
  if (v.size() != 1)
  {
    throw UsageError{ what + ": \"" + text + "\" is not one number" };
  }
  return v[0];
}

Options Parse(int argc, char* argv[])
{
  Options opt;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    auto value = [&](const char* what) -> std::string
    {
      if (i + 1 >= argc)
      {
        throw UsageError{ std::string(what) + " needs a value" };
      }
      return argv[++i];
    };
    // An optional count after a flag (the next argument, when it is a number).
    auto count = [&](int fallback) -> int
    {
      if (i + 1 < argc && argv[i + 1][0] >= '0' && argv[i + 1][0] <= '9')
      {
        return static_cast<int>(Number(argv[++i], arg));
      }
      return fallback;
    };
    if (arg == "--help" || arg == "-h")
    {
      std::cout << Usage;
      std::exit(0);
    }
    else if (arg == "--iso")
    {
      const std::string text = value("--iso");
      const std::size_t colon = text.find(':');
      IsosurfaceLook look;
      look.Value = Number(text.substr(0, colon), "--iso");
      look.Color[0] = 0.93f;
      look.Color[1] = 0.85f;
      look.Color[2] = 0.75f;
      if (colon != std::string::npos)
      {
        const std::vector<double> c = Numbers(text.substr(colon + 1), ',', "--iso colour");
        if (c.size() != 3 && c.size() != 4)
        {
          throw UsageError{ "--iso " + text + ": give R,G,B or R,G,B,A after the colon" };
        }
        for (double x : c)
        {
          if (x < 0.0 || x > 1.0)
          {
            throw UsageError{ "--iso " + text + ": colour and opacity go from 0 to 1" };
          }
        }
        for (int k = 0; k < 3; ++k)
        {
          look.Color[k] = static_cast<float>(c[k]);
        }
        look.Opacity = c.size() == 4 ? static_cast<float>(c[3]) : 1.0f;
        if (look.Opacity <= 0.0f)
        {
          throw UsageError{ "--iso " + text + ": an isosurface of opacity 0 draws nothing" };
        }
      }
      opt.Surfaces.push_back(look);
    }
    else if (arg == "--size")
    {
      const std::string text = value("--size");
      const std::vector<double> wh = Numbers(text, 'x', "--size");
      if (wh.size() != 2 || wh[0] < 1 || wh[1] < 1 || wh[0] > 16384 || wh[1] > 16384 ||
        wh[0] != std::floor(wh[0]) || wh[1] != std::floor(wh[1]))
      {
        throw UsageError{ "--size " + text + ": give WIDTHxHEIGHT, 1 to 16384 each" };
      }
      opt.Width = static_cast<int>(wh[0]);
      opt.Height = static_cast<int>(wh[1]);
    }
    else if (arg == "--azimuth")
    {
      opt.Azimuth = Number(value("--azimuth"), "--azimuth");
    }
    else if (arg == "--elevation")
    {
      opt.Elevation = Number(value("--elevation"), "--elevation");
    }
    else if (arg == "--zoom")
    {
      opt.Zoom = Number(value("--zoom"), "--zoom");
      if (!(opt.Zoom > 0.0))
      {
        throw UsageError{ "--zoom must be positive" };
      }
    }
    else if (arg == "--parallel")
    {
      opt.Parallel = true;
    }
    else if (arg == "--background" || arg == "--material")
    {
      const std::vector<double> v = Numbers(value(arg.c_str()), ',', arg);
      const std::size_t n = arg == "--background" ? 3 : 4;
      if (v.size() != n)
      {
        throw UsageError{ arg + " takes " + std::to_string(n) + " numbers" };
      }
      std::copy(v.begin(), v.end(), arg == "--background" ? opt.Background : opt.Material);
    }
    else if (arg == "--clip")
    {
      const std::vector<double> v = Numbers(value("--clip"), ',', "--clip");
      if (v.size() != 4 || (v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0))
      {
        throw UsageError{ "--clip takes 4 numbers A,B,C,D with (A, B, C) not zero" };
      }
      if (opt.ClipPlanes.size() == 6)
      {
        throw UsageError{ "--clip: at most 6 planes" };
      }
      opt.ClipPlanes.push_back({ v[0], v[1], v[2], v[3] });
    }
    else if (arg == "--crop")
    {
      const std::vector<double> v = Numbers(value("--crop"), ',', "--crop");
      if (v.size() != 6 || v[0] > v[1] || v[2] > v[3] || v[4] > v[5])
      {
        throw UsageError{ "--crop takes 6 indices I0,I1,J0,J1,K0,K1 with I0 <= I1, J0 <= J1, K0 <= K1" };
      }
      opt.Crop = true;
      std::copy(v.begin(), v.end(), opt.CropBox);
    }
    else if (arg == "--no-points")
    {
      opt.Points = false;
    }
    else if (arg == "--no-first-hit")
    {
      opt.FirstHit = false;
    }
    else if (arg == "--sample-distance")
    {
      opt.SampleDistance = Number(value("--sample-distance"), "--sample-distance");
      if (!(opt.SampleDistance >= 1.0) || !std::isfinite(opt.SampleDistance))
      {
        throw UsageError{ "--sample-distance must be a number of at least 1" };
      }
    }
    else if (arg == "--output")
    {
      opt.Output = value("--output");
    }
    else if (arg == "--resample")
    {
      const std::string text = value("--resample");
      const std::vector<double> d = Numbers(text, 'x', "--resample");
      if (d.size() != 3)
      {
        throw UsageError{ "--resample takes WxHxD, not " + text };
      }
      for (int a = 0; a < 3; ++a)
      {
        if (d[a] != std::floor(d[a]) || d[a] < 2 || d[a] > 16384)
        {
          throw UsageError{ "--resample: each size must be a whole number from 2 to 16384, not " + text };
        }
        opt.Resample[a] = static_cast<int>(d[a]);
      }
    }
    else if (arg == "--write-volume")
    {
      opt.WriteVolume = value("--write-volume");
    }
    else if (arg == "--stats")
    {
      opt.Stats = true;
    }
    else if (arg == "--frames")
    {
      opt.Frames = static_cast<int>(Number(value("--frames"), "--frames"));
      if (opt.Frames < 1 || opt.Frames > 100000)
      {
        throw UsageError{ "--frames must be 1 to 100000" };
      }
    }
    else if (arg == "--rotate")
    {
      opt.Rotate = count(360);
      if (opt.Rotate < 1 || opt.Rotate > 100000)
      {
        throw UsageError{ "--rotate takes 1 to 100000 frames" };
      }
    }
    else if (arg == "--sweep")
    {
      opt.Sweep = count(95);
      if (opt.Sweep < 1 || opt.Sweep > 100000)
      {
        throw UsageError{ "--sweep takes 1 to 100000 isovalues" };
      }
    }
    else if (arg == "--api")
    {
      const std::string api = value("--api");
      if (api != "es" && api != "gl")
      {
        throw UsageError{ "--api is es or gl, not " + api };
      }
      opt.ES = api == "es";
    }
    else if (arg == "--hit-cull")
    {
      const std::string mode = value("--hit-cull");
      if (mode != "auto" && mode != "on" && mode != "off")
      {
        throw UsageError{ "--hit-cull is auto, on or off, not " + mode };
      }
      opt.Cull = mode == "on" ? HitCull::On : mode == "off" ? HitCull::Off : HitCull::Auto;
    }
    else if (arg == "--no-brick-pool")
    {
      opt.BrickPool = false;
    }
    else if (arg == "--max-texture-size")
    {
      const double n = Number(value("--max-texture-size"), "--max-texture-size");
      if (n != std::floor(n) || n < 16 || n > 65536)
      {
        throw UsageError{ "--max-texture-size must be a whole number from 16 to 65536" };
      }
      opt.MaxTextureSize = static_cast<int>(n);
    }
    else if (arg == "--gpu-budget-mb")
    {
      const double mb = Number(value("--gpu-budget-mb"), "--gpu-budget-mb");
      if (!(mb > 0.0) || mb > 1048576.0)
      {
        throw UsageError{ "--gpu-budget-mb must be a positive number of megabytes" };
      }
      opt.GPUBudget = static_cast<std::uint64_t>(mb * 1e6);
    }
    else if (!arg.empty() && arg[0] == '-')
    {
      throw UsageError{ "unknown option " + arg };
    }
    else if (opt.Input.empty())
    {
      opt.Input = arg;
    }
    else
    {
      throw UsageError{ "one volume only (got " + opt.Input + " and " + arg + ")" };
    }
  }
  if (opt.Input.empty())
  {
    throw UsageError{ "no volume given" };
  }
  if (opt.Surfaces.empty() && opt.Sweep == 0 && opt.WriteVolume.empty())
  {
    throw UsageError{ "give at least one --iso (or --sweep, or --write-volume)" };
  }
  if (opt.Surfaces.size() > static_cast<std::size_t>(MaximumIsovalues))
  {
    throw UsageError{ "at most " + std::to_string(MaximumIsovalues) + " isosurfaces" };
  }
  // The scene's order (increasing values); a repeated value is a mistake here.
  const SurfaceSelection selection = IsosurfaceScene::Normalize(opt.Surfaces);
  if (!selection.Repeated.empty())
  {
    throw UsageError{ "isovalue " + std::to_string(selection.Repeated.front()) + " given twice" };
  }
  opt.Surfaces = selection.Surfaces;
  return opt;
}

double Milliseconds(Clock::duration d)
{
  return std::chrono::duration<double, std::milli>(d).count();
}

double Median(std::vector<double> v)
{
  if (v.empty())
  {
    return 0.0;
  }
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string JsonString(const std::string& s)
{
  std::string out = "\"";
  for (char c : s)
  {
    if (c == '"' || c == '\\')
    {
      out += '\\';
      out += c;
    }
    else if (static_cast<unsigned char>(c) < 0x20)
    {
      out += ' ';
    }
    else
    {
      out += c;
    }
  }
  return out + "\"";
}

// The core's scene with the volume, the camera and the target framebuffer.
class HeadlessView
{
public:
  HeadlessView(
    const Options& options, const headless::MetaImage& image, std::shared_ptr<const GLApi> gl)
    : Opt(options)
    , Image(image)
    , GL(std::move(gl))
    , Scene(ThreadedFor)
  {
    this->Scene.SetContext(this->GL);
    this->Scene.SetMaxTextureSize(options.MaxTextureSize);
    this->Scene.SetGPUMemoryBudget(options.GPUBudget);
    this->Scene.SetBrickPool(options.BrickPool);
    this->Scene.SetHitCull(options.Cull);
  }

  ~HeadlessView()
  {
    this->Scene.Release();
    const GLApi::Functions& f = this->GL->F();
    f.DeleteFramebuffers(1, &this->FBO);
    f.DeleteRenderbuffers(2, this->Buffers);
  }

  // The target framebuffer and the volume on the GPU: "" or why they cannot be made.
  std::string MakeTargetAndVolume()
  {
    const GLApi::Functions& f = this->GL->F();
    GLint maxRenderbuffer = 0, maxViewport[2] = { 0, 0 };
    f.GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &maxRenderbuffer);
    f.GetIntegerv(GL_MAX_VIEWPORT_DIMS, maxViewport);
    const int limit = std::min({ maxRenderbuffer, maxViewport[0], maxViewport[1] });
    if (this->Opt.Width > limit || this->Opt.Height > limit)
    {
      return "a " + std::to_string(this->Opt.Width) + "x" + std::to_string(this->Opt.Height) +
        " image exceeds this context's limit of " + std::to_string(limit) + " pixels per side";
    }
    f.GenFramebuffers(1, &this->FBO);
    f.GenRenderbuffers(2, this->Buffers);
    f.BindRenderbuffer(GL_RENDERBUFFER, this->Buffers[0]);
    f.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, this->Opt.Width, this->Opt.Height);
    f.BindRenderbuffer(GL_RENDERBUFFER, this->Buffers[1]);
    f.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, this->Opt.Width, this->Opt.Height);
    f.BindFramebuffer(GL_FRAMEBUFFER, this->FBO);
    f.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, this->Buffers[0]);
    f.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, this->Buffers[1]);
    if (f.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    {
      return "the " + std::to_string(this->Opt.Width) + "x" + std::to_string(this->Opt.Height) +
        " framebuffer cannot be made (" + this->GL->TakeErrors() + ")";
    }
    VolumeDescription volume;
    volume.Type = this->Image.Type;
    volume.Data = this->Image.Bytes.data();
    std::copy(this->Image.Dimensions, this->Image.Dimensions + 3, volume.Dims);
    std::string error;
    if (!this->Scene.SetVolume(volume, error))
    {
      return error;
    }
    this->SetCamera(0.0);
    return "";
  }

  // VTK's camera for the options, turned `extraAzimuth` degrees more.
  void SetCamera(double extraAzimuth)
  {
    VolumePlacement placement;
    std::copy(this->Image.Dimensions, this->Image.Dimensions + 3, placement.Dimensions);
    std::copy(this->Image.Origin, this->Image.Origin + 3, placement.Origin);
    std::copy(this->Image.Spacing, this->Image.Spacing + 3, placement.Spacing);
    std::copy(this->Image.Direction, this->Image.Direction + 9, placement.Direction);
    double bounds[6];
    placement.Bounds(bounds);
    Camera camera;
    camera.Parallel = this->Opt.Parallel;
    camera.Reset(bounds, static_cast<double>(this->Opt.Width) / this->Opt.Height);
    camera.Azimuth(this->Opt.Azimuth + extraAzimuth);
    camera.Elevation(this->Opt.Elevation);
    camera.OrthogonalizeViewUp();
    camera.Zoom(this->Opt.Zoom);
    camera.ResetClippingRange(bounds);
    SetFrameView(this->Frame, camera, placement, this->Opt.Width, this->Opt.Height);
    this->Frame.Ambient = static_cast<float>(this->Opt.Material[0]);
    this->Frame.Diffuse = static_cast<float>(this->Opt.Material[1]);
    this->Frame.Specular = static_cast<float>(this->Opt.Material[2]);
    this->Frame.SpecularPower = static_cast<float>(this->Opt.Material[3]);
    this->Frame.AllowPointFootprint = this->Opt.Points;
    this->Frame.FirstHitPass = this->Opt.FirstHit;
    // Clipping planes to index space (a plane is a row vector: its value at
    // M x is (plane M) x), then the cropping box's faces (already there).
    this->Frame.ClipPlanes.clear();
    const matrix4::Matrix indexToWorld = placement.IndexToWorld();
    for (const auto& plane : this->Opt.ClipPlanes)
    {
      std::array<double, 4> index = { 0.0, 0.0, 0.0, 0.0 };
      for (int c = 0; c < 4; ++c)
      {
        for (int r = 0; r < 4; ++r)
        {
          index[c] += plane[r] * indexToWorld[4 * r + c];
        }
      }
      this->Frame.ClipPlanes.push_back(index);
    }
    if (this->Opt.Crop)
    {
      for (int a = 0; a < 3; ++a)
      {
        std::array<double, 4> low = { 0.0, 0.0, 0.0, -this->Opt.CropBox[2 * a] };
        std::array<double, 4> high = { 0.0, 0.0, 0.0, this->Opt.CropBox[2 * a + 1] };
        low[a] = 1.0;
        high[a] = -1.0;
        this->Frame.ClipPlanes.push_back(low);
        this->Frame.ClipPlanes.push_back(high);
      }
    }
    this->Frame.SampleDistance = static_cast<float>(this->Opt.SampleDistance);
  }

  // Builds the pyramid for `surfaces` (ahead of the frame, to time it apart); "" or why not.
  std::string Build(const std::vector<IsosurfaceLook>& surfaces)
  {
    this->Scene.SetSurfaces(surfaces);
    std::string error;
    return this->Scene.Update(error) ? "" : error;
  }

  // One frame, finished: "" or why not.
  std::string Draw()
  {
    const GLApi::Functions& f = this->GL->F();
    const auto start = Clock::now();
    f.BindFramebuffer(GL_FRAMEBUFFER, this->FBO);
    f.Viewport(0, 0, this->Opt.Width, this->Opt.Height);
    f.Enable(GL_DEPTH_TEST);
    f.DepthFunc(GL_LEQUAL);
    f.DepthMask(GL_TRUE);
    const GLfloat background[4] = { static_cast<float>(this->Opt.Background[0]),
      static_cast<float>(this->Opt.Background[1]), static_cast<float>(this->Opt.Background[2]), 1.0f };
    const GLfloat one = 1.0f;
    f.ClearBufferfv(GL_COLOR, 0, background);
    f.ClearBufferfv(GL_DEPTH, 0, &one);
    std::string error;
    if (!this->Scene.Render(this->Frame, error))
    {
      return error;
    }
    f.Finish();
    this->FrameMs = Milliseconds(Clock::now() - start);
    const std::string errors = this->GL->TakeErrors();
    return errors.empty() ? "" : "OpenGL errors: " + errors;
  }

  std::vector<unsigned char> ReadImage()
  {
    const GLApi::Functions& f = this->GL->F();
    std::vector<unsigned char> rgba(4 * static_cast<std::size_t>(this->Opt.Width) * this->Opt.Height);
    f.BindFramebuffer(GL_FRAMEBUFFER, this->FBO);
    f.ReadBuffer(GL_COLOR_ATTACHMENT0);
    f.PixelStorei(GL_PACK_ALIGNMENT, 1);
    f.ReadPixels(0, 0, this->Opt.Width, this->Opt.Height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    return rgba;
  }

  const Options& Opt;
  const headless::MetaImage& Image;
  // Milliseconds the scene's last upload and build took.
  double UploadMs() const { return 1000.0 * this->Scene.GetStats().UploadSeconds; }
  double BuildMs() const { return 1000.0 * this->Scene.GetStats().BuildSeconds; }

  std::shared_ptr<const GLApi> GL;
  IsosurfaceScene Scene;
  IsosurfaceFrame Frame;
  GLuint FBO = 0;
  GLuint Buffers[2] = { 0, 0 };
  double FrameMs = 0.0;
};

int Fail(int code, const std::string& text)
{
  std::cerr << "mediso-render: " << text << "\n";
  return code;
}

int Run(int argc, char* argv[])
{
  Options opt;
  try
  {
    opt = Parse(argc, argv);
  }
  catch (const UsageError& e)
  {
    std::cerr << "mediso-render: " << e.Text << "\n(mediso-render --help lists the options)\n";
    return 2;
  }
  headless::MetaImage image;
  std::string error;
  int phantomSize = 0;
  if (headless::ParsePhantomSpec(opt.Input, phantomSize, error))
  {
    if (!error.empty() || !headless::MakePhantom(phantomSize, image, error))
    {
      return Fail(3, error);
    }
  }
  else if (!headless::ReadMetaImage(opt.Input, image, error))
  {
    return Fail(3, error);
  }
  if (opt.Resample[0] > 0)
  {
    headless::MetaImage resampled;
    if (!headless::Resample(image, opt.Resample, resampled, error))
    {
      return Fail(3, opt.Input + ": " + error);
    }
    image = std::move(resampled);
  }
  if (!opt.WriteVolume.empty())
  {
    if (!headless::WriteMetaImage(opt.WriteVolume, image, error))
    {
      return Fail(1, error);
    }
    if (opt.Surfaces.empty() && opt.Sweep == 0)
    {
      return 0;
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    if (image.Dimensions[a] < 2)
    {
      return Fail(3, opt.Input + ": a " + std::to_string(image.Dimensions[0]) + "x" +
          std::to_string(image.Dimensions[1]) + "x" + std::to_string(image.Dimensions[2]) +
          " volume has no cells; isosurfaces need at least 2 points per axis");
    }
  }
  double range[2];
  image.GetRange(range);
  if (!(range[0] <= range[1]))
  {
    return Fail(3, opt.Input + ": every value is NaN");
  }
  auto context = headless::HeadlessContext::Create(
    opt.ES ? headless::ContextApi::ES3 : headless::ContextApi::GL32, error);
  if (!context)
  {
    return Fail(4, error);
  }
  const GLApi& gl = *context->GetGLApi();
  if (ProbeGL(gl, error) != ProbeResult::Passed)
  {
    return Fail(4, gl.Describe() + " cannot run the GPU path: " + error);
  }
  HeadlessView scene(opt, image, context->GetGLApi());
  error = scene.MakeTargetAndVolume();
  if (!error.empty())
  {
    return Fail(4, opt.Input + ": " + error);
  }
  const int* d = image.Dimensions;
  std::printf("mediso-render: %s, %dx%dx%d %s (%g..%g), %s, EGL %s, %dx%d\n", opt.Input.c_str(),
    d[0], d[1], d[2], headless::MetaElementType(image.Type), range[0], range[1],
    gl.Describe().c_str(), context->GetPlatform().c_str(), opt.Width, opt.Height);

  if (!opt.Surfaces.empty())
  {
    error = scene.Build(opt.Surfaces);
    if (!error.empty())
    {
      // The bricks the isovalues cross over the GPU budget: the volume over the context's limits.
      return Fail(scene.Scene.GetStats().OverBudget ? 4 : 1, opt.Input + ": " + error);
    }
    std::vector<double> frames;
    for (int i = 0; i < opt.Frames; ++i)
    {
      error = scene.Draw();
      if (!error.empty())
      {
        return Fail(1, error);
      }
      frames.push_back(scene.FrameMs);
    }
    if (!opt.Output.empty() && !headless::WritePng(opt.Output, opt.Width, opt.Height, scene.ReadImage(), error))
    {
      return Fail(1, error);
    }
    if (opt.Stats)
    {
      std::ostringstream json;
      json.precision(6);
      json << "{\"renderer\": " << JsonString(gl.GetRenderer())
           << ", \"gl\": " << JsonString(gl.GetVersion())
           << ", \"egl_platform\": " << JsonString(context->GetPlatform())
           << ", \"volume\": [" << d[0] << ", " << d[1] << ", " << d[2]
           << "], \"type\": " << JsonString(headless::MetaElementType(image.Type))
           << ", \"image\": [" << opt.Width << ", " << opt.Height << "], \"isovalues\": [";
      for (std::size_t i = 0; i < opt.Surfaces.size(); ++i)
      {
        json << (i ? ", " : "") << opt.Surfaces[i].Value;
      }
      const IsosurfaceSceneStats& stats = scene.Scene.GetStats();
      json << "], \"primitives\": " << stats.Primitives << ", \"upload_ms\": " << scene.UploadMs()
           << ", \"build_ms\": " << scene.BuildMs() << ", \"draw_ms\": " << Median(frames)
           << ", \"frame_ms\": " << scene.BuildMs() + Median(frames)
           << ", \"frames\": " << frames.size()
           << ", \"gpu_bytes\": " << scene.Scene.GetGPUMemoryBytes()
           << ", \"framebuffer_bytes\": " << scene.Scene.GetFrameBufferBytes()
           << ", \"volume_bytes\": " << image.Bytes.size()
           << ", \"footprint\": " << JsonString(stats.PointFootprint ? "points" : "boxes")
           << ", \"first_hit\": " << (stats.FirstHit ? "true" : "false")
           << ", \"hit_cull\": " << (stats.HitCull ? "true" : "false")
           << ", \"sample_distance\": " << stats.SampleDistance << ", \"bricks\": " << stats.Bricks
           << ", \"brick_points\": " << stats.BrickPoints
           << ", \"active_bricks\": " << stats.ActiveBricks
           << ", \"resident_bricks\": " << stats.ResidentBricks
           << ", \"pool_slots\": " << stats.PoolSlots
           << ", \"brick_pyramid_builds\": " << stats.BrickPyramidBuilds
           << ", \"pool_reason\": " << JsonString(scene.Scene.GetBrickPoolReason())
           << ", \"gpu_budget_mb\": " << scene.Scene.GetGPUMemoryBudget() / 1e6 << "}";
      std::printf("%s\n", json.str().c_str());
    }
  }

  if (opt.Rotate > 0 || opt.Sweep > 0)
  {
    std::printf("%-9s %7s %10s %9s %10s %10s %10s %12s\n", "protocol", "frames", "total s", "fps",
      "median ms", "min ms", "build ms", "primitives");
  }
  if (opt.Rotate > 0 && !opt.Surfaces.empty())
  {
    std::vector<double> frames;
    double total = 0.0;
    for (int i = 1; i <= opt.Rotate; ++i)
    {
      scene.SetCamera(static_cast<double>(i));
      error = scene.Draw();
      if (!error.empty())
      {
        return Fail(1, error);
      }
      frames.push_back(scene.FrameMs);
      total += scene.FrameMs;
    }
    std::printf("%-9s %7d %10.3f %9.2f %10.3f %10.3f %10s %12llu\n", "rotation", opt.Rotate,
      total / 1000.0, 1000.0 * opt.Rotate / total, Median(frames),
      *std::min_element(frames.begin(), frames.end()), "-",
      static_cast<unsigned long long>(scene.Scene.GetStats().Primitives));
    scene.SetCamera(0.0);
  }
  if (opt.Sweep > 0)
  {
    IsosurfaceLook look;
    if (!opt.Surfaces.empty())
    {
      look = opt.Surfaces.front();
      look.Opacity = 1.0f;
    }
    else
    {
      look.Color[0] = 0.93f;
      look.Color[1] = 0.85f;
      look.Color[2] = 0.75f;
    }
    std::vector<double> steps, builds;
    double total = 0.0;
    std::uint64_t primitives = 0;
    // Isovalues whose crossed bricks exceed the GPU budget are not drawn (a
    // host falls back for them); the sweep goes on over the others and says
    // how many there were, with the first one's reason.
    int overBudget = 0;
    std::string firstOver;
    for (int i = 0; i < opt.Sweep; ++i)
    {
      look.Value = range[0] + (range[1] - range[0]) * (i + 1) / (opt.Sweep + 1);
      const auto start = Clock::now();
      error = scene.Build({ look });
      if (!error.empty() && scene.Scene.GetStats().OverBudget)
      {
        if (overBudget++ == 0)
        {
          std::ostringstream first;
          first << "the first, " << look.Value << ": " << error;
          firstOver = first.str();
        }
        continue;
      }
      if (error.empty())
      {
        error = scene.Draw();
      }
      if (!error.empty())
      {
        return Fail(1, error);
      }
      const double ms = Milliseconds(Clock::now() - start);
      steps.push_back(ms);
      builds.push_back(scene.BuildMs());
      total += ms;
      primitives = std::max(primitives, scene.Scene.GetStats().Primitives);
    }
    const int drawn = static_cast<int>(steps.size());
    if (overBudget > 0)
    {
      std::printf("(sweep: %d of the %d isovalues not drawn, their crossed bricks over the GPU "
                  "budget; the row is over the other %d; %s)\n",
        overBudget, opt.Sweep, drawn, firstOver.c_str());
    }
    if (drawn == 0)
    {
      std::fflush(stdout);
      return Fail(4, opt.Input + ": no isovalue of the sweep fits the GPU budget");
    }
    std::printf("%-9s %7d %10.3f %9.2f %10.3f %10.3f %10.3f %12llu\n", "sweep", drawn,
      total / 1000.0, 1000.0 * drawn / total, Median(steps),
      *std::min_element(steps.begin(), steps.end()), Median(builds),
      static_cast<unsigned long long>(primitives));
    std::printf("(sweep: median ms is one isovalue change + frame; primitives the largest)\n");
  }
  return 0;
}
} // namespace

int main(int argc, char* argv[])
{
  try
  {
    return Run(argc, argv);
  }
  catch (const std::bad_alloc&)
  {
    return Fail(1, "out of memory");
  }
  catch (const std::exception& e)
  {
    return Fail(1, e.what());
  }
}
