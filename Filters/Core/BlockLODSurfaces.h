// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file BlockLODSurfaces.h
 * @brief The CPU isosurfaces of one volume, as a host asks for them (no VTK):
 * the block LOD volume, its estimator, the surface cache and a cost model
 * behind one call per update.
 *
 * Every CPU host of the block LOD method (the VTK filter vtkBlockLODContour,
 * the web page's WebAssembly module) runs the same steps per update; this
 * unit runs them, and the host only converts its input and output:
 *
 * -# **Volume.** SetVolume() adopts a VolumeDescription; a new one (any field
 *    changed) forgets counts, plans and cached surfaces, and computes the
 *    block ranges (BlockLODVolume.h).
 * -# **Choose.** A fixed level, or LevelChoice::Auto: the highest level whose
 *    estimated output, all isovalues together, fits the byte budget
 *    (BlockLODEstimator.h). The budget is not trusted beyond what the process
 *    may allocate (ProcessMemory.h): when the process's allowance is smaller,
 *    the choice is made within it and the update says so.
 * -# **Plan.** Pass 1 for every isovalue not cached at that level: exact
 *    counts before any output is allocated, recorded in the estimator. With a
 *    binding budget, a level whose exact bytes do not fit is dropped for the
 *    next coarser one (the estimate was low); below level 0 nothing fits.
 * -# **Generate.** Pass 2 for each planned isovalue into the host's own
 *    surface (SurfaceMaker: a vtkPolyData's arrays, or plain vectors), then
 *    cached per (isovalue, level) within the cache limit; a cached pair costs
 *    no extraction. While a volume streams, a level-3 surface extracted
 *    ahead (SetAheadIsovalues; BlockLODVolume.h) is taken instead, when the
 *    host can adopt its arrays (SurfaceMaker::Adopt).
 * -# **Record.** RecordCost() feeds the update's seconds, as the host timed
 *    them, to the cost model when the update extracted something and did no
 *    one-time work (block ranges, coarse copies).
 *
 * Memory: the plan and every surface are checked against the process's
 * allowance before they are allocated (the allowance read once per update,
 * at its first allocation of at least LargeAllocationBytes, and counted off
 * after that), and a `std::bad_alloc` in planning or generation ends the
 * update with the same kind of message instead of escaping: the update's
 * Status is OutOfMemory and its Message says what did not fit.
 *
 * The cost model is passed in (SharedCostModel): it describes the machine,
 * not a volume, so a host may share one among all its units. The surface
 * type is the host's: it should be cheap to copy (a smart pointer), as the
 * cache and the update's list both hold it.
 */
#ifndef MedicalIsosurfaces_BlockLODSurfaces_h
#define MedicalIsosurfaces_BlockLODSurfaces_h

#include "BlockLODCache.h"
#include "BlockLODEstimator.h"
#include "BlockLODVolume.h"
#include "ProcessMemory.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <utility>
#include <vector>

namespace mediso
{

/// An isovalue as the unit's messages print it (as a C++ stream does by default).
std::string FormatIsovalue(double isovalue);

/// A CostModel that several units (and threads) learn into and predict from.
class SharedCostModel
{
public:
  void Record(int level, double cubes, double triangles, double seconds);
  double Predict(int level, const SurfaceCounts& counts) const;
  int GetNumberOfSamples() const;

private:
  mutable std::mutex Mutex;
  CostModel Model;
};

/// How an update's level is chosen.
struct LevelChoice
{
  static constexpr int Auto = -1;
  /// 0..3, or Auto: the highest level whose estimate fits BudgetBytes.
  int Level = NumberOfLevels - 1;
  /// Auto: the bytes all isovalues' surfaces together may take.
  double BudgetBytes = 0;
  /// Auto: true when the budget binds the exact output too (a level whose
  /// plan exceeds it is dropped; nothing is made when level 0 exceeds it);
  /// false when it only guides the choice (level 0 when nothing fits, and
  /// the update says so).
  bool BudgetBinds = true;
};

/// What an update did.
struct SurfacesUpdate
{
  enum class Outcome
  {
    Done,        ///< The surfaces of Level are in GetSurfaces().
    NothingFits, ///< Auto with a binding budget: not even level 0 fits.
    OutOfMemory, ///< The process could not hold a plan or a surface (Message).
    Aborted      ///< The host's abort stopped it.
  };
  Outcome Status = Outcome::Done;
  int Level = -1; ///< The level made (-1 when nothing was).

  /// Auto: the bytes the choice fitted (the budget, or the process's
  /// allowance when that is smaller), and that allowance.
  double ChoiceBytes = 0;
  MemoryAllowance Allowance;
  /// Auto: the process's allowance, not the budget, bounded the choice: it
  /// gave a lower level than the budget alone (BudgetLevel), or none.
  bool LimitedByProcess = false;
  int BudgetLevel = -1;
  /// Levels planned over ChoiceBytes and dropped, with their exact bytes.
  std::vector<std::pair<int, double>> Dropped;
  /// NothingFits, or Done over a guiding budget: level 0's bytes, estimated
  /// or (Level0Planned) exact.
  double Level0Bytes = 0;
  bool Level0Planned = false;
  bool OverBudget = false; ///< Done at level 0 though it exceeds a guiding budget.

  std::string Message; ///< OutOfMemory: what did not fit, and what binds.

  int Extractions = 0;      ///< Surfaces extracted.
  int CacheHits = 0;        ///< Surfaces served from the cache (those taken ahead included).
  int TakenAhead = 0;       ///< Surfaces extracted ahead while streaming, taken.
  SurfaceCounts Extracted;  ///< Cubes and triangles of the extracted surfaces.
  bool OneTimeWork = false; ///< Block ranges or a coarse copy were made for it.
};

/// Where pass 2 writes one surface: the host fills one of the two (32- or
/// 64-bit connectivity) and says which.
struct SurfaceTarget
{
  SurfaceBuffers<std::int32_t> Narrow;
  SurfaceBuffers<std::int64_t> Wide;
  bool UseWide = false;
};

/// How a host makes its surfaces.
template<typename Surface>
struct SurfaceMaker
{
  /// A new surface of `points` and `triangles` for `key`, with the buffers
  /// pass 2 writes (Ranges is set by the unit); false when it could not be
  /// allocated.
  std::function<bool(const SurfaceKey& key, std::int64_t points, std::int64_t triangles,
    Surface& surface, SurfaceTarget& target)>
    Allocate;
  /// Optional: called after pass 2 with the ranges it wrote.
  std::function<void(const SurfaceKey& key, Surface& surface, const SurfaceRanges& written)> Finish;
  /// Optional: the bytes the cache counts for a surface (default: the
  /// layout's bytes of its counts).
  std::function<double(const Surface& surface)> Bytes;
  /// Optional (used only without Bytes): a surface the cache drops to make
  /// room for the next one, offered just before that one is allocated, so
  /// that Allocate may reuse its memory (pages already mapped: no fresh page
  /// faults) instead of the process freeing it and faulting new pages in. The
  /// host may move the surface out; what it leaves is destroyed when the
  /// update's surfaces are made. With it the cache evicts before each new
  /// surface instead of after all of them: the same pairs go, earlier.
  std::function<void(Surface& evicted)> Recycle;
  /// Optional: a new surface for `key` holding the arrays of a surface
  /// extracted ahead (streaming), which the host may move into it; false
  /// when it cannot. Without it the surfaces made ahead are not taken.
  std::function<bool(const SurfaceKey& key, SurfaceArrays& arrays, Surface& surface)> Adopt;
};

/// Checks an update's hosts may give.
struct UpdateHooks
{
  /// Polled between blocks of a pass, from any thread; true stops the update.
  std::function<bool()> PollAbort;
  /// Called between steps on the updating thread; true stops the update.
  std::function<bool()> CheckAbort;
  /// Called once the level is planned, before any surface is made.
  std::function<void(int level)> Planned;
};

/// The part of the unit that does not depend on the host's surface type.
class BlockLODSurfacesBase
{
public:
  /// Allocations below this size do not read the process's allowance (a
  /// failure there is caught as std::bad_alloc).
  static constexpr double LargeAllocationBytes = 1.0e6;

  /// `costs` null: a model of the unit's own. `layout`: see SetLayout().
  BlockLODSurfacesBase(TriangleCaseTable cases, ParallelFor parallel,
    std::shared_ptr<SharedCostModel> costs, const SurfaceLayout& layout = SurfaceLayout());
  virtual ~BlockLODSurfacesBase();
  BlockLODSurfacesBase(const BlockLODSurfacesBase&) = delete;
  BlockLODSurfacesBase& operator=(const BlockLODSurfacesBase&) = delete;

  /// Adopts a volume; true when it is new (counts, plans and surfaces of the
  /// old one forgotten, block ranges computed).
  bool SetVolume(const VolumeDescription& description);
  /// Adopts a volume whose values are still to arrive, streaming from the
  /// start (BlockLODVolume::SetStreamingVolume: no block ranges read from the
  /// empty buffer); otherwise as SetVolume() then BeginStreaming().
  bool SetStreamingVolume(const VolumeDescription& description);
  const BlockLODVolume& GetVolume() const { return this->Volume; }

  /// Streaming (BlockLODVolume's BeginStreaming, RegionArrived, EndStreaming):
  /// each also forgets the estimator's counts and the plans, which read the
  /// ranges. Cached surfaces stay: a host draws from a streaming volume only
  /// the level-3 surfaces whose blocks are all resident, which later regions
  /// do not change.
  void BeginStreaming();
  std::int64_t RegionArrived(const int first[3], const int last[3]);
  void EndStreaming();
  /// Streaming: the isovalues whose level-3 surfaces are extracted ahead as
  /// regions arrive (BlockLODVolume::SetAheadIsovalues), but for those the
  /// cache holds at level 3 already. Update() takes a surface so made instead
  /// of extracting it, for a maker with Adopt.
  void SetAheadIsovalues(const std::vector<double>& isovalues);

  /// The bytes of a surface in the host's layout; a change empties the cache.
  void SetLayout(const SurfaceLayout& layout);
  const SurfaceLayout& GetLayout() const { return this->Layout; }

  /// Counts of a pair, before extraction (BlockLODEstimator::Estimate).
  SurfaceEstimate Estimate(double isovalue, int level);
  /// Its bytes in the layout; -1 when there is no estimate (no volume).
  double EstimateBytes(double isovalue, int level);
  /// Seconds of an update that makes it: 0 when cached, -1 with no estimate;
  /// `method` (when given) receives how its counts were estimated (Exact when cached).
  double EstimateSeconds(double isovalue, int level, EstimateMethod* method = nullptr);

  /// Feeds an update's seconds (the host's timing of the whole update) to
  /// the cost model when it extracted something and did no one-time work;
  /// true when recorded.
  bool RecordCost(const SurfacesUpdate& update, double seconds);

  /// The work one estimate may do (BlockLODEstimator::SetSampleBudget).
  void SetSampleBudget(double budget) { this->Estimator.SetSampleBudget(budget); }

  virtual bool IsCached(const SurfaceKey& key) const = 0;
  virtual void ClearCache() = 0;

protected:
  virtual double CachedBytes(const SurfaceKey& key) const = 0;

  // Steps of an update. Each sets the update's outcome when it fails.
  void Begin(SurfacesUpdate& update);
  int ChooseLevel(
    const std::vector<double>& values, const LevelChoice& choice, SurfacesUpdate& update);
  bool PlanLevel(const std::vector<double>& values, const LevelChoice& choice, int& level,
    const UpdateHooks& hooks, SurfacesUpdate& update);
  // Checks `bytes` against the process's allowance (see LargeAllocationBytes).
  bool Fits(double bytes, const std::string& what, SurfacesUpdate& update);
  // Fills the update's message for a std::bad_alloc while making `what`.
  void RanOut(const std::string& what, SurfacesUpdate& update);
  bool Stopped(const UpdateHooks& hooks, SurfacesUpdate& update);
  void End(SurfacesUpdate& update);

  BlockLODVolume Volume;
  BlockLODEstimator Estimator;
  std::shared_ptr<SharedCostModel> Costs;
  SurfaceLayout Layout;
  std::vector<ExtractionPlan> Plans; // one per isovalue, buffers reused between updates

private:
  // After the volume's SetVolume or SetStreamingVolume: what a new volume
  // forgets; returns `adopted`.
  bool Adopted(bool adopted);
  bool PendingOneTimeWork = false; // a volume was adopted since the last update
  int CoarseCopiesAtBegin = 0;
  // The allowance of the current update, once read, and what it has allocated since.
  bool AllowanceRead = false;
  MemoryAllowance UpdateAllowance;
  double Allocated = 0;
};

/**
 * The unit for a host's surface type (see the file's description). A host
 * holds one per input, and per update calls SetVolume() and Update().
 */
template<typename Surface>
class BlockLODSurfaces : public BlockLODSurfacesBase
{
public:
  using BlockLODSurfacesBase::BlockLODSurfacesBase;

  /// Makes the surfaces of `isovalues` (distinct) at the level `choice` gives.
  SurfacesUpdate Update(const std::vector<double>& isovalues, const LevelChoice& choice,
    const SurfaceMaker<Surface>& maker, const UpdateHooks& hooks = UpdateHooks());

  /// The last update's surfaces, one per isovalue in their order (empty when
  /// it made none).
  const std::vector<Surface>& GetSurfaces() const { return this->Surfaces; }

  /// Bytes the cache may hold; 0 caches nothing. The current update's
  /// surfaces stay even when they exceed it.
  void SetCacheLimit(double bytes) { this->CacheLimit = bytes; }
  double GetCacheLimit() const { return this->CacheLimit; }
  double GetCacheBytes() const { return this->Cache.GetBytes(); }
  std::size_t GetCacheSize() const { return this->Cache.GetSize(); }

  bool IsCached(const SurfaceKey& key) const override { return this->Cache.Contains(key); }
  void ClearCache() override { this->Cache.Clear(); }

protected:
  double CachedBytes(const SurfaceKey& key) const override { return this->Cache.EntryBytes(key); }

private:
  bool Generate(const std::vector<double>& values, int level, const SurfaceMaker<Surface>& maker,
    const UpdateHooks& hooks, SurfacesUpdate& update);
  // Moves the surfaces extracted ahead of `values` into the cache (level 3).
  void TakeAhead(
    const std::vector<double>& values, const SurfaceMaker<Surface>& maker, SurfacesUpdate& update);

  SurfaceCache<Surface> Cache;
  std::vector<Surface> Surfaces;
  double CacheLimit = 0;
};

//------------------------------------------------------------------------------
template<typename Surface>
SurfacesUpdate BlockLODSurfaces<Surface>::Update(const std::vector<double>& isovalues,
  const LevelChoice& choice, const SurfaceMaker<Surface>& maker, const UpdateHooks& hooks)
{
  SurfacesUpdate update;
  this->Surfaces.clear();
  this->Begin(update);
  if (!this->Volume.IsValid() || isovalues.empty())
  {
    this->End(update);
    return update;
  }
  int level = this->ChooseLevel(isovalues, choice, update);
  if (level == NumberOfLevels - 1)
  {
    this->TakeAhead(isovalues, maker, update);
  }
  if (level >= 0 && this->PlanLevel(isovalues, choice, level, hooks, update))
  {
    update.Level = level;
    if (hooks.Planned)
    {
      hooks.Planned(level);
    }
    if (!this->Generate(isovalues, level, maker, hooks, update))
    {
      this->Surfaces.clear();
      update.Level = -1;
    }
  }
  this->End(update);
  return update;
}

//------------------------------------------------------------------------------
template<typename Surface>
void BlockLODSurfaces<Surface>::TakeAhead(
  const std::vector<double>& values, const SurfaceMaker<Surface>& maker, SurfacesUpdate& update)
{
  if (!maker.Adopt || this->CacheLimit <= 0)
  {
    return;
  }
  for (double v : values)
  {
    const SurfaceKey key{ v, NumberOfLevels - 1 };
    SurfaceArrays arrays;
    if (this->Cache.Contains(key) || !this->Volume.TakeAhead(v, arrays))
    {
      continue;
    }
    SurfaceCounts counts;
    counts.Points = static_cast<double>(arrays.Points.size() / 3);
    counts.Triangles = static_cast<double>(arrays.Triangles.size() / 3);
    Surface surface{};
    if (maker.Adopt(key, arrays, surface))
    {
      this->Cache.Insert(
        key, surface, maker.Bytes ? maker.Bytes(surface) : this->Layout.Bytes(counts));
      ++update.TakenAhead;
    }
  }
}

//------------------------------------------------------------------------------
template<typename Surface>
bool BlockLODSurfaces<Surface>::Generate(const std::vector<double>& values, int level,
  const SurfaceMaker<Surface>& maker, const UpdateHooks& hooks, SurfacesUpdate& update)
{
  std::vector<SurfaceKey> used;
  for (double v : values)
  {
    used.push_back(SurfaceKey{ v, level });
  }
  // Surfaces dropped to make room, offered to the host's Recycle; destroyed
  // (whatever the host left of them) when this returns.
  std::vector<Surface> evicted;
  const bool recycle = maker.Recycle && !maker.Bytes && this->CacheLimit > 0;
  for (std::size_t i = 0; i < values.size(); ++i)
  {
    const SurfaceKey key = used[i];
    if (Surface* cached = this->Cache.Find(key))
    {
      ++update.CacheHits;
      this->Surfaces.push_back(*cached);
      continue;
    }
    const ExtractionPlan& plan = this->Plans[i];
    const SurfaceCounts counts = BlockLODVolume::CountsOf(plan);
    const double bytes = this->Layout.Bytes(counts);
    const std::string what =
      "level " + std::to_string(level) + "'s surface of isovalue " + FormatIsovalue(values[i]);
    if (!this->Fits(bytes, what, update))
    {
      return false;
    }
    if (recycle)
    {
      // What the eviction after the last surface would drop, dropped before
      // this one is allocated (the update's pairs are kept either way, and
      // the least recently used go first in both).
      const std::size_t first = evicted.size();
      this->Cache.Evict(this->CacheLimit - bytes, used, &evicted);
      for (std::size_t e = first; e < evicted.size(); ++e)
      {
        maker.Recycle(evicted[e]);
      }
    }
    Surface surface{};
    try
    {
      SurfaceTarget target;
      SurfaceRanges written;
      if (!maker.Allocate(
            key, plan.GetNumberOfPoints(), plan.GetNumberOfTriangles(), surface, target))
      {
        this->RanOut(what, update);
        return false;
      }
      if (target.UseWide)
      {
        target.Wide.Ranges = &written;
        this->Volume.Generate(plan, target.Wide);
      }
      else
      {
        target.Narrow.Ranges = &written;
        this->Volume.Generate(plan, target.Narrow);
      }
      if (maker.Finish)
      {
        maker.Finish(key, surface, written);
      }
    }
    catch (const std::bad_alloc&)
    {
      this->RanOut(what, update);
      return false;
    }
    ++update.Extractions;
    update.Extracted.Cubes += counts.Cubes;
    update.Extracted.Triangles += counts.Triangles;
    this->Surfaces.push_back(surface);
    if (this->CacheLimit > 0)
    {
      this->Cache.Insert(key, surface, maker.Bytes ? maker.Bytes(surface) : bytes);
    }
    if (this->Stopped(hooks, update))
    {
      return false;
    }
  }
  this->Cache.Evict(this->CacheLimit, used);
  return true;
}

} // namespace mediso

#endif
