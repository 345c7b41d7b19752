// SPDX-License-Identifier: BSD-3-Clause
#include "vtkHistoPyramidIsoMapper.h"

#include "vtkBlockLODIsosurfaces.h"
#include "vtkColorTransferFunction.h"
#include "vtkCommand.h"
#include "vtkContourValues.h"
#include "vtkDataArray.h"
#include "vtkDiscretizableColorTransferFunction.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLHistoPyramidIsosurfaces.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPlane.h"
#include "vtkPlaneCollection.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include "FrameFixedCost.h"
#include "IsosurfaceScene.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <set>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkHistoPyramidIsoMapper);

namespace
{
bool SupportedType(int type)
{
  switch (type)
  {
    case VTK_CHAR:
    case VTK_SIGNED_CHAR:
    case VTK_UNSIGNED_CHAR:
    case VTK_SHORT:
    case VTK_UNSIGNED_SHORT:
    case VTK_INT:
    case VTK_UNSIGNED_INT:
    case VTK_FLOAT:
    case VTK_DOUBLE:
      return true;
    default:
      return false;
  }
}

// Image sample distances an interactive GPU frame chooses from, finest first.
constexpr float SampleDistances[] = { 1.0f, 1.5f, 2.0f, 2.5f, 3.0f, 4.0f, 5.0f, 6.0f, 8.0f };

// The full-resolution Block LOD level (vtkBlockLODContour's LOD 3: cubes of one voxel).
constexpr int FullLevel = 3;

// The coarse volume levels an interactive GPU frame chooses from, finest first (strides 2, 4,
// 8): on a software rasteriser a frame costs about its primitives, 4x fewer per level.
constexpr int VolumeLevels[] = { 2, 1, 0 };

using Clock = std::chrono::steady_clock;
} // anonymous namespace

//------------------------------------------------------------------------------
// The two paths, and the messages already given (each is said once).
struct vtkHistoPyramidIsoMapper::Internals
{
  vtkNew<vtkOpenGLHistoPyramidIsosurfaces> GPU;
  vtkNew<vtkBlockLODIsosurfaces> Fallback;
  std::set<std::string> Said;

  // The frame-time model and what it is fed: every frame, with the one-off
  // work it did (a level's pyramid or extraction, the programs of a level
  // and translucency not drawn before: Warm says which were), so that the
  // model predicts the frames that switch level too.
  mediso::FrameTimeModel Model;
  std::set<std::pair<int, bool>> Warm;
  // The Block LOD level the fallback drew last (-1: none): another level's
  // triangles are uploaded again (one vtkPolyDataMapper draws them all).
  int LastTriangleLevel = -1;

  // Warm's key of the programs a frame compiles. A GPU frame's is its volume
  // level's and translucency's: the pyramid walk is compiled with the level's
  // layout (its levels and their constants); a sample distance compiles
  // nothing (its framebuffer is resized, its full-screen pass is compiled
  // once). A fallback frame's is its translucency's alone: every Block LOD
  // level is drawn by the same polygon shaders, a new level only uploads.
  static std::pair<int, bool> GPUKey(int level, bool translucent) { return { level, translucent }; }
  static std::pair<int, bool> TrianglesKey(bool translucent) { return { -1, translucent }; }
  // The fallback's triangles per level for the current values and input
  // (-1: not drawn yet), which its interactive choice predicts from.
  std::array<double, 4> LevelTriangles = { { -1.0, -1.0, -1.0, -1.0 } };
  std::vector<double> CountedValues;
  vtkMTimeType CountedStamp = 0;
  // Active pairs of the last GPU frame of these values and input (0: none yet).
  std::uint64_t Primitives = 0;
  // The same for the coarse volume levels (index = level; 0: not drawn yet).
  std::array<std::uint64_t, 4> LevelPairs = { { 0, 0, 0, 0 } };

  // Triangles of `level`: drawn, or scaled from the nearest level drawn
  // (a surface's triangles grow about 4x per finer level); 0 when none was.
  double TrianglesAt(int level) const
  {
    for (int distance = 0; distance < 4; ++distance)
    {
      for (int other : { level + distance, level - distance })
      {
        if (other >= 0 && other < 4 && this->LevelTriangles[other] >= 0.0)
        {
          return this->LevelTriangles[other] * std::pow(4.0, level - other);
        }
      }
    }
    return 0.0;
  }

  // Triangles of a Block LOD level: drawn, scaled from a level drawn, or
  // (none drawn yet) from the GPU path's active pairs, about two triangles
  // each at the full level.
  std::uint64_t EstimatedTriangles(int level) const
  {
    const double drawn = this->TrianglesAt(level);
    return static_cast<std::uint64_t>(
      drawn > 0.0 ? drawn : 2.0 * static_cast<double>(this->Primitives) * std::pow(4.0, level - 3));
  }

  // Cells of a GPU volume level of a volume of `dims` points (the coarse
  // copy keeps every stride-th point and the last of each axis): what its
  // pyramid's build covers.
  static std::uint64_t LevelCells(const int dims[3], int level)
  {
    const int stride = 1 << (FullLevel - level);
    std::uint64_t cells = 1;
    for (int a = 0; a < 3; ++a)
    {
      cells *= static_cast<std::uint64_t>(std::max(0, (dims[a] - 1 + stride - 1) / stride));
    }
    return cells;
  }

  // The render window's frames around this mapper's (issue 30: the budget is
  // the whole frame's). Each frame of the window in which this mapper drew
  // and timed its drawing gives the window's seconds (StartEvent to
  // EndEvent: the clear, the other props, post-processing, the blit and the
  // swap) less the mapper's own; the interactive choice is made for the
  // budget less their median (mediso::FrameFixedCost). The window's first
  // frame with this mapper (which creates the window and its context) is not
  // seen: the mapper starts to observe the window during it.
  mediso::FrameFixedCost WindowCost;
  // How far the last interactive frames overran their predictions: the
  // choice is made for the budget left divided by one plus that margin
  // (mediso::FrameTimeSpread; issue 30, the 512^3 phantom's frame).
  mediso::FrameTimeSpread Spread;
  vtkWeakPointer<vtkRenderWindow> Window;
  unsigned long WindowStartTag = 0;
  unsigned long WindowEndTag = 0;
  Clock::time_point FrameStart;
  bool InFrame = false;    // between the window's StartEvent and EndEvent
  double OwnSeconds = 0.0; // this mapper's timed drawing within the frame
  bool OwnTimed = false;   // whether it drew and timed in this frame

  ~Internals() { this->Unwatch(); }

  // Observe `window`'s frames (another window: forget the last one's).
  void Watch(vtkRenderWindow* window)
  {
    if (window == this->Window.GetPointer())
    {
      return;
    }
    this->Unwatch();
    this->WindowCost.Reset();
    this->InFrame = false;
    this->OwnTimed = false;
    this->OwnSeconds = 0.0;
    this->Window = window;
    if (window)
    {
      this->WindowStartTag =
        window->AddObserver(vtkCommand::StartEvent, this, &Internals::OnWindowStart);
      this->WindowEndTag = window->AddObserver(vtkCommand::EndEvent, this, &Internals::OnWindowEnd);
    }
  }
  void Unwatch()
  {
    if (vtkRenderWindow* window = this->Window.GetPointer())
    {
      window->RemoveObserver(this->WindowStartTag);
      window->RemoveObserver(this->WindowEndTag);
    }
    this->Window = nullptr;
  }
  void OnWindowStart()
  {
    this->FrameStart = Clock::now();
    this->InFrame = true;
    this->OwnSeconds = 0.0;
    this->OwnTimed = false;
  }
  void OnWindowEnd()
  {
    if (this->InFrame && this->OwnTimed)
    {
      const double window = std::chrono::duration<double>(Clock::now() - this->FrameStart).count();
      this->WindowCost.Observe(window, this->OwnSeconds);
    }
    this->InFrame = false;
    this->OwnTimed = false;
    this->OwnSeconds = 0.0;
  }
  // This mapper's timed drawing, within the window's frame if one is open.
  void AddOwnSeconds(double seconds)
  {
    if (this->InFrame)
    {
      this->OwnSeconds += seconds;
      this->OwnTimed = true;
    }
  }

  // Active pairs of a GPU volume level: drawn, else estimated from the full level's.
  std::uint64_t EstimatedPairs(int level) const
  {
    const std::uint64_t drawn = this->LevelPairs[static_cast<std::size_t>(level)];
    if (level == FullLevel)
    {
      return this->Primitives;
    }
    return drawn > 0 ? drawn : mediso::IsosurfaceScene::EstimateActivePairs(this->Primitives, level);
  }
};

//------------------------------------------------------------------------------
vtkHistoPyramidIsoMapper::vtkHistoPyramidIsoMapper()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkHistoPyramidIsoMapper::~vtkHistoPyramidIsoMapper() = default;

//------------------------------------------------------------------------------
int vtkHistoPyramidIsoMapper::FillInputPortInformation(int vtkNotUsed(port), vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

//------------------------------------------------------------------------------
const char* vtkHistoPyramidIsoMapper::GetLastFootprintAsString() const
{
  return this->LastFootprint == PointFootprint ? "points" : "boxes";
}

//------------------------------------------------------------------------------
const char* vtkHistoPyramidIsoMapper::GetLastRenderPathAsString() const
{
  switch (this->LastRenderPath)
  {
    case GPUPath:
      return "gpu";
    case FallbackPath:
      return "fallback";
    default:
      return "none";
  }
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoMapper::GetWindowFixedSeconds() const
{
  return this->Impl->WindowCost.Seconds();
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoMapper::GetPredictionMargin() const
{
  return this->Impl->Spread.Margin();
}

//------------------------------------------------------------------------------
const mediso::FrameTimeModel& vtkHistoPyramidIsoMapper::GetFrameTimeModel() const
{
  return this->Impl->Model;
}

//------------------------------------------------------------------------------
std::uint64_t vtkHistoPyramidIsoMapper::GetGPUMemoryBytes() const
{
  return this->Impl->GPU->GetGPUMemoryBytes();
}

//------------------------------------------------------------------------------
std::uint64_t vtkHistoPyramidIsoMapper::GetFrameBufferBytes() const
{
  return this->Impl->GPU->GetFrameBufferBytes();
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoMapper::ReleaseGraphicsResources(vtkWindow* win)
{
  this->Impl->GPU->ReleaseGraphicsResources(win);
  this->Impl->Fallback->ReleaseGraphicsResources(win);
  this->Impl->Warm.clear();
}

//------------------------------------------------------------------------------
bool vtkHistoPyramidIsoMapper::MapsScalarOpacity(vtkVolumeProperty* property) const
{
  if (this->ColorSource != TransferFunctionColors || !property)
  {
    return false;
  }
  // ParaView's colour maps are vtkDiscretizableColorTransferFunctions; like
  // its Surface representation's mapper, apply their opacity function only
  // when the map says so (a plain vtkColorTransferFunction has no such switch).
  auto* map = vtkDiscretizableColorTransferFunction::SafeDownCast(
    property->GetColorChannels(0) == 1 ? nullptr : property->GetRGBTransferFunction(0));
  return !map || map->GetEnableOpacityMapping();
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoMapper::GetSurfaceLook(
  vtkVolumeProperty* property, int index, double value, double color[3], double& opacity) const
{
  const std::size_t i = static_cast<std::size_t>(std::max(0, index));
  opacity = 1.0;
  if (this->ColorSource == TransferFunctionColors && property)
  {
    if (property->GetColorChannels(0) == 1)
    {
      color[0] = color[1] = color[2] = property->GetGrayTransferFunction(0)->GetValue(value);
    }
    else
    {
      property->GetRGBTransferFunction(0)->GetColor(value, color);
    }
    vtkPiecewiseFunction* map = property->GetScalarOpacity(0);
    if (map && this->MapsScalarOpacity(property))
    {
      opacity = map->GetValue(value);
    }
  }
  else if (this->ColorSource == SurfaceColors && 3 * i < this->SurfaceColorValues.size())
  {
    std::copy_n(&this->SurfaceColorValues[3 * i], 3, color);
  }
  else
  {
    std::copy_n(this->SolidColor, 3, color);
  }
  if (i < this->SurfaceOpacityValues.size())
  {
    opacity *= this->SurfaceOpacityValues[i];
  }
  opacity = std::min(1.0, std::max(0.0, opacity * this->Opacity));
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  Internals& impl = *this->Impl;
  this->LastRenderPath = NoPath;
  this->GPUStats.Primitives = 0;
  this->NumberOfFallbackTriangles = 0;
  this->LastInteractive = false;
  this->LastSampleDistance = 1.0;
  this->LastLevel = FullLevel;
  this->LastPredictedSeconds = 0.0;
  this->LastPredictedOneOffSeconds = 0.0;
  this->LastMeasuredSeconds = 0.0;
  this->LastOneOffSeconds = 0.0;
  this->LastBudgetSeconds = 0.0;

  // Say a message once (per distinct text), as an error or a warning.
  auto sayOnce = [&](bool error, const std::string& text)
  {
    if (impl.Said.insert(text).second)
    {
      if (error)
      {
        vtkErrorMacro(<< text);
      }
      else
      {
        vtkWarningMacro(<< text);
      }
    }
  };

  // 1. The input. No input at all is normal (a ParaView rank without data).
  vtkImageData* image = vtkImageData::SafeDownCast(this->GetInputDataObject(0, 0));
  if (!image || !vol || !ren)
  {
    return;
  }
  int dims[3];
  image->GetDimensions(dims);
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2)
  {
    std::ostringstream msg;
    msg << "needs 3D image data (at least 2 points along every axis), not " << dims[0] << "x"
        << dims[1] << "x" << dims[2] << "; nothing is drawn.";
    sayOnce(true, msg.str());
    return;
  }
  const std::string spacingProblem = CheckSpacing(image->GetSpacing());
  if (!spacingProblem.empty())
  {
    sayOnce(true, spacingProblem);
    return;
  }
  int cellFlag = 0;
  vtkDataArray* scalars = vtkDataArray::SafeDownCast(this->GetScalars(
    image, this->ScalarMode, this->ArrayAccessMode, this->ArrayId, this->ArrayName, cellFlag));
  if (!scalars)
  {
    sayOnce(true, "the input has no point scalars to contour; nothing is drawn.");
    return;
  }
  if (cellFlag)
  {
    sayOnce(true,
      std::string("array '") + (scalars->GetName() ? scalars->GetName() : "") +
        "' is cell data; isosurfaces need point data (apply Cell Data to Point Data first); "
        "nothing is drawn.");
    return;
  }
  if (scalars->GetNumberOfComponents() != 1 || !SupportedType(scalars->GetDataType()))
  {
    std::ostringstream msg;
    msg << "array '" << (scalars->GetName() ? scalars->GetName() : "") << "' has "
        << scalars->GetNumberOfComponents() << " components of type "
        << scalars->GetDataTypeAsString()
        << "; one component of an 8, 16 or 32-bit integer, float or double type is needed; "
           "nothing is drawn.";
    sayOnce(true, msg.str());
    return;
  }

  // 2. The isovalues and their looks, normalised as every host of the core
  //    does (mediso::IsosurfaceScene::Normalize(): increasing values, each
  //    once, at most MaximumIsovalues, NaN ones left out, each said once);
  //    invisible ones (opacity 0) left out after. A value's index in the
  //    property's list picks its surface colour and opacity.
  vtkVolumeProperty* property = vol->GetProperty();
  vtkContourValues* values = property->GetIsoSurfaceValues();
  std::vector<mediso::IsosurfaceLook> given(values ? values->GetNumberOfContours() : 0);
  for (std::size_t i = 0; i < given.size(); ++i)
  {
    given[i].Value = values->GetValue(static_cast<int>(i));
  }
  const mediso::SurfaceSelection requested = mediso::IsosurfaceScene::Normalize(given);
  for (const std::string& note : requested.Notes)
  {
    sayOnce(false, note);
  }
  if (requested.Surfaces.empty())
  {
    if (requested.NotANumber == 0)
    {
      sayOnce(false,
        "no isovalues: set them with vtkVolumeProperty::GetIsoSurfaceValues() "
        "(ParaView: the representation's Isosurfaces); nothing is drawn.");
    }
    return;
  }
  std::vector<Surface> surfaces;
  for (std::size_t k = 0; k < requested.Surfaces.size(); ++k)
  {
    Surface s;
    s.Value = requested.Surfaces[k].Value;
    this->GetSurfaceLook(property, requested.Sources[k], s.Value, s.Color, s.Opacity);
    if (s.Opacity > 0.0)
    {
      surfaces.push_back(s);
    }
  }
  if (surfaces.empty())
  {
    this->LastRenderPath = NoPath;
    return;
  }

  // 3. The clipping planes and the cropping box's faces, in world
  //    coordinates (the cropping planes are in the volume's own, as for
  //    VTK's volume mappers: moved by the volume's matrix).
  using Plane = vtkOpenGLHistoPyramidIsosurfaces::Plane;
  std::vector<Plane> planes;
  if (this->ClippingPlanes)
  {
    const int count = this->ClippingPlanes->GetNumberOfItems();
    if (count > 6)
    {
      sayOnce(false,
        "more than 6 clipping planes (" + std::to_string(count) + "): only the first 6 are used.");
    }
    for (int i = 0; i < std::min(count, 6); ++i)
    {
      vtkPlane* plane = this->ClippingPlanes->GetItem(i);
      const double* n = plane->GetNormal();
      const double* o = plane->GetOrigin();
      const Plane p = { n[0], n[1], n[2], -(n[0] * o[0] + n[1] * o[1] + n[2] * o[2]) };
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]) ||
        !std::isfinite(p[3]) || (p[0] == 0.0 && p[1] == 0.0 && p[2] == 0.0))
      {
        sayOnce(
          false, "a clipping plane has a zero or non-finite normal or origin: it is ignored.");
        continue;
      }
      planes.push_back(p);
    }
  }
  if (this->Cropping)
  {
    if (this->CroppingRegionFlags != VTK_CROP_SUBVOLUME)
    {
      std::ostringstream msg;
      msg << "cropping region flags 0x" << std::hex << this->CroppingRegionFlags
          << " are not supported (only the subvolume, 0x" << VTK_CROP_SUBVOLUME
          << "): the volume is drawn uncropped.";
      sayOnce(false, msg.str());
    }
    else
    {
      std::vector<Plane> box;
      for (int a = 0; a < 3; ++a)
      {
        Plane low = { 0.0, 0.0, 0.0, -this->CroppingRegionPlanes[2 * a] };
        low[a] = 1.0;
        Plane high = { 0.0, 0.0, 0.0, this->CroppingRegionPlanes[2 * a + 1] };
        high[a] = -1.0;
        box.push_back(low);
        box.push_back(high);
      }
      vtkNew<vtkMatrix4x4> worldToModel;
      vtkMatrix4x4::Invert(vol->GetMatrix(), worldToModel);
      for (const Plane& p : vtkOpenGLHistoPyramidIsosurfaces::PullBackPlanes(box, worldToModel))
      {
        planes.push_back(p);
      }
    }
  }
  impl.GPU->SetClipPlanes(planes);
  impl.Fallback->SetClipPlanes(planes);

  // 4. Interactive or still (VTK's rule: less than a second allocated to
  //    the prop), the budget, and the counts the frame-time model predicts
  //    from (known for these values and this input once drawn).
  const double allocated = vol->GetAllocatedRenderTime();
  const bool adjust = this->InteractiveAdjust;
  const bool interactive = adjust && allocated < 1.0;
  // The budget is the whole frame's: the window's cost outside this mapper,
  // measured over its last frames, is taken off it (see Internals::Watch).
  impl.Watch(ren->GetRenderWindow());
  const double frameBudget =
    this->InteractiveFrameBudget > 0.0 ? this->InteractiveFrameBudget : allocated;
  const double budget = impl.Spread.BudgetLeft(impl.WindowCost.BudgetLeft(frameBudget));
  int width = 0, height = 0;
  ren->GetTiledSize(&width, &height);
  bool translucent = false;
  std::vector<double> drawnValues;
  for (const Surface& s : surfaces)
  {
    translucent = translucent || s.Opacity < 1.0;
    drawnValues.push_back(s.Value);
  }
  if (drawnValues != impl.CountedValues || scalars->GetMTime() != impl.CountedStamp)
  {
    impl.LevelTriangles.fill(-1.0);
    impl.LevelPairs.fill(0);
    // New isovalues of the same data keep the last full level's active pairs
    // as the prior of the next interactive choice (a nearby isovalue crosses
    // about as many cells), so that an interactive render right after a
    // change (a histogram line dragged, medical_isosurfaces.
    // RefineHistoPyramidChange) draws a coarse level at once, building only
    // that level's pyramid, instead of the full volume; new data forgets it.
    if (scalars->GetMTime() != impl.CountedStamp)
    {
      impl.Primitives = 0;
    }
    impl.CountedValues = drawnValues;
    impl.CountedStamp = scalars->GetMTime();
  }
  this->LastInteractive = interactive;
  this->LastBudgetSeconds = interactive ? budget : 0.0;
  const std::uint64_t fullPixels = mediso::FrameTimeModel::ShadedPixels(width, height, 1.0);
  auto trianglesAt = [&](int level) { return impl.EstimatedTriangles(level); };
  auto gpuCandidate = [&](int level, float distance, std::uint64_t primitives)
  {
    mediso::FrameTimeModel::Candidate candidate;
    candidate.Level = level;
    candidate.SampleDistance = distance;
    candidate.Work.Method = mediso::FrameMethod::CellRasterisation;
    candidate.Work.Primitives = primitives;
    candidate.Work.Pixels = mediso::FrameTimeModel::ShadedPixels(width, height, distance);
    candidate.Work.Translucent = translucent;
    return candidate;
  };
  auto triangleCandidate = [&](int level)
  {
    mediso::FrameTimeModel::Candidate candidate;
    candidate.Level = level;
    candidate.Work.Method = mediso::FrameMethod::Triangles;
    candidate.Work.Primitives = trianglesAt(level);
    candidate.Work.Pixels = fullPixels;
    candidate.Work.Translucent = translucent;
    this->AddOneOffWork(candidate, dims);
    return candidate;
  };

  // The triangles of a Block LOD level (the CPU path: the fallback, or an
  // interactive frame that even the GPU path's coarsest distance would not
  // fit in the budget), timed and observed unless it extracted.
  auto drawTriangles = [&](int level)
  {
    impl.Fallback->SetLevel(level);
    const Clock::time_point start = Clock::now();
    impl.Fallback->RenderIsosurfaces(ren, vol, image, scalars, surfaces);
    this->NumberOfFallbackTriangles = impl.Fallback->GetNumberOfTriangles();
    this->LastRenderPath = FallbackPath;
    this->LastLevel = level;
    if (adjust)
    {
      // Predicted as known before the frame (the one-off work the level
      // would need), observed with what the frame did.
      const mediso::FrameTimeModel::Candidate predicted = triangleCandidate(level);
      this->LastPredictedSeconds = impl.Model.PredictDrawing(predicted.Work);
      this->LastPredictedOneOffSeconds = impl.Model.PredictOneOff(predicted.Work);
      glFinish();
      this->LastMeasuredSeconds = std::chrono::duration<double>(Clock::now() - start).count();
      impl.AddOwnSeconds(this->LastMeasuredSeconds);
      mediso::FrameWork work = predicted.Work;
      work.Primitives = this->NumberOfFallbackTriangles;
      const bool uploaded =
        impl.Fallback->GetLastFrameExtracted() || level != impl.LastTriangleLevel;
      work.BuildElements = uploaded ? this->NumberOfFallbackTriangles : 0;
      work.Programs = impl.Warm.insert(Internals::TrianglesKey(translucent)).second ? 1 : 0;
      impl.Model.Observe(work, this->LastMeasuredSeconds);
      if (interactive && !work.HasOneOff())
      {
        impl.Spread.Observe(
          this->LastPredictedSeconds, this->LastMeasuredSeconds, frameBudget);
      }
    }
    impl.LevelTriangles[static_cast<std::size_t>(level)] =
      static_cast<double>(this->NumberOfFallbackTriangles);
    impl.LastTriangleLevel = level;
  };

  // 5. An interactive frame whose GPU distances are all predicted over the
  //    budget (the primitives dominate: a coarser volume is needed) draws a
  //    coarser level instead, when one is predicted to fit better: the GPU
  //    path on a coarse volume level, or a Block LOD level's triangles.
  //    Needs the active pairs of a GPU frame of these values.
  vtkOpenGLHistoPyramidIsosurfaces* gpu = impl.GPU;
  int gpuLevel = FullLevel;
  if (interactive && (this->InteractiveTriangleLevels || this->InteractiveVolumeLevels) &&
    !this->ForceCPUFallback && impl.Primitives > 0 && this->LastGPUPathWorked)
  {
    const mediso::FrameTimeModel::Candidate& chosen =
      this->ChooseInteractiveLevel(translucent, width, height, budget, dims);
    if (chosen.Work.Method == mediso::FrameMethod::Triangles)
    {
      this->FallbackReason.clear();
      drawTriangles(chosen.Level);
      return;
    }
    gpuLevel = chosen.Level;
  }

  // 6. The GPU path, or the fallback when it cannot run (said once, with the reason).
  std::string reason;
  mediso::FrameWork chosenWork;
  vtkOpenGLHistoPyramidIsosurfaces::SampleDistanceChooser chooser;
  if (adjust)
  {
    chooser = [&](std::uint64_t primitives)
    {
      std::vector<mediso::FrameTimeModel::Candidate> candidates;
      for (float distance : SampleDistances)
      {
        candidates.push_back(gpuCandidate(gpuLevel, distance, primitives));
        this->AddOneOffWork(candidates.back(), dims);
      }
      const std::size_t chosen = interactive ? impl.Model.Choose(candidates, budget) : 0;
      chosenWork = candidates[chosen].Work;
      this->LastPredictedSeconds = impl.Model.PredictDrawing(chosenWork);
      this->LastPredictedOneOffSeconds = impl.Model.PredictOneOff(chosenWork);
      return candidates[chosen].SampleDistance;
    };
  }
  gpu->SetVolumeLevel(gpuLevel);
  gpu->SetGPUMemoryBudget(static_cast<std::uint64_t>(1.0e6 * this->GPUMemoryBudget));
  const mediso::IsosurfaceSceneStats statsBefore = gpu->GetStats();
  const Clock::time_point gpuStart = Clock::now();
  if (this->ForceCPUFallback)
  {
    reason = "ForceCPUFallback is on";
  }
  else if (gpu->RenderIsosurfaces(ren, vol, image, scalars, surfaces, this->AllowPointFootprint,
             this->FirstHitPass, chooser, reason))
  {
    this->LastRenderPath = GPUPath;
    this->LastGPUPathWorked = true;
    this->FallbackReason.clear();
    this->GPUStats = gpu->GetStats();
    this->LastBrickPoolReason = gpu->GetBrickPoolReason();
    this->LastFootprint = this->GPUStats.PointFootprint ? PointFootprint : BoxFootprint;
    this->LastSampleDistance = this->GPUStats.SampleDistance;
    this->LastLevel = this->GPUStats.Level;
    impl.Primitives = gpu->GetActivePairs(FullLevel);
    impl.LevelPairs[static_cast<std::size_t>(this->GPUStats.Level)] = this->GPUStats.Primitives;
    if (adjust && this->GPUStats.Primitives > 0)
    {
      // Timed to the frame's end: a GL frame's calls return before its work is done.
      glFinish();
      this->LastMeasuredSeconds = std::chrono::duration<double>(Clock::now() - gpuStart).count();
      impl.AddOwnSeconds(this->LastMeasuredSeconds);
      // Observed with the one-off work it did: the full level's pyramid (the
      // first frame, with the volume's upload, or after an isovalue change),
      // a coarse level's on its first frame of these values, the program of
      // a level and translucency not drawn before (not of a distance).
      mediso::FrameWork work = chosenWork;
      work.Primitives = this->GPUStats.Primitives;
      work.BuildElements = 0;
      if (this->GPUStats.VolumeUploads != statsBefore.VolumeUploads ||
        this->GPUStats.PyramidBuilds != statsBefore.PyramidBuilds)
      {
        work.BuildElements += Internals::LevelCells(dims, FullLevel);
      }
      if (this->GPUStats.CoarseBuilds != statsBefore.CoarseBuilds)
      {
        work.BuildElements += Internals::LevelCells(dims, this->LastLevel);
      }
      const std::pair<int, bool> key = Internals::GPUKey(this->LastLevel, chosenWork.Translucent);
      work.Programs = impl.Warm.insert(key).second ? 1 : 0;
      // The upload and builds end in a read-back, so the GPU path timed them
      // on their own: the model takes them as one-off work and the rest as
      // the frame's drawing, not split by its own predictions.
      this->LastOneOffSeconds = gpu->GetLastOneOffSeconds();
      if (work.BuildElements > 0)
      {
        impl.Model.Observe(work, this->LastMeasuredSeconds, this->LastOneOffSeconds);
      }
      else
      {
        impl.Model.Observe(work, this->LastMeasuredSeconds);
      }
      if (interactive && !work.HasOneOff())
      {
        impl.Spread.Observe(
          this->LastPredictedSeconds, this->LastMeasuredSeconds, frameBudget);
      }
    }
    else
    {
      this->LastPredictedSeconds = 0.0;
      this->LastPredictedOneOffSeconds = 0.0;
    }
    return;
  }
  this->LastGPUPathWorked = false;
  this->LastPredictedSeconds = 0.0;
  this->LastPredictedOneOffSeconds = 0.0;
  if (!this->ForceCPUFallback)
  {
    sayOnce(false,
      "GPU isosurface path unavailable (" + reason +
        "); rendering with vtkBlockLODContour and vtkPolyDataMapper instead.");
  }
  this->FallbackReason = reason;

  // The fallback's level: the finest predicted within the budget while
  // interactive, from the triangles each level had for these values.
  int level = FullLevel;
  if (interactive)
  {
    std::vector<mediso::FrameTimeModel::Candidate> candidates;
    for (int l = FullLevel; l >= 0; --l)
    {
      candidates.push_back(triangleCandidate(l));
    }
    level = candidates[impl.Model.Choose(candidates, budget)].Level;
  }
  drawTriangles(level);
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoMapper::AddOneOffWork(mediso::FrameTimeModel::Candidate& candidate,
  const int dims[3]) const
{
  // What a candidate would make before it draws, as known before the frame:
  // a GPU level not built for these values (its pairs unknown) builds its
  // pyramid; a Block LOD level not drawn for them extracts, and a level other
  // than the last one drawn uploads its triangles; a program not compiled
  // before (Internals::GPUKey, TrianglesKey) is compiled.
  const Internals& impl = *this->Impl;
  mediso::FrameWork& work = candidate.Work;
  const std::size_t level = static_cast<std::size_t>(candidate.Level);
  if (work.Method == mediso::FrameMethod::CellRasterisation)
  {
    const bool built =
      candidate.Level == FullLevel ? impl.Primitives > 0 : impl.LevelPairs[level] > 0;
    work.BuildElements = built ? 0 : Internals::LevelCells(dims, candidate.Level);
    work.Programs = impl.Warm.count(Internals::GPUKey(candidate.Level, work.Translucent)) ? 0 : 1;
  }
  else
  {
    const bool drawn =
      impl.LevelTriangles[level] >= 0.0 && candidate.Level == impl.LastTriangleLevel;
    work.BuildElements = drawn ? 0 : work.Primitives;
    work.Programs = impl.Warm.count(Internals::TrianglesKey(work.Translucent)) ? 0 : 1;
  }
}

//------------------------------------------------------------------------------
mediso::FrameTimeModel::Candidate vtkHistoPyramidIsoMapper::ChooseInteractiveLevel(
  bool translucent, int width, int height, double budget, const int dims[3])
{
  // Finest first: the full volume at each sample distance, then per coarser
  // level its GPU frames (InteractiveVolumeLevels) and its triangles
  // (InteractiveTriangleLevels), level 0's triangles last.
  Internals& impl = *this->Impl;
  std::vector<mediso::FrameTimeModel::Candidate> candidates;
  auto add = [&](int level, mediso::FrameMethod method, float distance)
  {
    mediso::FrameTimeModel::Candidate candidate;
    candidate.Level = level;
    candidate.SampleDistance = distance;
    candidate.Work.Method = method;
    candidate.Work.Primitives = method == mediso::FrameMethod::Triangles
      ? impl.EstimatedTriangles(level)
      : impl.EstimatedPairs(level);
    candidate.Work.Pixels = mediso::FrameTimeModel::ShadedPixels(width, height, distance);
    candidate.Work.Translucent = translucent;
    this->AddOneOffWork(candidate, dims);
    candidates.push_back(candidate);
  };
  for (int level = FullLevel; level >= 0; --level)
  {
    const bool volumeLevel = level == FullLevel ||
      (this->InteractiveVolumeLevels &&
        std::find(std::begin(VolumeLevels), std::end(VolumeLevels), level) !=
          std::end(VolumeLevels));
    for (float distance : SampleDistances)
    {
      if (volumeLevel)
      {
        add(level, mediso::FrameMethod::CellRasterisation, distance);
      }
    }
    if (level < FullLevel && this->InteractiveTriangleLevels)
    {
      add(level, mediso::FrameMethod::Triangles, 1.0f);
    }
  }
  std::size_t chosen = impl.Model.Choose(candidates, budget);
  // None predicted within the budget: the one predicted fastest. The list's
  // last, level 0's triangles, is the coarsest but not always the cheapest:
  // translucent triangles are sorted on the CPU every frame, where level 0's
  // GPU frame of a large volume costs little more than its few primitives.
  // On the drawing, as Choose(): a level's one-off work is paid once.
  if (impl.Model.PredictDrawing(candidates[chosen].Work) > budget)
  {
    for (std::size_t i = 0; i < candidates.size(); ++i)
    {
      if (impl.Model.PredictDrawing(candidates[i].Work) <
        impl.Model.PredictDrawing(candidates[chosen].Work))
      {
        chosen = i;
      }
    }
  }
  return candidates[chosen];
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LastRenderPath: " << this->GetLastRenderPathAsString() << "\n";
  os << indent << "FallbackReason: " << this->FallbackReason << "\n";
  os << indent << "ForceCPUFallback: " << this->ForceCPUFallback << "\n";
  os << indent << "NumberOfPrimitives: " << this->GPUStats.Primitives << "\n";
  os << indent << "NumberOfPyramidBuilds: " << this->GPUStats.PyramidBuilds << "\n";
  os << indent << "NumberOfVolumeUploads: " << this->GPUStats.VolumeUploads << "\n";
  os << indent << "GPUMemoryBytes: " << this->GetGPUMemoryBytes() << "\n";
  os << indent << "InteractiveAdjust: " << this->InteractiveAdjust << "\n";
  os << indent << "InteractiveFrameBudget: " << this->InteractiveFrameBudget << "\n";
  os << indent << "GPUMemoryBudget: " << this->GPUMemoryBudget << " MB\n";
  os << indent << "LastBrickPoolSlots: " << this->GPUStats.PoolSlots << "\n";
  os << indent << "LastBrickPoolReason: " << this->LastBrickPoolReason << "\n";
  os << indent << "InteractiveTriangleLevels: " << this->InteractiveTriangleLevels << "\n";
  os << indent << "InteractiveVolumeLevels: " << this->InteractiveVolumeLevels << "\n";
  os << indent << "LastInteractive: " << this->LastInteractive << "\n";
  os << indent << "LastSampleDistance: " << this->LastSampleDistance << "\n";
  os << indent << "LastLevel: " << this->LastLevel << "\n";
  os << indent << "LastPredictedSeconds: " << this->LastPredictedSeconds << "\n";
  os << indent << "LastPredictedOneOffSeconds: " << this->LastPredictedOneOffSeconds << "\n";
  os << indent << "LastOneOffSeconds: " << this->LastOneOffSeconds << "\n";
  os << indent << "LastMeasuredSeconds: " << this->LastMeasuredSeconds << "\n";
  os << indent << "LastBudgetSeconds: " << this->LastBudgetSeconds << "\n";
  os << indent << "WindowFixedSeconds: " << this->GetWindowFixedSeconds() << "\n";
}
