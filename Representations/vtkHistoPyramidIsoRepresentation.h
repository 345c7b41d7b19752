// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkHistoPyramidIsoRepresentation
 * @brief   ParaView representation of image data as exact GPU isosurfaces.
 *
 * vtkHistoPyramidIsoRepresentation is ParaView's vtkImageVolumeRepresentation
 * with its volume mapper replaced by a vtkHistoPyramidIsoMapper (the swap is
 * made once, in the constructor). Everything else is inherited: data
 * delivery, bounds, the outline on ranks without data, ordered compositing,
 * and the vtkVolumeProperty the volume representation's properties fill. The
 * mapper reads from that property what it needs:
 *
 * - the isovalues, from IsosurfaceValues (SetIsosurfaceValue /
 *   SetNumberOfIsosurfaces fill vtkVolumeProperty::GetIsoSurfaceValues());
 * - the colour and opacity of each isovalue, from the colour map
 *   (LookupTable) and the opacity map (ScalarOpacityFunction) at that value;
 * - the lighting, from Ambient, Diffuse, Specular and SpecularPower.
 *
 * In the ServerManager XML it is the "HistoPyramid Isosurface" type of
 * UniformGridRepresentation and shares the volume representation's
 * properties, so switching between "Volume" and this type keeps the colour
 * map, opacity and isovalues.
 *
 * What the mapper did in the last frame is readable through the information
 * getters (GetRenderPath(), GetFallbackReason(), GetNumberOfPrimitives(), ...).
 * They describe the last render *on this process*: in client/server mode
 * with remote rendering that is the server's representation, which is the
 * one ParaView's information properties are pulled from.
 *
 * Colours: with a colour array chosen, each isovalue takes the colour map's
 * colour and the opacity map's opacity at its value; with none (Solid Color)
 * every surface takes the solid colour (SetDiffuseColor) and the input's
 * active point scalars are contoured (the base class would hide the volume),
 * so the type shows a surface as soon as it is selected. With
 * ColorEachSurface on, surface i takes SurfaceColor(i) instead, whatever the
 * colouring. Each surface's opacity is further multiplied by
 * SurfaceOpacity(i) and by Opacity, so surfaces get their own colour and
 * opacity without editing transfer-function points.
 *
 * Input: image data. A vtkRectilinearGrid (which ParaView's image-data
 * display also takes) is drawn as the image data it describes when its
 * coordinates are evenly spaced, and resampled onto an even grid (with one
 * warning saying so) when they are not.
 *
 * @sa vtkHistoPyramidIsoMapper vtkImageVolumeRepresentation
 */
#ifndef vtkHistoPyramidIsoRepresentation_h
#define vtkHistoPyramidIsoRepresentation_h

#include "MedicalIsosurfacesRepresentationsModule.h" // For export macro
#include "vtkDoubleArray.h"                          // For vtkNew<vtkDoubleArray>
#include "vtkImageVolumeRepresentation.h"
#include "vtkNew.h"   // For vtkNew
#include "vtkPlane.h" // For vtkPlane

#include <string> // For std::string

class vtkDoubleArray;
class vtkHistoPyramidIsoMapper;

class MEDICALISOSURFACESREPRESENTATIONS_EXPORT vtkHistoPyramidIsoRepresentation
  : public vtkImageVolumeRepresentation
{
public:
  static vtkHistoPyramidIsoRepresentation* New();
  vtkTypeMacro(vtkHistoPyramidIsoRepresentation, vtkImageVolumeRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The mapper that draws the isosurfaces (owned by the representation).
  vtkHistoPyramidIsoMapper* GetIsoMapper();

  ///@{
  /**
   * Draw with the CPU fallback (vtkBlockLODContour + vtkPolyDataMapper) even
   * where the GPU path works: comparisons, tests. Default off.
   */
  void SetForceCPUFallback(bool force);
  bool GetForceCPUFallback();
  ///@}

  ///@{
  /**
   * Let the GPU path draw cells as point sprites where they provably cover
   * them (vtkHistoPyramidIsoMapper::SetAllowPointFootprint); off: always the
   * geometry stage's cell boxes. Same image either way. Default on.
   */
  void SetAllowPointFootprint(bool allow);
  bool GetAllowPointFootprint();
  ///@}

  ///@{
  /**
   * Draw opaque frames through the first-hit pass
   * (vtkHistoPyramidIsoMapper::SetFirstHitPass: hidden fragments cost no ray
   * cast; 10 bytes per pixel of the volume's projection on the view). Same
   * image either way. Default on.
   */
  void SetFirstHitPass(bool use);
  bool GetFirstHitPass();
  ///@}

  ///@{
  /**
   * A clipping plane, the representation's counterpart of ParaView's Clip
   * filter with a Plane: on (ClipPlane), the surfaces are cut at the plane
   * through ClipPlaneOrigin with ClipPlaneNormal (data coordinates, moved with
   * the display's transform) and left open at the cut. As Clip does, the side
   * the normal points to is removed while ClipPlaneInvert is on (the default)
   * and kept when it is off. Both paths honour it (the mapper's clipping
   * planes), together with cropping (UseCropping). Default off, origin 0,
   * normal +x.
   */
  void SetClipPlane(bool use);
  void SetClipPlaneOrigin(double x, double y, double z);
  void SetClipPlaneNormal(double x, double y, double z);
  void SetClipPlaneInvert(bool invert);
  ///@}

  ///@{
  /**
   * Interactive frames (vtkHistoPyramidIsoMapper::SetInteractiveAdjust,
   * SetInteractiveFrameBudget): during the view's interactive renders draw
   * within the budget (seconds; 0: the time the view allocates), at a coarser
   * image sample distance (GPU) or Block LOD level (fallback; also the GPU
   * path's frames that no distance fits, with InteractiveTriangleLevels;
   * before a level's triangles, the GPU path on the volume sampled at that
   * level's stride, with InteractiveVolumeLevels). Defaults on, 0.1 s, on, on.
   */
  void SetInteractiveAdjust(bool adjust);
  bool GetInteractiveAdjust();
  void SetInteractiveFrameBudget(double seconds);
  double GetInteractiveFrameBudget();
  void SetInteractiveTriangleLevels(bool use);
  bool GetInteractiveTriangleLevels();
  void SetInteractiveVolumeLevels(bool use);
  bool GetInteractiveVolumeLevels();
  ///@}

  ///@{
  /**
   * The GPU memory budget in MB (vtkHistoPyramidIsoMapper::SetGPUMemoryBudget;
   * 0, the default: half the device's memory where OpenGL tells it, else
   * 1 GiB), and the last GPU frame's bricks: how many the volume is kept as
   * (0: one texture), how many the isovalues cross, how many are resident.
   */
  void SetGPUMemoryBudget(double megabytes);
  double GetGPUMemoryBudget();
  double* GetLastBricks() VTK_SIZEHINT(3);
  ///@}

  ///@{
  /**
   * Whether the last GPU frame drew those bricks from the brick pool: its
   * slots (0: no pool), and why not ("" where the pool drew them, and for
   * one texture; vtkHistoPyramidIsoMapper::GetLastBrickPoolReason()).
   */
  double GetBrickPoolSlots();
  const char* GetBrickPoolReason();
  ///@}

  ///@{
  /**
   * What the last frame on this process did: interactive (1) or still (0),
   * its image sample distance and Block LOD level, the seconds predicted
   * and measured (see vtkHistoPyramidIsoMapper). Doubles for the
   * ServerManager's information helpers.
   */
  double GetLastInteractive();
  double GetLastSampleDistance();
  double GetLastLevel();
  double GetLastPredictedSeconds();
  double GetLastMeasuredSeconds();
  ///@}

  /**
   * The view's window's measured cost outside the mapper, which interactive
   * frames take off their budget (vtkHistoPyramidIsoMapper::GetWindowFixedSeconds()).
   */
  double GetWindowFixedSeconds();

  ///@{
  /**
   * Colouring of the surfaces (see the class description): the solid colour,
   * one colour per surface (used when ColorEachSurface is on), an opacity per
   * surface, and a global opacity multiplier. Surface i is the i-th value of
   * IsosurfaceValues.
   */
  void SetDiffuseColor(double r, double g, double b);
  void SetOpacity(double opacity);
  void SetColorEachSurface(bool each);
  void SetNumberOfSurfaceColors(int number);
  void SetSurfaceColor(int i, double r, double g, double b);
  void SetNumberOfSurfaceOpacities(int number);
  void SetSurfaceOpacity(int i, double opacity);
  ///@}

  ///@{
  /**
   * What the last frame rendered on this process did: the path ("gpu",
   * "fallback", or "none" before the first frame and when nothing was drawn),
   * why the GPU path is not used (empty while it is), the primitives (active
   * cell-isovalue pairs) of a GPU frame, the triangles of a fallback frame,
   * the pyramid builds so far, the GPU memory held and the first-hit
   * buffers (in bytes, and in MB of 10^6 bytes), and the footprint of the
   * last GPU frame ("points", "boxes"; "none" when the last frame was not a
   * GPU one).
   * Counts are doubles for the ServerManager's information helpers.
   */
  const char* GetRenderPath();
  const char* GetFootprint();
  const char* GetFallbackReason();
  double GetNumberOfPrimitives();
  double GetNumberOfFallbackTriangles();
  double GetNumberOfPyramidBuilds();
  double GetGPUMemoryBytes();
  double GetFrameBufferBytes();
  double GetGPUMemoryMB() { return this->GetGPUMemoryBytes() / 1.0e6; }
  double GetFrameBufferMB() { return this->GetFrameBufferBytes() / 1.0e6; }
  ///@}

  /**
   * What each isovalue, in the order of IsosurfaceValues, is drawn with:
   * red, green, blue and opacity per isovalue (vtkHistoPyramidIsoMapper::
   * GetSurfaceLook() under the colouring of the last update; opacity 0: not
   * drawn). The panel's Opacity column and the mesh made from the view read
   * it, so both show what the view draws.
   */
  vtkDoubleArray* GetSurfaceLooks();

  /**
   * The warning for `count` isovalues `values` outside `range` of the array
   * `arrayName` ("" when all are inside): the one text the representation
   * gives in Output Messages and the panel shows above the list.
   */
  static std::string OutsideRangeMessage(
    const double* values, int count, const double range[2], const char* arrayName);

protected:
  vtkHistoPyramidIsoRepresentation();
  ~vtkHistoPyramidIsoRepresentation() override;

  /**
   * The base class's settings (array, scalar mode, cropping, transfer
   * function mode; its vtkSmartVolumeMapper/vtkMultiBlockVolumeMapper-only
   * settings find no such mapper and do nothing), then the active point
   * scalars when no colour array is chosen. An isovalue outside the range of
   * the contoured array draws nothing: one warning says so, with the values
   * and the range, each time the values, the array or its range change (not
   * on every render); not in a parallel run, where a piece's range is not
   * the data's.
   */
  void UpdateMapperParameters() override;

  /**
   * The base class's data cache, with a rectilinear grid replaced by the
   * image data it describes (resampled when its spacing is uneven).
   */
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkHistoPyramidIsoRepresentation(const vtkHistoPyramidIsoRepresentation&) = delete;
  void operator=(const vtkHistoPyramidIsoRepresentation&) = delete;

  /// The warning for isovalues outside the contoured array's range ("" when
  /// none).
  std::string IsovaluesOutsideRange();

  vtkNew<vtkHistoPyramidIsoMapper> IsoMapper;
  vtkNew<vtkDoubleArray> SurfaceLooks;
  bool ColorEachSurface = false;
  bool ClipPlane = false;
  double ClipPlaneOrigin[3] = { 0.0, 0.0, 0.0 };
  double ClipPlaneNormal[3] = { 1.0, 0.0, 0.0 };
  bool ClipPlaneInvert = true;
  double LastBricks[3] = { 0.0, 0.0, 0.0 };
  vtkNew<vtkPlane> MapperClipPlane; // the plane as the mapper takes it (world, kept side)
  std::string LastResampleMessage;
  std::string LastRangeMessage;
};

#endif
