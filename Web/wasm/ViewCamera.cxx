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
 * the main thread keeps the camera, the same PageCamera the WebViewer holds
 * (PageCamera.h: the same moves, the same reset, the same JavaScript names),
 * and hands the worker the view with each frame. `countCrossings` is
 * WebViewer.countOnCPU without a viewer: the CPU model's count of active
 * (cell, isovalue) pairs over the volume the main thread keeps.
 */
#include "PageCamera.h"

#include <emscripten/bind.h>

#include <cstdint>

namespace
{
using emscripten::val;
using mediso::web::PageCamera;

/// The camera of a WebViewer, without the viewer.
class ViewCamera
{
public:
  /// The volume's placement (the camera resets to it, as WebViewer.setVolume does).
  void SetVolume(const val& dims, const val& spacing, const val& origin)
  {
    this->Camera.SetPlacement(dims, spacing, origin);
    this->Camera.ResetCamera();
  }
  void Resize(int width, int height) { this->Camera.Resize(width, height); }
  PageCamera& GetPageCamera() { return this->Camera; }

private:
  PageCamera Camera;
};

/// The CPU model's count of active (cell, isovalue) pairs of a volume of
/// ScalarType `type` at `bytes` in the module's memory, on a level's samples (3: all).
double CountCrossings(
  int type, std::uintptr_t bytes, const val& dims, const val& isovalues, int level)
{
  int points[3];
  for (int a = 0; a < 3; ++a)
  {
    points[a] = dims[a].as<int>();
  }
  return mediso::web::CountActivePairs(
    static_cast<mediso::ScalarType>(type), reinterpret_cast<const void*>(bytes), points, isovalues,
    level);
}
} // namespace

EMSCRIPTEN_BINDINGS(mediso_web_camera)
{
  emscripten::function("countCrossings", &CountCrossings);
  const emscripten::class_<ViewCamera> camera("ViewCamera");
  mediso::web::BindPageCamera(camera);
  camera.constructor<>()
    .function("setVolume", &ViewCamera::SetVolume)
    .function("resize", &ViewCamera::Resize);
}
