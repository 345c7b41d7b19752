// SPDX-License-Identifier: BSD-3-Clause
#include "vtkBlockLODSurfaceRepresentation.h"

#include "FrameTimeModel.h"
#include "vtkBlockLODContour.h"
#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkCommunicator.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkMultiProcessController.h"
#include "vtkObjectFactory.h"
#include "vtkPVRenderView.h"
#include "vtkPVView.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <map>
#include <mutex>
#include <vector>

vtkStandardNewMacro(vtkBlockLODSurfaceRepresentation);

namespace
{
constexpr int Levels = 4;

// The frames of this process, for every Block LOD display in it: the model
// describes the renderer and the machine, not one display. A frame is
// observed once, with the triangles of every Block LOD display it drew
// together, and a display's candidate level is predicted with the other
// displays' last triangles added (what the frame will draw besides it).
struct ProcessFrames
{
  struct Frame
  {
    double Triangles = 0.0;
    double Uploaded = 0.0; // the triangles of data new to its display (their upload)
    bool Translucent = false;
    double Start = 0.0;         // the render window's StartEvent
    double RendererStart = 0.0; // the view's renderer's StartEvent
    double RendererSeconds = -1.0;
    // Translucent displays of the frame that ask to blend it in one pass, or
    // to peel it (then it is peeled, as the still frame).
    bool AskBlend = false;
    bool AskPeel = false;
    // The view's depth peeling was switched off for this frame (on again at
    // the renderer's end).
    bool Blended = false;
    // The frame drew its translucent geometry in one blended pass (switched
    // off above, or a view that does not peel): a kind of frame of its own
    // for the model, dearer than an opaque one.
    bool OnePass = false;
    bool Started = false;
  };
  std::mutex Mutex;
  // Fitted to the view's renderer's time of each frame: the triangles' cost.
  mediso::FrameTimeModel Model;
  // Per renderer, the rest of its window's render (the other renderers, the
  // blit and the swap), a fixed cost per frame whatever the level: added to
  // the model's prediction, so that the prediction is the frame a user waits
  // for without that cost blurring the model's split of the triangles' cost.
  std::map<const void*, double> Overhead;
  // Per renderer: the frame being drawn, and each display's last triangles.
  std::map<const void*, Frame> Pending;
  std::map<const void*, std::map<const void*, double>> Drawn;
  // Per renderer, each display's triangles at each level for its current
  // data (-1: unknown), known from its first frame of the data.
  std::map<const void*, std::map<const void*, std::array<double, Levels>>> AtLevel;
  // Per renderer, whether each display drew translucent last: a frame with
  // one translucent display is a translucent frame for all of them.
  std::map<const void*, std::map<const void*, bool>> Translucent;

  bool OthersTranslucent(const void* renderer, const void* display)
  {
    const auto& translucent = this->Translucent[renderer];
    for (const auto& entry : this->Drawn[renderer])
    {
      const auto known = translucent.find(entry.first);
      if (entry.first != display && known != translucent.end() && known->second)
      {
        return true;
      }
    }
    return false;
  }

  // The triangles the other displays of a renderer draw in a frame in which
  // `display` draws `level`: the same level for those that have one (their
  // candidates are the same sums, so they choose it too, and the prediction
  // is the frame's), else what they drew last.
  double OthersAt(const void* renderer, const void* display, int level)
  {
    double sum = 0.0;
    const auto& levels = this->AtLevel[renderer];
    for (const auto& entry : this->Drawn[renderer])
    {
      if (entry.first == display)
      {
        continue;
      }
      const auto known = levels.find(entry.first);
      const double at = known == levels.end() ? -1.0 : known->second[level];
      sum += at >= 0.0 ? at : entry.second;
    }
    return sum;
  }
};
ProcessFrames& Frames()
{
  static ProcessFrames frames;
  return frames;
}

double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The first vtkPolyData of a delivered piece (a vtkPolyData, or a composite
// dataset around one).
vtkPolyData* FirstSurface(vtkDataObject* data)
{
  if (auto* surface = vtkPolyData::SafeDownCast(data))
  {
    return surface;
  }
  if (auto* composite = vtkCompositeDataSet::SafeDownCast(data))
  {
    vtkSmartPointer<vtkCompositeDataIterator> it;
    it.TakeReference(composite->NewIterator());
    for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
    {
      if (auto* surface = vtkPolyData::SafeDownCast(it->GetCurrentDataObject()))
      {
        return surface;
      }
    }
  }
  return nullptr;
}

// The field that marks LOD geometry made here, with its level (a decimated
// copy may carry the output's own "BlockLODLevel" along).
const char* const LevelMark = "BlockLODInteractiveLevel";

// Triangles and level of a delivered LOD piece (-1 when it is not marked as
// a Block LOD level: the decimated copy).
void DescribeLOD(vtkDataObject* data, int& level, double& triangles)
{
  level = -1;
  triangles = 0.0;
  if (auto* composite = vtkCompositeDataSet::SafeDownCast(data))
  {
    vtkSmartPointer<vtkCompositeDataIterator> it;
    it.TakeReference(composite->NewIterator());
    for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
    {
      if (auto* surface = vtkPolyData::SafeDownCast(it->GetCurrentDataObject()))
      {
        triangles += static_cast<double>(surface->GetNumberOfPolys());
      }
    }
  }
  else if (auto* surface = vtkPolyData::SafeDownCast(data))
  {
    triangles = static_cast<double>(surface->GetNumberOfPolys());
  }
  vtkPolyData* first = FirstSurface(data);
  vtkDataArray* field = first ? first->GetFieldData()->GetArray(LevelMark) : nullptr;
  if (field && field->GetNumberOfTuples() == 1)
  {
    level = static_cast<int>(field->GetTuple1(0));
  }
}
}

//------------------------------------------------------------------------------
vtkBlockLODSurfaceRepresentation::vtkBlockLODSurfaceRepresentation() = default;
vtkBlockLODSurfaceRepresentation::~vtkBlockLODSurfaceRepresentation() = default;

//------------------------------------------------------------------------------
void vtkBlockLODSurfaceRepresentation::SetInteractiveLevels(bool use)
{
  if (use != this->InteractiveLevels)
  {
    this->InteractiveLevels = use;
    // The LOD geometry is remade by the next update's REQUEST_UPDATE_LOD.
    this->MarkModified();
  }
}

//------------------------------------------------------------------------------
void vtkBlockLODSurfaceRepresentation::SetInteractiveFrameBudget(double seconds)
{
  seconds = std::max(0.0, seconds);
  if (seconds != this->InteractiveFrameBudget)
  {
    this->InteractiveFrameBudget = seconds;
    this->MarkModified();
  }
}

//------------------------------------------------------------------------------
void vtkBlockLODSurfaceRepresentation::SetInteractiveTriangleBudget(double triangles)
{
  triangles = std::max(0.0, triangles);
  if (triangles != this->InteractiveTriangleBudget)
  {
    this->InteractiveTriangleBudget = triangles;
    this->MarkModified();
  }
}

//------------------------------------------------------------------------------
void vtkBlockLODSurfaceRepresentation::SetInteractiveTranslucency(int mode)
{
  mode = std::min<int>(BLENDED, std::max<int>(PEELED, mode));
  if (mode != this->InteractiveTranslucency)
  {
    this->InteractiveTranslucency = mode;
    // The level is chosen for the frame this mode draws (a peeled frame costs
    // more): chosen again by the next update's REQUEST_UPDATE_LOD.
    this->MarkModified();
  }
}

//------------------------------------------------------------------------------
vtkBlockLODContour* vtkBlockLODSurfaceRepresentation::FindContour()
{
  if (this->GetNumberOfInputPorts() < 1 || this->GetNumberOfInputConnections(0) != 1)
  {
    return nullptr; // the client's copy, in client/server
  }
  // ParaView's own pass-through filters between a source and its displays
  // (vtkPVPostFilter) are skipped; any other filter ends the search.
  vtkAlgorithm* producer = this->GetInputAlgorithm(0, 0);
  while (producer && producer->IsA("vtkPVPostFilter") && producer->GetNumberOfInputPorts() == 1 &&
    producer->GetNumberOfInputConnections(0) == 1)
  {
    producer = producer->GetInputAlgorithm(0, 0);
  }
  auto* contour = vtkBlockLODContour::SafeDownCast(producer);
  if (!contour)
  {
    return nullptr;
  }
  // The filter's output must be the data shown here: shallow copies along
  // the way share its points array.
  auto* shown = vtkPolyData::SafeDownCast(this->GetInputDataObject(0, 0));
  vtkPolyData* made = contour->GetOutput();
  if (!shown || !made || !shown->GetPoints() || !made->GetPoints() ||
    shown->GetPoints()->GetData() != made->GetPoints()->GetData())
  {
    return nullptr;
  }
  return contour;
}

//------------------------------------------------------------------------------
std::array<double, 4> vtkBlockLODSurfaceRepresentation::LevelTriangles(vtkBlockLODContour* contour)
{
  // The shown surface's triangles at its level and above it (a display never
  // draws finer than its output), the estimator's below.
  std::array<double, Levels> triangles;
  triangles.fill(-1.0);
  const int still = contour ? contour->GetChosenLevel() : -1;
  auto* shown = vtkPolyData::SafeDownCast(this->GetInputDataObject(0, 0));
  if (still >= 0 && still < Levels && shown)
  {
    for (int level = still; level < Levels; ++level)
    {
      triangles[level] = static_cast<double>(shown->GetNumberOfPolys());
    }
    for (int level = still - 1; level >= 0; --level)
    {
      triangles[level] = contour->EstimateLevelTriangles(level);
    }
  }
  return triangles;
}

//------------------------------------------------------------------------------
bool vtkBlockLODSurfaceRepresentation::MakeLevelLOD()
{
  this->ChosenInteractiveLevel = -1;
  this->PredictedInteractiveSeconds = 0.0;
  this->LevelSurface->Initialize();
  vtkBlockLODContour* contour = this->FindContour();
  const int still = contour ? contour->GetChosenLevel() : -1;

  // Triangles per level, this process's (unknown: -1), then summed over the
  // processes so that every piece picks the same level. Every data process
  // runs this pass, with or without a piece.
  std::array<double, Levels> triangles = this->LevelTriangles(contour);
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  const bool parallel = controller && controller->GetNumberOfProcesses() > 1;
  if (parallel)
  {
    // Unknown counts are summed as a large negative number, so that a level
    // unknown on any process stays unknown; a process without a Block LOD
    // piece (an empty piece) adds nothing.
    std::array<double, Levels> local, global;
    for (int level = 0; level < Levels; ++level)
    {
      local[level] = !contour ? 0.0 : (triangles[level] < 0 ? -1e300 : triangles[level]);
    }
    controller->AllReduce(local.data(), global.data(), Levels, vtkCommunicator::SUM_OP);
    triangles = global;
  }

  // The finest level, from the output's down, within the triangle budget (when
  // set) and predicted within the frame budget (when set); else the coarsest.
  // Levels stands for none.
  int chosen = Levels;
  std::vector<mediso::FrameTimeModel::Candidate> candidates;
  if (contour && still >= 0 && still < Levels)
  {
    mediso::FrameWork work = this->ViewFrameWork();
    std::array<double, Levels> others;
    others.fill(0.0);
    if (this->ObservedRenderer)
    {
      std::lock_guard<std::mutex> lock(Frames().Mutex);
      for (int level = 0; level < Levels; ++level)
      {
        others[level] = Frames().OthersAt(this->ObservedRenderer.GetPointer(), this, level);
      }
      work.Translucent =
        work.Translucent || Frames().OthersTranslucent(this->ObservedRenderer.GetPointer(), this);
    }
    // A translucent frame blended in one pass is its own kind of frame for
    // the model: no peels, but the blended pass's targets and resolve over
    // the whole view (counted as an opaque frame, it was predicted 30 ms
    // short at level 2 of the head CT, docs/blocklod.md).
    work.Blended = this->BlendsInteractiveFrames() ||
      (this->ObservedRenderer && !this->ObservedRenderer->GetUseDepthPeeling());
    for (int level = still; level >= 0; --level)
    {
      const bool allowed =
        this->InteractiveTriangleBudget <= 0 || triangles[level] <= this->InteractiveTriangleBudget;
      if (triangles[level] >= 0 && (allowed || level == 0))
      {
        mediso::FrameTimeModel::Candidate candidate;
        candidate.Level = level;
        candidate.Work = work;
        candidate.Work.Primitives = static_cast<std::uint64_t>(triangles[level] + others[level]);
        candidates.push_back(candidate);
      }
    }
    if (!candidates.empty())
    {
      std::size_t pick = 0;
      if (this->InteractiveFrameBudget > 0)
      {
        std::lock_guard<std::mutex> lock(Frames().Mutex);
        pick = Frames().Model.Choose(
          candidates, this->InteractiveFrameBudget - this->FrameOverhead());
      }
      chosen = candidates[pick].Level;
    }
  }
  if (parallel)
  {
    // Every piece draws the same level: the coarsest any process chose (each
    // process's frame-time model learnt from its own frames).
    int local = chosen, agreed = Levels;
    controller->AllReduce(&local, &agreed, 1, vtkCommunicator::MIN_OP);
    chosen = agreed;
  }
  if (!contour || chosen >= Levels || chosen > still)
  {
    return false;
  }
  double predicted = 0.0;
  for (const auto& candidate : candidates)
  {
    if (candidate.Level == chosen)
    {
      std::lock_guard<std::mutex> lock(Frames().Mutex);
      predicted = Frames().Model.Predict(candidate.Work) + this->FrameOverhead();
    }
  }
  if (chosen == still)
  {
    // Within the budget already: the shown surface is its own LOD.
    this->LevelSurface->ShallowCopy(this->GetInputDataObject(0, 0));
  }
  else if (!contour->GenerateLevel(chosen, this->LevelSurface))
  {
    return false;
  }
  // Marked in field data of its own (a shallow copy shares the source's).
  vtkNew<vtkFieldData> fields;
  fields->ShallowCopy(this->LevelSurface->GetFieldData());
  vtkNew<vtkIntArray> mark;
  mark->SetName(LevelMark);
  mark->InsertNextValue(chosen);
  fields->AddArray(mark);
  this->LevelSurface->SetFieldData(fields);
  this->ChosenInteractiveLevel = chosen;
  this->PredictedInteractiveSeconds = predicted;
  return true;
}

//------------------------------------------------------------------------------
double* vtkBlockLODSurfaceRepresentation::GetPredictedStillSeconds()
{
  std::fill(this->PredictedStillSeconds, this->PredictedStillSeconds + Levels, -1.0);
  vtkBlockLODContour* contour = this->FindContour();
  if (!contour)
  {
    return this->PredictedStillSeconds;
  }
  const double* triangles = contour->GetCurrentEstimatedTriangles();
  mediso::FrameWork work = this->ViewFrameWork();
  std::lock_guard<std::mutex> lock(Frames().Mutex);
  const void* renderer = this->ObservedRenderer.GetPointer();
  work.Translucent = work.Translucent || (renderer && Frames().OthersTranslucent(renderer, this));
  // A still frame peels when the view does.
  work.Blended = renderer && !this->ObservedRenderer->GetUseDepthPeeling();
  for (int level = 0; level < Levels; ++level)
  {
    if (triangles[level] >= 0.0)
    {
      const double others = renderer ? Frames().OthersAt(renderer, this, level) : 0.0;
      work.Primitives = static_cast<std::uint64_t>(triangles[level] + others);
      this->PredictedStillSeconds[level] = Frames().Model.Predict(work) + this->FrameOverhead();
    }
  }
  return this->PredictedStillSeconds;
}

//------------------------------------------------------------------------------
vtkDataObject* vtkBlockLODSurfaceRepresentation::WrapLikePiece(vtkDataObject* piece)
{
  // The view moves LOD geometry between processes as data of the piece's
  // type (the client's placeholder is an empty piece of that type): the level
  // takes the place of the piece's surface in a copy of its structure.
  auto* composite = vtkCompositeDataSet::SafeDownCast(piece);
  if (!composite)
  {
    return this->LevelSurface;
  }
  this->LevelPiece.TakeReference(composite->NewInstance());
  this->LevelPiece->CopyStructure(composite);
  vtkSmartPointer<vtkCompositeDataIterator> it;
  it.TakeReference(composite->NewIterator());
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
  {
    if (vtkPolyData::SafeDownCast(it->GetCurrentDataObject()))
    {
      this->LevelPiece->SetDataSet(it, this->LevelSurface);
      break;
    }
  }
  return this->LevelPiece;
}

//------------------------------------------------------------------------------
int vtkBlockLODSurfaceRepresentation::ProcessViewRequest(vtkInformationRequestKey* request_type,
  vtkInformation* inInfo,
  vtkInformation* outInfo)
{
  if (request_type == vtkPVView::REQUEST_UPDATE_LOD() && this->InteractiveLevels &&
    !this->SuppressLOD && !inInfo->Has(vtkPVRenderView::USE_OUTLINE_FOR_LOD()))
  {
    // vtkGeometryRepresentation's pass would decimate the data; the surfaces
    // base class adds nothing to this pass, so only the data
    // representation's bookkeeping runs before the level replaces it.
    if (!this->vtkPVDataRepresentation::ProcessViewRequest(request_type, inInfo, outInfo))
    {
      return 0;
    }
    // Run on every data process (a parallel run reduces counts in it).
    const bool made = this->MakeLevelLOD();
    vtkDataObject* piece = vtkPVView::GetPiece(inInfo, this);
    if (made && piece != nullptr)
    {
      vtkPVView::SetPieceLOD(inInfo, this, this->WrapLikePiece(piece));
      return 1;
    }
  }
  else if (request_type == vtkPVView::REQUEST_UPDATE_LOD())
  {
    this->ChosenInteractiveLevel = -1;
  }

  if (!this->Superclass::ProcessViewRequest(request_type, inInfo, outInfo))
  {
    return 0;
  }
  if (request_type == vtkPVView::REQUEST_RENDER())
  {
    vtkDataObject* lod = vtkPVView::GetDeliveredPieceLOD(inInfo, this);
    this->LastRenderUsedLOD =
      !this->SuppressLOD && inInfo->Has(vtkPVRenderView::USE_LOD()) == 1 && lod != nullptr;
    if (lod)
    {
      DescribeLOD(lod, this->InteractiveLevel, this->InteractiveTriangles);
    }
    else
    {
      this->InteractiveLevel = -1;
      this->InteractiveTriangles = 0.0;
    }
    // What the coming frame draws, for the frame-time model: the LOD's
    // triangles or the full data's, and those of them new here (their upload,
    // one-off work the model keeps apart from the drawing).
    vtkDataObject* drawn =
      this->LastRenderUsedLOD ? lod : vtkPVView::GetDeliveredPiece(inInfo, this);
    this->DrawsTranslucent =
      drawn != nullptr && this->GetVisibility() && this->Property->GetOpacity() < 1.0;
    if (drawn && this->GetVisibility() && this->ObservedRenderer)
    {
      int level = -1;
      double triangles = 0.0;
      DescribeLOD(drawn, level, triangles);
      // A display's levels, for the others' choices, once per new data it
      // shows (their triangles in a frame at a level they choose too).
      // The actor keeps the full data's and the LOD's buffers apart (ParaView's
      // LOD actor has a mapper for each): each is new when it changed since
      // it was drawn last.
      vtkMTimeType& drawnTime =
        this->LastRenderUsedLOD ? this->DrawnLODTime : this->DrawnDataTime;
      const bool newData = drawn->GetMTime() != drawnTime;
      std::array<double, Levels> levels;
      levels.fill(-1.0);
      if (newData && !this->LastRenderUsedLOD && this->InteractiveLevels)
      {
        levels = this->LevelTriangles(this->FindContour());
      }
      std::lock_guard<std::mutex> lock(Frames().Mutex);
      ProcessFrames::Frame& frame = Frames().Pending[this->ObservedRenderer.GetPointer()];
      frame.Triangles += triangles;
      frame.Uploaded += newData ? triangles : 0.0;
      frame.Translucent = frame.Translucent || this->Property->GetOpacity() < 1.0;
      if (this->DrawsTranslucent && this->LastRenderUsedLOD)
      {
        // Only interactive frames: a still frame is always the view's.
        (this->InteractiveTranslucency == BLENDED ? frame.AskBlend : frame.AskPeel) = true;
      }
      Frames().Drawn[this->ObservedRenderer.GetPointer()][this] = triangles;
      Frames().Translucent[this->ObservedRenderer.GetPointer()][this] =
        this->Property->GetOpacity() < 1.0;
      if (newData && !this->LastRenderUsedLOD)
      {
        Frames().AtLevel[this->ObservedRenderer.GetPointer()][this] = levels;
      }
      drawnTime = drawn->GetMTime();
    }
  }
  return 1;
}

//------------------------------------------------------------------------------
bool vtkBlockLODSurfaceRepresentation::AddToView(vtkView* view)
{
  if (!this->Superclass::AddToView(view))
  {
    return false;
  }
  if (auto* renderView = vtkPVRenderView::SafeDownCast(view))
  {
    // Frames are timed by the render window, what a user waits for, and by
    // the view's renderer within it: the model learns the renderer's time
    // (the triangles' cost), and the rest of the window's (the other
    // renderers, the blit and the swap; under load most of a coarse level's
    // frame on llvmpipe) is a fixed cost added to its predictions.
    this->ObservedRenderer = renderView->GetRenderer();
    this->ObservedWindow = renderView->GetRenderWindow();
    this->RendererStartObserver = this->ObservedRenderer->AddObserver(
      vtkCommand::StartEvent, this, &vtkBlockLODSurfaceRepresentation::OnRendererStart);
    this->RendererEndObserver = this->ObservedRenderer->AddObserver(
      vtkCommand::EndEvent, this, &vtkBlockLODSurfaceRepresentation::OnRendererEnd);
    if (this->ObservedWindow)
    {
      this->StartObserver = this->ObservedWindow->AddObserver(
        vtkCommand::StartEvent, this, &vtkBlockLODSurfaceRepresentation::OnRenderStart);
      this->EndObserver = this->ObservedWindow->AddObserver(
        vtkCommand::EndEvent, this, &vtkBlockLODSurfaceRepresentation::OnRenderEnd);
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkBlockLODSurfaceRepresentation::RemoveFromView(vtkView* view)
{
  if (this->ObservedRenderer)
  {
    {
      std::lock_guard<std::mutex> lock(Frames().Mutex);
      Frames().Drawn[this->ObservedRenderer.GetPointer()].erase(this);
      Frames().AtLevel[this->ObservedRenderer.GetPointer()].erase(this);
      Frames().Translucent[this->ObservedRenderer.GetPointer()].erase(this);
      if (Frames().Drawn[this->ObservedRenderer.GetPointer()].empty())
      {
        Frames().Drawn.erase(this->ObservedRenderer.GetPointer());
        Frames().AtLevel.erase(this->ObservedRenderer.GetPointer());
        Frames().Translucent.erase(this->ObservedRenderer.GetPointer());
        Frames().Overhead.erase(this->ObservedRenderer.GetPointer());
        Frames().Pending.erase(this->ObservedRenderer.GetPointer());
      }
    }
    if (this->ObservedWindow)
    {
      this->ObservedWindow->RemoveObserver(this->StartObserver);
      this->ObservedWindow->RemoveObserver(this->EndObserver);
    }
    this->ObservedRenderer->RemoveObserver(this->RendererStartObserver);
    this->ObservedRenderer->RemoveObserver(this->RendererEndObserver);
    this->ObservedWindow = nullptr;
    this->ObservedRenderer = nullptr;
  }
  return this->Superclass::RemoveFromView(view);
}

//------------------------------------------------------------------------------
mediso::FrameWork vtkBlockLODSurfaceRepresentation::ViewFrameWork()
{
  mediso::FrameWork work;
  work.Method = mediso::FrameMethod::Triangles;
  work.Translucent = this->Property->GetOpacity() < 1.0;
  if (auto* view = vtkPVRenderView::SafeDownCast(this->GetView()))
  {
    const int* size = view->GetSize();
    work.Pixels = static_cast<std::uint64_t>(std::max(0, size[0])) *
      static_cast<std::uint64_t>(std::max(0, size[1]));
  }
  return work;
}

//------------------------------------------------------------------------------
void vtkBlockLODSurfaceRepresentation::OnRenderStart()
{
  // Every Block LOD display observes the render window; the first one to
  // hear of a prepared frame starts its clock.
  std::lock_guard<std::mutex> lock(Frames().Mutex);
  if (!this->ObservedRenderer)
  {
    return;
  }
  auto frame = Frames().Pending.find(this->ObservedRenderer.GetPointer());
  if (frame != Frames().Pending.end() && frame->second.Start == 0.0)
  {
    frame->second.Start = Now();
  }
}

//------------------------------------------------------------------------------
void vtkBlockLODSurfaceRepresentation::OnRenderEnd()
{
  // The first display to hear of the frame's end records it, once.
  const double end = Now();
  std::lock_guard<std::mutex> lock(Frames().Mutex);
  if (!this->ObservedRenderer)
  {
    return;
  }
  auto frame = Frames().Pending.find(this->ObservedRenderer.GetPointer());
  if (frame == Frames().Pending.end())
  {
    return;
  }
  const ProcessFrames::Frame drawn = frame->second;
  Frames().Pending.erase(frame);
  if (drawn.Start == 0.0 || drawn.RendererSeconds < 0.0)
  {
    return;
  }
  // The window's fixed cost, from every frame (an upload is the renderer's
  // work): half the last frame's, half the frames' before.
  const double overhead = std::max(0.0, end - drawn.Start - drawn.RendererSeconds);
  auto known = Frames().Overhead.find(this->ObservedRenderer.GetPointer());
  if (known == Frames().Overhead.end())
  {
    Frames().Overhead[this->ObservedRenderer.GetPointer()] = overhead;
  }
  else
  {
    known->second = 0.5 * (known->second + overhead);
  }
  if (drawn.Triangles <= 0)
  {
    return;
  }
  mediso::FrameWork work;
  work.Method = mediso::FrameMethod::Triangles;
  work.Primitives = static_cast<std::uint64_t>(drawn.Triangles);
  work.BuildElements = static_cast<std::uint64_t>(drawn.Uploaded);
  const int* size = this->ObservedRenderer->GetSize();
  work.Pixels = static_cast<std::uint64_t>(std::max(0, size[0])) *
    static_cast<std::uint64_t>(std::max(0, size[1]));
  work.Translucent = drawn.Translucent;
  work.Blended = drawn.OnePass;
  Frames().Model.Observe(work, drawn.RendererSeconds);
}

//------------------------------------------------------------------------------
void vtkBlockLODSurfaceRepresentation::OnRendererStart()
{
  std::lock_guard<std::mutex> lock(Frames().Mutex);
  if (!this->ObservedRenderer)
  {
    return;
  }
  auto frame = Frames().Pending.find(this->ObservedRenderer.GetPointer());
  if (frame != Frames().Pending.end() && !frame->second.Started)
  {
    // The first display to hear of the frame switches the view's depth
    // peeling off for it, when the frame's translucent displays ask for one
    // blended pass; the renderer reads the setting in this render only.
    frame->second.Started = true;
    if (frame->second.AskBlend && !frame->second.AskPeel &&
      this->ObservedRenderer->GetUseDepthPeeling())
    {
      this->ObservedRenderer->SetUseDepthPeeling(0);
      frame->second.Blended = true;
    }
    frame->second.OnePass = !this->ObservedRenderer->GetUseDepthPeeling();
  }
  // Every display says how it is drawn, after the switch above.
  if (!this->DrawsTranslucent)
  {
    this->LastRenderTranslucency = OPAQUE_SURFACE;
  }
  else
  {
    this->LastRenderTranslucency =
      this->ObservedRenderer->GetUseDepthPeeling() ? PEELED_SURFACE : BLENDED_SURFACE;
  }
  if (frame != Frames().Pending.end() && frame->second.RendererStart == 0.0)
  {
    frame->second.RendererStart = Now();
  }
}

//------------------------------------------------------------------------------
void vtkBlockLODSurfaceRepresentation::OnRendererEnd()
{
  const double end = Now();
  std::lock_guard<std::mutex> lock(Frames().Mutex);
  if (!this->ObservedRenderer)
  {
    return;
  }
  auto frame = Frames().Pending.find(this->ObservedRenderer.GetPointer());
  if (frame != Frames().Pending.end() && frame->second.RendererStart != 0.0 &&
    frame->second.RendererSeconds < 0.0)
  {
    frame->second.RendererSeconds = end - frame->second.RendererStart;
  }
  if (frame != Frames().Pending.end() && frame->second.Blended &&
    !this->ObservedRenderer->GetUseDepthPeeling())
  {
    // The view's setting back, before anything else renders.
    this->ObservedRenderer->SetUseDepthPeeling(1);
  }
}

//------------------------------------------------------------------------------
bool vtkBlockLODSurfaceRepresentation::BlendsInteractiveFrames()
{
  return this->InteractiveTranslucency == BLENDED && this->ObservedRenderer &&
    this->ObservedRenderer->GetUseDepthPeeling();
}

//------------------------------------------------------------------------------
double vtkBlockLODSurfaceRepresentation::FrameOverhead()
{
  // Called with Frames().Mutex held.
  if (!this->ObservedRenderer)
  {
    return 0.0;
  }
  const auto known = Frames().Overhead.find(this->ObservedRenderer.GetPointer());
  return known == Frames().Overhead.end() ? 0.0 : known->second;
}

//------------------------------------------------------------------------------
void vtkBlockLODSurfaceRepresentation::SetVisibility(bool visible)
{
  if (!visible && this->ObservedRenderer)
  {
    std::lock_guard<std::mutex> lock(Frames().Mutex);
    Frames().Drawn[this->ObservedRenderer.GetPointer()].erase(this);
  }
  if (!visible)
  {
    // A hidden display gets no REQUEST_RENDER: its frames draw nothing of it.
    this->DrawsTranslucent = false;
  }
  this->Superclass::SetVisibility(visible);
}

//------------------------------------------------------------------------------
void vtkBlockLODSurfaceRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "InteractiveLevels: " << this->InteractiveLevels << "\n";
  os << indent << "InteractiveFrameBudget: " << this->InteractiveFrameBudget << " s\n";
  os << indent << "PredictedInteractiveSeconds: " << this->PredictedInteractiveSeconds << "\n";
  os << indent << "InteractiveTriangleBudget: " << this->InteractiveTriangleBudget << "\n";
  os << indent << "InteractiveTranslucency: "
     << (this->InteractiveTranslucency == BLENDED ? "BLENDED" : "PEELED") << "\n";
  os << indent << "LastRenderTranslucency: " << this->LastRenderTranslucency << "\n";
  os << indent << "InteractiveLevel: " << this->InteractiveLevel << "\n";
  os << indent << "InteractiveTriangles: " << this->InteractiveTriangles << "\n";
  os << indent << "LastRenderUsedLOD: " << this->LastRenderUsedLOD << "\n";
  os << indent << "ChosenInteractiveLevel: " << this->ChosenInteractiveLevel << "\n";
}
