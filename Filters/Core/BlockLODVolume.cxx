// SPDX-License-Identifier: BSD-3-Clause
#include "BlockLODVolume.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>

namespace mediso
{

bool VolumeDescription::IsPiece() const
{
  return this->GlobalDims[0] > 0;
}

bool VolumeDescription::operator==(const VolumeDescription& o) const
{
  return this->Type == o.Type && this->Data == o.Data && this->Stamp == o.Stamp &&
    std::equal(this->Dims, this->Dims + 3, o.Dims) &&
    std::equal(this->Origin, this->Origin + 3, o.Origin) &&
    std::equal(this->Spacing, this->Spacing + 3, o.Spacing) &&
    std::equal(this->OwnedCells, this->OwnedCells + 6, o.OwnedCells) &&
    std::equal(this->GlobalOffset, this->GlobalOffset + 3, o.GlobalOffset) &&
    std::equal(this->GlobalDims, this->GlobalDims + 3, o.GlobalDims);
}

// The typed half: the volume as Volume<T>, and the coarse copies of levels 0-2.
struct BlockLODVolume::Typed
{
  virtual ~Typed() = default;
  virtual void ComputeRanges(BlockRanges& ranges) = 0;
  virtual bool Plan(double isovalue, int level, ExtractionPlan& plan,
    const std::function<bool()>& abort) = 0;
  virtual void Generate(const ExtractionPlan& plan, const SurfaceBuffers<std::int32_t>& out) = 0;
  virtual void Generate(const ExtractionPlan& plan, const SurfaceBuffers<std::int64_t>& out) = 0;
  // Active blocks of a level's coarse copy (building it when `build`), or
  // null when it has none.
  virtual const BlockRanges* CoarseRanges(int level, bool build) = 0;
  // Exact counts on a level's coarse copy (which must exist).
  virtual SurfaceCounts CountCoarse(double isovalue, int level) = 0;
  // Counts on full-volume blocks.
  virtual BlockSums CountFull(const std::vector<std::int32_t>& blocks, double isovalue, int level,
    int auxLevel) = 0;
  // The range of one block of the full volume (its points, as ComputeBlockRanges reads them).
  virtual void BlockRange(std::int64_t block, BlockRanges& ranges) = 0;
  // Forgets the coarse copies (the values they copied changed).
  virtual void ForgetCoarseCopies() = 0;
  // Extraction ahead on the full volume (BlockLOD.h, AppendToPlan, GenerateBlocks).
  virtual std::int64_t AppendAhead(
    const std::vector<std::int32_t>& blocks, ExtractionPlan& plan) = 0;
  virtual void GenerateAhead(const ExtractionPlan& plan, const std::vector<std::int64_t>& list,
    int parts, const SurfaceBuffers<std::int32_t>& out) = 0;
  int CoarseCopies = 0; // made so far
};

namespace
{
double CubesPerBlock(int stride)
{
  const double perAxis = BlockCells / stride;
  return perAxis * perAxis * perAxis;
}

// A well-mixed 32-bit hash (for the estimator's deterministic sample).
std::uint32_t Mix(std::uint32_t x)
{
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  return x ^ (x >> 16);
}
} // namespace

template <typename T>
struct BlockLODVolume::TypedImpl : BlockLODVolume::Typed
{
  struct Coarse
  {
    bool Built = false;
    std::vector<T> Values;
    Volume<T> Samples;
    BlockRanges Ranges;
  };

  TriangleCaseTable Cases;
  const ParallelFor& Parallel;
  const BlockRanges& FullRanges;
  Volume<T> Full;
  Coarse Levels[NumberOfLevels - 1];

  TypedImpl(const VolumeDescription& d, TriangleCaseTable cases, const ParallelFor& parallel,
    const BlockRanges& fullRanges)
    : Cases(cases)
    , Parallel(parallel)
    , FullRanges(fullRanges)
  {
    this->Full.Data = static_cast<const T*>(d.Data);
    for (int a = 0; a < 3; ++a)
    {
      this->Full.Dims[a] = d.Dims[a];
      this->Full.Origin[a] = d.Origin[a];
      this->Full.Spacing[a] = d.Spacing[a];
      this->Full.OwnedCells[2 * a] = d.OwnedCells[2 * a];
      this->Full.OwnedCells[2 * a + 1] = d.OwnedCells[2 * a + 1];
      this->Full.GlobalOffset[a] = d.IsPiece() ? d.GlobalOffset[a] : 0;
      this->Full.GlobalDims[a] = d.IsPiece() ? d.GlobalDims[a] : 0;
    }
  }

  void ComputeRanges(BlockRanges& ranges) override
  {
    ComputeBlockRanges(this->Full, ranges, this->Parallel);
  }

  // Runs f(volume, ranges) on the volume a level is extracted from at stride
  // 1: the full volume at level 3, the level's coarse copy below (built on
  // first use).
  template <typename F>
  void WithLevel(int level, F&& f)
  {
    if (level == NumberOfLevels - 1)
    {
      f(this->Full, this->FullRanges);
      return;
    }
    Coarse& c = this->Levels[level];
    if (!c.Built)
    {
      c.Samples = MakeCoarseCopy(this->Full, level, c.Values, this->Parallel);
      ComputeBlockRanges(c.Samples, c.Ranges, this->Parallel);
      c.Built = true;
      ++this->CoarseCopies;
    }
    f(c.Samples, c.Ranges);
  }

  bool Plan(double isovalue, int level, ExtractionPlan& plan,
    const std::function<bool()>& abort) override
  {
    bool complete = true;
    this->WithLevel(level, [&](const Volume<T>& volume, const BlockRanges& ranges) {
      complete = PlanExtraction(
        volume, ranges, this->Cases, isovalue, NumberOfLevels - 1, plan, this->Parallel, abort);
    });
    plan.VolumeLevel = level;
    return complete;
  }

  template <typename IdType>
  void GenerateAny(const ExtractionPlan& plan, const SurfaceBuffers<IdType>& out)
  {
    this->WithLevel(plan.VolumeLevel, [&](const Volume<T>& volume, const BlockRanges& ranges) {
      GenerateSurface(volume, ranges, this->Cases, plan, out, this->Parallel);
    });
  }
  void Generate(const ExtractionPlan& plan, const SurfaceBuffers<std::int32_t>& out) override
  {
    this->GenerateAny(plan, out);
  }
  void Generate(const ExtractionPlan& plan, const SurfaceBuffers<std::int64_t>& out) override
  {
    this->GenerateAny(plan, out);
  }

  const BlockRanges* CoarseRanges(int level, bool build) override
  {
    if (level >= NumberOfLevels - 1 || (!this->Levels[level].Built && !build))
    {
      return nullptr;
    }
    this->WithLevel(level, [](const Volume<T>&, const BlockRanges&) {});
    return &this->Levels[level].Ranges;
  }

  SurfaceCounts CountCoarse(double isovalue, int level) override
  {
    const Coarse& coarse = this->Levels[level];
    const std::vector<std::int32_t> active = ListActiveBlocks(coarse.Ranges, isovalue);
    const BlockSums sums = CountBlocks(coarse.Samples, coarse.Ranges, this->Cases, active, isovalue,
      NumberOfLevels - 1, -1, this->Parallel);
    SurfaceCounts c;
    c.Points = sums.Points;
    c.Triangles = sums.Triangles;
    c.Cubes = static_cast<double>(active.size()) * CubesPerBlock(1);
    return c;
  }

  std::int64_t AppendAhead(const std::vector<std::int32_t>& blocks, ExtractionPlan& plan) override
  {
    return AppendToPlan(this->Full, this->FullRanges, this->Cases, blocks, plan, this->Parallel);
  }

  void GenerateAhead(const ExtractionPlan& plan, const std::vector<std::int64_t>& list, int parts,
    const SurfaceBuffers<std::int32_t>& out) override
  {
    GenerateBlocks(
      this->Full, this->FullRanges, this->Cases, plan, &list, parts, out, this->Parallel);
  }

  BlockSums CountFull(const std::vector<std::int32_t>& blocks, double isovalue, int level,
    int auxLevel) override
  {
    return CountBlocks(
      this->Full, this->FullRanges, this->Cases, blocks, isovalue, level, auxLevel, this->Parallel);
  }

  void BlockRange(std::int64_t block, BlockRanges& ranges) override
  {
    std::int64_t nans = 0, infinities = 0;
    if (ComputeBlockRange(this->Full, ranges, block, nans, infinities))
    {
      ranges.ValueRange[0] = std::min(ranges.ValueRange[0], ranges.Min[block]);
      ranges.ValueRange[1] = std::max(ranges.ValueRange[1], ranges.Max[block]);
    }
    ranges.NaNCount += nans;
    ranges.InfiniteCount += infinities;
  }

  void ForgetCoarseCopies() override
  {
    for (Coarse& c : this->Levels)
    {
      c = Coarse();
    }
  }
};

BlockLODVolume::BlockLODVolume(TriangleCaseTable cases, ParallelFor parallel)
  : Cases(cases)
  , Parallel(parallel ? std::move(parallel) : ParallelFor(SerialFor))
{
}

// One isovalue's level-3 surface extracted ahead: its growing plan, its
// arrays sized to the plan, and the active blocks whose triangles wait for a
// block above them.
struct BlockLODVolume::Ahead
{
  double Isovalue = 0;
  bool Begun = false; // caught up over the blocks resident when it was named
  ExtractionPlan Plan;
  SurfaceArrays Arrays;
  std::vector<std::int64_t> Waiting;

  SurfaceBuffers<std::int32_t> Buffers()
  {
    SurfaceBuffers<std::int32_t> out;
    out.Points = this->Arrays.Points.data();
    out.Normals = this->Arrays.Normals.data();
    out.Connectivity = this->Arrays.Triangles.data();
    return out;
  }
};

BlockLODVolume::~BlockLODVolume() = default;

void BlockLODVolume::Reset()
{
  this->Streaming = false;
  this->ResidentRuns.clear();
  this->ResidentBlocks.clear();
  this->NumberOfResidentBlocks = 0;
  this->Valid = false;
  this->AheadSurfaces.clear();
  this->Impl.reset();
  this->ActiveLists.clear();
  this->Ranges = BlockRanges();
  this->Description = VolumeDescription();
}

bool BlockLODVolume::IsValid() const
{
  return this->Valid;
}

int BlockLODVolume::GetNumberOfCoarseCopies() const
{
  return this->Impl ? this->Impl->CoarseCopies : 0;
}

bool BlockLODVolume::SetVolume(const VolumeDescription& description)
{
  if (this->Valid && description == this->Description)
  {
    return false;
  }
  if (!this->Adopt(description))
  {
    return false; // not a ScalarType value: nothing to contour
  }
  this->Impl->ComputeRanges(this->Ranges);
  this->Valid = true;
  return true;
}

bool BlockLODVolume::SetStreamingVolume(const VolumeDescription& description)
{
  if (!this->Adopt(description))
  {
    return false;
  }
  // Sized and empty; BeginStreaming keeps them so until regions arrive.
  SizeBlockRanges(description.Dims, this->Ranges);
  this->Valid = true;
  this->BeginStreaming();
  return true;
}

bool BlockLODVolume::Adopt(const VolumeDescription& description)
{
  this->Reset();
  this->Description = description;
  VisitScalarType(description.Type, [this, &description](auto tag) {
    this->Impl = std::make_unique<TypedImpl<decltype(tag)>>(
      description, this->Cases, this->Parallel, this->Ranges);
  });
  return this->Impl != nullptr;
}

bool BlockLODVolume::Plan(
  double isovalue, int level, ExtractionPlan& plan, const std::function<bool()>& abort)
{
  return this->Impl->Plan(isovalue, level, plan, abort);
}

void BlockLODVolume::Generate(const ExtractionPlan& plan, const SurfaceBuffers<std::int32_t>& out)
{
  this->Impl->Generate(plan, out);
}

void BlockLODVolume::Generate(const ExtractionPlan& plan, const SurfaceBuffers<std::int64_t>& out)
{
  this->Impl->Generate(plan, out);
}

SurfaceCounts BlockLODVolume::CountsOf(const ExtractionPlan& plan)
{
  SurfaceCounts c;
  c.Points = static_cast<double>(plan.GetNumberOfPoints());
  c.Triangles = static_cast<double>(plan.GetNumberOfTriangles());
  c.Cubes = static_cast<double>(plan.ActiveBlocks.size()) * plan.CubesPerBlock;
  return c;
}

double BlockLODVolume::PlanBytes(double isovalue, int level)
{
  // Plan() runs the full-resolution pass on the level's volume.
  const int pass = NumberOfLevels - 1;
  const std::int64_t fullActive = static_cast<std::int64_t>(this->ActiveBlocks(isovalue).size());
  if (level >= pass)
  {
    return ExtractionPlanBytes(this->Ranges.GetNumberOfBlocks(), fullActive, pass);
  }
  if (const BlockRanges* coarse = this->Impl->CoarseRanges(level, false))
  {
    const std::int64_t active =
      static_cast<std::int64_t>(ListActiveBlocks(*coarse, isovalue).size());
    return ExtractionPlanBytes(coarse->GetNumberOfBlocks(), active, pass);
  }
  // The copy samples every stride-th point and the last one along each axis.
  const int stride = LevelStride(level);
  double samples = 1, blocks = 1;
  for (int a = 0; a < 3; ++a)
  {
    const int points = (this->Description.Dims[a] - 1 + stride - 1) / stride + 1;
    samples *= points;
    blocks *= (points - 1 + BlockCells - 1) / BlockCells;
  }
  const double copy =
    samples * ScalarTypeSize(this->Description.Type) + blocks * 2 * sizeof(double);
  const auto copyBlocks = static_cast<std::int64_t>(blocks);
  return copy + ExtractionPlanBytes(copyBlocks, std::min(copyBlocks, fullActive), pass);
}

double BlockLODVolume::BlockCost(int level)
{
  // Measured on the project's machine: 0.12, 0.16, 0.49 and 1.5 microseconds.
  constexpr double cost[NumberOfLevels] = { 1.0, 1.4, 4.2, 13.0 };
  return cost[std::min(std::max(level, 0), NumberOfLevels - 1)];
}

double BlockLODVolume::ExactCountCost(double isovalue, int level)
{
  const bool small = level < NumberOfLevels - 2; // levels 0 and 1: copies of 1/512, 1/64
  if (const BlockRanges* coarse = this->Impl->CoarseRanges(level, small))
  {
    return static_cast<double>(ListActiveBlocks(*coarse, isovalue).size()) *
      BlockCost(NumberOfLevels - 1);
  }
  return static_cast<double>(this->ActiveBlocks(isovalue).size()) * BlockCost(level);
}

SurfaceCounts BlockLODVolume::CountExact(double isovalue, int level)
{
  const bool small = level < NumberOfLevels - 2;
  if (this->Impl->CoarseRanges(level, small))
  {
    return this->Impl->CountCoarse(isovalue, level);
  }
  const std::vector<std::int32_t>& active = this->ActiveBlocks(isovalue);
  const BlockSums sums = this->Impl->CountFull(active, isovalue, level, -1);
  SurfaceCounts c;
  c.Points = sums.Points;
  c.Triangles = sums.Triangles;
  c.Cubes = static_cast<double>(active.size()) * CubesPerBlock(LevelStride(level));
  return c;
}

BlockSums BlockLODVolume::CountSample(
  double isovalue, int level, int auxLevel, std::int64_t samples)
{
  const std::vector<std::int32_t>& active = this->ActiveBlocks(isovalue);
  const std::int64_t n = static_cast<std::int64_t>(active.size());
  if (samples >= n)
  {
    return this->Impl->CountFull(active, isovalue, level, auxLevel);
  }
  // Jittered systematic sample: one block at a pseudo-random place in each of
  // `samples` equal runs of the active list (which is in volume order), so
  // the sample spreads over the volume without following its period.
  std::vector<std::int32_t> chosen(static_cast<std::size_t>(samples));
  for (std::int64_t s = 0; s < samples; ++s)
  {
    const std::int64_t lo = s * n / samples;
    const std::int64_t hi = (s + 1) * n / samples;
    const std::uint32_t r = Mix(static_cast<std::uint32_t>(s) * 2654435761u + static_cast<std::uint32_t>(level));
    chosen[s] = active[lo + static_cast<std::int64_t>(r % static_cast<std::uint32_t>(hi - lo))];
  }
  return this->Impl->CountFull(chosen, isovalue, level, auxLevel);
}

const std::vector<std::int32_t>& BlockLODVolume::ActiveBlocks(double isovalue)
{
  for (auto& entry : this->ActiveLists)
  {
    if (entry.first == isovalue)
    {
      return entry.second;
    }
  }
  if (this->ActiveLists.size() >= 4)
  {
    this->ActiveLists.erase(this->ActiveLists.begin());
  }
  this->ActiveLists.emplace_back(isovalue, ListActiveBlocks(this->Ranges, isovalue));
  return this->ActiveLists.back().second;
}

void BlockLODVolume::BeginStreaming()
{
  if (!this->Valid)
  {
    return;
  }
  this->Streaming = true;
  for (int a = 0; a < 3; ++a)
  {
    this->Runs[a] = (this->Description.Dims[a] + BlockCells - 1) / BlockCells;
  }
  this->ResidentRuns.assign(
    static_cast<std::size_t>(this->Runs[0]) * this->Runs[1] * this->Runs[2], 0);
  this->ResidentBlocks.assign(static_cast<std::size_t>(this->Ranges.GetNumberOfBlocks()), 0);
  this->NumberOfResidentBlocks = 0;
  std::fill(this->Ranges.Min.begin(), this->Ranges.Min.end(), std::numeric_limits<double>::infinity());
  std::fill(
    this->Ranges.Max.begin(), this->Ranges.Max.end(), -std::numeric_limits<double>::infinity());
  this->Ranges.NaNCount = this->Ranges.InfiniteCount = 0;
  this->Ranges.ValueRange[0] = std::numeric_limits<double>::infinity();
  this->Ranges.ValueRange[1] = -std::numeric_limits<double>::infinity();
  this->ActiveLists.clear();
  this->AheadSurfaces.clear();
  this->Impl->ForgetCoarseCopies();
}

std::int64_t BlockLODVolume::RegionArrived(const int first[3], const int last[3])
{
  if (!this->Streaming)
  {
    return 0;
  }
  // The runs the region covers whole, per axis: [r0, r1].
  int r0[3], r1[3];
  for (int a = 0; a < 3; ++a)
  {
    const int n = this->Description.Dims[a];
    const int lo = std::max(0, first[a]);
    const int hi = std::min(n - 1, last[a]);
    r0[a] = (lo + BlockCells - 1) / BlockCells;
    r1[a] = hi == n - 1 ? this->Runs[a] - 1 : (hi + 1) / BlockCells - 1;
    if (lo > hi || r0[a] > r1[a])
    {
      return 0;
    }
  }
  for (int z = r0[2]; z <= r1[2]; ++z)
  {
    for (int y = r0[1]; y <= r1[1]; ++y)
    {
      for (int x = r0[0]; x <= r1[0]; ++x)
      {
        this->ResidentRuns[(static_cast<std::size_t>(z) * this->Runs[1] + y) * this->Runs[0] + x] =
          1;
      }
    }
  }
  // Block b reads the points 8b - 1 .. 8b + 9 (its own and the gradient's), runs b - 1 .. b + 1:
  // only the blocks next to the new runs can have been completed.
  int b0[3], b1[3];
  for (int a = 0; a < 3; ++a)
  {
    b0[a] = std::max(0, r0[a] - 1);
    b1[a] = std::min(this->Ranges.Blocks[a] - 1, r1[a] + 1);
  }
  auto readRuns = [this](int a, int b, int& lo, int& hi) {
    const int n = this->Description.Dims[a];
    lo = std::max(0, b * BlockCells - 1) / BlockCells;
    hi = std::min(n - 1, b * BlockCells + BlockCells + 1) / BlockCells;
  };
  std::vector<std::int32_t> completed;
  for (int bz = b0[2]; bz <= b1[2]; ++bz)
  {
    for (int by = b0[1]; by <= b1[1]; ++by)
    {
      for (int bx = b0[0]; bx <= b1[0]; ++bx)
      {
        const std::int64_t block =
          (static_cast<std::int64_t>(bz) * this->Ranges.Blocks[1] + by) * this->Ranges.Blocks[0] +
          bx;
        if (this->ResidentBlocks[block])
        {
          continue;
        }
        int lo[3], hi[3];
        const int b[3] = { bx, by, bz };
        for (int a = 0; a < 3; ++a)
        {
          readRuns(a, b[a], lo[a], hi[a]);
        }
        bool resident = true;
        for (int z = lo[2]; z <= hi[2] && resident; ++z)
        {
          for (int y = lo[1]; y <= hi[1] && resident; ++y)
          {
            for (int x = lo[0]; x <= hi[0] && resident; ++x)
            {
              resident =
                this->ResidentRuns[(static_cast<std::size_t>(z) * this->Runs[1] + y) * this->Runs[0] +
                  x] != 0;
            }
          }
        }
        if (resident)
        {
          this->Impl->BlockRange(block, this->Ranges);
          this->ResidentBlocks[block] = 1;
          completed.push_back(static_cast<std::int32_t>(block));
        }
      }
    }
  }
  this->NumberOfResidentBlocks += static_cast<std::int64_t>(completed.size());
  this->ActiveLists.clear();
  this->Impl->ForgetCoarseCopies();
  this->AdvanceAhead(completed);
  return static_cast<std::int64_t>(completed.size());
}

void BlockLODVolume::SetAheadIsovalues(const std::vector<double>& isovalues)
{
  auto named = [&isovalues](double v)
  { return std::find(isovalues.begin(), isovalues.end(), v) != isovalues.end(); };
  this->AheadSurfaces.erase(
    std::remove_if(this->AheadSurfaces.begin(), this->AheadSurfaces.end(),
      [&named](const std::unique_ptr<Ahead>& a) { return !named(a->Isovalue); }),
    this->AheadSurfaces.end());
  if (!this->Streaming)
  {
    return;
  }
  for (double v : isovalues)
  {
    const std::vector<double> held = this->GetAheadIsovalues();
    if (std::isfinite(v) && std::find(held.begin(), held.end(), v) == held.end())
    {
      auto ahead = std::make_unique<Ahead>();
      ahead->Isovalue = v;
      this->AheadSurfaces.push_back(std::move(ahead));
    }
  }
}

std::vector<double> BlockLODVolume::GetAheadIsovalues() const
{
  std::vector<double> values;
  for (const auto& a : this->AheadSurfaces)
  {
    values.push_back(a->Isovalue);
  }
  return values;
}

void BlockLODVolume::AdvanceAhead(const std::vector<std::int32_t>& completed)
{
  const int full = NumberOfLevels - 1;
  for (auto it = this->AheadSurfaces.begin(); it != this->AheadSurfaces.end();)
  {
    Ahead& a = **it;
    try
    {
      std::vector<std::int32_t> caughtUp;
      const bool catchUp = !a.Begun;
      if (catchUp)
      {
        // Named since the last region: every block resident so far, once.
        BeginPlan(this->Ranges, a.Isovalue, full, a.Plan);
        for (std::size_t b = 0; b < this->ResidentBlocks.size(); ++b)
        {
          if (this->ResidentBlocks[b])
          {
            caughtUp.push_back(static_cast<std::int32_t>(b));
          }
        }
        a.Begun = true;
      }
      const std::int64_t first = this->Impl->AppendAhead(catchUp ? caughtUp : completed, a.Plan);
      const std::int64_t end = static_cast<std::int64_t>(a.Plan.ActiveBlocks.size());
      a.Arrays.Points.resize(3 * static_cast<std::size_t>(a.Plan.GetNumberOfPoints()));
      a.Arrays.Normals.resize(a.Arrays.Points.size());
      a.Arrays.Triangles.resize(3 * static_cast<std::size_t>(a.Plan.GetNumberOfTriangles()));
      std::vector<std::int64_t> added;
      for (std::int64_t i = first; i < end; ++i)
      {
        added.push_back(i);
        a.Waiting.push_back(i);
      }
      this->Impl->GenerateAhead(a.Plan, added, GeneratePoints, a.Buffers());
      // The triangles of the blocks whose blocks above are all resident now.
      std::vector<std::int64_t> ready, waiting;
      for (std::int64_t i : a.Waiting)
      {
        std::int64_t owners[7];
        const int n = PlanOwners(this->Ranges, a.Plan.ActiveBlocks[i], owners);
        bool settled = true;
        for (int o = 0; o < n && settled; ++o)
        {
          settled = this->ResidentBlocks[owners[o]] != 0;
        }
        (settled ? ready : waiting).push_back(i);
      }
      this->Impl->GenerateAhead(a.Plan, ready, GenerateTriangles, a.Buffers());
      a.Waiting.swap(waiting);
      ++it;
    }
    catch (const std::bad_alloc&)
    {
      it = this->AheadSurfaces.erase(it); // ahead is an optimisation: the frame extracts it
    }
  }
}

bool BlockLODVolume::TakeAhead(double isovalue, SurfaceArrays& surface)
{
  for (auto it = this->AheadSurfaces.begin(); it != this->AheadSurfaces.end(); ++it)
  {
    Ahead& a = **it;
    if (a.Isovalue != isovalue)
    {
      continue;
    }
    if (!a.Begun)
    {
      return false;
    }
    this->Impl->GenerateAhead(a.Plan, a.Waiting, GenerateTriangles, a.Buffers());
    surface = std::move(a.Arrays);
    this->AheadSurfaces.erase(it);
    return true;
  }
  return false;
}

void BlockLODVolume::EndStreaming()
{
  if (!this->Streaming)
  {
    return;
  }
  this->Streaming = false;
  this->ResidentRuns.clear();
  this->ResidentBlocks.clear();
  this->ActiveLists.clear();
  this->Impl->ForgetCoarseCopies();
  // The surfaces under way stay (every block is resident: complete once taken);
  // those not begun would have nothing to catch up from.
  this->AheadSurfaces.erase(std::remove_if(this->AheadSurfaces.begin(), this->AheadSurfaces.end(),
                              [](const std::unique_ptr<Ahead>& a) { return !a->Begun; }),
    this->AheadSurfaces.end());
}

std::int64_t BlockLODVolume::GetNumberOfResidentBlocks() const
{
  return this->Streaming ? this->NumberOfResidentBlocks : this->Ranges.GetNumberOfBlocks();
}

} // namespace mediso
