// SPDX-License-Identifier: BSD-3-Clause
#include "BlockLODSurfaces.h"

#include <algorithm>
#include <sstream>

namespace mediso
{

std::string FormatIsovalue(double isovalue)
{
  std::ostringstream text;
  text << isovalue;
  return text.str();
}

//------------------------------------------------------------------------------
void SharedCostModel::Record(int level, double cubes, double triangles, double seconds)
{
  std::lock_guard<std::mutex> lock(this->Mutex);
  this->Model.Record(level, cubes, triangles, seconds);
}

double SharedCostModel::Predict(int level, const SurfaceCounts& counts) const
{
  std::lock_guard<std::mutex> lock(this->Mutex);
  return this->Model.Predict(level, counts);
}

int SharedCostModel::GetNumberOfSamples() const
{
  std::lock_guard<std::mutex> lock(this->Mutex);
  return this->Model.GetNumberOfSamples();
}

//------------------------------------------------------------------------------
BlockLODSurfacesBase::BlockLODSurfacesBase(TriangleCaseTable cases, ParallelFor parallel,
  std::shared_ptr<SharedCostModel> costs, const SurfaceLayout& layout)
  : Volume(cases, std::move(parallel))
  , Estimator(Volume)
  , Costs(costs ? std::move(costs) : std::make_shared<SharedCostModel>())
  , Layout(layout)
{
}

BlockLODSurfacesBase::~BlockLODSurfacesBase() = default;

bool BlockLODSurfacesBase::SetVolume(const VolumeDescription& description)
{
  return this->Adopted(this->Volume.SetVolume(description));
}

bool BlockLODSurfacesBase::Adopted(bool adopted)
{
  if (adopted)
  {
    this->Estimator.Reset();
    this->ClearCache();
    this->Plans.clear(); // sized for the old volume
  }
  // Not adopted (the same volume): an update now does no one-time work for it
  // (a host may adopt a volume and then make nothing, e.g. for a bad isovalue).
  this->PendingOneTimeWork = adopted;
  return adopted;
}

bool BlockLODSurfacesBase::SetStreamingVolume(const VolumeDescription& description)
{
  return this->Adopted(this->Volume.SetStreamingVolume(description));
}

void BlockLODSurfacesBase::BeginStreaming()
{
  this->Volume.BeginStreaming();
  this->Estimator.Reset();
  this->Plans.clear();
}

std::int64_t BlockLODSurfacesBase::RegionArrived(const int first[3], const int last[3])
{
  const std::int64_t completed = this->Volume.RegionArrived(first, last);
  this->Estimator.Reset();
  this->Plans.clear();
  return completed;
}

void BlockLODSurfacesBase::SetAheadIsovalues(const std::vector<double>& isovalues)
{
  std::vector<double> values;
  for (double v : isovalues)
  {
    if (!this->IsCached(SurfaceKey{ v, NumberOfLevels - 1 }))
    {
      values.push_back(v);
    }
  }
  this->Volume.SetAheadIsovalues(values);
}

void BlockLODSurfacesBase::EndStreaming()
{
  this->Volume.EndStreaming();
  this->Estimator.Reset();
  this->Plans.clear();
}

void BlockLODSurfacesBase::SetLayout(const SurfaceLayout& layout)
{
  if (layout != this->Layout)
  {
    this->ClearCache();
    this->Layout = layout;
  }
}

SurfaceEstimate BlockLODSurfacesBase::Estimate(double isovalue, int level)
{
  return this->Estimator.Estimate(isovalue, level);
}

double BlockLODSurfacesBase::EstimateBytes(double isovalue, int level)
{
  const SurfaceEstimate e = this->Estimator.Estimate(isovalue, level);
  return e.Method == EstimateMethod::None ? -1.0 : this->Layout.Bytes(e.Counts);
}

double BlockLODSurfacesBase::EstimateSeconds(double isovalue, int level, EstimateMethod* method)
{
  if (this->Volume.IsValid() && this->IsCached(SurfaceKey{ isovalue, level }))
  {
    if (method)
    {
      *method = EstimateMethod::Exact;
    }
    return 0.0; // served from the cache
  }
  const SurfaceEstimate e = this->Estimator.Estimate(isovalue, level);
  if (method)
  {
    *method = e.Method;
  }
  return e.Method == EstimateMethod::None ? -1.0 : this->Costs->Predict(level, e.Counts);
}

bool BlockLODSurfacesBase::RecordCost(const SurfacesUpdate& update, double seconds)
{
  if (update.Status != SurfacesUpdate::Outcome::Done || update.Extracted.Cubes <= 0 ||
    update.OneTimeWork)
  {
    return false;
  }
  this->Costs->Record(update.Level, update.Extracted.Cubes, update.Extracted.Triangles, seconds);
  return true;
}

//------------------------------------------------------------------------------
void BlockLODSurfacesBase::Begin(SurfacesUpdate& update)
{
  update.OneTimeWork = this->PendingOneTimeWork;
  this->PendingOneTimeWork = false;
  this->CoarseCopiesAtBegin = this->Volume.GetNumberOfCoarseCopies();
  this->AllowanceRead = false;
  this->Allocated = 0;
}

void BlockLODSurfacesBase::End(SurfacesUpdate& update)
{
  update.OneTimeWork =
    update.OneTimeWork || this->Volume.GetNumberOfCoarseCopies() != this->CoarseCopiesAtBegin;
}

//------------------------------------------------------------------------------
int BlockLODSurfacesBase::ChooseLevel(
  const std::vector<double>& values, const LevelChoice& choice, SurfacesUpdate& update)
{
  if (choice.Level != LevelChoice::Auto)
  {
    return choice.Level;
  }
  update.ChoiceBytes = choice.BudgetBytes;
  double level0Bytes = 0;
  const int level =
    this->Estimator.ChooseLevel(values, choice.BudgetBytes, this->Layout, level0Bytes);
  // The budget is the host's wish; the process may hold less. Reading the
  // allowance costs a few file reads: only for a choice that allocates much.
  double chosenBytes = level0Bytes;
  if (level >= 0)
  {
    chosenBytes = 0;
    for (double v : values)
    {
      chosenBytes += this->Layout.Bytes(this->Estimator.Estimate(v, level).Counts);
    }
  }
  int within = level;
  if (chosenBytes >= LargeAllocationBytes)
  {
    update.Allowance = ProcessMemoryAllowance();
    const double allowed = static_cast<double>(update.Allowance.Bytes);
    if (allowed < choice.BudgetBytes)
    {
      update.ChoiceBytes = allowed;
      within = this->Estimator.ChooseLevel(values, allowed, this->Layout, level0Bytes);
      if (within != level)
      {
        update.LimitedByProcess = true;
        update.BudgetLevel = level;
      }
    }
  }
  if (within >= 0)
  {
    return within;
  }
  update.Level0Bytes = level0Bytes;
  if (choice.BudgetBinds)
  {
    update.Status = SurfacesUpdate::Outcome::NothingFits;
    return -1;
  }
  update.OverBudget = true;
  return 0;
}

//------------------------------------------------------------------------------
bool BlockLODSurfacesBase::PlanLevel(const std::vector<double>& values, const LevelChoice& choice,
  int& level, const UpdateHooks& hooks, SurfacesUpdate& update)
{
  const bool binding = choice.Level == LevelChoice::Auto && choice.BudgetBinds;
  for (;;)
  {
    this->Plans.resize(values.size());
    double bytes = 0;
    for (std::size_t i = 0; i < values.size(); ++i)
    {
      const double v = values[i];
      const SurfaceKey key{ v, level };
      if (this->IsCached(key))
      {
        bytes += this->CachedBytes(key);
        continue;
      }
      const std::string what =
        "planning level " + std::to_string(level) + " of isovalue " + FormatIsovalue(v);
      if (!this->Fits(this->Volume.PlanBytes(v, level), what, update))
      {
        return false;
      }
      ExtractionPlan& plan = this->Plans[i];
      try
      {
        if (!this->Volume.Plan(v, level, plan, hooks.PollAbort))
        {
          update.Status = SurfacesUpdate::Outcome::Aborted;
          return false;
        }
      }
      catch (const std::bad_alloc&)
      {
        plan = ExtractionPlan(); // what it holds is incomplete: give it back
        this->RanOut(what, update);
        return false;
      }
      if (this->Stopped(hooks, update))
      {
        return false;
      }
      const SurfaceCounts exact = BlockLODVolume::CountsOf(plan);
      this->Estimator.RecordExact(v, level, exact);
      bytes += this->Layout.Bytes(exact);
    }
    if (!binding || bytes <= update.ChoiceBytes)
    {
      return true;
    }
    if (level == 0)
    {
      update.Status = SurfacesUpdate::Outcome::NothingFits;
      update.Level0Bytes = bytes;
      update.Level0Planned = true;
      return false;
    }
    update.Dropped.emplace_back(level, bytes);
    --level;
  }
}

//------------------------------------------------------------------------------
bool BlockLODSurfacesBase::Fits(double bytes, const std::string& what, SurfacesUpdate& update)
{
  if (!this->AllowanceRead)
  {
    if (bytes < LargeAllocationBytes)
    {
      return true;
    }
    this->UpdateAllowance = ProcessMemoryAllowance();
    this->AllowanceRead = true;
  }
  MemoryAllowance left = this->UpdateAllowance;
  if (left.Bounded())
  {
    const double rest = static_cast<double>(left.Bytes) - this->Allocated;
    left.Bytes = rest > 0 ? static_cast<std::uint64_t>(rest) : 0;
  }
  std::string message;
  if (!FitsInAllowance(left, static_cast<std::uint64_t>(bytes), what.c_str(), message))
  {
    update.Status = SurfacesUpdate::Outcome::OutOfMemory;
    update.Allowance = left;
    update.Message = message;
    return false;
  }
  this->Allocated += bytes;
  return true;
}

void BlockLODSurfacesBase::RanOut(const std::string& what, SurfacesUpdate& update)
{
  update.Status = SurfacesUpdate::Outcome::OutOfMemory;
  update.Allowance = ProcessMemoryAllowance();
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(1);
  text << what << " ran out of memory (";
  if (update.Allowance.Bounded())
  {
    text << "the process may still allocate " << static_cast<double>(update.Allowance.Bytes) / 1.0e6
         << " MB: " << update.Allowance.Limit << ")";
  }
  else
  {
    text << "no known limit was reached)";
  }
  update.Message = text.str();
}

bool BlockLODSurfacesBase::Stopped(const UpdateHooks& hooks, SurfacesUpdate& update)
{
  if (hooks.CheckAbort && hooks.CheckAbort())
  {
    update.Status = SurfacesUpdate::Outcome::Aborted;
    return true;
  }
  return false;
}

} // namespace mediso
