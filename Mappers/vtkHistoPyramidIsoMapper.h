// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkHistoPyramidIsoMapper
 * @brief   Exact GPU isosurfaces of image data by HistoPyramid cell rasterisation.
 *
 * vtkHistoPyramidIsoMapper renders the isosurfaces of a vtkVolumeProperty
 * (vtkVolumeProperty::GetIsoSurfaceValues(), up to 8) of a single-component
 * vtkImageData as the exact surfaces of the trilinear interpolant, with
 * correct depth. It implements the GPU path of "Hardware Accelerated Medical
 * Data Visualisation on the Web" (section 4.1), which follows Liu, Clapworthy
 * & Dong, "Fast isosurface rendering on a GPU by cell rasterization" (2009),
 * with the HistoPyramid of Ziegler et al. (2006), and the paper's CPU path
 * where a GPU cannot run it. Like vtkSmartVolumeMapper, it checks the input
 * and chooses; the work is done by:
 *
 * - vtkOpenGLHistoPyramidIsosurfaces, the GPU path: a thin VTK shell over
 *   the portable core's scene (mediso::IsosurfaceScene;
 *   OpenGL 3.2 core / OpenGL ES 3.0, the same code as mediso-render and the
 *   web page). The volume is uploaded once as a 3D texture of its own type
 *   (int16 stays 16-bit); the core counts the active cells of the current
 *   isovalues (min < iso <= max over the 8 corners, as vtkMarchingCubes) in
 *   a 3D 8:1 pyramid built by render-to-texture passes, rebuilt only when the
 *   isovalues or the data change (camera moves reuse it:
 *   GetNumberOfPyramidBuilds()); one draw call with no vertex attributes
 *   draws every active (cell, isovalue) pair, each walking down the pyramid
 *   to its cell front to back (back to front for translucency), covering the
 *   projected box that holds its surface with a point sprite or, where points
 *   cannot provably cover the cells (close zooms, the eye in the volume), a
 *   quad (see AllowPointFootprint, GetLastFootprint()); the fragment stage
 *   finds the first root of the trilinear interpolant's cubic along the ray,
 *   shades it with Phong (the volume property's ambient, diffuse, specular
 *   and specular power, the renderer's lights) and writes its depth.
 *   Opaque frames draw one isovalue per primitive front to back (through the
 *   first-hit pass, see FirstHitPass); translucent ones draw each cell once,
 *   back to front, compositing all its isovalues' hits in depth order
 *   (translucent skin over opaque bone in one pass).
 * - vtkBlockLODIsosurfaces, the CPU path: vtkBlockLODContour (level 3) and a
 *   vtkPolyDataMapper (translucent surfaces sorted back to front).
 *
 * Colour and opacity of each isovalue come from the property's colour and
 * scalar opacity transfer functions at that value, or from colours and
 * opacities given per surface (SetColorSource()). The volume's matrix
 * (position, orientation, scale), the image's spacing, origin and direction
 * matrix are honoured. Surfaces are always shaded (an unshaded isosurface
 * shows no shape), regardless of vtkVolumeProperty::GetShade().
 *
 * Clipping and cropping: the mapper's clipping planes
 * (vtkAbstractMapper::AddClippingPlane(), world coordinates, at most 6; the
 * normal points to the side that is kept) and vtkVolumeMapper's cropping
 * (SetCropping(), SetCroppingRegionPlanes() in the volume's own coordinates,
 * as for VTK's volume mappers) cut the surfaces exactly, on both paths: the
 * GPU path cuts each fragment's ray (a surface behind a removed one shows
 * through) and skips cells wholly removed; the CPU path cuts its triangles
 * (vtkClipPolyData). Cut faces are left open (not capped). Of the cropping
 * region flags, only the subvolume (VTK_CROP_SUBVOLUME, the default: keep the
 * box) is supported; other flags are warned about once and the volume is
 * drawn uncropped. Planes beyond the sixth are warned about once and ignored.
 *
 * Capability check and fallback: the first render in a window runs
 * vtkMedicalGLCapabilities::Probe(); if the context lacks OpenGL 3.2 or
 * working integer textures, a shader does not build, the volume exceeds the
 * context's texture limits, or the pyramid needs more vertex texture units
 * than the context has (or MEDISO_DISABLE_GPU_PATH=1, or ForceCPUFallback is
 * on), the mapper says so once (a warning with the reason) and renders with
 * the CPU path. GetLastRenderPath() tells which path drew the last frame,
 * GetFallbackReason() why.
 *
 * Interactive frames (InteractiveAdjust, on by default): a render whose
 * prop has less than a second allocated (vtkVolume::GetAllocatedRenderTime(),
 * the render window's DesiredUpdateRate shared among its props: the rule
 * vtkGPUVolumeRayCastMapper's AutoAdjustSampleDistances uses; ParaView's
 * interactive renders ask for 5 frames a second, its still ones for 0.002)
 * is drawn within InteractiveFrameBudget seconds, less the render window's
 * measured cost outside this mapper (GetWindowFixedSeconds()) and divided
 * by one plus the last frames' measured overrun (GetPredictionMargin()), as the
 * frame-time model (mediso::FrameTimeModel, fitted from this mapper's own
 * frames) predicts:
 * the GPU path at the finest image sample distance predicted within the
 * budget (the surfaces drawn into a reduced target, then up to the viewport
 * with their depth), the CPU fallback at the finest Block LOD level
 * predicted within it. Where even the GPU path's coarsest distance is
 * predicted over the budget (its per-cell work dominates: the frame needs a
 * coarser volume), the frame draws a coarser level, finest first, each at
 * its finest distance predicted within the budget: the GPU path on the
 * volume sampled at Block LOD level 2's, 1's or 0's stride (2, 4 or 8: a
 * coarse volume and pyramid the GPU core makes on the level's first frame;
 * InteractiveVolumeLevels; the frame reports the "gpu" path and its level),
 * else that level's Block LOD triangles, and level 0's last (the CPU path's
 * cached levels, InteractiveTriangleLevels; such a frame reports the
 * "fallback" path with an empty FallbackReason). When no candidate is
 * predicted within the budget the frame is the one predicted fastest (the
 * last, level 0's triangles, is not always: translucent triangles are sorted
 * every frame). Other renders are full
 * quality, the same image as with InteractiveAdjust off. GetLastSampleDistance(), GetLastLevel(),
 * GetLastPredictedSeconds() and GetLastMeasuredSeconds() say what the last
 * frame did; frames are timed to their end (glFinish) while InteractiveAdjust
 * is on. Still frames of the GPU path draw the full volume (level 3).
 *
 * GPU memory: GetGPUMemoryBytes() (the volume texture plus about 0.16 bytes
 * per padded cell for the pyramid) stays the same across isovalue changes;
 * ReleaseGraphicsResources() frees every OpenGL object.
 *
 * Bad input (no scalars, cell scalars, several components, fewer than 2
 * points along an axis, a zero or non-finite spacing, an unsupported type,
 * no isovalues, isovalues that are not numbers) gives one error or warning
 * and nothing drawn, never a crash.
 *
 * @sa vtkOpenGLHistoPyramidIsosurfaces vtkBlockLODIsosurfaces vtkMedicalGLCapabilities
 * vtkBlockLODContour
 */
#ifndef vtkHistoPyramidIsoMapper_h
#define vtkHistoPyramidIsoMapper_h

#include "FrameTimeModel.h"                  // For mediso::FrameTimeModel
#include "IsosurfaceFrame.h"                 // For mediso::IsosurfaceSceneStats
#include "MedicalIsosurfacesMappersModule.h" // For export macro
#include "vtkOpenGLHistoPyramidIsosurfaces.h" // For Surface
#include "vtkVolumeMapper.h"

#include <cmath>   // For std::isfinite
#include <cstdint> // For std::uint64_t
#include <memory>  // For std::unique_ptr
#include <sstream> // For std::ostringstream
#include <string>  // For std::string
#include <vector>  // For std::vector

class vtkVolumeProperty;

class MEDICALISOSURFACESMAPPERS_EXPORT vtkHistoPyramidIsoMapper : public vtkVolumeMapper
{
public:
  static vtkHistoPyramidIsoMapper* New();
  vtkTypeMacro(vtkHistoPyramidIsoMapper, vtkVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Which path drew the last frame.
  enum RenderPathType
  {
    NoPath = 0,      ///< Nothing drawn (no input, bad input, no isovalues, nothing active).
    GPUPath = 1,     ///< HistoPyramid cell rasterisation.
    FallbackPath = 2 ///< vtkBlockLODContour + vtkPolyDataMapper.
  };

  ///@{
  /**
   * The path of the last Render() (a RenderPathType), as a value and as a
   * word ("none", "gpu", "fallback").
   */
  vtkGetMacro(LastRenderPath, int);
  const char* GetLastRenderPathAsString() const;
  ///@}

  /// Why the GPU path is not used (empty while it is).
  const std::string& GetFallbackReason() const { return this->FallbackReason; }

  ///@{
  /**
   * Render through the CPU fallback even when the GPU path works (tests,
   * comparisons). Default off.
   */
  vtkSetMacro(ForceCPUFallback, bool);
  vtkGetMacro(ForceCPUFallback, bool);
  vtkBooleanMacro(ForceCPUFallback, bool);
  ///@}

  /// How the GPU path covers each cell on screen.
  enum FootprintType
  {
    BoxFootprint = 0,  ///< A quad over the projection of the surface's box in the cell, cut by the near plane.
    PointFootprint = 1 ///< One point sprite over the projected bounding square of the surface's box in the cell.
  };

  ///@{
  /**
   * Let the GPU path draw each cell as one point sprite on frames where that
   * provably covers every cell: the whole volume lies beyond the near plane
   * and no cell can project to more pixels than GL_POINT_SIZE_RANGE allows.
   * Other frames (close zooms, the eye in or near the volume) draw a quad
   * per cell (an instanced strip of 4 vertices, each walking the pyramid).
   * Both footprints feed the same ray casting, so they give the same image;
   * points are much cheaper where vertex work is costly (software
   * rasterisers). Default on.
   */
  vtkSetMacro(AllowPointFootprint, bool);
  vtkGetMacro(AllowPointFootprint, bool);
  vtkBooleanMacro(AllowPointFootprint, bool);
  ///@}

  ///@{
  /// The footprint of the last GPU frame (a FootprintType; "boxes" for the quads, or "points").
  vtkGetMacro(LastFootprint, int);
  const char* GetLastFootprintAsString() const;
  ///@}

  ///@{
  /**
   * Draw opaque frames with point footprints in two passes (default on):
   * the cells into the mapper's own buffers, where the depth test keeps
   * only the first hit of each pixel in drawing order, then that colour and
   * exact depth into the scene with the scene's depth test. The cells come
   * out front to back, so the first hit in drawing order is the nearest, and
   * the depth test runs before the fragment stage: a fragment behind a
   * surface already found costs no ray cast. With several (opaque)
   * isovalues each cell is one primitive that takes the nearest hit of its
   * isovalues. In one pass the fragment stage writes gl_FragDepth, which
   * makes many rasterisers (llvmpipe always; GPUs without
   * GL_ARB_conservative_depth) test depth only after it. The image is the
   * same; the buffers cost 10 bytes per pixel of the rectangle the volume's
   * box projects to (cut to the viewport, rounded up to 64 pixels; kept
   * while the projection fits, remade when it outgrows them or shrinks
   * below a quarter of them; GetFrameBufferBytes()). Off: always one pass.
   */
  vtkSetMacro(FirstHitPass, bool);
  vtkGetMacro(FirstHitPass, bool);
  vtkBooleanMacro(FirstHitPass, bool);
  ///@}

  ///@{
  /**
   * Draw interactive renders (the prop's allocated render time below one
   * second, see the class description) at the image sample distance (GPU
   * path) or Block LOD level (CPU fallback) that the frame-time model
   * predicts within the budget. Still renders are always full quality.
   * Default on.
   */
  vtkSetMacro(InteractiveAdjust, bool);
  vtkGetMacro(InteractiveAdjust, bool);
  vtkBooleanMacro(InteractiveAdjust, bool);
  ///@}

  ///@{
  /**
   * Seconds an interactive frame may take. Default 0.1. When positive it
   * wins over the prop's allocated render time; 0 takes the allocated
   * render time as the budget, as VTK's volume mappers do (ParaView's
   * interactive renders allocate 0.2 s shared among the view's props).
   */
  vtkSetClampMacro(InteractiveFrameBudget, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(InteractiveFrameBudget, double);
  ///@}

  ///@{
  /**
   * GPU memory, in MB (10^6 bytes), that the volume's textures and pyramids
   * may take (mediso::IsosurfaceScene::SetGPUMemoryBudget). 0, the default:
   * half of the device's memory where OpenGL tells it
   * (GL_NVX_gpu_memory_info, GL_ATI_meminfo), else 1 GiB. A volume whose one
   * texture exceeds it (or GL_MAX_3D_TEXTURE_SIZE) is kept as bricks, only
   * those the isovalues cross on the GPU (GetLastBricks()); where even those
   * exceed it the CPU fallback draws, with that reason.
   */
  vtkSetClampMacro(GPUMemoryBudget, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(GPUMemoryBudget, double);
  ///@}

  /**
   * The last GPU frame's bricks: how many the volume is kept as (0 where it
   * is one texture), how many the isovalues cross, how many are on the GPU.
   */
  std::uint64_t GetLastBricks() const { return this->GPUStats.Bricks; }
  std::uint64_t GetLastActiveBricks() const { return this->GPUStats.ActiveBricks; }
  std::uint64_t GetLastResidentBricks() const { return this->GPUStats.ResidentBricks; }

  ///@{
  /**
   * Whether the last GPU frame drew a volume kept as bricks from the brick
   * pool (the crossed bricks in the slots of one texture, one pyramid over
   * them; mediso::IsosurfaceScene::SetBrickPool()): the pool's slots (0:
   * no pool), and why not ("" where the pool drew them, and for one
   * texture): the pool over the texture limit or the budget, or over
   * mediso::IsosurfaceScene::MaximumPoolMemoryRatio the memory of the
   * crossed bricks as their own pyramids, which then drew them. Decided again
   * at each isovalue change.
   */
  std::uint64_t GetLastBrickPoolSlots() const { return this->GPUStats.PoolSlots; }
  const std::string& GetLastBrickPoolReason() const { return this->LastBrickPoolReason; }
  ///@}

  ///@{
  /**
   * Let an interactive GPU frame whose coarsest sample distance is still
   * predicted over the budget draw a coarser Block LOD level's triangles
   * instead (see the class description). Off: interactive GPU frames stay
   * on the GPU path at its coarsest distance. Default on.
   */
  vtkSetMacro(InteractiveTriangleLevels, bool);
  vtkGetMacro(InteractiveTriangleLevels, bool);
  vtkBooleanMacro(InteractiveTriangleLevels, bool);
  ///@}

  ///@{
  /**
   * Let an interactive GPU frame whose sample distances are all predicted
   * over the budget draw the GPU path on a coarser volume level: Block LOD
   * level 2, 1 or 0 (the volume sampled at stride 2, 4 or 8, the points
   * those levels' triangles are made from), whose coarse volume and pyramid
   * the GPU core makes on the level's first frame (up to 1/8 + 1/64 + 1/512
   * more GPU memory). Candidates go finest first: a level's GPU frames before
   * its triangles. Default on.
   */
  vtkSetMacro(InteractiveVolumeLevels, bool);
  vtkGetMacro(InteractiveVolumeLevels, bool);
  vtkBooleanMacro(InteractiveVolumeLevels, bool);
  ///@}

  ///@{
  /**
   * What the last frame did: whether it was an interactive render, the image
   * sample distance (1: every pixel) and Block LOD level (3: full
   * resolution; on the GPU path, below 3, the coarse volume level) it drew at, the
   * seconds the frame-time model predicted for its drawing, those it
   * predicted for the one-off work the frame did before drawing (a level's
   * pyramid or extraction, the program of a level, distance or translucency
   * not drawn before; 0 when it made nothing), and the seconds it took, both
   * included (0 while InteractiveAdjust is off or nothing was drawn). The
   * frame's predicted time is the sum of the two predictions. On the GPU
   * path the one-off work is also measured on its own (the volume's upload
   * and the pyramids built, to their read-back; 0 when it made nothing, and
   * on the CPU path, whose extraction is not timed apart): the model learns
   * the frame's drawing from the rest.
   */
  vtkGetMacro(LastInteractive, bool);
  vtkGetMacro(LastSampleDistance, double);
  vtkGetMacro(LastLevel, int);
  vtkGetMacro(LastPredictedSeconds, double);
  vtkGetMacro(LastPredictedOneOffSeconds, double);
  vtkGetMacro(LastMeasuredSeconds, double);
  vtkGetMacro(LastOneOffSeconds, double);
  ///@}

  ///@{
  /**
   * The budget of a frame is the whole frame's, the render window's included
   * (issue 30): the window's clear, the other props, post-processing such as
   * ParaView's FXAA, the blit and the swap take part of it whatever this
   * mapper draws. The mapper measures that part on the window's frames in
   * which it drew (the window's StartEvent to EndEvent, less its own timed
   * drawing; the median of the last frames, mediso::FrameFixedCost: a
   * stalled frame moves nothing; the window's first frame with this mapper,
   * which creates the context, is not seen: the mapper starts to observe
   * the window during it) and
   * chooses an interactive frame for what is left of the budget.
   * GetWindowFixedSeconds() is that part as measured so far, what the next
   * frame takes off its budget (0 until the window's second frame with this
   * mapper's drawing, and while InteractiveAdjust is off: frames are then
   * untimed); GetLastBudgetSeconds() the budget left that the last frame was
   * chosen for (0 for a still frame).
   */
  double GetWindowFixedSeconds() const;
  vtkGetMacro(LastBudgetSeconds, double);
  ///@}

  /**
   * The budget left after the window's cost is divided by one plus this
   * margin before the interactive choice (issue 30): how far the last
   * interactive frames overran their predictions, the 75th percentile of
   * their measured / predicted ratios less one (the last 9 frames without
   * one-off work; 0 before any, or when the model over-predicts them).
   * Where the candidates near the budget lie close together, a model right
   * on average puts half the frames over the budget; this keeps three in
   * four within it, by the model's own measured error
   * (mediso::FrameTimeSpread).
   */
  double GetPredictionMargin() const;

#if !defined(__VTK_WRAP__)
  /// The frame-time model fitted from this mapper's frames.
  const mediso::FrameTimeModel& GetFrameTimeModel() const;

  /**
   * What the GPU path did, as the core's scene says it (the last GPU frame,
   * the last pyramid build and volume upload, the builds and uploads so far):
   * one structure, which vtkHistoPyramidIsoRepresentation forwards whole.
   * The getters below read it. Primitives is 0 after a frame the GPU path
   * did not draw.
   */
  const mediso::IsosurfaceSceneStats& GetGPUStats() const { return this->GPUStats; }
#endif

  /// Whether the last GPU frame drew through the first-hit pass.
  bool GetLastFirstHitPass() const { return this->GPUStats.FirstHit; }

  /// Primitives (active cell-isovalue pairs) of the last GPU frame.
  std::uint64_t GetNumberOfPrimitives() const { return this->GPUStats.Primitives; }

  /// Seconds the last pyramid build took (its passes and the read-back of the total).
  double GetLastBuildSeconds() const { return this->GPUStats.BuildSeconds; }

  ///@{
  /**
   * The last pyramid build's level-1 pass: how many of its tiles it drew
   * (those whose value range holds an isovalue; see mediso::VolumeTiles)
   * and how many there are.
   */
  std::uint64_t GetLastBuildTilesDrawn() const { return this->GPUStats.BuildTilesDrawn; }
  std::uint64_t GetLastBuildTiles() const { return this->GPUStats.BuildTiles; }
  ///@}

  /// Pyramid builds and volume uploads so far (camera moves do neither).
  std::uint64_t GetNumberOfPyramidBuilds() const { return this->GPUStats.PyramidBuilds; }
  std::uint64_t GetNumberOfVolumeUploads() const { return this->GPUStats.VolumeUploads; }

  /// Bytes of GPU memory the mapper holds now for the volume (volume and pyramid).
  std::uint64_t GetGPUMemoryBytes() const;

  /// Bytes of the first-hit pass's buffers (0 until one is drawn; see SetFirstHitPass).
  std::uint64_t GetFrameBufferBytes() const;

  /// Triangles of the last fallback frame (0 on the GPU path).
  vtkGetMacro(NumberOfFallbackTriangles, std::uint64_t);

  /// Where each isovalue's colour and opacity come from (see SetColorSource()).
  enum ColorSourceType
  {
    TransferFunctionColors = 0, ///< The property's colour and scalar opacity functions at the value.
    SolidColors = 1,            ///< SolidColor for every isovalue.
    SurfaceColors = 2           ///< SurfaceColor(i) for the i-th isovalue.
  };

  ///@{
  /**
   * The colour of each isosurface: from the vtkVolumeProperty's colour
   * transfer function at the isovalue and its opacity multiplied by the
   * scalar opacity function there (TransferFunctionColors, the default), one
   * SolidColor for all (SolidColors), or SurfaceColor(i) for the i-th value
   * of vtkVolumeProperty::GetIsoSurfaceValues(), in the order given there
   * (SurfaceColors; values past the colours set take SolidColor). Whatever
   * the source, surface i's opacity is further multiplied by
   * SurfaceOpacity(i) (1 where none is set) and by Opacity: an application
   * can give each surface its own colour and opacity without editing
   * transfer functions. A surface of opacity 0 is not drawn.
   *
   * The scalar opacity function applies only with TransferFunctionColors,
   * and, when the colour function is a vtkDiscretizableColorTransferFunction
   * (ParaView's colour maps), only while its EnableOpacityMapping is on: the
   * rule of VTK's surface mappers and of ParaView's Surface representation
   * (whose colour map editor calls it "Enable opacity mapping for surfaces"),
   * so colouring by an array does not make a surface translucent unasked.
   */
  vtkSetClampMacro(ColorSource, int, TransferFunctionColors, SurfaceColors);
  vtkGetMacro(ColorSource, int);
  vtkSetVector3Macro(SolidColor, double);
  vtkGetVector3Macro(SolidColor, double);
  void SetNumberOfSurfaceColors(int number);
  int GetNumberOfSurfaceColors() const { return static_cast<int>(this->SurfaceColorValues.size() / 3); }
  void SetSurfaceColor(int i, double r, double g, double b);
  void SetNumberOfSurfaceOpacities(int number);
  int GetNumberOfSurfaceOpacities() const { return static_cast<int>(this->SurfaceOpacityValues.size()); }
  void SetSurfaceOpacity(int i, double opacity);
  vtkSetClampMacro(Opacity, double, 0.0, 1.0);
  vtkGetMacro(Opacity, double);
  ///@}

  /**
   * The colour and opacity the isovalue `value`, the `index`-th of
   * `property`'s isovalues, is drawn with under the rules above (an opacity
   * of 0: not drawn). Render() takes every surface's look from here; a host
   * reads it to show or export what the view draws.
   */
  void GetSurfaceLook(
    vtkVolumeProperty* property, int index, double value, double color[3], double& opacity) const;

  /// Whether `property`'s scalar opacity function applies (see SetColorSource()).
  bool MapsScalarOpacity(vtkVolumeProperty* property) const;

  /**
   * Why an image of this spacing holds no surface (a zero or non-finite
   * component: its points would not be apart along that axis), as the
   * message Render() gives for it; empty when the spacing is fine.
   */
  static std::string CheckSpacing(const double spacing[3]);

  void Render(vtkRenderer* ren, vtkVolume* vol) override;
  void ReleaseGraphicsResources(vtkWindow* win) override;

protected:
  vtkHistoPyramidIsoMapper();
  ~vtkHistoPyramidIsoMapper() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;

private:
  vtkHistoPyramidIsoMapper(const vtkHistoPyramidIsoMapper&) = delete;
  void operator=(const vtkHistoPyramidIsoMapper&) = delete;

  // An interactive GPU frame's level, method and sample distance: the first
  // of the candidates, finest first, that the frame-time model predicts
  // within `budget` (the last when none is).
  mediso::FrameTimeModel::Candidate ChooseInteractiveLevel(
    bool translucent, int width, int height, double budget, const int dims[3]);
  // The one-off work a candidate would do (a level to build or extract, a
  // program to set up), for the model to predict its whole frame.
  void AddOneOffWork(mediso::FrameTimeModel::Candidate& candidate, const int dims[3]) const;

  int LastRenderPath = NoPath;
  std::string FallbackReason;
  std::string LastBrickPoolReason;
  bool ForceCPUFallback = false;
  bool AllowPointFootprint = true;
  int LastFootprint = BoxFootprint;
  bool FirstHitPass = true;
  bool InteractiveAdjust = true;
  double InteractiveFrameBudget = 0.1;
  double GPUMemoryBudget = 0.0;
  bool InteractiveTriangleLevels = true;
  bool InteractiveVolumeLevels = true;
  bool LastInteractive = false;
  double LastSampleDistance = 1.0;
  int LastLevel = 3;
  double LastPredictedSeconds = 0.0;
  double LastPredictedOneOffSeconds = 0.0;
  double LastMeasuredSeconds = 0.0;
  double LastOneOffSeconds = 0.0;
  double LastBudgetSeconds = 0.0;
  bool LastGPUPathWorked = false;
  mediso::IsosurfaceSceneStats GPUStats;
  std::uint64_t NumberOfFallbackTriangles = 0;
  int ColorSource = TransferFunctionColors;
  double SolidColor[3] = { 1.0, 1.0, 1.0 };
  std::vector<double> SurfaceColorValues;   // r, g, b per surface
  std::vector<double> SurfaceOpacityValues; // one per surface
  double Opacity = 1.0;

  using Surface = vtkOpenGLHistoPyramidIsosurfaces::Surface;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

//------------------------------------------------------------------------------
inline std::string vtkHistoPyramidIsoMapper::CheckSpacing(const double spacing[3])
{
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(spacing[a]) || spacing[a] == 0.0)
    {
      std::ostringstream msg;
      msg << "the image's spacing (" << spacing[0] << ", " << spacing[1] << ", " << spacing[2]
          << ") has a zero or non-finite component: the points of a volume need a non-zero, "
             "finite distance along every axis; nothing is drawn.";
      return msg.str();
    }
  }
  return std::string();
}

//------------------------------------------------------------------------------
inline void vtkHistoPyramidIsoMapper::SetNumberOfSurfaceColors(int number)
{
  const std::size_t size = 3 * static_cast<std::size_t>(number > 0 ? number : 0);
  if (size != this->SurfaceColorValues.size())
  {
    this->SurfaceColorValues.resize(size, 1.0);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
inline void vtkHistoPyramidIsoMapper::SetSurfaceColor(int i, double r, double g, double b)
{
  if (i < 0)
  {
    return;
  }
  if (static_cast<std::size_t>(i) >= this->SurfaceColorValues.size() / 3)
  {
    this->SetNumberOfSurfaceColors(i + 1);
  }
  double* color = &this->SurfaceColorValues[3 * static_cast<std::size_t>(i)];
  if (color[0] != r || color[1] != g || color[2] != b)
  {
    color[0] = r;
    color[1] = g;
    color[2] = b;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
inline void vtkHistoPyramidIsoMapper::SetNumberOfSurfaceOpacities(int number)
{
  const std::size_t size = static_cast<std::size_t>(number > 0 ? number : 0);
  if (size != this->SurfaceOpacityValues.size())
  {
    this->SurfaceOpacityValues.resize(size, 1.0);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
inline void vtkHistoPyramidIsoMapper::SetSurfaceOpacity(int i, double opacity)
{
  if (i < 0)
  {
    return;
  }
  if (static_cast<std::size_t>(i) >= this->SurfaceOpacityValues.size())
  {
    this->SetNumberOfSurfaceOpacities(i + 1);
  }
  if (this->SurfaceOpacityValues[static_cast<std::size_t>(i)] != opacity)
  {
    this->SurfaceOpacityValues[static_cast<std::size_t>(i)] = opacity;
    this->Modified();
  }
}

#endif
