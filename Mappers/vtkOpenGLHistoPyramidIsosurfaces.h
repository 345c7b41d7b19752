// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkOpenGLHistoPyramidIsosurfaces
 * @brief   The GPU path of vtkHistoPyramidIsoMapper: a VTK shell over the portable GPU core.
 *
 * All GPU work is the VTK-free core's (mediso::HistoPyramidGL builds the
 * pyramid, mediso::IsosurfaceRendererGL draws; OpenGL 3.2 core / ES 3.0,
 * the same code mediso-render and the web page run). This class is what
 * VTK adds, in the shape of vtkOpenGLGPUVolumeRayCastMapper:
 * - one capability check per window (vtkMedicalGLCapabilities) and the
 *   core's view of the window's context, with VTK's GLEW functions;
 * - one rebuild decision (Prepare()): the volume is uploaded again only when
 *   its array, values or size change, the pyramid rebuilt only when the
 *   isovalues or the volume change; camera moves reuse both;
 * - the camera (cell-index space to view through the image's index-to-
 *   physical matrix, its extent and the volume's matrix; the projection)
 *   and the renderer's lights (view-space directions, diffuse colour times
 *   intensity) and the property's material, as the core's frame;
 * - the render window's context made current around every call, and the
 *   core's objects released with the window's resources.
 *
 * vtkHistoPyramidIsoMapper checks the input and builds the list of
 * surfaces; when RenderIsosurfaces() says the path cannot run (with the
 * reason), it draws with the CPU fallback (vtkBlockLODIsosurfaces) instead.
 *
 * @sa vtkHistoPyramidIsoMapper vtkBlockLODIsosurfaces vtkMedicalGLCapabilities
 */
#ifndef vtkOpenGLHistoPyramidIsosurfaces_h
#define vtkOpenGLHistoPyramidIsosurfaces_h

#include "MedicalIsosurfacesMappersModule.h" // For export macro
#include "vtkObject.h"

#include <cstdint> // For std::uint64_t
#include <memory>  // For std::unique_ptr
#include <string>  // For std::string
#include <vector>  // For std::vector

class vtkDataArray;
class vtkImageData;
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

  /**
   * Draw `surfaces` (increasing values, at most 8) of the single-component
   * point array `scalars` of `image` for `vol` into `ren`. False, with the
   * reason, when the GPU path cannot draw them (the caller falls back).
   */
  bool RenderIsosurfaces(vtkRenderer* ren, vtkVolume* vol, vtkImageData* image,
    vtkDataArray* scalars, const std::vector<Surface>& surfaces, bool allowPointFootprint,
    bool firstHitPass, std::string& reason);

  ///@{
  /// What the last successful RenderIsosurfaces() did.
  vtkGetMacro(NumberOfPrimitives, std::uint64_t);
  vtkGetMacro(LastPointFootprint, bool);
  vtkGetMacro(LastFirstHitPass, bool);
  ///@}

  ///@{
  /// The last pyramid build: seconds, level-1 tiles drawn and in all.
  vtkGetMacro(LastBuildSeconds, double);
  vtkGetMacro(LastBuildTilesDrawn, std::uint64_t);
  vtkGetMacro(LastBuildTiles, std::uint64_t);
  ///@}

  /// Pyramid builds and volume uploads so far.
  vtkGetMacro(NumberOfPyramidBuilds, std::uint64_t);
  vtkGetMacro(NumberOfVolumeUploads, std::uint64_t);

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

  std::uint64_t NumberOfPrimitives = 0;
  bool LastPointFootprint = false;
  bool LastFirstHitPass = false;
  double LastBuildSeconds = 0.0;
  std::uint64_t LastBuildTilesDrawn = 0;
  std::uint64_t LastBuildTiles = 0;
  std::uint64_t NumberOfPyramidBuilds = 0;
  std::uint64_t NumberOfVolumeUploads = 0;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
