// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file ViewCamera.cxx
 * @brief The page's camera and the CPU model's count on the main thread, while the viewer draws in a worker.
 *
 * Where the browser can draw WebGL2 in a worker (an OffscreenCanvas), the
 * page runs its WebViewer there (Web/static/render-worker.js), so that an
 * extraction or a slow frame never holds the page's main thread. The camera
 * must still answer at once: the page reads it to pan, to zoom at the cursor
 * and to draw the orientation marker, between two frames of the worker. So
 * the main thread keeps the camera, the same mediso::Camera the WebViewer
 * holds, with the same reset, and hands the worker the view with each frame.
 * `countCrossings` is WebViewer.countOnCPU without a viewer: the CPU model's
 * count of active (cell, isovalue) pairs over the volume the main thread keeps.
 */
#include "Camera.h"
#include "HistoPyramid.h"
#include "ScalarTypes.h"
#include "SceneView.h"

#include <emscripten/bind.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace
{
using emscripten::val;
using namespace mediso;

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

/// The camera of a WebViewer, without the viewer: the same members, the same reset.
class ViewCamera
{
public:
  /// The volume's placement (the camera resets to it, as WebViewer.setVolume does).
  void SetVolume(const val& dims, const val& spacing, const val& origin)
  {
    for (int a = 0; a < 3; ++a)
    {
      this->Placement.Dimensions[a] = dims[a].as<int>();
      this->Placement.Spacing[a] = spacing[a].as<double>();
      this->Placement.Origin[a] = origin[a].as<double>();
    }
    this->ResetCamera();
  }
  void Resize(int width, int height)
  {
    this->Width = std::max(1, width);
    this->Height = std::max(1, height);
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

private:
  VolumePlacement Placement;
  Camera View;
  bool Parallel = false;
  int Width = 640, Height = 480;
};

/// The CPU model's count of active (cell, isovalue) pairs of a volume of
/// ScalarType `type` at `bytes` in the module's memory.
double CountCrossings(int type, std::uintptr_t bytes, const val& dims, const val& isovalues)
{
  int points[3];
  for (int a = 0; a < 3; ++a)
  {
    points[a] = dims[a].as<int>();
  }
  std::vector<double> values;
  const int n = isovalues["length"].as<int>();
  for (int i = 0; i < n; ++i)
  {
    values.push_back(isovalues[i].as<double>());
  }
  if (!bytes || ScalarTypeSize(static_cast<ScalarType>(type)) == 0)
  {
    return 0.0;
  }
  std::uint64_t total = 0;
  VisitScalarType(static_cast<ScalarType>(type),
    [&](auto tag)
    {
      using T = decltype(tag);
      for (std::uint32_t count :
        HistoPyramid::CountCrossings(reinterpret_cast<const T*>(bytes), points, values))
      {
        total += count;
      }
    });
  return static_cast<double>(total);
}
} // namespace

EMSCRIPTEN_BINDINGS(mediso_web_camera)
{
  emscripten::function("countCrossings", &CountCrossings);
  emscripten::class_<ViewCamera>("ViewCamera")
    .constructor<>()
    .function("setVolume", &ViewCamera::SetVolume)
    .function("resize", &ViewCamera::Resize)
    .function("resetCamera", &ViewCamera::ResetCamera)
    .function("azimuth", &ViewCamera::Azimuth)
    .function("elevation", &ViewCamera::Elevation)
    .function("zoom", &ViewCamera::Zoom)
    .function("dolly", &ViewCamera::Dolly)
    .function("setParallel", &ViewCamera::SetParallel)
    .function("setView", &ViewCamera::SetView)
    .function("getView", &ViewCamera::GetView);
}
