// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkBlockLODIsosurfaces
 * @brief   The CPU path of vtkHistoPyramidIsoMapper: vtkBlockLODContour + vtkPolyDataMapper.
 *
 * Draws the isosurfaces vtkHistoPyramidIsoMapper asks for where its GPU path
 * (vtkOpenGLHistoPyramidIsosurfaces) cannot run, or when the fallback is
 * forced: the surfaces are extracted by vtkBlockLODContour at full
 * resolution (level 3) from an index-space copy of the image (the surface then
 * does not depend on where the image lies) placed by an actor matrix that also
 * carries the image's direction and the volume's matrix; every point is coloured by its
 * isovalue (RGBA), recoloured only when the surface or the looks change.
 * Translucent surfaces are drawn sorted back to front (vtkDepthSortPolyData)
 * with blending: the renderer's depth peeling does not reach geometry a
 * volume mapper draws. Clipping planes (a cropping box's faces among them)
 * cut the coloured triangles exactly (vtkClipPolyData, one per plane, in the
 * index space of the copy), recut only when the planes or the surface change;
 * the cut faces are left open, as on the GPU path.
 * SetLevel() picks a coarser level (vtkBlockLODContour's
 * LOD 0..2, cube edges of 8, 4, 2 voxels): vtkHistoPyramidIsoMapper's
 * interactive frames. The coloured surface of each level drawn is kept
 * for the current input and looks (dropped when either changes), so that
 * switching back and forth neither runs the filter nor recolours.
 *
 * @sa vtkHistoPyramidIsoMapper vtkOpenGLHistoPyramidIsosurfaces vtkBlockLODContour
 */
#ifndef vtkBlockLODIsosurfaces_h
#define vtkBlockLODIsosurfaces_h

#include "MedicalIsosurfacesMappersModule.h" // For export macro
#include "vtkObject.h"
#include "vtkOpenGLHistoPyramidIsosurfaces.h" // For Surface

#include <cstdint> // For std::uint64_t
#include <memory>  // For std::unique_ptr
#include <vector>  // For std::vector

class vtkDataArray;
class vtkImageData;
class vtkRenderer;
class vtkVolume;
class vtkWindow;

class MEDICALISOSURFACESMAPPERS_EXPORT vtkBlockLODIsosurfaces : public vtkObject
{
public:
  static vtkBlockLODIsosurfaces* New();
  vtkTypeMacro(vtkBlockLODIsosurfaces, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  using Surface = vtkOpenGLHistoPyramidIsosurfaces::Surface;

  /// Draw `surfaces` of `scalars` of `image` for `vol` into `ren`.
  void RenderIsosurfaces(vtkRenderer* ren, vtkVolume* vol, vtkImageData* image,
    vtkDataArray* scalars, const std::vector<Surface>& surfaces);

  using Plane = vtkOpenGLHistoPyramidIsosurfaces::Plane;

  /// Clipping planes in world coordinates for the next RenderIsosurfaces() (see
  /// vtkOpenGLHistoPyramidIsosurfaces::SetClipPlanes()).
  void SetClipPlanes(const std::vector<Plane>& worldPlanes);

  /// Triangles of the last frame (after clipping).
  vtkGetMacro(NumberOfTriangles, std::uint64_t);

  ///@{
  /// The level drawn (vtkBlockLODContour's LOD, 0..3; default 3, full resolution).
  void SetLevel(int level);
  int GetLevel() const;
  ///@}

  /// Whether the last frame extracted its surfaces (a new level, values or input) rather than
  /// drawing ones already extracted: such a frame's time is not a drawing time.
  vtkGetMacro(LastFrameExtracted, bool);

  void ReleaseGraphicsResources(vtkWindow* win);

protected:
  vtkBlockLODIsosurfaces();
  ~vtkBlockLODIsosurfaces() override;

private:
  vtkBlockLODIsosurfaces(const vtkBlockLODIsosurfaces&) = delete;
  void operator=(const vtkBlockLODIsosurfaces&) = delete;

  std::uint64_t NumberOfTriangles = 0;
  bool LastFrameExtracted = false;
  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
