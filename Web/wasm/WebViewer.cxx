// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file WebViewer.cxx
 * @brief The web page's render module: the GPU core on the browser's WebGL2, compiled to WebAssembly.
 *
 * The paper's client runs "the same render module" as the server. Here that
 * is the GPU core of Mappers/Core (mediso::IsosurfaceScene), byte for byte
 * the code the ParaView mapper and mediso-render run, on a WebGL2 context of a canvas, with the
 * functions Emscripten links in (GLFunctionList.h). JavaScript (Web/static/app.js) hands it the
 * volume once and then only parameters: isovalues, colours, the camera. WebViewer holds the
 * volume's placement and the camera (a PageCamera, as the main thread's ViewCamera does); the core's scene rebuilds the pyramid only when the isovalues
 * change.
 *
 * The CPU path, for clients whose GPU cannot afford the GPU path (a software
 * rasteriser, small limits): the BlockLOD core (Filters/Core, the code of
 * ParaView's BlockLODContour, with VTK's case table generated at build
 * time) extracts each surface at the level of detail its memory estimator
 * fits in the client's budget; surfaces are cached per (isovalue, level) and
 * drawn as triangles (MeshRenderer). A surface the server made is drawn beside
 * either path.
 *
 * Streaming (the CPU path; docs/web.md, Streaming): the page gives the
 * server's level 0 as a coarse volume of its own (SetCoarseVolume) and the
 * full level's buffer, then writes the bricks into the buffer as they arrive
 * (WriteBrick: BrickGrid's bricks, the buffer's BlockLOD ranges completed for
 * them). Each surface the page names in SetCoarseValues is drawn from the
 * coarse volume (at its own full resolution); the others, whose bricks have
 * all arrived, from the buffer at level 3. On the GPU path the scene streams
 * too (IsosurfaceScene::BeginStreaming): each brick goes into the volume
 * texture as a sub-region, level 0 is the scene's coarse level drawn from the
 * server's samples (SetCoarseSource), and a frame is drawn at one level for
 * all its surfaces: level 0 while any of them is named coarse, else the full
 * level, whose pyramid is built then (docs/web.md, Streaming).
 */
#include "BlockLOD.h"
#include "BlockLODSurfaces.h"
#include "BrickGrid.h"
#include "Camera.h"
#include "FrameTimeModel.h"
#include "GLApiFunctions.h"
#include "GLObjects.h"
#include "GLProbe.h"
#include "HistoPyramid.h"
#include "HistogramThreshold.h"
#include "IsosurfaceScene.h"
#include "MeshRenderer.h"
#include "PageCamera.h"
#include "PyramidLayout.h"
#include "ScalarTypes.h"
#include "SceneView.h"
#ifdef MEDISO_WEB_THREADS
#include "ThreadedFor.h"
#endif

#include <emscripten.h>
#include <emscripten/bind.h>
#include <emscripten/html5.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace mediso_web
{
extern const int MarchingCubesCases[256][16];
}

#ifndef MEDISO_WEB_THREADS
// The one-thread module's memory is not shared: the page's generation word is a
// SharedArrayBuffer of the worker's own (render-worker.js sets self.medisoGenerationWord),
// read here on the worker's thread, the only one that polls.
EM_JS(int, mediso_page_generation, (), {
  const word = self.medisoGenerationWord;
  return word ? Atomics.load(word, 0) : 0;
});
#endif

namespace
{
using emscripten::val;
using namespace mediso;
using mediso::web::CountActivePairs;
using mediso::web::PageCamera;

/// A surface of the CPU path, as drawn.
struct CPUSurface
{
  std::vector<float> Points, Normals;
  std::vector<std::int32_t> Triangles; // as the core writes them (ids below 2^31)
  double Bytes() const
  {
    return 4.0 * (this->Points.size() + this->Normals.size() + this->Triangles.size());
  }
};
/// What the CPU path's estimates count: normals, no scalars, block ids or offsets.
const SurfaceLayout CPULayout{ true, false, false, false };

/// As the surfaces unit holds it: shared by its cache and the update's list.
using CPUSurfaceRef = std::shared_ptr<CPUSurface>;

/// How the CPU path's surfaces are made: plain vectors, 32-bit indices.
SurfaceMaker<CPUSurfaceRef> CPUSurfaceMaker()
{
  SurfaceMaker<CPUSurfaceRef> maker;
  maker.Allocate = [](const SurfaceKey&, std::int64_t points, std::int64_t triangles,
                     CPUSurfaceRef& surface, SurfaceTarget& target)
  {
    surface = std::make_shared<CPUSurface>();
    surface->Points.resize(3 * static_cast<std::size_t>(points));
    surface->Normals.resize(surface->Points.size());
    surface->Triangles.resize(3 * static_cast<std::size_t>(triangles));
    target.Narrow.Points = surface->Points.data();
    target.Narrow.Normals = surface->Normals.data();
    target.Narrow.Connectivity = surface->Triangles.data();
    return true;
  };
  // A surface extracted ahead while streaming: its arrays moved in, not copied.
  maker.Adopt = [](const SurfaceKey&, SurfaceArrays& arrays, CPUSurfaceRef& surface)
  {
    surface = std::make_shared<CPUSurface>();
    surface->Points = std::move(arrays.Points);
    surface->Normals = std::move(arrays.Normals);
    surface->Triangles = std::move(arrays.Triangles);
    return true;
  };
  maker.Bytes = [](const CPUSurfaceRef& surface) { return surface->Bytes(); };
  return maker;
}

/// Mesh slots: the CPU path's surfaces, then the server's result.
constexpr int ResultSlot = MaximumIsovalues;

// The core's functions: Emscripten's own WebGL2 bindings, by name.
void* LookUp(const char* name, void*)
{
#define MEDISO_LOOK_UP(f)                                                                          \
  if (std::strcmp(name, "gl" #f) == 0)                                                             \
  {                                                                                                \
    return reinterpret_cast<void*>(&::gl##f);                                                      \
  }
  MEDISO_GL_FUNCTIONS(MEDISO_LOOK_UP)
#undef MEDISO_LOOK_UP
  return nullptr;
}
} // namespace

class WebViewer
{
public:
  explicit WebViewer(const std::string& canvas)
    : Canvas(canvas)
  {
    EmscriptenWebGLContextAttributes attributes;
    emscripten_webgl_init_context_attributes(&attributes);
    attributes.majorVersion = 2;
    attributes.minorVersion = 0;
    attributes.alpha = false;
    attributes.depth = true;
    attributes.stencil = false;
    attributes.antialias = false;
    attributes.preserveDrawingBuffer = true; // the image can be read after a frame (tests)
    this->Context = emscripten_webgl_create_context(canvas.c_str(), &attributes);
    if (this->Context <= 0)
    {
      this->Error = "this browser gives no WebGL2 context";
      return;
    }
    emscripten_webgl_make_context_current(this->Context);
    std::string error;
    this->GL = GLApi::Load(LookUp, nullptr, error);
    if (!this->GL)
    {
      this->Error = error;
      return;
    }
    if (ProbeGL(*this->GL, error) != ProbeResult::Passed)
    {
      this->Error = "this WebGL2 cannot run the GPU path: " + error;
      return;
    }
    this->Scene.reset(new IsosurfaceScene(nullptr));
    this->Scene->SetContext(this->GL);
    this->Meshes.reset(new web::MeshRenderer(this->GL));
  }

  ~WebViewer()
  {
    if (this->Context > 0)
    {
      emscripten_webgl_make_context_current(this->Context);
      if (this->Scene)
      {
        this->Scene->Release();
      }
      if (this->Meshes)
      {
        this->Meshes->Release();
      }
      this->Sampled.Reset();
      this->SampledColor.Reset();
      this->SampledDepth.Reset();
      emscripten_webgl_destroy_context(this->Context);
    }
  }

  bool Ready() const { return this->Error.empty(); }
  std::string GetError() const { return this->Error; }

  /// What the context is and can do: the page chooses its path from it.
  val Info() const
  {
    val info = val::object();
    if (this->GL)
    {
      info.set("renderer", this->GL->GetRenderer());
      info.set("version", this->GL->GetVersion());
      info.set("max3DTextureSize", this->GL->GetMax3DTextureSize());
      info.set("maxTextureSize", this->GL->GetMaxTextureSize());
      info.set("maxPointSize", this->GL->GetMaxPointSize());
      info.set("maxVertexTextureUnits", this->GL->GetMaxVertexTextureUnits());
    }
    info.set("error", this->Error);
    return info;
  }

  /**
   * The volume: `bytes` in the module's memory (the caller keeps them alive
   * while this viewer uses them), x fastest, of ScalarType `type`.
   */
  bool SetVolume(int type, std::uintptr_t bytes, const val& dims, const val& spacing,
    const val& origin)
  {
    return this->AdoptVolume(type, bytes, dims, spacing, origin, false);
  }

  /**
   * Streaming from the start (the page's stream, render-worker.js): the
   * volume as SetVolume takes it, its values still to arrive as bricks of
   * `brickPoints` points a side (BeginStreaming), without the BlockLOD ranges
   * SetVolume would read from the buffer that holds nothing yet
   * (BlockLODSurfaces::SetStreamingVolume): that read held the first frame.
   */
  bool SetStreamingVolume(int type, std::uintptr_t bytes, const val& dims, const val& spacing,
    const val& origin, int brickPoints)
  {
    return this->AdoptVolume(type, bytes, dims, spacing, origin, true) &&
      this->BeginStreaming(brickPoints);
  }

  /// "gpu" or "cpu": which path draws.
  void SetPath(const std::string& path)
  {
    this->CPUPath = path == "cpu";
    // The CPU path's meshes are drawn after the GPU path's surfaces (the server's result is
    // drawn on both paths), so those of its last frame must go with it: kept, they were drawn
    // over the GPU path's frames (a translucent skin over the next opaque surfaces). The
    // surfaces unit keeps its cache; going back to the CPU path uploads them again.
    if (!this->CPUPath && this->Meshes)
    {
      emscripten_webgl_make_context_current(this->Context);
      for (int slot = 0; slot < MaximumIsovalues; ++slot)
      {
        this->Meshes->Clear(slot);
      }
      this->ShownKeys.assign(MaximumIsovalues, SurfaceKey{ NAN, -1 });
      this->ShownTriangles = 0.0;
    }
  }

  /// The CPU path's level of detail: 0-3, or -1 to let the estimator choose
  /// within the budget.
  void SetCPULevel(int level) { this->RequestedLevel = std::max(-1, std::min(3, level)); }

  /// The client's memory budget (bytes) for the CPU path's surfaces and their cache.
  void SetBudget(double bytes) { this->Budget = std::max(0.0, bytes); }

  /**
   * Where the GPU path keeps the volume as bricks (IsosurfaceScene::SetMaxTextureSize and
   * SetGPUMemoryBudget): a texture limit below the context's and a GPU budget in bytes, 0 for
   * the defaults (the context's limit, 1 GiB). The page sets them from ?maxTextureSize= and
   * ?gpuBudgetMB= (tests) before the volume; they take effect at the next setVolume.
   */
  void SetMaxTextureSize(int texels)
  {
    if (this->Scene)
    {
      this->Scene->SetMaxTextureSize(std::max(0, texels));
    }
  }
  void SetGPUBudget(double bytes)
  {
    if (this->Scene)
    {
      this->Scene->SetGPUMemoryBudget(
        std::isfinite(bytes) && bytes > 0.0 ? static_cast<std::uint64_t>(bytes) : 0);
    }
  }

  /**
   * Whether a volume kept as bricks is drawn from one pool texture with one pyramid
   * (IsosurfaceScene::SetBrickPool, on by default) or each active brick as its own pyramid. The
   * page turns it off from ?brickPool=0 (tests and benchmarks: the pool against per-brick
   * drawing in the same browser); it takes effect at the next setVolume.
   */
  void SetBrickPool(bool on)
  {
    if (this->Scene)
    {
      this->Scene->SetBrickPool(on);
    }
  }

  /**
   * The image sample distance of the next frames, 1 to 8: above 1 the
   * surfaces are drawn into a framebuffer 1/distance the size along each
   * axis and scaled up to the canvas, as VTK's volume mappers do with
   * ImageSampleDistance during interaction. The page's worker sets it for
   * the frames of a drag on the GPU path, whose cost grows with the pixels
   * each cell's footprint covers; 1 (every pixel) for still frames.
   */
  void SetSampleDistance(double distance)
  {
    this->SampleDistance = std::isfinite(distance) ? std::max(1.0, std::min(8.0, distance)) : 1.0;
  }

  /**
   * Where the page's generation word lives in this module's memory (a byte
   * address), or 0 when the module's memory is not shared (the one-thread
   * module: the worker then keeps the word in a SharedArrayBuffer of its own,
   * self.medisoGenerationWord). The page's main thread adds one to the word
   * on every change that makes a running refinement obsolete (new isovalues,
   * a drag), before it sends the frame; the worker reads it through this
   * module (docs/web.md, The worker).
   */
  double GenerationWord()
  {
#ifdef MEDISO_WEB_THREADS
    return static_cast<double>(reinterpret_cast<std::uintptr_t>(&this->Generation));
#else
    return 0.0;
#endif
  }

  /**
   * With `watch`, the CPU path's extractions of the next frames stop as soon
   * as the page's generation word is no longer `generation` (the core's
   * abort, polled between blocks of a pass and between surfaces): Render()
   * then returns false and Aborted() is true, nothing is drawn, and what was
   * on the canvas stays. The worker watches its refinements only: a first
   * answer or a drag's frame is always drawn.
   */
  void WatchGeneration(bool watch, int generation)
  {
    this->Watching = watch;
    this->WatchedGeneration = generation;
  }

  /// True when the last Render() stopped because a newer change made it obsolete.
  bool Aborted() const { return this->LastAborted; }

  /**
   * A test hook (the page's ?slowExtraction=MS&slowPass=P): a watched
   * extraction lasts at least `ms`, waiting (still watching) in pass `pass`
   * until then: 1, the plan (its abort poll), or 2, the surface's writing
   * (before its first batch of blocks), so that a test can supersede it in
   * either pass without depending on the machine's speed. 0 ms: off.
   */
  void SetSlowExtraction(double ms, int pass)
  {
    this->SlowExtractionMs = std::isfinite(ms) ? std::max(0.0, ms) : 0.0;
    this->SlowPass = pass == 2 ? 2 : 1;
  }

  /**
   * The GPU path's volume level of the next frames (IsosurfaceFrame::Level):
   * 3 the volume; 2, 1 or 0 the volume sampled at Block LOD's stride 2, 4 or
   * 8, -1 at stride 16 (IsosurfaceScene::CoarsestLevel), a coarse volume and
   * pyramid the scene makes on the level's first frame (about 1 / stride^2 of
   * the primitives). The page's worker sets it for the frames of a drag
   * (chooseFrame's level); 3 for still frames.
   */
  void SetGPULevel(int level)
  {
    this->GPULevel = std::max(IsosurfaceScene::CoarsestLevel, std::min(NumberOfLevels - 1, level));
  }

  /// The estimator's table for the current isovalues: per level, triangles, MB and seconds.
  val Estimates()
  {
    val table = val::array();
    for (int level = 0; level < 4; ++level)
    {
      double triangles = 0.0, bytes = 0.0, seconds = 0.0;
      for (const IsosurfaceLook& s : this->Frame.Surfaces)
      {
        const SurfaceEstimate e = this->CPU.Estimate(s.Value, level);
        triangles += e.Counts.Triangles;
        bytes += this->CPU.GetLayout().Bytes(e.Counts);
        seconds += this->CPU.EstimateSeconds(s.Value, level);
      }
      val row = val::object();
      row.set("level", level);
      row.set("triangles", triangles);
      row.set("mb", bytes / 1e6);
      row.set("seconds", seconds);
      table.call<void>("push", row);
    }
    return table;
  }

  /// A surface the server made (world coordinates): `points` 3 floats each,
  /// `triangles` 3 indices each, in the module's memory; normals are made here.
  void SetResultMesh(std::uintptr_t points, double numberOfPoints, std::uintptr_t triangles,
    double numberOfTriangles, const val& color, double opacity)
  {
    const float* p = reinterpret_cast<const float*>(points);
    const std::uint32_t* t = reinterpret_cast<const std::uint32_t*>(triangles);
    const std::int64_t np = static_cast<std::int64_t>(numberOfPoints);
    const std::int64_t nt = static_cast<std::int64_t>(numberOfTriangles);
    std::vector<float> normals(3 * static_cast<std::size_t>(np), 0.0f);
    for (std::int64_t i = 0; i < nt; ++i)
    {
      const std::uint32_t a = t[3 * i], b = t[3 * i + 1], c = t[3 * i + 2];
      if (a >= np || b >= np || c >= np)
      {
        this->LastError = "the server's surface has a triangle with a point it does not have";
        return;
      }
      float e1[3], e2[3];
      for (int k = 0; k < 3; ++k)
      {
        e1[k] = p[3 * b + k] - p[3 * a + k];
        e2[k] = p[3 * c + k] - p[3 * a + k];
      }
      const float n[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0] };
      for (std::uint32_t v : { a, b, c })
      {
        for (int k = 0; k < 3; ++k)
        {
          normals[3 * v + k] += n[k]; // area-weighted
        }
      }
    }
    emscripten_webgl_make_context_current(this->Context);
    this->Meshes->SetMesh(ResultSlot, p, normals.data(), np, t, nt);
    const float rgb[3] = { color[0].as<float>(), color[1].as<float>(), color[2].as<float>() };
    this->Meshes->SetLook(ResultSlot, rgb, static_cast<float>(opacity), true);
  }

  void ClearResultMesh()
  {
    emscripten_webgl_make_context_current(this->Context);
    this->Meshes->Clear(ResultSlot);
  }

  /// Streaming: the server's level 0 (`bytes` kept alive by the caller, as
  /// for SetVolume), drawn for the isovalues named in SetCoarseValues; a null
  /// `bytes` forgets it.
  bool SetCoarseVolume(int type, std::uintptr_t bytes, const val& dims, const val& spacing,
    const val& origin)
  {
    this->CoarseData = reinterpret_cast<const void*>(bytes);
    VolumeDescription description;
    description.Type = static_cast<ScalarType>(type);
    description.Data = this->CoarseData;
    for (int a = 0; a < 3; ++a)
    {
      description.Dims[a] = bytes ? dims[a].as<int>() : 0;
      description.Spacing[a] = bytes ? spacing[a].as<double>() : 1.0;
      description.Origin[a] = bytes ? origin[a].as<double>() : 0.0;
    }
    description.Stamp = ++this->VolumeStamp;
    this->ShownKeys.assign(MaximumIsovalues, SurfaceKey{ NAN, -1 });
    if (!bytes)
    {
      this->Coarse.ClearCache();
      return true;
    }
    return this->Coarse.SetVolume(description) && this->StreamCoarseOnGPU(description);
  }

  /// The GPU path's streaming scene draws the coarse volume as its coarse level of the same
  /// stride (the server's level 0 of the full level: stride 8, the scene's level 0).
  bool StreamCoarseOnGPU(const VolumeDescription& coarse)
  {
    if (!this->Scene || !this->Scene->IsStreaming())
    {
      return true;
    }
    const VolumePlacement& placement = this->Viewpoint.GetPlacement();
    const int stride =
      static_cast<int>(std::lround(coarse.Spacing[0] / std::max(1e-300, placement.Spacing[0])));
    this->StreamLevel = -1;
    for (int level = 0; level < NumberOfLevels - 1; ++level)
    {
      bool fits = LevelStride(level) == stride;
      for (int a = 0; a < 3; ++a)
      {
        fits = fits && coarse.Dims[a] == (placement.Dimensions[a] - 1) / stride + 1;
      }
      this->StreamLevel = fits ? level : this->StreamLevel;
    }
    std::string error;
    if (this->StreamLevel < 0)
    {
      error = "the coarse volume is not a level of the streaming one";
    }
    emscripten_webgl_make_context_current(this->Context);
    if (this->StreamLevel < 0 || !this->Scene->SetCoarseSource(this->StreamLevel, coarse, error))
    {
      this->LastError = error;
      return false;
    }
    return true;
  }

  /**
   * Streaming begins on the volume given to SetVolume (its buffer, whose
   * values arrive as bricks of `brickPoints` points a side, a multiple of 8):
   * no brick is resident.
   */
  bool BeginStreaming(int brickPoints)
  {
    const int* dims = this->Viewpoint.GetPlacement().Dimensions;
    this->Bricks = BrickGrid(dims, brickPoints);
    if (!this->Bricks.IsValid() || !this->Data)
    {
      this->LastError = "bricks of " + std::to_string(brickPoints) + " points cannot stream this volume";
      return false;
    }
    // The GPU path streams into its texture too (a volume kept as bricks does not: refused).
    std::string error;
    emscripten_webgl_make_context_current(this->Context);
    if (!this->CPUPath && !this->Scene->BeginStreaming(error))
    {
      this->LastError = error;
      return false;
    }
    this->CPU.BeginStreaming();
    this->TakenAhead = 0;
    this->ShownKeys.assign(MaximumIsovalues, SurfaceKey{ NAN, -1 });
    return true;
  }

  /**
   * A brick's owned points (`values` in the module's memory, x fastest, as
   * the server sent them) written into the buffer; the blocks they complete
   * get their ranges. False for a brick id outside the grid.
   */
  bool WriteBrick(double brick, std::uintptr_t values)
  {
    const auto id = static_cast<std::int64_t>(brick);
    int extent[6];
    this->Bricks.OwnedPoints(id, extent);
    if (!this->CPU.GetVolume().IsStreaming() ||
      !mediso::WriteBrick(this->Bricks, id, extent, ScalarTypeSize(this->Type),
        reinterpret_cast<const void*>(values), const_cast<void*>(this->Data)))
    {
      this->LastError = "brick " + std::to_string(id) + " is not one of this volume's";
      return false;
    }
    const int first[3] = { extent[0], extent[2], extent[4] };
    const int last[3] = { extent[1], extent[3], extent[5] };
    if (!this->CPUPath)
    {
      this->CPU.SetAheadIsovalues({}); // the GPU path draws from its texture
    }
    this->CPU.RegionArrived(first, last);
    std::string error;
    emscripten_webgl_make_context_current(this->Context);
    if (this->Scene->IsStreaming() && !this->Scene->RegionArrived(first, last, error))
    {
      this->LastError = error;
      return false;
    }
    return true;
  }

  /// Streaming ends (every brick arrived): the coarse volume is forgotten and
  /// the CPU path chooses its levels again.
  void EndStreaming()
  {
    emscripten_webgl_make_context_current(this->Context);
    std::string error;
    if (this->Scene->IsStreaming())
    {
      // The GPU path's texture has every brick (RegionArrived).
      if (!this->Scene->EndStreaming(error))
      {
        this->LastError = error;
      }
    }
    else
    {
      // A texture uploaded from the buffer before its bricks (a path switched mid-stream) is
      // stale: a new stamp uploads the values, now on the GPU path, else when it first draws.
      this->Described.Stamp = ++this->VolumeStamp;
      this->SceneVolumeStale = true;
      if (!this->CPUPath && !this->UpdateSceneVolume(error))
      {
        this->LastError = error;
      }
    }
    this->CPU.EndStreaming();
    this->CoarseValues.clear();
    this->SetCoarseVolume(0, 0, val::undefined(), val::undefined(), val::undefined());
  }

  /// The isovalues drawn from the coarse volume (their bricks are not all resident).
  void SetCoarseValues(const val& values)
  {
    this->CoarseValues.clear();
    const int n = values["length"].as<int>();
    for (int i = 0; i < n; ++i)
    {
      this->CoarseValues.push_back(values[i].as<double>());
    }
  }

  /// The isosurfaces: [{value, color: [r, g, b], opacity}], at most 8.
  bool SetSurfaces(const val& surfaces)
  {
    std::vector<IsosurfaceLook> looks;
    const int n = surfaces["length"].as<int>();
    for (int i = 0; i < n; ++i)
    {
      const val s = surfaces[i];
      IsosurfaceLook look;
      look.Value = s["value"].as<double>();
      const val color = s["color"];
      for (int c = 0; c < 3; ++c)
      {
        look.Color[c] = color.isUndefined() ? 1.0f : color[c].as<float>();
      }
      look.Opacity = s["opacity"].isUndefined() ? 1.0f : s["opacity"].as<float>();
      if (std::isfinite(look.Value) && look.Opacity > 0.0f)
      {
        looks.push_back(look);
      }
    }
    this->Frame.Surfaces = IsosurfaceScene::Normalize(looks).Surfaces;
    return true;
  }

  PageCamera& GetPageCamera() { return this->Viewpoint; }

  void Resize(int width, int height)
  {
    this->Viewpoint.Resize(width, height);
    emscripten_set_canvas_element_size(
      this->Canvas.c_str(), this->Viewpoint.GetWidth(), this->Viewpoint.GetHeight());
  }

  void SetBackground(double r, double g, double b)
  {
    this->Background[0] = static_cast<float>(r);
    this->Background[1] = static_cast<float>(g);
    this->Background[2] = static_cast<float>(b);
  }

  void SetMaterial(double ambient, double diffuse, double specular, double power)
  {
    this->Frame.Ambient = static_cast<float>(ambient);
    this->Frame.Diffuse = static_cast<float>(diffuse);
    this->Frame.Specular = static_cast<float>(specular);
    this->Frame.SpecularPower = static_cast<float>(power);
  }

  /// Draws a frame (building the pyramid first if the isovalues changed).
  bool Render()
  {
    if (!this->Ready() || !this->Data)
    {
      return false;
    }
    emscripten_webgl_make_context_current(this->Context);
    const GLApi::Functions& f = this->GL->F();
    const double start = emscripten_get_now();
    this->FrameStart = start;
    this->MeshesUploaded = false;
    this->LastUploadMs = 0.0;
    std::vector<double> values;
    for (const IsosurfaceLook& s : this->Frame.Surfaces)
    {
      values.push_back(s.Value);
    }
    this->LastBuildMs = 0.0;
    // The frame's one-off work for the frame-time model (Finish()): the
    // estimator's seconds of what it extracts (0 for cached surfaces), the
    // cells of the pyramids it builds.
    this->FrameExtractSeconds = 0.0;
    this->FrameBuildCells = 0;
    const std::uint64_t programsBefore = this->Scene ? this->Scene->GetProgramBuilds() : 0;
    std::string sceneError;
    if (!this->CPUPath && !this->UpdateSceneVolume(sceneError))
    {
      this->LastError = sceneError;
      return false;
    }
    if (this->CPUPath)
    {
      this->FrameExtractSeconds = this->ExtractSeconds(
        this->RequestedLevel >= 0 ? this->RequestedLevel : this->MemoryLevel());
      if (!this->UpdateCPUSurfaces())
      {
        return false;
      }
      this->LastBuildMs = emscripten_get_now() - start;
    }
    else if (!values.empty())
    {
      // The scene builds only when the isovalues changed (a coarse level: also on its first frame),
      // and only the level drawn: a change's first answer on a coarse level leaves the full
      // volume's pyramid to its refinement.
      const auto builds = [this]()
      { return this->Scene->GetStats().PyramidBuilds + this->Scene->GetStats().CoarseBuilds; };
      const std::uint64_t before = builds();
      const IsosurfaceSceneStats statsBefore = this->Scene->GetStats();
      this->Scene->SetSurfaces(this->Frame.Surfaces);
      this->Frame.Level = this->StreamedGPULevel();
      std::string error;
      // Streaming, the full level's pyramid is built only for a frame that draws it (UpdateLevel of
      // the full level is Update); otherwise only the level drawn is built.
      if (!this->Scene->UpdateLevel(this->Frame.Level, error))
      {
        this->LastError = error;
        return false;
      }
      if (builds() != before)
      {
        this->LastBuildMs = emscripten_get_now() - start;
        const IsosurfaceSceneStats& after = this->Scene->GetStats();
        if (after.PyramidBuilds != statsBefore.PyramidBuilds)
        {
          this->FrameBuildCells += this->LevelCells(NumberOfLevels - 1);
        }
        if (after.CoarseBuilds != statsBefore.CoarseBuilds)
        {
          this->FrameBuildCells += this->LevelCells(this->Frame.Level);
        }
      }
    }
    Camera& camera = this->Viewpoint.GetCamera();
    const VolumePlacement& placement = this->Viewpoint.GetPlacement();
    const int canvasWidth = this->Viewpoint.GetWidth();
    const int canvasHeight = this->Viewpoint.GetHeight();
    double bounds[6];
    placement.Bounds(bounds);
    camera.ResetClippingRange(bounds);
    // A sample distance above 1: the frame is drawn smaller, into Sampled, and scaled up below.
    const bool sampled = this->SampleDistance > 1.0 && this->PrepareSampled();
    const int width = sampled ? this->SampledSize[0] : canvasWidth;
    const int height = sampled ? this->SampledSize[1] : canvasHeight;
    SetFrameView(this->Frame, camera, placement, width, height);
    f.BindFramebuffer(GL_FRAMEBUFFER, sampled ? this->Sampled.Get() : 0);
    f.Viewport(0, 0, width, height);
    f.Enable(GL_DEPTH_TEST);
    f.DepthFunc(GL_LEQUAL);
    f.DepthMask(GL_TRUE);
    const GLfloat background[4] = { this->Background[0], this->Background[1], this->Background[2],
      1.0f };
    const GLfloat one = 1.0f;
    f.ClearBufferfv(GL_COLOR, 0, background);
    f.ClearBufferfv(GL_DEPTH, 0, &one);
    this->Stats = IsosurfaceSceneStats();
    std::string error;
    if (!this->CPUPath && !values.empty())
    {
      if (!this->Scene->Render(this->Frame, error))
      {
        this->LastError = error;
        return false;
      }
      this->Stats = this->Scene->GetStats();
      this->NoteGPUSurfaces();
    }
    // The CPU path's surfaces and the server's result, in world coordinates.
    if (this->Meshes->GetNumberOfMeshes() > 0)
    {
      const double aspect = static_cast<double>(canvasWidth) / std::max(1, canvasHeight);
      const matrix4::Matrix modelToView =
        matrix4::Multiply(camera.ViewMatrix(), this->PlacementModel());
      if (!this->Meshes->Render(this->Frame, modelToView, camera.ProjectionMatrix(aspect), error))
      {
        this->LastError = error;
        return false;
      }
    }
    if (sampled && !this->Rehearsing)
    {
      f.BindFramebuffer(GL_READ_FRAMEBUFFER, this->Sampled.Get());
      f.BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
      glBlitFramebuffer(
        0, 0, width, height, 0, 0, canvasWidth, canvasHeight, GL_COLOR_BUFFER_BIT, GL_LINEAR);
      f.BindFramebuffer(GL_FRAMEBUFFER, 0);
    }
    this->DrawnSampleDistance = sampled ? this->SampleDistance : 1.0;
    this->FrameDrawn = true;
    this->FramePrograms = this->Scene ? this->Scene->GetProgramBuilds() - programsBefore : 0;
    if (!this->Rehearsing)
    {
      ++this->FramesDrawn;
    }
    this->LastFrameMs = emscripten_get_now() - start;
    return true;
  }

  /// Waits for the GPU to finish (a one-pixel read-back): for timings. The
  /// frame is then given to the frame-time model with its time to here and
  /// the one-off work it did (GPU path: the pyramids it built; CPU path: the
  /// estimator's seconds of its extraction and the triangles it uploaded;
  /// either: a program not compiled before, WarmKey),
  /// which the model keeps apart from the drawing. The GPU path's pyramid
  /// build ends in a read-back, so its time (LastBuildMs) is the build's own
  /// and is given with it: the model then learns the drawing from the rest.
  void Finish()
  {
    emscripten_webgl_make_context_current(this->Context);
    unsigned char pixel[4];
    this->GL->F().ReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel);
    const double seconds = (emscripten_get_now() - this->FrameStart) / 1000.0;
    if (this->FrameDrawn)
    {
      FrameWork work = this->DrawnWork(this->DrawnSampleDistance);
      const int level = this->CPUPath ? this->CPULevel : this->Stats.Level;
      if (this->CPUPath)
      {
        work.ExtractSeconds = this->MeshesUploaded ? this->FrameExtractSeconds : 0.0;
        work.BuildElements = this->MeshesUploaded ? work.Primitives : 0;
      }
      else
      {
        work.BuildElements = this->FrameBuildCells;
      }
      work.Programs = this->Warm.insert(this->WarmKey(level, work)).second ? 1 : 0;
      if (!this->CPUPath)
      {
        // What the GPU path compiled, as its renderer counts it: a frame of two surfaces compiles
        // a variant per look (an opaque bone beside a translucent skin) that a level's first
        // translucent frame did not, and a drawing sample of such a frame took a compile of
        // seconds on SwiftShader as drawing (issue 30). Warm still predicts the candidates.
        work.Programs = static_cast<std::uint32_t>(this->FramePrograms);
      }
      if (!this->CPUPath && work.BuildElements > 0)
      {
        this->Times.Observe(work, seconds, this->LastBuildMs / 1000.0);
      }
      else
      {
        this->Times.Observe(work, seconds);
      }
    }
    this->FrameDrawn = false;
  }

  /**
   * The frame that fits `budgetSeconds` on this client, from the frame-time
   * model (mediso::FrameTimeModel, fitted from this viewer's frames) and, on
   * the CPU path, the estimator's seconds for an extraction not yet cached:
   * {level, sampleDistance, predictedMs, fullMs} for the current isovalues.
   * CPU path: the finest level, at most the one the memory budget allows,
   * whose extraction, upload and drawing fit, then (`interactive`: a drag's frame)
   * level 0 at image sample distances 1.5 to 8 (the coarsest when none
   * does). GPU path:
   * the full volume at the smallest image sample distance whose frame fits
   * (1 to 8), else the coarse volume levels 2, 1 and 0 (strides 2, 4, 8) the
   * same way, then level -1 (stride 16: where level 0's primitives alone are
   * over the budget), from each level's active pairs (estimated from the full
   * level's before its first frame); a drag's next frame keeps the candidate its
   * last frame drew unless its prediction leaves the budget by the model's
   * margin, and goes finer one candidate at a time (FrameTimeModel::ChooseHeld).
   * fullMs: the prediction of the full frame (level
   * the memory allows, every pixel), which the page states when it is over.
   */
  val ChooseFrame(double budgetSeconds, bool interactive)
  {
    std::vector<FrameTimeModel::Candidate> candidates;
    const int memoryLevel = this->CPUPath ? this->MemoryLevel() : NumberOfLevels - 1;
    if (this->CPUPath)
    {
      for (int level = memoryLevel; level >= 0; --level)
      {
        FrameTimeModel::Candidate c;
        c.Level = level;
        double triangles = 0.0;
        for (const IsosurfaceLook& s : this->Frame.Surfaces)
        {
          triangles += this->CPU.Estimate(s.Value, level).Counts.Triangles;
        }
        c.Work = this->Work(static_cast<std::uint64_t>(triangles), 1.0);
        c.Work.ExtractSeconds = this->ExtractSeconds(level);
        // Its one-off work as well: a level not shown uploads its triangles (after extracting
        // those not cached), and a look not drawn before compiles the meshes' program.
        const bool shown = c.Work.ExtractSeconds <= 0.0 && level == this->CPULevel;
        c.Work.BuildElements = shown ? 0 : c.Work.Primitives;
        c.Work.Programs = this->Warm.count(this->WarmKey(level, c.Work)) ? 0 : 1;
        candidates.push_back(c);
      }
      // A drag whose level 0 is over the budget: level 0 on fewer pixels (on software WebGL about
      // half of such a frame of a few thousand triangles is its pixels: shading, blending).
      const FrameTimeModel::Candidate levelZero = candidates.back();
      if (interactive)
      {
        for (double distance : { 1.5, 2.0, 3.0, 4.0, 6.0, 8.0 })
        {
          FrameTimeModel::Candidate c = levelZero;
          c.SampleDistance = static_cast<float>(distance);
          c.Work = this->Work(levelZero.Work.Primitives, distance);
          c.Work.ExtractSeconds = levelZero.Work.ExtractSeconds;
          c.Work.BuildElements = levelZero.Work.BuildElements;
          c.Work.Programs = levelZero.Work.Programs; // a distance compiles nothing (WarmKey)
          candidates.push_back(c);
        }
      }
    }
    else
    {
      this->AddGPUCandidates(candidates);
    }
    // CPU path: the whole frame (the drawing, the extraction of the surfaces not cached, the
    // upload of a level not shown). GPU path: ChooseOnWholeFrame; a drag's frame holds the
    // candidate its last frame drew (FrameTimeModel::ChooseHeld) where that frame was the one
    // this chose and drew last (no still frame since: a new drag chooses afresh).
    const bool wholeFrame = this->ChooseOnWholeFrame(interactive);
    std::size_t held = candidates.size();
    if (!this->CPUPath && interactive && this->HeldChoice.Frame > 0 &&
      this->HeldChoice.Frame == this->FramesDrawn)
    {
      for (std::size_t i = 0; i < candidates.size(); ++i)
      {
        if (candidates[i].Level == this->HeldChoice.Level &&
          candidates[i].SampleDistance == this->HeldChoice.SampleDistance)
        {
          held = i;
        }
      }
    }
    const bool finer = held == candidates.size() || this->HeldChoice.Finer;
    const std::size_t chosen = !this->CPUPath && interactive
      ? this->Times.ChooseHeld(candidates, budgetSeconds, held, wholeFrame, finer)
      : wholeFrame ? this->Times.ChooseWholeFrame(candidates, budgetSeconds)
                   : this->Times.Choose(candidates, budgetSeconds);
    // A drag that went coarser goes no finer again (ChooseHeld's `finer`).
    this->HeldChoice.Finer = finer && !(held < candidates.size() && chosen > held);
    // The frame drawn next is this choice's (the worker draws it at once).
    this->HeldChoice.Level = candidates[chosen].Level;
    this->HeldChoice.SampleDistance = candidates[chosen].SampleDistance;
    this->HeldChoice.Frame = interactive ? this->FramesDrawn + 1 : 0;
    val out = val::object();
    out.set("level", candidates[chosen].Level);
    out.set("sampleDistance", candidates[chosen].SampleDistance);
    out.set("predictedMs", 1000.0 * this->Times.Predict(candidates[chosen].Work));
    out.set("fullMs", 1000.0 * this->Times.Predict(candidates[0].Work));
    out.set("memoryLevel", memoryLevel);
    return out;
  }

  /**
   * One step of making ready, in the idle time after a still frame, the GPU frame a drag would be
   * drawn as, so that the first drag frame after an isovalue change (or a switch to the GPU path)
   * does not pay for it: the candidate a drag holds (ChooseFrame's on the drawing alone,
   * FrameTimeModel::Choose, within `budgetSeconds`) gets
   * -# "pyramid": its volume level's pyramid built for the current isovalues (the level's
   *    samples uploaded on its first build; the build ends by reading its total back, so the GPU
   *    is idle again when the step returns), then
   * -# "programs": its programs compiled, by drawing that frame once into the sampled
   *    framebuffer, never shown (the canvas keeps the still frame; a drag at every pixel is
   *    rehearsed at distance 2: only a sampled frame stays off the canvas, and a distance
   *    compiles nothing), waited for with a one-pixel read-back.
   * Each call does at most one step, so that the page's worker reads its messages between them: a
   * drag or a change that comes meanwhile is drawn at once, and the worker calls again after the
   * next settled frame, which goes on from what is made (nothing is kept here between calls: each
   * call asks again what a drag would draw and what of it is not ready). A drag that begins after
   * the first step finds the level's pyramid built (the whole-frame choice, ChooseOnWholeFrame,
   * then counts only its programs). The pyramid is the one a drag frame would build (the same
   * UpdateLevel). Nothing is done on the CPU path, while the scene streams (a coarse level
   * samples points not all there yet), or where that level is built for these isovalues and its
   * programs were used (WarmKey). The rehearsal is not observed by the frame-time model (it draws
   * no blit and is not shown); the frame after it reports its own work as before.
   * Returns {level, sampleDistance, step, done, ms}: step the one done ("" when nothing was
   * needed), done false when a step is left, ms its time; error where a step failed.
   */
  val PrepareDragStep(double budgetSeconds)
  {
    val out = val::object();
    out.set("step", std::string());
    out.set("done", true);
    out.set("ms", 0.0);
    if (this->CPUPath || !this->Ready() || !this->Data || !this->Scene ||
      this->Frame.Surfaces.empty() || this->Scene->IsStreaming())
    {
      return out;
    }
    std::vector<FrameTimeModel::Candidate> candidates;
    this->AddGPUCandidates(candidates);
    const FrameTimeModel::Candidate drag =
      candidates[this->Times.Choose(candidates, budgetSeconds)];
    out.set("level", drag.Level);
    out.set("sampleDistance", drag.SampleDistance);
    const std::array<int, 3> key = this->WarmKey(drag.Level, drag.Work);
    const bool built = this->Scene->GetBuiltValues(drag.Level) == this->SurfaceValues();
    // Its programs: asked of the scene once the level is built (drag.Work's count was made
    // before, where the level may not have been).
    const bool compiled =
      built && this->GPUPrograms(drag.Level, drag.SampleDistance, drag.Work) == 0;
    if (compiled)
    {
      return out;
    }
    emscripten_webgl_make_context_current(this->Context);
    const double start = emscripten_get_now();
    if (!built)
    {
      // Render()'s own build of that level, without the frame: a drag frame finds it made.
      std::string error;
      this->Scene->SetSurfaces(this->Frame.Surfaces);
      if (!this->Scene->UpdateLevel(drag.Level, error))
      {
        out.set("error", error);
        return out;
      }
      out.set("step", std::string("pyramid"));
      out.set("done", this->GPUPrograms(drag.Level, drag.SampleDistance, drag.Work) == 0);
      out.set("ms", emscripten_get_now() - start);
      return out;
    }
    // What the last shown frame says (GetStats) is kept: the rehearsal is not a frame.
    const double distance = this->SampleDistance;
    const int gpuLevel = this->GPULevel;
    const IsosurfaceSceneStats shown = this->Stats;
    const double buildMs = this->LastBuildMs, frameMs = this->LastFrameMs;
    const double drawnDistance = this->DrawnSampleDistance;
    const std::uint64_t buildCells = this->FrameBuildCells;
    const std::string lastError = this->LastError;
    this->SetGPULevel(drag.Level);
    this->SampleDistance = std::max(2.0, static_cast<double>(drag.SampleDistance));
    bool ok = false;
    if (this->PrepareSampled())
    {
      this->Rehearsing = true;
      ok = this->Render();
      this->Rehearsing = false;
    }
    if (ok)
    {
      // Waits for the GPU (the compilation and the draw are done by the time it returns), so
      // that a drag's first frame does not find them still queued.
      unsigned char pixel[4];
      this->GL->F().ReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel);
      this->Warm.insert(key);
      out.set("step", std::string("programs"));
      out.set("ms", emscripten_get_now() - start);
    }
    else
    {
      out.set("error", this->LastError.empty() ? std::string("no sampled framebuffer")
                                               : this->LastError);
    }
    this->GL->F().BindFramebuffer(GL_FRAMEBUFFER, 0);
    this->FrameDrawn = false;
    this->SampleDistance = distance;
    this->GPULevel = gpuLevel;
    this->Stats = shown;
    this->LastBuildMs = buildMs;
    this->LastFrameMs = frameMs;
    this->DrawnSampleDistance = drawnDistance;
    this->FrameBuildCells = buildCells;
    this->LastError = lastError;
    return out;
  }

  val GetStats() const
  {
    val stats = val::object();
    stats.set("path", std::string(this->CPUPath ? "cpu" : "gpu"));
    stats.set("gpuLevel", this->CPUPath ? NumberOfLevels - 1 : this->Stats.Level);
    stats.set("primitives", this->CPUPath ? 0.0 : static_cast<double>(this->Stats.Primitives));
    stats.set("triangles", this->CPUPath ? this->ShownTriangles : 0.0);
    stats.set("cpuLevel", this->CPULevel);
    stats.set("cacheMB", this->CPU.GetCacheBytes() / 1e6);
    stats.set("takenAhead", this->TakenAhead);
    stats.set("footprint", std::string(this->Stats.PointFootprint ? "points" : "boxes"));
    stats.set("firstHit", this->Stats.FirstHit);
    stats.set("buildMs", this->LastBuildMs);
    stats.set("uploadMs", this->LastUploadMs);
    // Whether the last frame built a pyramid (its volume level's, for new isovalues or on the
    // level's first frame) before drawing; a drag frame on a level made ahead (PrepareDragStep)
    // did not.
    stats.set("pyramidBuilt", this->FrameBuildCells > 0);
    // The programs the last frame compiled (the GPU path's renderer; one-off work the frame-time
    // model keeps apart from the drawing).
    stats.set("programsCompiled", static_cast<double>(this->FramePrograms));
    stats.set("sampleDistance", this->DrawnSampleDistance);
    stats.set("pixels",
      static_cast<double>(this->Viewpoint.GetWidth()) * this->Viewpoint.GetHeight() /
        (this->DrawnSampleDistance * this->DrawnSampleDistance));
    stats.set("frameMs", this->LastFrameMs);
    stats.set(
      "gpuBytes", this->Scene ? static_cast<double>(this->Scene->GetGPUMemoryBytes()) : 0.0);
    stats.set("frameBufferBytes",
      this->Scene ? static_cast<double>(this->Scene->GetFrameBufferBytes()) : 0.0);
    stats.set("error", this->LastError);
    // The GPU path's bricks (0 where the volume is one texture), those the isovalues cross and
    // those on the GPU; overBudget: the last update failed because the crossed ones exceed the
    // GPU budget (the page then falls back to the CPU path with the error as its reason).
    const IsosurfaceSceneStats bricks =
      this->Scene ? this->Scene->GetStats() : IsosurfaceSceneStats();
    stats.set("bricks", static_cast<double>(bricks.Bricks));
    stats.set("activeBricks", static_cast<double>(bricks.ActiveBricks));
    stats.set("residentBricks", static_cast<double>(bricks.ResidentBricks));
    // The bricks' edge in points, the pool's slots (0: no pool, each active brick its own
    // pyramid) and the pyramids the last build built (1 with the pool).
    stats.set("brickPoints", static_cast<double>(bricks.BrickPoints));
    stats.set("poolSlots", static_cast<double>(bricks.PoolSlots));
    stats.set("brickPyramidBuilds", static_cast<double>(bricks.BrickPyramidBuilds));
    // Why the crossed bricks are drawn each as its own pyramid ("" from the pool): the pool
    // off, or one that would not fit or would take over 3x their own pyramids' GPU memory.
    stats.set("poolReason",
      this->Scene && !this->CPUPath ? this->Scene->GetBrickPoolReason() : std::string());
    stats.set("overBudget", !this->CPUPath && bricks.OverBudget);
    // Whole volume uploads and streamed regions (sub-region uploads) of the GPU path's texture.
    stats.set("volumeUploads", static_cast<double>(bricks.VolumeUploads));
    stats.set("regionUploads", static_cast<double>(bricks.RegionUploads));
    // Per surface of the last CPU frame, in the order drawn (IsosurfaceScene::Normalize's): its
    // isovalue, whether it came from the coarse volume (streaming), and its triangles.
    val values = val::array(), coarse = val::array(), triangles = val::array();
    for (std::size_t i = 0; i < this->SlotCoarse.size(); ++i)
    {
      values.call<void>("push", this->SlotValues[i]);
      coarse.call<void>("push", static_cast<bool>(this->SlotCoarse[i]));
      triangles.call<void>("push", this->SlotTriangles[i]);
    }
    stats.set("surfaceValues", values);
    stats.set("coarse", coarse);
    stats.set("surfaceTriangles", triangles);
    return stats;
  }

  /// The CPU model's count of active (cell, isovalue) pairs on the samples of a volume level
  /// (3: the volume; tests compare the GPU's with it, at the GPU path's level).
  double CountOnCPU(const val& isovalues, int level) const
  {
    return CountActivePairs(
      this->Type, this->Data, this->Viewpoint.GetPlacement().Dimensions, isovalues, level);
  }

private:
  // SetVolume, or with `streaming` the start of SetStreamingVolume.
  bool AdoptVolume(int type, std::uintptr_t bytes, const val& dims, const val& spacing,
    const val& origin, bool streaming)
  {
    if (!this->Ready())
    {
      return false;
    }
    this->Viewpoint.SetPlacement(dims, spacing, origin);
    const VolumePlacement& placement = this->Viewpoint.GetPlacement();
    this->Type = static_cast<ScalarType>(type);
    this->Data = reinterpret_cast<const void*>(bytes);
    emscripten_webgl_make_context_current(this->Context);
    VolumeDescription description;
    description.Type = this->Type;
    description.Data = this->Data;
    std::copy(placement.Dimensions, placement.Dimensions + 3, description.Dims);
    std::copy(placement.Origin, placement.Origin + 3, description.Origin);
    std::copy(placement.Spacing, placement.Spacing + 3, description.Spacing);
    description.Stamp = ++this->VolumeStamp;
    this->Described = description;
    this->SceneVolumeStale = true;
    std::string error;
    if (!this->CPUPath && !this->UpdateSceneVolume(error))
    {
      this->LastError = error;
      return false;
    }
    if (streaming)
    {
      this->CPU.SetStreamingVolume(description);
    }
    else
    {
      this->CPU.SetVolume(description);
    }
    this->ShownKeys.assign(MaximumIsovalues, SurfaceKey{ NAN, -1 });
    this->Warm.clear(); // another volume: other pyramids, other programs
    this->Viewpoint.ResetCamera();
    return true;
  }

  // The GPU path's volume level: the one asked for (SetGPULevel), or while the scene streams, for
  // all the frame's surfaces, the coarse volume's level when any of them is named coarse
  // (SetCoarseValues: its bricks are not all there), else the full level.
  int StreamedGPULevel() const
  {
    if (!this->Scene->IsStreaming())
    {
      return this->GPULevel;
    }
    for (const IsosurfaceLook& s : this->Frame.Surfaces)
    {
      if (std::find(this->CoarseValues.begin(), this->CoarseValues.end(), s.Value) !=
        this->CoarseValues.end())
      {
        return this->StreamLevel;
      }
    }
    return NumberOfLevels - 1;
  }

  // Per surface of a GPU frame, as the CPU path's (stats' surfaceValues, coarse): while streaming,
  // coarse for every surface of a frame drawn from the coarse volume.
  void NoteGPUSurfaces()
  {
    const bool coarse = this->Scene->IsStreaming() && this->Stats.Level == this->StreamLevel;
    this->SlotValues.clear();
    for (const IsosurfaceLook& s : this->Frame.Surfaces)
    {
      this->SlotValues.push_back(s.Value);
    }
    this->SlotCoarse.assign(this->SlotValues.size(), coarse ? 1 : 0);
    // The GPU path counts primitives for the frame, not triangles per surface.
    this->SlotTriangles.assign(this->SlotValues.size(), std::numeric_limits<double>::quiet_NaN());
  }

  // The current surfaces' values, as the scene keeps a level's built values.
  std::vector<double> SurfaceValues() const
  {
    std::vector<double> values;
    for (const IsosurfaceLook& s : this->Frame.Surfaces)
    {
      values.push_back(s.Value);
    }
    return values;
  }

  bool FullLevelBuiltForSurfaces() const
  {
    return this->Scene && this->Scene->GetBuiltValues(NumberOfLevels - 1) == this->SurfaceValues();
  }

  // Whether the GPU path chooses on each candidate's whole frame, its pyramid build and first
  // programs included (FrameTimeModel::ChooseWholeFrame), or on the drawing alone (Choose):
  // after an isovalue change, when every candidate's pyramid has to be built, so that the first
  // answer is a level whose build fits as well; and during a drag, so that a drag frame is never
  // the one that builds a level for these isovalues when that is over the budget (the first drag
  // frame after a change built its level's pyramid and first used its programs: seconds on a
  // loaded machine, against 20-280 ms for the next). A still frame of built surfaces chooses on
  // the drawing: the level a drag can hold, which PrepareDragStep makes ready in the idle time
  // before the drag, so a drag still reaches a finer level, from its next drag on.
  bool ChooseOnWholeFrame(bool interactive) const
  {
    return this->CPUPath || interactive || !this->FullLevelBuiltForSurfaces();
  }

  // The GPU path's candidates, finest first: the full volume at each sample distance, then the
  // coarse volume levels 2, 1, 0 and -1 (strides 2, 4, 8, 16) the same way, each from its pyramid's
  // active pairs when built for these surfaces, else estimated from the full level's
  // (IsosurfaceScene). A software rasteriser's frame costs about its primitives, so only a
  // coarser volume brings a large surface within the budget there.
  void AddGPUCandidates(std::vector<FrameTimeModel::Candidate>& candidates) const
  {
    const std::uint64_t full = this->Scene ? this->Scene->GetActivePairs() : 0;
    const std::vector<double> values = this->SurfaceValues();
    for (int level : { NumberOfLevels - 1, 2, 1, 0, IsosurfaceScene::CoarsestLevel })
    {
      const std::uint64_t built = this->Scene ? this->Scene->GetActivePairs(level) : 0;
      const bool builtNow = this->Scene && this->Scene->GetBuiltValues(level) == values;
      const std::uint64_t pairs =
        built > 0 ? built : IsosurfaceScene::EstimateActivePairs(full, level);
      for (double distance : { 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0 })
      {
        FrameTimeModel::Candidate c;
        c.Level = level;
        c.SampleDistance = static_cast<float>(distance);
        c.Work = this->Work(pairs, distance);
        c.Work.BuildElements = builtNow ? 0 : this->LevelCells(level);
        c.Work.Programs = this->GPUPrograms(level, distance, c.Work);
        candidates.push_back(c);
      }
    }
  }

  // The programs a GPU frame of the current surfaces at volume level `level` and image sample
  // distance `distance` would compile: the scene's own answer where the level is built for these
  // surfaces (IsosurfaceScene::ProgramsToBuild: the variant looked up in what its renderer
  // compiled; the view is the last frame's), else Warm's key. The key alone predicted a skin over
  // a bone on volume level -1 as compiled because a skin alone had been drawn there, and the
  // drag's first frame compiled for 0.6 s against 86 ms predicted (issue 30).
  std::uint32_t GPUPrograms(int level, double distance, const FrameWork& work) const
  {
    if (this->Scene)
    {
      IsosurfaceFrame frame = this->Frame;
      frame.Level = level;
      const int width =
        std::max(1, static_cast<int>(std::ceil(this->Viewpoint.GetWidth() / distance)));
      const int height =
        std::max(1, static_cast<int>(std::ceil(this->Viewpoint.GetHeight() / distance)));
      SetFrameView(
        frame, this->Viewpoint.GetCamera(), this->Viewpoint.GetPlacement(), width, height);
      const int known = this->Scene->ProgramsToBuild(frame);
      if (known >= 0)
      {
        return static_cast<std::uint32_t>(known);
      }
    }
    return this->Warm.count(this->WarmKey(level, work)) ? 0 : 1;
  }

  // The work of a frame of the current surfaces with `primitives` (triangles on the CPU path)
  // at an image sample distance.
  FrameWork Work(std::uint64_t primitives, double sampleDistance) const
  {
    FrameWork work;
    work.Method = this->CPUPath ? FrameMethod::Triangles : FrameMethod::CellRasterisation;
    work.Primitives = primitives;
    work.Pixels = FrameTimeModel::ShadedPixels(
      this->Viewpoint.GetWidth(), this->Viewpoint.GetHeight(), sampleDistance);
    work.Translucent = std::any_of(this->Frame.Surfaces.begin(), this->Frame.Surfaces.end(),
      [](const IsosurfaceLook& s) { return s.Opacity < 1.0f; });
    return work;
  }

  // The estimator's seconds of extracting the current surfaces at a CPU level (0 when cached).
  double ExtractSeconds(int level)
  {
    double seconds = 0.0;
    for (const IsosurfaceLook& s : this->Frame.Surfaces)
    {
      seconds += std::max(0.0, this->CPU.EstimateSeconds(s.Value, level));
    }
    return seconds;
  }

  // Cells of a GPU volume level (every stride-th point and the last of each axis): what its
  // pyramid's build covers.
  std::uint64_t LevelCells(int level) const
  {
    const int* dims = this->Viewpoint.GetPlacement().Dimensions;
    const int stride = IsosurfaceScene::VolumeLevelStride(level);
    std::uint64_t cells = 1;
    for (int a = 0; a < 3; ++a)
    {
      cells *= static_cast<std::uint64_t>(std::max(0, (dims[a] - 1 + stride - 1) / stride));
    }
    return cells;
  }

  // Warm's key: the programs a frame compiles, where a frame's one-off work
  // counts one (FrameWork::Programs). The GPU path compiles its pyramid walk
  // per volume level (the level's layout is compiled in), translucency and
  // number of isovalues (a translucent frame's shaders are compiled for the
  // isovalues it counts, and one isovalue walks another layout); the
  // CPU path's meshes have one program whatever their level or translucency; a
  // sample distance compiles nothing on either (its framebuffer is resized,
  // the blit needs no program). Keyed by the distance as well, every new
  // distance of a drag was predicted to pay a level's set-up.
  std::array<int, 3> WarmKey(int level, const FrameWork& work) const
  {
    if (work.Method == FrameMethod::Triangles)
    {
      return { static_cast<int>(work.Method), 0, 0 };
    }
    return { static_cast<int>(work.Method), level,
      (work.Translucent ? 1 : 0) + 2 * static_cast<int>(this->Frame.Surfaces.size()) };
  }

  // The last frame's work, as drawn.
  FrameWork DrawnWork(double sampleDistance) const
  {
    return this->Work(this->CPUPath ? static_cast<std::uint64_t>(this->ShownTriangles)
                                    : this->Stats.Primitives,
      sampleDistance);
  }

  // The finest level whose estimated surfaces fit the memory budget (the
  // estimator's choice that Update makes with LevelChoice::Auto; level 0 when
  // none does).
  int MemoryLevel()
  {
    if (this->RequestedLevel >= 0)
    {
      return this->RequestedLevel;
    }
    for (int level = NumberOfLevels - 1; level > 0; --level)
    {
      double bytes = 0.0;
      for (const IsosurfaceLook& s : this->Frame.Surfaces)
      {
        bytes += this->CPU.GetLayout().Bytes(this->CPU.Estimate(s.Value, level).Counts);
      }
      if (bytes <= this->Budget)
      {
        return level;
      }
    }
    return 0;
  }

  // The framebuffer of a sampled frame (colour and depth), at the canvas's size over the
  // sample distance; false when it cannot be made (the frame is then drawn in full).
  bool PrepareSampled()
  {
    const int width =
      std::max(1, static_cast<int>(std::ceil(this->Viewpoint.GetWidth() / this->SampleDistance)));
    const int height =
      std::max(1, static_cast<int>(std::ceil(this->Viewpoint.GetHeight() / this->SampleDistance)));
    const GLApi::Functions& f = this->GL->F();
    if (this->Sampled && this->SampledSize[0] == width && this->SampledSize[1] == height)
    {
      return true;
    }
    this->Sampled = glcore::Name(*this->GL, glcore::NameKind::Framebuffer);
    this->SampledColor = glcore::Name(*this->GL, glcore::NameKind::Renderbuffer);
    this->SampledDepth = glcore::Name(*this->GL, glcore::NameKind::Renderbuffer);
    f.BindRenderbuffer(GL_RENDERBUFFER, this->SampledColor.Get());
    f.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    f.BindRenderbuffer(GL_RENDERBUFFER, this->SampledDepth.Get());
    f.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    f.BindRenderbuffer(GL_RENDERBUFFER, 0);
    f.BindFramebuffer(GL_FRAMEBUFFER, this->Sampled.Get());
    f.FramebufferRenderbuffer(
      GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, this->SampledColor.Get());
    f.FramebufferRenderbuffer(
      GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, this->SampledDepth.Get());
    const bool complete = f.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    f.BindFramebuffer(GL_FRAMEBUFFER, 0);
    if (!complete)
    {
      this->Sampled.Reset();
      return false;
    }
    this->SampledSize[0] = width;
    this->SampledSize[1] = height;
    return true;
  }

  // The CPU path's model transform: the volume's direction about its origin
  // (the BlockLOD core places points at origin + spacing * index).
  matrix4::Matrix PlacementModel() const
  {
    matrix4::Matrix m = matrix4::Identity();
    const double* d = this->Viewpoint.GetPlacement().Direction;
    const double* o = this->Viewpoint.GetPlacement().Origin;
    for (int r = 0; r < 3; ++r)
    {
      double shift = o[r];
      for (int c = 0; c < 3; ++c)
      {
        m[4 * r + c] = d[3 * r + c];
        shift -= d[3 * r + c] * o[c];
      }
      m[4 * r + 3] = shift;
    }
    return m;
  }

  // The CPU path's ParallelFor: over the machine's threads (threaded module) or this one.
  // A watched extraction's ranges are cut into batches of blocks: the core polls its abort
  // once per range it is handed (pass 1), so a batch bounds how long an obsolete pass runs on.
  // Pass 2 (writing a surface, after the level is planned) takes no abort in the core: there
  // the batches themselves stop once the extraction is obsolete, the surface is left partial,
  // and the core's check after it stops the update; UpdateCPUSurfaces then empties the cache,
  // which holds that partial surface.
  void RunPass(std::int64_t begin, std::int64_t end, const RangeBody& body)
  {
#ifdef MEDISO_WEB_THREADS
    const ParallelFor run = ThreadedFor;
#else
    const ParallelFor run = SerialFor;
#endif
    if (!this->Watching)
    {
      run(begin, end, body);
      return;
    }
    constexpr std::int64_t BlocksPerPoll = 256;
    const bool stoppable = this->Generating;
    run(begin, end,
      [this, &body, stoppable](std::int64_t a, std::int64_t b)
      {
        for (std::int64_t c = a; c < b; c += BlocksPerPoll)
        {
          while (stoppable && this->SlowPass == 2 &&
            emscripten_get_now() - this->WatchStart < this->SlowExtractionMs &&
            this->PageGeneration() == this->WatchedGeneration)
          {
          }
          if (stoppable && this->PageGeneration() != this->WatchedGeneration)
          {
            this->SkippedBatches = true;
            return;
          }
          body(c, std::min(b, c + BlocksPerPoll));
        }
      });
  }

  // The page's generation word as it is now (see GenerationWord()).
  int PageGeneration() const
  {
#ifdef MEDISO_WEB_THREADS
    return this->Generation.load(std::memory_order_relaxed);
#else
    return mediso_page_generation();
#endif
  }

  // The core's abort for a watched extraction begun at `start` (ms): true once the page's
  // generation moved on. Polled from the pass's threads; with the test hook, each poll first
  // waits (still watching) until the extraction is SlowExtractionMs old.
  UpdateHooks AbortHooks(double start)
  {
    UpdateHooks hooks;
    this->Generating = false;
    this->SkippedBatches = false;
    if (!this->Watching)
    {
      return hooks;
    }
    hooks.Planned = [this](int) { this->Generating = true; };
    const int generation = this->WatchedGeneration;
    const double slowMs = this->SlowPass == 1 ? this->SlowExtractionMs : 0.0;
    this->WatchStart = start;
    hooks.PollAbort = [this, generation, slowMs, start]()
    {
      while (slowMs > 0.0 && emscripten_get_now() - start < slowMs)
      {
        if (this->PageGeneration() != generation)
        {
          return true;
        }
      }
      return this->PageGeneration() != generation;
    };
    hooks.CheckAbort = hooks.PollAbort;
    return hooks;
  }

  // The CPU path: the surfaces unit makes or finds each surface at the
  // level requested, or the estimator's within the budget (a guide here:
  // level 0 when nothing fits, said in the error); uploaded when it changed.
  /**
   * The GPU scene takes the volume SetVolume described when the GPU path first needs it (its
   * frame, or SetVolume on the GPU path), not while the CPU path draws: that upload is the bulk
   * of SetVolume on a software renderer, and a streamed volume's empty buffer (docs/web.md,
   * Streaming) then never goes up before its values have arrived.
   */
  bool UpdateSceneVolume(std::string& error)
  {
    if (!this->SceneVolumeStale)
    {
      return true;
    }
    emscripten_webgl_make_context_current(this->Context);
    if (!this->Scene->SetVolume(this->Described, error))
    {
      return false;
    }
    this->SceneVolumeStale = false;
    return true;
  }

  bool UpdateCPUSurfaces()
  {
    // Streaming: the surfaces named coarse come from the coarse volume, the others from the
    // buffer at level 3 (its coarse copies would read bricks not yet there).
    const bool streaming = this->CPU.GetVolume().IsStreaming();
    std::vector<double> values, fine, coarse;
    std::vector<char> isCoarse;
    for (const IsosurfaceLook& s : this->Frame.Surfaces)
    {
      const bool c = streaming && this->CoarseData &&
        std::find(this->CoarseValues.begin(), this->CoarseValues.end(), s.Value) !=
          this->CoarseValues.end();
      values.push_back(s.Value);
      isCoarse.push_back(c);
      (c ? coarse : fine).push_back(s.Value);
    }
    LevelChoice choice;
    choice.Level = streaming ? NumberOfLevels - 1
      : this->RequestedLevel < 0 ? LevelChoice::Auto
                                 : this->RequestedLevel;
    choice.BudgetBytes = this->Budget;
    choice.BudgetBinds = false;
    this->CPU.SetCacheLimit(std::max(this->Budget / 4.0, 0.0));
    // Streaming: the frame's surfaces are extracted ahead as the bricks arrive (WriteBrick), the
    // level-3 update then takes them made; after the end, one no longer drawn is forgotten.
    this->CPU.SetAheadIsovalues(values);
    const double start = emscripten_get_now();
    this->LastAborted = false;
    const SurfacesUpdate update =
      this->CPU.Update(fine, choice, CPUSurfaceMaker(), this->AbortHooks(start));
    this->Generating = false;
    if (update.Status == SurfacesUpdate::Outcome::Aborted)
    {
      if (this->SkippedBatches)
      {
        this->CPU.ClearCache(); // a surface left partial was cached (RunPass)
      }
      this->LastAborted = true; // not an error: the worker goes on to the newer change
      return false;
    }
    if (update.OverBudget)
    {
      this->LastError = "not even level 0 of these isosurfaces fits the memory budget (" +
        std::to_string(update.Level0Bytes / 1e6) + " MB needed)";
    }
    if (update.Status != SurfacesUpdate::Outcome::Done)
    {
      this->LastError = update.Status == SurfacesUpdate::Outcome::OutOfMemory
        ? update.Message
        : "the extraction stopped";
      return false;
    }
    if (!streaming)
    {
      this->CPU.RecordCost(update, (emscripten_get_now() - start) / 1000.0);
    }
    this->TakenAhead += update.TakenAhead;
    std::vector<CPUSurfaceRef> coarseSurfaces;
    if (!coarse.empty())
    {
      LevelChoice whole;
      whole.Level = NumberOfLevels - 1;
      this->Coarse.SetCacheLimit(std::max(this->Budget / 16.0, 0.0));
      const SurfacesUpdate c = this->Coarse.Update(coarse, whole, CPUSurfaceMaker());
      if (c.Status != SurfacesUpdate::Outcome::Done)
      {
        this->LastError = c.Status == SurfacesUpdate::Outcome::OutOfMemory
          ? c.Message
          : "the extraction stopped";
        return false;
      }
      coarseSurfaces = this->Coarse.GetSurfaces();
    }
    // No isovalues: the level the choice would give for nothing, as before any surface.
    this->CPULevel = !fine.empty() ? update.Level
      : streaming || this->RequestedLevel < 0 ? NumberOfLevels - 1
                                              : this->RequestedLevel;
    const std::vector<CPUSurfaceRef>& surfaces = this->CPU.GetSurfaces();
    this->ShownTriangles = 0.0;
    this->SlotValues = values;
    this->SlotCoarse.assign(isCoarse.begin(), isCoarse.end());
    this->SlotTriangles.assign(values.size(), 0.0);
    std::size_t nextFine = 0, nextCoarse = 0;
    for (int slot = 0; slot < MaximumIsovalues; ++slot)
    {
      if (slot >= static_cast<int>(values.size()))
      {
        this->Meshes->Clear(slot);
        this->ShownKeys[slot] = SurfaceKey{ NAN, -1 };
        continue;
      }
      // A coarse surface's key: a level no fine one has.
      const bool c = isCoarse[slot] != 0;
      const SurfaceKey key{ values[slot], c ? -2 : update.Level };
      const CPUSurface& surface = c ? *coarseSurfaces[nextCoarse++] : *surfaces[nextFine++];
      if (!(this->ShownKeys[slot] == key))
      {
        this->MeshesUploaded = true;
        const double uploadStart = emscripten_get_now();
        this->Meshes->SetMesh(slot, surface.Points.data(), surface.Normals.data(),
          static_cast<std::int64_t>(surface.Points.size() / 3),
          reinterpret_cast<const std::uint32_t*>(surface.Triangles.data()),
          static_cast<std::int64_t>(surface.Triangles.size() / 3));
        this->LastUploadMs += emscripten_get_now() - uploadStart;
        this->ShownKeys[slot] = key;
      }
      const IsosurfaceLook& look = this->Frame.Surfaces[slot];
      this->Meshes->SetLook(slot, look.Color, look.Opacity, true);
      this->SlotTriangles[slot] = static_cast<double>(surface.Triangles.size() / 3);
      this->ShownTriangles += this->SlotTriangles[slot];
    }
    return true;
  }

  std::string Canvas; // the canvas's CSS selector
  EMSCRIPTEN_WEBGL_CONTEXT_HANDLE Context = 0;
  std::string Error;
  std::string LastError;
  std::shared_ptr<const GLApi> GL;
  std::unique_ptr<IsosurfaceScene> Scene;
  ScalarType Type = ScalarType::Int16;
  const void* Data = nullptr;
  PageCamera Viewpoint; // the volume's placement, the camera and the canvas's size
  IsosurfaceFrame Frame;
  IsosurfaceSceneStats Stats; // of the last frame the GPU path drew (zero otherwise)
  float Background[3] = { 0.1f, 0.12f, 0.16f };
  double LastBuildMs = 0.0, LastFrameMs = 0.0;
  double SampleDistance = 1.0, DrawnSampleDistance = 1.0;
  int GPULevel = NumberOfLevels - 1; // the GPU path's volume level (SetGPULevel)
  FrameTimeModel Times; // this client's frames: the time each level or sample distance takes
  double FrameStart = 0.0;
  bool FrameDrawn = false; // a frame was drawn since the last Finish
  std::uint64_t FramesDrawn = 0; // frames drawn (not PrepareDragStep's rehearsals)
  // The GPU path's last interactive choice (ChooseFrame), held by the next drag frame where the
  // frame drawn last (FramesDrawn) was that choice's.
  struct
  {
    int Level = 0;
    float SampleDistance = 1.0f;
    std::uint64_t Frame = 0;
    bool Finer = true; // the drag has not gone coarser
  } HeldChoice;
  // The one-off work of the frame being drawn (Finish() reports it), and what was drawn before.
  double FrameExtractSeconds = 0.0;
  std::uint64_t FrameBuildCells = 0;
  std::uint64_t FramePrograms = 0; // the GPU path's programs compiled by the last frame
  std::set<std::array<int, 3>> Warm;
  bool MeshesUploaded = false; // the last frame made or uploaded a CPU path surface
  // The part of the last frame's buildMs that uploaded its CPU path surfaces
  // (MeshRenderer::SetMesh; the rest took them from the extraction).
  double LastUploadMs = 0.0;
  bool Rehearsing = false;     // PrepareDragStep's rehearsal: drawn into Sampled only, never shown
  glcore::Name Sampled, SampledColor, SampledDepth; // a sampled frame's framebuffer
  int SampledSize[2] = { 0, 0 };

  // The CPU path.
  bool CPUPath = false;
  // Its own cost model: this page's updates give the estimator's seconds.
  BlockLODSurfaces<CPUSurfaceRef> CPU{ mediso_web::MarchingCubesCases,
    [this](std::int64_t begin, std::int64_t end, const RangeBody& body)
    { this->RunPass(begin, end, body); },
    std::make_shared<SharedCostModel>(), CPULayout };
  std::vector<SurfaceKey> ShownKeys = std::vector<SurfaceKey>(MaximumIsovalues, SurfaceKey{ NAN, -1 });
  int TakenAhead = 0; // surfaces of this stream the CPU path took extracted ahead
  // Streaming: the server's level 0 and its surfaces, the bricks of the buffer, the isovalues
  // drawn from level 0, and per slot of the last frame whether it was and its triangles.
#ifdef MEDISO_WEB_THREADS
  BlockLODSurfaces<CPUSurfaceRef> Coarse{ mediso_web::MarchingCubesCases, ThreadedFor, nullptr,
    CPULayout };
#else
  BlockLODSurfaces<CPUSurfaceRef> Coarse{ mediso_web::MarchingCubesCases, SerialFor, nullptr,
    CPULayout };
#endif
  const void* CoarseData = nullptr;
  VolumeDescription Described; // the volume as SetVolume described it (EndStreaming uploads it again)
  bool SceneVolumeStale = false; // the GPU scene has not taken Described yet (UpdateSceneVolume)
  BrickGrid Bricks;
  std::vector<double> CoarseValues;
  int StreamLevel = 0; // the GPU scene's coarse level the coarse volume is (streaming)
  std::vector<double> SlotValues;
  std::vector<char> SlotCoarse;
  std::vector<double> SlotTriangles;
  std::uint64_t VolumeStamp = 0;
  int RequestedLevel = -1;
  int CPULevel = 3;
  double Budget = 1e9;
  double ShownTriangles = 0.0;
  std::unique_ptr<web::MeshRenderer> Meshes;

  // The abort of an obsolete extraction (WatchGeneration()).
#ifdef MEDISO_WEB_THREADS
  std::atomic<std::int32_t> Generation{ 0 }; // the page's word, written by its main thread
#endif
  bool Watching = false;
  int WatchedGeneration = 0;
  bool LastAborted = false;
  double SlowExtractionMs = 0.0;
  int SlowPass = 1;
  double WatchStart = 0.0;
  bool Generating = false;                  // the watched update is past its plan (pass 2)
  std::atomic<bool> SkippedBatches{ false }; // RunPass left a surface partial
};

namespace
{
// The facts the page takes from the cores rather than writing them again
// (docs/web.md, The page's modules): each is stated once in C++.

/// The scalar types the cores take: [{name, value, bytes}], `value` as
/// WebViewer.setVolume takes it, `name` as the server's X-Mediso-Type says it.
val ScalarTypes()
{
  val list = val::array();
  for (int value = 0;; ++value)
  {
    const ScalarType type = static_cast<ScalarType>(value);
    const int bytes = ScalarTypeSize(type);
    if (bytes == 0)
    {
      break;
    }
    val entry = val::object();
    entry.set("name", std::string(ScalarTypeName(type)));
    entry.set("value", value);
    entry.set("bytes", bytes);
    list.call<void>("push", entry);
  }
  return list;
}

/// The sample stride of a level of detail (BlockLOD's levels; the server's
/// volume levels sample the same points); 0 outside 0 .. NumberOfLevels - 1.
int Stride(int level)
{
  return level >= 0 && level < NumberOfLevels ? LevelStride(level) : 0;
}

/// What the GPU path needs for a volume of `dims` points of scalar type
/// `type` before it is fetched: {bytes: the volume texture and the built
/// pyramid, texture: the volume texture's texels per axis}.
val GPUVolume(int type, const val& dims)
{
  int points[3];
  for (int a = 0; a < 3; ++a)
  {
    points[a] = std::max(1, dims[a].as<int>());
  }
  const std::array<int, 3> texture = IsosurfaceScene::VolumeTextureSize(points);
  val out = val::object();
  out.set("bytes",
    static_cast<double>(
      IsosurfaceScene::EstimateGPUMemoryBytes(static_cast<ScalarType>(type), points)));
  val size = val::array();
  for (int t : texture)
  {
    size.call<void>("push", t);
  }
  out.set("texture", size);
  return out;
}

// The first isovalue's rule (Filters/Core/HistogramThreshold.h), the one the
// ParaView side applies, handed to the page's histogram
// (Web/static/histogram.js): the page counts the values of the volume it holds
// into these bins, and the module says whether the range is Hounsfield units
// and where Otsu's threshold lies.

/// The cores' brick ranges (BrickGrid.h, ComputeBrickRanges) of a volume of
/// ScalarType `type` at `bytes` in the module's memory: [[min, max] or null
/// per brick, x fastest]. The page's test compares them with the server's
/// manifest, which computes them with numpy.
val BrickRanges(int type, std::uintptr_t bytes, const val& dims, int brickPoints, int apron)
{
  int points[3];
  for (int a = 0; a < 3; ++a)
  {
    points[a] = dims[a].as<int>();
  }
  const BrickGrid grid(points, brickPoints);
  val out = val::array();
  for (const BrickRange& r : ComputeBrickRanges(grid, static_cast<ScalarType>(type),
         reinterpret_cast<const void*>(bytes), apron, SerialFor))
  {
    if (r.Min > r.Max)
    {
      out.call<void>("push", val::null());
      continue;
    }
    val pair = val::array();
    pair.call<void>("push", r.Min);
    pair.call<void>("push", r.Max);
    out.call<void>("push", pair);
  }
  return out;
}

/// The bins the first isovalue's rule counts a range in: {low, width, count}.
val HistogramBinsFor(double min, double max, bool integral)
{
  const HistogramBins bins = HistogramBins::For(min, max, integral);
  val out = val::object();
  out.set("low", bins.Low);
  out.set("width", bins.Width);
  out.set("count", static_cast<double>(bins.Count));
  return out;
}

/// Otsu's threshold of `counts` (a JavaScript array, one entry per bin of
/// {low, width}); NaN when the histogram has fewer than two non-empty bins.
double Otsu(const val& counts, double low, double width)
{
  const std::size_t n = counts["length"].as<std::size_t>();
  std::vector<std::uint64_t> values(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    values[i] = static_cast<std::uint64_t>(std::max(0.0, counts[i].as<double>()));
  }
  HistogramBins bins;
  bins.Low = low;
  bins.Width = width;
  bins.Count = n;
  double threshold = 0.0;
  return OtsuThreshold(values, bins, threshold) ? threshold
                                                : std::numeric_limits<double>::quiet_NaN();
}
} // namespace

EMSCRIPTEN_BINDINGS(mediso_web)
{
  emscripten::function("scalarTypes", &ScalarTypes);
  emscripten::constant("NumberOfLevels", NumberOfLevels);
  emscripten::function("levelStride", &Stride);
  // The GPU path's volume levels' strides (stats().gpuLevel: -1 to 3; IsosurfaceScene).
  emscripten::constant("CoarsestGPULevel", IsosurfaceScene::CoarsestLevel);
  emscripten::function("gpuLevelStride", &IsosurfaceScene::VolumeLevelStride);
  emscripten::constant("MaximumIsovalues", MaximumIsovalues);
  emscripten::function("gpuVolume", &GPUVolume);
  emscripten::function("looksLikeHounsfieldUnits", &LooksLikeHounsfieldUnits);
  emscripten::constant("SkinHounsfield", SkinHounsfield);
  emscripten::constant("BoneHounsfield", BoneHounsfield);
  emscripten::function("histogramBins", &HistogramBinsFor);
  emscripten::function("brickRanges", &BrickRanges);
  emscripten::function("otsuThreshold", &Otsu);
  const emscripten::class_<WebViewer> viewer("WebViewer");
  mediso::web::BindPageCamera(viewer);
  viewer.constructor<std::string>()
    .function("ready", &WebViewer::Ready)
    .function("error", &WebViewer::GetError)
    .function("info", &WebViewer::Info)
    .function("setVolume", &WebViewer::SetVolume)
    .function("setStreamingVolume", &WebViewer::SetStreamingVolume)
    .function("setSurfaces", &WebViewer::SetSurfaces)
    .function("resize", &WebViewer::Resize)
    .function("setBackground", &WebViewer::SetBackground)
    .function("setMaterial", &WebViewer::SetMaterial)
    .function("render", &WebViewer::Render)
    .function("finish", &WebViewer::Finish)
    .function("stats", &WebViewer::GetStats)
    .function("countOnCPU", &WebViewer::CountOnCPU)
    .function("setPath", &WebViewer::SetPath)
    .function("setCPULevel", &WebViewer::SetCPULevel)
    .function("setBudget", &WebViewer::SetBudget)
    .function("setMaxTextureSize", &WebViewer::SetMaxTextureSize)
    .function("setGPUBudget", &WebViewer::SetGPUBudget)
    .function("setBrickPool", &WebViewer::SetBrickPool)
    .function("setSampleDistance", &WebViewer::SetSampleDistance)
    .function("setGPULevel", &WebViewer::SetGPULevel)
    .function("chooseFrame", &WebViewer::ChooseFrame)
    .function("prepareDragStep", &WebViewer::PrepareDragStep)
    .function("estimates", &WebViewer::Estimates)
    .function("setResultMesh", &WebViewer::SetResultMesh)
    .function("clearResultMesh", &WebViewer::ClearResultMesh)
    .function("generationWord", &WebViewer::GenerationWord)
    .function("watchGeneration", &WebViewer::WatchGeneration)
    .function("aborted", &WebViewer::Aborted)
    .function("setSlowExtraction", &WebViewer::SetSlowExtraction)
    .function("setCoarseVolume", &WebViewer::SetCoarseVolume)
    .function("beginStreaming", &WebViewer::BeginStreaming)
    .function("writeBrick", &WebViewer::WriteBrick)
    .function("endStreaming", &WebViewer::EndStreaming)
    .function("setCoarseValues", &WebViewer::SetCoarseValues);
}
