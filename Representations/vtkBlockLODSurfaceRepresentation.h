// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkBlockLODSurfaceRepresentation
 * @brief   ParaView's Surface representation of a vtkBlockLODContour output,
 *          whose interactive frames draw a coarser Block LOD level.
 *
 * ParaView's render view keeps a second, lighter copy of large geometry for
 * interactive renders (while the camera moves): when the shown geometry
 * exceeds the view's LODThreshold (MB), each vtkGeometryRepresentation is
 * asked, in the REQUEST_UPDATE_LOD pass, for a decimated copy of its data
 * (vtkQuadricClustering), which the view delivers to the rendering processes
 * like the full data (the client in client/server with local rendering) and
 * draws through the actor's LOD mapper during interaction. The still render
 * draws the full data.
 *
 * An isosurface from vtkBlockLODContour has better copies than a decimated
 * one: the method's own coarser levels (cube edges of 8, 4, 2 voxels), every
 * one watertight and with normals from the volume, and cached by the filter,
 * so switching between them costs no extraction. This representation is the
 * Surface representation (vtkGeometryRepresentationWithFaces, every property
 * unchanged) with one difference: in REQUEST_UPDATE_LOD it supplies, as the
 * LOD, the finest level at or below the output's whose triangles fit the
 * interactive budget, made by the filter (vtkBlockLODContour::GenerateLevel),
 * instead of the decimated copy. The view's decision to use the LOD at all
 * (LODThreshold), its delivery and the still render are ParaView's and
 * unchanged.
 *
 * How the filter is found: ParaView connects a representation to its
 * source's output through a pass-through filter of its own (vtkPVPostFilter);
 * the representation looks upstream through those for a vtkBlockLODContour,
 * on the data processes, and uses its level only when the filter's current
 * output is the data the representation received (the same points array).
 * Anything else (another source, an output not current, the view asking for
 * outlines as LOD, InteractiveLevels off) gets ParaView's decimated copy.
 *
 * Level choice: the candidates are the output's level and every coarser one,
 * finest first, with their triangles (the output's exactly, the others from
 * the filter's estimator: exact for cached or planned levels and for levels
 * 0 and 1 almost always, predicted otherwise). The first one predicted to
 * draw within InteractiveFrameBudget seconds, and with at most
 * InteractiveTriangleBudget triangles when that is set, is chosen, else the
 * coarsest allowed. The seconds come from a frame-time model
 * (mediso::FrameTimeModel, Mappers/Core/FrameTimeModel.h: seconds = a + b *
 * triangles + c * pixels, fitted per opaque/translucent), which this
 * representation feeds with the frames it draws in this process: each
 * frame's renderer time, with the triangles every Block LOD display drew in
 * it together, the view's pixels and whether any was translucent (a frame
 * that drew new data reports those triangles as uploaded, one-off work the
 * model keeps apart from the drawing). A display's
 * candidate is predicted with the other Block LOD displays' last triangles
 * added, the frame it will share. Before any frame the model's prior is
 * conservative (a software renderer), so the first interactive level errs on
 * the coarse side. Other displays in the view (not Block LOD's) are part of
 * the frame's time but not of its counted work. In a parallel run the counts
 * are summed over the processes first, and every piece draws the coarsest
 * level any process chose (each learnt from its own frames), so that the
 * pieces meet at one level; in
 * client/server the level is chosen on the server, which renders no frame to
 * learn from when the client renders: there the prior decides.
 *
 * Translucency while interacting: ParaView's render view peels translucent
 * geometry (vtkDualDepthPeelingPass, up to the view's MaximumNumberOfPeels),
 * full-viewport passes that on a software renderer are most of a translucent
 * frame whatever its triangles, so a coarser level alone does not bring such
 * a frame within the budget (docs/blocklod.md). A renderer whose depth
 * peeling is off draws translucent geometry in one pass of weighted blended
 * order-independent transparency (vtkOrderIndependentTranslucentPass), and
 * it reads UseDepthPeeling at each render; so with InteractiveTranslucency
 * BLENDED (the default) a frame that draws the interactive geometry of a
 * translucent display switches it off at the view's renderer's StartEvent
 * and on again at its EndEvent: that frame blends, every other frame (the
 * still one) is the view's. The blended image is not the peeled one (layers
 * weighted by depth instead of composited in order): close to it on a
 * single-colour surface, and the camera is moving. The frame-time model
 * keeps such frames apart (FrameWork::Blended, a kind of frame with its own
 * coefficients): the blended pass costs less than peeling but more than an
 * opaque frame of the same triangles (its targets and resolve cover the whole
 * view), and a level chosen as if it drew opaque overran the budget.
 *
 * What interactive frames draw is readable on the rendering process:
 * GetInteractiveLevel() (the level of the LOD geometry, -1 when it is not a
 * Block LOD level), GetInteractiveTriangles(), GetLastRenderUsedLOD() and
 * GetLastRenderTranslucency() (opaque, peeled or blended).
 *
 * @sa vtkBlockLODContour vtkGeometryRepresentation vtkPVRenderView
 */
#ifndef vtkBlockLODSurfaceRepresentation_h
#define vtkBlockLODSurfaceRepresentation_h

#include "MedicalIsosurfacesRepresentationsModule.h" // For export macro
#include "vtkGeometryRepresentationWithFaces.h"
#include "vtkNew.h"          // For vtkNew
#include "vtkSmartPointer.h" // For vtkSmartPointer
#include "vtkWeakPointer.h"  // For vtkWeakPointer

#include <array> // For std::array

namespace mediso
{
struct FrameWork;
}

class vtkBlockLODContour;
class vtkCompositeDataSet;
class vtkRenderWindow;
class vtkRenderer;
class vtkPolyData;

class MEDICALISOSURFACESREPRESENTATIONS_EXPORT vtkBlockLODSurfaceRepresentation
  : public vtkGeometryRepresentationWithFaces
{
public:
  static vtkBlockLODSurfaceRepresentation* New();
  vtkTypeMacro(vtkBlockLODSurfaceRepresentation, vtkGeometryRepresentationWithFaces);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  int ProcessViewRequest(vtkInformationRequestKey* request_type,
    vtkInformation* inInfo,
    vtkInformation* outInfo) override;

  /**
   * As the base class's; a hidden display also stops counting in the frames
   * the other Block LOD displays predict.
   */
  void SetVisibility(bool visible) override;

  ///@{
  /**
   * Draw a coarser Block LOD level during interaction (when the view uses its
   * LOD at all) instead of ParaView's decimated copy. Default on.
   */
  void SetInteractiveLevels(bool use);
  vtkGetMacro(InteractiveLevels, bool);
  ///@}

  ///@{
  /**
   * The seconds an interactive frame should take, as the frame-time model
   * predicts them: the finest level within it is chosen, else level 0. 0
   * leaves the choice to InteractiveTriangleBudget alone. Default 0.1.
   */
  void SetInteractiveFrameBudget(double seconds);
  vtkGetMacro(InteractiveFrameBudget, double);
  ///@}

  ///@{
  /**
   * The most triangles (all isovalues, all processes together) an
   * interactive frame may draw, on top of the frame budget; 0 for no such
   * limit. Default 0.
   */
  void SetInteractiveTriangleBudget(double triangles);
  vtkGetMacro(InteractiveTriangleBudget, double);
  ///@}

  /**
   * How interactive frames draw translucent surfaces. The still frame is the
   * view's (ParaView's render view peels translucent geometry: up to
   * MaximumNumberOfPeels full-viewport passes, most of a translucent frame's
   * time on a software renderer whatever its triangles).
   * - PEELED: as the still frame, with the view's depth peeling.
   * - BLENDED: during the frames that draw the interactive geometry, the
   *   view's renderer blends translucent geometry in one pass instead (VTK's
   *   vtkOrderIndependentTranslucentPass, weighted blended order-independent
   *   transparency, which vtkOpenGLRenderer uses when depth peeling is off):
   *   no sorting and no peels, the layers weighted by depth rather than
   *   composited exactly, which a coarse surface in motion hides. The view's
   *   setting is switched off at the renderer's StartEvent and back at its
   *   EndEvent, so it holds for that frame only, and for every translucent
   *   prop of the view in it. A frame blends only when no translucent Block
   *   LOD display in it asks for PEELED.
   * The interactive level is chosen for the frame this mode draws. Default
   * BLENDED.
   */
  enum InteractiveTranslucencyModes
  {
    PEELED = 0,
    BLENDED = 1
  };
  void SetInteractiveTranslucency(int mode);
  vtkGetMacro(InteractiveTranslucency, int);

  /**
   * How the last render on this process drew this display's surface:
   * OPAQUE_SURFACE (opaque, hidden or not drawn), PEELED_SURFACE (translucent,
   * with the view's depth peeling) or BLENDED_SURFACE (translucent, in one
   * blended pass: an interactive frame with InteractiveTranslucency BLENDED,
   * or a view without depth peeling). Read from the renderer when it starts
   * the frame, on the rendering process.
   */
  enum SurfaceTranslucency
  {
    OPAQUE_SURFACE = 0,
    PEELED_SURFACE = 1,
    BLENDED_SURFACE = 2
  };
  vtkGetMacro(LastRenderTranslucency, int);

  /**
   * The seconds the frame-time model predicted, when the level was chosen
   * (on this data process), for a frame drawing that level (0 when none was).
   */
  vtkGetMacro(PredictedInteractiveSeconds, double);

  /**
   * The seconds a still frame drawing each level (0..3) of the isovalues set
   * now would take: the frame-time model's prediction (fitted to this
   * process's frames, as for the interactive level) for the filter's
   * estimated triangles of those isovalues at that level
   * (vtkBlockLODContour::GetCurrentEstimatedTriangles()), at the view's size,
   * with the other displays' last triangles and the window's overhead added;
   * -1 where there is no estimate (no filter, no update yet). An isovalue
   * change answered coarse first (medical_isosurfaces.RefineAfterChange)
   * adds them to the extraction's seconds, so that its first answer's level
   * fits the budget with its frame, not the extraction alone.
   */
  double* GetPredictedStillSeconds() VTK_SIZEHINT(4);

  ///@{
  /**
   * What the LOD geometry on this process is: its Block LOD level (-1 when
   * there is none, or it is ParaView's decimated copy) and its triangles.
   * Set by the last render that had LOD geometry delivered, so on the
   * rendering process (the client with local rendering).
   */
  vtkGetMacro(InteractiveLevel, int);
  vtkGetMacro(InteractiveTriangles, double);
  ///@}

  /**
   * Whether the last render on this process drew the LOD geometry (an
   * interactive render with the view's LOD in use).
   */
  vtkGetMacro(LastRenderUsedLOD, bool);

  /**
   * The level chosen by the last REQUEST_UPDATE_LOD pass on this (data)
   * process, -1 when the decimated copy was used.
   */
  vtkGetMacro(ChosenInteractiveLevel, int);

protected:
  vtkBlockLODSurfaceRepresentation();
  ~vtkBlockLODSurfaceRepresentation() override;

  // The vtkBlockLODContour whose current output this representation shows,
  // or null.
  vtkBlockLODContour* FindContour();
  // The LOD geometry of REQUEST_UPDATE_LOD: the chosen level, or false (the
  // decimated copy is used).
  bool MakeLevelLOD();
  // This process's triangles of each of the four levels for the shown data
  // (-1 where unknown, all -1 without the filter).
  std::array<double, 4> LevelTriangles(vtkBlockLODContour* contour);
  // The LOD geometry in the shape of the view's piece.
  vtkDataObject* WrapLikePiece(vtkDataObject* piece);

  // Frames drawn here, for the frame-time model: the render window's
  // StartEvent and EndEvent around the render that REQUEST_RENDER prepared
  // (the frame a user waits for), and the view's renderer's within it (the
  // triangles' cost, what the model is fitted to; the rest is a fixed cost
  // per frame, added to its predictions).
  void OnRenderStart();
  void OnRenderEnd();
  void OnRendererStart();
  void OnRendererEnd();
  // The window's fixed cost per frame on this renderer (0 before a frame).
  double FrameOverhead();
  bool AddToView(vtkView* view) override;
  bool RemoveFromView(vtkView* view) override;

  // Whether interactive frames that draw this display translucent are to be
  // blended in one pass (InteractiveTranslucency BLENDED, a view that peels).
  bool BlendsInteractiveFrames();

  bool InteractiveLevels = true;
  int InteractiveTranslucency = BLENDED;
  int LastRenderTranslucency = OPAQUE_SURFACE;
  // Set by REQUEST_RENDER: the coming frame draws this display translucent.
  bool DrawsTranslucent = false;
  double InteractiveFrameBudget = 0.1;
  double InteractiveTriangleBudget = 0.0;
  double PredictedInteractiveSeconds = 0.0;
  double PredictedStillSeconds[4] = { -1.0, -1.0, -1.0, -1.0 };
  unsigned long StartObserver = 0;
  unsigned long EndObserver = 0;
  unsigned long RendererStartObserver = 0;
  unsigned long RendererEndObserver = 0;
  vtkWeakPointer<vtkRenderer> ObservedRenderer;
  vtkWeakPointer<vtkRenderWindow> ObservedWindow;
  // The full data and the LOD drawn last, so that a frame that draws either
  // anew reports its upload.
  vtkMTimeType DrawnDataTime = 0;
  vtkMTimeType DrawnLODTime = 0;
  int InteractiveLevel = -1;
  double InteractiveTriangles = 0.0;
  bool LastRenderUsedLOD = false;
  int ChosenInteractiveLevel = -1;
  vtkNew<vtkPolyData> LevelSurface;
  vtkSmartPointer<vtkCompositeDataSet> LevelPiece;

private:
  // A triangle frame of this display in its view: translucency and the view's pixels.
  mediso::FrameWork ViewFrameWork();

  vtkBlockLODSurfaceRepresentation(const vtkBlockLODSurfaceRepresentation&) = delete;
  void operator=(const vtkBlockLODSurfaceRepresentation&) = delete;
};

#endif
