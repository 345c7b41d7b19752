// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class PageCamera
 * @brief The page's camera over the volume's placement, stated once for the two places that hold one.
 *
 * The page may hold the camera twice: the WebViewer that draws (in a worker
 * where the browser can draw WebGL2 on an OffscreenCanvas, else on the main
 * thread), and the main thread's ViewCamera, which must answer at once
 * between two of the worker's frames (to pan, to zoom at the cursor, to draw
 * the orientation marker) and hands the worker the view with each frame.
 * Both must move the camera the same way, or the worker would draw a view
 * the page did not ask for; so both hold a PageCamera and forward to it.
 *
 * A PageCamera is:
 * 1. the volume's placement (dimensions, spacing, origin; the camera resets
 *    to its bounds), and the direction its grid is drawn with about its
 *    origin: the identity, or a reflection of one index axis for a volume
 *    whose axes are a mirror image of patient space (the page then turns the
 *    drawn frame into patient space by a rotation, so that the picture is not
 *    mirrored: docs/web.md, Orientation),
 * 2. the canvas's size in pixels (its aspect ratio; never below one pixel),
 * 3. a mediso::Camera (Mappers/Core, the one the ParaView mapper and
 *    mediso-render use) and whether it projects in parallel, which a reset
 *    keeps,
 * 4. the conversions of the view to and from JavaScript: an object
 *    `{position, focalPoint, viewUp, viewAngle, parallelScale}` whose
 *    vectors are arrays of three numbers (`viewAngle` and `parallelScale`
 *    may be left out when setting, and keep their values).
 *
 * Elevation re-orthogonalises the view-up, as VTK's interactor styles do, so
 * that repeated drags never tilt the camera into a degenerate basis.
 *
 * BindPageCamera gives a bound class that holds one (WebViewer, ViewCamera)
 * the camera's JavaScript names, so that they are written once too:
 * `resetCamera`, `azimuth`, `elevation`, `zoom`, `dolly`, `setParallel`,
 * `setView`, `getView`, `setDirection` (each class binds `resize` and `setVolume` itself,
 * since the viewer also sizes its canvas and uploads the volume).
 *
 * CountActivePairs is the CPU model's count of active (cell, isovalue) pairs
 * over a volume in the module's memory: both the viewer (`countOnCPU`) and
 * the main thread (`countCrossings`) offer it, so that tests can check the
 * GPU's count wherever the viewer runs.
 *
 * @sa mediso::Camera, mediso::VolumePlacement, WebViewer.cxx, ViewCamera.cxx
 */
#ifndef MedicalIsosurfaces_PageCamera_h
#define MedicalIsosurfaces_PageCamera_h

#include "Camera.h"
#include "ScalarTypes.h"
#include "SceneView.h"

#include <emscripten/bind.h>
#include <emscripten/val.h>

namespace mediso
{
namespace web
{

class PageCamera
{
public:
  /// The volume's placement from three arrays of three numbers; the camera is not reset.
  void SetPlacement(
    const emscripten::val& dims, const emscripten::val& spacing, const emscripten::val& origin);
  const VolumePlacement& GetPlacement() const { return this->Placement; }
  /**
   * The direction the grid is drawn with about its origin, a JavaScript
   * array of 9 numbers (row-major, column a the direction of index axis a),
   * kept by later SetPlacement calls (another level of the same volume).
   * Anything but an orthonormal matrix is refused (false; the direction is
   * left as it was). The camera is not reset.
   */
  bool SetDirection(const emscripten::val& direction);

  /// The canvas's size in pixels (default 640 x 480); each side at least 1.
  void Resize(int width, int height);
  int GetWidth() const { return this->Width; }
  int GetHeight() const { return this->Height; }

  /// Looks at the whole volume at the canvas's aspect ratio, keeping the projection.
  void ResetCamera();
  void Azimuth(double degrees) { this->View.Azimuth(degrees); }
  void Elevation(double degrees);
  void Zoom(double factor) { this->View.Zoom(factor); }
  void Dolly(double factor) { this->View.Dolly(factor); }
  /// Parallel (true) or perspective projection, kept by later resets (default perspective).
  void SetParallel(bool parallel);

  /// The view to and from JavaScript's `{position, focalPoint, viewUp, viewAngle, parallelScale}`.
  void SetView(const emscripten::val& view);
  emscripten::val GetView() const;

  /// The camera itself, for drawing (the viewer sets its clipping range each frame).
  Camera& GetCamera() { return this->View; }
  const Camera& GetCamera() const { return this->View; }

private:
  VolumePlacement Placement;
  Camera View;
  bool Parallel = false;
  int Width = 640, Height = 480;
};

/**
 * Binds the camera's functions to `bound`, a class whose `GetPageCamera()`
 * returns its PageCamera.
 */
template <typename Holder>
void BindPageCamera(const emscripten::class_<Holder>& bound)
{
  using emscripten::optional_override;
  using emscripten::val;
  bound
    .function("resetCamera", optional_override([](Holder& h) { h.GetPageCamera().ResetCamera(); }))
    .function(
      "azimuth", optional_override([](Holder& h, double d) { h.GetPageCamera().Azimuth(d); }))
    .function(
      "elevation", optional_override([](Holder& h, double d) { h.GetPageCamera().Elevation(d); }))
    .function("zoom", optional_override([](Holder& h, double f) { h.GetPageCamera().Zoom(f); }))
    .function("dolly", optional_override([](Holder& h, double f) { h.GetPageCamera().Dolly(f); }))
    .function(
      "setParallel", optional_override([](Holder& h, bool p) { h.GetPageCamera().SetParallel(p); }))
    .function(
      "setView", optional_override([](Holder& h, const val& v) { h.GetPageCamera().SetView(v); }))
    .function("getView", optional_override([](Holder& h) { return h.GetPageCamera().GetView(); }))
    .function("setDirection",
      optional_override([](Holder& h, const val& d) { return h.GetPageCamera().SetDirection(d); }));
}

/**
 * The CPU model's count of active (cell, isovalue) pairs of a volume of
 * `type`, x fastest, at `data` with `dims` points, for the isovalues of the
 * JavaScript array `isovalues`, on Block LOD's samples of `level` (3: the
 * volume itself; 2, 1, 0, -1: every 2nd, 4th, 8th, 16th point and the last,
 * the GPU path's coarse volume levels, IsosurfaceScene::VolumeLevelStride);
 * 0 for no data, an unknown type or level.
 */
double CountActivePairs(ScalarType type, const void* data, const int dims[3],
  const emscripten::val& isovalues, int level);

} // namespace web
} // namespace mediso

#endif
