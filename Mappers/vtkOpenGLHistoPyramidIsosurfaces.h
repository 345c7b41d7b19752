// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkOpenGLHistoPyramidIsosurfaces
 * @brief   The GPU path of vtkHistoPyramidIsoMapper: a VTK shell over the portable GPU core.
 *
 * All GPU work is the VTK-free core's, through its one unit
 * mediso::IsosurfaceScene (OpenGL 3.2 core / ES 3.0, the same code
 * mediso-render and the web page run): the scene uploads the volume only
 * when its array, values or size change and rebuilds the pyramid only when
 * the isovalues or the volume change (camera moves reuse both). This class
 * is what VTK adds, in the shape of vtkOpenGLGPUVolumeRayCastMapper:
 * - one capability check per window (vtkMedicalGLCapabilities) and the
 *   core's view of the window's context, with VTK's GLEW functions;
 * - the volume as the scene's description (the array's values, type and
 *   size, its modification time as the stamp);
 * - the camera (cell-index space to view through the image's index-to-
 *   physical matrix, its extent and the volume's matrix; the projection)
 *   and the renderer's lights (view-space directions, diffuse colour times
 *   intensity) and the property's material, as the core's frame;
 * - the render window's context made current around every call, and the
 *   scene's GL objects released with the window's resources.
 *
 * vtkHistoPyramidIsoMapper checks the input and builds the list of
 * surfaces; when RenderIsosurfaces() says the path cannot run (with the
 * reason), it draws with the CPU fallback (vtkBlockLODIsosurfaces) instead.
 *
 * @sa vtkHistoPyramidIsoMapper vtkBlockLODIsosurfaces vtkMedicalGLCapabilities
 */
#ifndef vtkOpenGLHistoPyramidIsosurfaces_h
#define vtkOpenGLHistoPyramidIsosurfaces_h

#include "IsosurfaceFrame.h"                 // For mediso::IsosurfaceSceneStats
#include "MedicalIsosurfacesMappersModule.h" // For export macro
#include "vtkObject.h"

#include <array>      // For std::array
#include <cstdint>    // For std::uint64_t
#include <functional> // For std::function
#include <memory>  // For std::unique_ptr
#include <string>  // For std::string
#include <vector>  // For std::vector

class vtkDataArray;
class vtkImageData;
class vtkMatrix4x4;
class vtkRenderer;
class vtkVolume;
class vtkWindow;

class MEDICALISOSURFACESMAPPERS_EXPORT vtkOpenGLHistoPyramidIsosurfaces : public vtkObject
{
public:
  static vtkOpenGLHistoPyramidIsosurfaces* New();
  vtkTypeMacro(vtkOpenGLHistoPyramidIsosurfaces, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// One isosurface to draw: its value, colour and opacity (0 < opacity <= 1).
  struct Surface
  {
    double Value;
    double Color[3];
    double Opacity;
  };

  /// The image sample distance of a frame, from the primitives it will draw (see
  /// RenderIsosurfaces).
  using SampleDistanceChooser = std::function<float(std::uint64_t primitives)>;

  /**
   * Draw `surfaces` (increasing values, at most 8) of the single-component
   * point array `scalars` of `image` for `vol` into `ren`. False, with the
   * reason, when the GPU path cannot draw them (the caller falls back).
   * `sampleDistance`, when set, is asked for the frame's image sample
   * distance once the pyramid is up to date (its argument: the active
   * cell-isovalue pairs the frame draws); unset, the frame draws every pixel.
   */
  bool RenderIsosurfaces(vtkRenderer* ren, vtkVolume* vol, vtkImageData* image,
    vtkDataArray* scalars, const std::vector<Surface>& surfaces, bool allowPointFootprint,
    bool firstHitPass, const SampleDistanceChooser& sampleDistance, std::string& reason);

  /**
   * The volume level the next RenderIsosurfaces() draws (mediso::IsosurfaceFrame::Level):
   * 3, the volume (the default); 2, 1 or 0, the volume sampled at Block LOD's stride 2, 4
   * or 8, made and built by the scene on the level's first frame. The sample distance
   * chooser is then given that level's active pairs.
   */
  void SetVolumeLevel(int level);

  /// The scene's GPU budget in bytes (0: its default; IsosurfaceScene::SetGPUMemoryBudget).
  void SetGPUMemoryBudget(std::uint64_t bytes);

  /// The active pairs of a level built for the last frame's surfaces (0 when not built).
  std::uint64_t GetActivePairs(int level) const;

  /// A plane (a, b, c, d): the points where a x + b y + c z + d >= 0 are kept.
  using Plane = std::array<double, 4>;

  /**
   * Clipping planes in world coordinates (at most mediso::MaximumClipPlanes,
   * a cropping box's faces among them) for the next RenderIsosurfaces(): the
   * surfaces are cut exactly at them, left open.
   */
  void SetClipPlanes(const std::vector<Plane>& worldPlanes);

  /// `planes` moved from the space `toSpace` maps to, to the space it maps from.
  static std::vector<Plane> PullBackPlanes(const std::vector<Plane>& planes, vtkMatrix4x4* toSpace);

  /**
   * What the GPU path did (the scene's stats: the last frame drawn, the last
   * pyramid build and volume upload, the builds and uploads so far).
   */
  const mediso::IsosurfaceSceneStats& GetStats() const;

  /**
   * Why the last update of a volume kept as bricks drew them as their own
   * pyramids and not from the pool ("" where the pool did, and for one
   * texture): mediso::IsosurfaceScene::GetBrickPoolReason().
   */
  std::string GetBrickPoolReason() const;

  /**
   * Seconds the last RenderIsosurfaces() spent making what later frames
   * reuse, before it drew: the volume's upload and the pyramids it built,
   * timed to the builds' read-back of their totals (so the upload's GL work
   * is done too). 0 when it made nothing (a camera move). The mapper gives
   * it to its frame-time model with the frame, so the model learns the
   * drawing from the rest of the frame and not by splitting it with its own
   * predictions (mediso::FrameTimeModel::Observe with buildSeconds, as the
   * page does).
   */
  double GetLastOneOffSeconds() const;

  /// GPU memory held for the volume (volume and pyramid), and the first-hit buffers.
  std::uint64_t GetGPUMemoryBytes() const;
  std::uint64_t GetFrameBufferBytes() const;

  /// Free the OpenGL objects if they live in `win` (or in any window when null).
  void ReleaseGraphicsResources(vtkWindow* win);

protected:
  vtkOpenGLHistoPyramidIsosurfaces();
  ~vtkOpenGLHistoPyramidIsosurfaces() override;

private:
  vtkOpenGLHistoPyramidIsosurfaces(const vtkOpenGLHistoPyramidIsosurfaces&) = delete;
  void operator=(const vtkOpenGLHistoPyramidIsosurfaces&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
