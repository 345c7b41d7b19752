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
 * volume's placement and the camera; the core's scene rebuilds the pyramid only when the isovalues
 * change.
 *
 * The CPU path, for clients whose GPU cannot afford the GPU path (a software
 * rasteriser, small limits): the BlockLOD core (Filters/Core, the code of
 * ParaView's BlockLODContour, with VTK's case table generated at build
 * time) extracts each surface at the level of detail its memory estimator
 * fits in the client's budget; surfaces are cached per (isovalue, level) and
 * drawn as triangles (MeshRenderer). A surface the server made is drawn beside
 * either path.
 */
#include "BlockLOD.h"
#include "BlockLODSurfaces.h"
#include "Camera.h"
#include "GLApiFunctions.h"
#include "GLProbe.h"
#include "HistoPyramid.h"
#include "HistogramThreshold.h"
#include "IsosurfaceScene.h"
#include "MeshRenderer.h"
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
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace mediso_web
{
extern const int MarchingCubesCases[256][16];
}

namespace
{
using emscripten::val;
using namespace mediso;

/// A surface of the CPU path, as drawn.
struct CPUSurface
{
  std::vector<float> Points, Normals;
  std::vector<std::uint32_t> Triangles;
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
    target.Narrow.Connectivity = reinterpret_cast<std::int32_t*>(surface->Triangles.data());
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

std::vector<double> Doubles(const val& array)
{
  std::vector<double> out;
  const int n = array["length"].as<int>();
  for (int i = 0; i < n; ++i)
  {
    out.push_back(array[i].as<double>());
  }
  return out;
}

void Triple(const val& array, double out[3])
{
  for (int a = 0; a < 3; ++a)
  {
    out[a] = array[a].as<double>();
  }
}

val TripleVal(const double v[3])
{
  val out = val::array();
  for (int a = 0; a < 3; ++a)
  {
    out.call<void>("push", v[a]);
  }
  return out;
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
    if (!this->Ready())
    {
      return false;
    }
    for (int a = 0; a < 3; ++a)
    {
      this->Placement.Dimensions[a] = dims[a].as<int>();
      this->Placement.Spacing[a] = spacing[a].as<double>();
      this->Placement.Origin[a] = origin[a].as<double>();
    }
    this->Type = static_cast<ScalarType>(type);
    this->Data = reinterpret_cast<const void*>(bytes);
    emscripten_webgl_make_context_current(this->Context);
    VolumeDescription description;
    description.Type = this->Type;
    description.Data = this->Data;
    std::copy(this->Placement.Dimensions, this->Placement.Dimensions + 3, description.Dims);
    std::copy(this->Placement.Origin, this->Placement.Origin + 3, description.Origin);
    std::copy(this->Placement.Spacing, this->Placement.Spacing + 3, description.Spacing);
    description.Stamp = ++this->VolumeStamp;
    std::string error;
    if (!this->Scene->SetVolume(description, error))
    {
      this->LastError = error;
      return false;
    }
    this->CPU.SetVolume(description);
    this->ShownKeys.assign(MaximumIsovalues, SurfaceKey{ NAN, -1 });
    this->ResetCamera();
    return true;
  }

  /// "gpu" or "cpu": which path draws.
  void SetPath(const std::string& path) { this->CPUPath = path == "cpu"; }

  /// The CPU path's level of detail: 0-3, or -1 to let the estimator choose
  /// within the budget.
  void SetCPULevel(int level) { this->RequestedLevel = std::max(-1, std::min(3, level)); }

  /// The client's memory budget (bytes) for the CPU path's surfaces and their cache.
  void SetBudget(double bytes) { this->Budget = std::max(0.0, bytes); }

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

  void Resize(int width, int height)
  {
    this->Width = std::max(1, width);
    this->Height = std::max(1, height);
    emscripten_set_canvas_element_size(this->Canvas.c_str(), this->Width, this->Height);
  }

  void ResetCamera()
  {
    double bounds[6];
    this->Placement.Bounds(bounds);
    this->View = Camera();
    this->View.Parallel = this->Parallel;
    this->View.Reset(bounds, static_cast<double>(this->Width) / this->Height);
  }
  void Azimuth(double degrees) { this->View.Azimuth(degrees); }
  void Elevation(double degrees)
  {
    this->View.Elevation(degrees);
    this->View.OrthogonalizeViewUp();
  }
  void Zoom(double factor) { this->View.Zoom(factor); }
  void Dolly(double factor) { this->View.Dolly(factor); }
  void SetParallel(bool parallel)
  {
    this->Parallel = parallel;
    this->View.Parallel = parallel;
  }

  /// {position, focalPoint, viewUp, viewAngle[, parallelScale]}
  void SetView(const val& view)
  {
    double position[3], focal[3], up[3];
    Triple(view["position"], position);
    Triple(view["focalPoint"], focal);
    Triple(view["viewUp"], up);
    if (!view["viewAngle"].isUndefined())
    {
      this->View.ViewAngle = view["viewAngle"].as<double>();
    }
    if (!view["parallelScale"].isUndefined())
    {
      this->View.ParallelScale = view["parallelScale"].as<double>();
    }
    this->View.SetView(position, focal, up);
  }

  val GetView() const
  {
    val view = val::object();
    view.set("position", TripleVal(this->View.Position));
    view.set("focalPoint", TripleVal(this->View.FocalPoint));
    view.set("viewUp", TripleVal(this->View.ViewUp));
    view.set("viewAngle", this->View.ViewAngle);
    view.set("parallelScale", this->View.ParallelScale);
    return view;
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
    std::vector<double> values;
    for (const IsosurfaceLook& s : this->Frame.Surfaces)
    {
      values.push_back(s.Value);
    }
    this->LastBuildMs = 0.0;
    if (this->CPUPath)
    {
      if (!this->UpdateCPUSurfaces())
      {
        return false;
      }
      this->LastBuildMs = emscripten_get_now() - start;
    }
    else if (!values.empty())
    {
      // The scene builds only when the isovalues changed.
      const std::uint64_t builds = this->Scene->GetStats().PyramidBuilds;
      this->Scene->SetSurfaces(this->Frame.Surfaces);
      std::string error;
      if (!this->Scene->Update(error))
      {
        this->LastError = error;
        return false;
      }
      if (this->Scene->GetStats().PyramidBuilds != builds)
      {
        this->LastBuildMs = emscripten_get_now() - start;
      }
    }
    double bounds[6];
    this->Placement.Bounds(bounds);
    this->View.ResetClippingRange(bounds);
    SetFrameView(this->Frame, this->View, this->Placement, this->Width, this->Height);
    f.BindFramebuffer(GL_FRAMEBUFFER, 0);
    f.Viewport(0, 0, this->Width, this->Height);
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
    }
    // The CPU path's surfaces and the server's result, in world coordinates.
    if (this->Meshes->GetNumberOfMeshes() > 0)
    {
      const double aspect = static_cast<double>(this->Width) / std::max(1, this->Height);
      const matrix4::Matrix modelToView = matrix4::Multiply(this->View.ViewMatrix(), this->PlacementModel());
      if (!this->Meshes->Render(this->Frame, modelToView, this->View.ProjectionMatrix(aspect), error))
      {
        this->LastError = error;
        return false;
      }
    }
    this->LastFrameMs = emscripten_get_now() - start;
    return true;
  }

  /// Waits for the GPU to finish (a one-pixel read-back): for timings.
  void Finish()
  {
    emscripten_webgl_make_context_current(this->Context);
    unsigned char pixel[4];
    this->GL->F().ReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel);
  }

  val GetStats() const
  {
    val stats = val::object();
    stats.set("path", std::string(this->CPUPath ? "cpu" : "gpu"));
    stats.set("primitives", this->CPUPath ? 0.0 : static_cast<double>(this->Stats.Primitives));
    stats.set("triangles", this->CPUPath ? this->ShownTriangles : 0.0);
    stats.set("cpuLevel", this->CPULevel);
    stats.set("cacheMB", this->CPU.GetCacheBytes() / 1e6);
    stats.set("footprint", std::string(this->Stats.PointFootprint ? "points" : "boxes"));
    stats.set("firstHit", this->Stats.FirstHit);
    stats.set("buildMs", this->LastBuildMs);
    stats.set("frameMs", this->LastFrameMs);
    stats.set(
      "gpuBytes", this->Scene ? static_cast<double>(this->Scene->GetGPUMemoryBytes()) : 0.0);
    stats.set("frameBufferBytes",
      this->Scene ? static_cast<double>(this->Scene->GetFrameBufferBytes()) : 0.0);
    stats.set("error", this->LastError);
    return stats;
  }

  /// The CPU model's count of active (cell, isovalue) pairs (tests compare the GPU's with it).
  double CountOnCPU(const val& isovalues) const
  {
    if (!this->Data)
    {
      return 0.0;
    }
    const std::vector<double> values = Doubles(isovalues);
    std::uint64_t total = 0;
    VisitScalarType(this->Type,
      [&](auto tag)
      {
        using T = decltype(tag);
        for (std::uint32_t n : HistoPyramid::CountCrossings(
               static_cast<const T*>(this->Data), this->Placement.Dimensions, values))
        {
          total += n;
        }
      });
    return static_cast<double>(total);
  }

private:
  // The CPU path's model transform: the volume's direction about its origin
  // (the BlockLOD core places points at origin + spacing * index).
  matrix4::Matrix PlacementModel() const
  {
    matrix4::Matrix m = matrix4::Identity();
    const double* d = this->Placement.Direction;
    const double* o = this->Placement.Origin;
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

  // The CPU path: the surfaces unit makes or finds each surface at the
  // level requested, or the estimator's within the budget (a guide here:
  // level 0 when nothing fits, said in the error); uploaded when it changed.
  bool UpdateCPUSurfaces()
  {
    std::vector<double> values;
    for (const IsosurfaceLook& s : this->Frame.Surfaces)
    {
      values.push_back(s.Value);
    }
    LevelChoice choice;
    choice.Level = this->RequestedLevel < 0 ? LevelChoice::Auto : this->RequestedLevel;
    choice.BudgetBytes = this->Budget;
    choice.BudgetBinds = false;
    this->CPU.SetCacheLimit(std::max(this->Budget / 4.0, 0.0));
    const double start = emscripten_get_now();
    const SurfacesUpdate update = this->CPU.Update(values, choice, CPUSurfaceMaker());
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
    this->CPU.RecordCost(update, (emscripten_get_now() - start) / 1000.0);
    // No isovalues: the level the choice would give for nothing, as before any surface.
    this->CPULevel = !values.empty() ? update.Level
      : this->RequestedLevel < 0     ? NumberOfLevels - 1
                                     : this->RequestedLevel;
    const std::vector<CPUSurfaceRef>& surfaces = this->CPU.GetSurfaces();
    this->ShownTriangles = 0.0;
    for (int slot = 0; slot < MaximumIsovalues; ++slot)
    {
      if (slot >= static_cast<int>(surfaces.size()))
      {
        this->Meshes->Clear(slot);
        this->ShownKeys[slot] = SurfaceKey{ NAN, -1 };
        continue;
      }
      const SurfaceKey key{ values[slot], update.Level };
      const CPUSurface& surface = *surfaces[slot];
      if (!(this->ShownKeys[slot] == key))
      {
        this->Meshes->SetMesh(slot, surface.Points.data(), surface.Normals.data(),
          static_cast<std::int64_t>(surface.Points.size() / 3), surface.Triangles.data(),
          static_cast<std::int64_t>(surface.Triangles.size() / 3));
        this->ShownKeys[slot] = key;
      }
      const IsosurfaceLook& look = this->Frame.Surfaces[slot];
      this->Meshes->SetLook(slot, look.Color, look.Opacity, true);
      this->ShownTriangles += static_cast<double>(surface.Triangles.size() / 3);
    }
    return true;
  }

  std::string Canvas; // the canvas's CSS selector
  EMSCRIPTEN_WEBGL_CONTEXT_HANDLE Context = 0;
  std::string Error;
  std::string LastError;
  std::shared_ptr<const GLApi> GL;
  std::unique_ptr<IsosurfaceScene> Scene;
  VolumePlacement Placement;
  ScalarType Type = ScalarType::Int16;
  const void* Data = nullptr;
  Camera View;
  bool Parallel = false;
  IsosurfaceFrame Frame;
  IsosurfaceSceneStats Stats; // of the last frame the GPU path drew (zero otherwise)
  int Width = 640, Height = 480;
  float Background[3] = { 0.1f, 0.12f, 0.16f };
  double LastBuildMs = 0.0, LastFrameMs = 0.0;

  // The CPU path.
  bool CPUPath = false;
  // Its own cost model: this page's updates give the estimator's seconds.
#ifdef MEDISO_WEB_THREADS
  BlockLODSurfaces<CPUSurfaceRef> CPU{ mediso_web::MarchingCubesCases, ThreadedFor,
    std::make_shared<SharedCostModel>(), CPULayout };
#else
  BlockLODSurfaces<CPUSurfaceRef> CPU{ mediso_web::MarchingCubesCases, SerialFor,
    std::make_shared<SharedCostModel>(), CPULayout };
#endif
  std::vector<SurfaceKey> ShownKeys = std::vector<SurfaceKey>(MaximumIsovalues, SurfaceKey{ NAN, -1 });
  std::uint64_t VolumeStamp = 0;
  int RequestedLevel = -1;
  int CPULevel = 3;
  double Budget = 1e9;
  double ShownTriangles = 0.0;
  std::unique_ptr<web::MeshRenderer> Meshes;
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
  emscripten::constant("MaximumIsovalues", MaximumIsovalues);
  emscripten::function("gpuVolume", &GPUVolume);
  emscripten::function("looksLikeHounsfieldUnits", &LooksLikeHounsfieldUnits);
  emscripten::constant("SkinHounsfield", SkinHounsfield);
  emscripten::constant("BoneHounsfield", BoneHounsfield);
  emscripten::function("histogramBins", &HistogramBinsFor);
  emscripten::function("otsuThreshold", &Otsu);
  emscripten::class_<WebViewer>("WebViewer")
    .constructor<std::string>()
    .function("ready", &WebViewer::Ready)
    .function("error", &WebViewer::GetError)
    .function("info", &WebViewer::Info)
    .function("setVolume", &WebViewer::SetVolume)
    .function("setSurfaces", &WebViewer::SetSurfaces)
    .function("resize", &WebViewer::Resize)
    .function("resetCamera", &WebViewer::ResetCamera)
    .function("azimuth", &WebViewer::Azimuth)
    .function("elevation", &WebViewer::Elevation)
    .function("zoom", &WebViewer::Zoom)
    .function("dolly", &WebViewer::Dolly)
    .function("setParallel", &WebViewer::SetParallel)
    .function("setView", &WebViewer::SetView)
    .function("getView", &WebViewer::GetView)
    .function("setBackground", &WebViewer::SetBackground)
    .function("setMaterial", &WebViewer::SetMaterial)
    .function("render", &WebViewer::Render)
    .function("finish", &WebViewer::Finish)
    .function("stats", &WebViewer::GetStats)
    .function("countOnCPU", &WebViewer::CountOnCPU)
    .function("setPath", &WebViewer::SetPath)
    .function("setCPULevel", &WebViewer::SetCPULevel)
    .function("setBudget", &WebViewer::SetBudget)
    .function("estimates", &WebViewer::Estimates)
    .function("setResultMesh", &WebViewer::SetResultMesh)
    .function("clearResultMesh", &WebViewer::ClearResultMesh);
}
