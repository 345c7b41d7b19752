// SPDX-License-Identifier: BSD-3-Clause
#include "vtkBlockLODContour.h"

#include "BlockLOD.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkExtentTranslator.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMarchingCubesTriangleCases.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkTypeInt32Array.h"
#include "vtkTypeInt64Array.h"
#include "vtkUnsignedCharArray.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkDataSetAttributes.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <type_traits>
#include <sstream>
#include <utility>
#include <vector>

vtkStandardNewMacro(vtkBlockLODContour);

namespace
{
constexpr double BytesPerMB = 1.0e6;
// Sampled estimates count about this many active blocks.
constexpr std::int64_t EstimateSampleBlocks = 256;

// Every `step`-th active block is counted; step 1 counts them all (exact).
int SampleStep(std::int64_t activeBlocks)
{
  return static_cast<int>(std::max<std::int64_t>(1, activeBlocks / EstimateSampleBlocks));
}

mediso::TriangleCaseTable VTKCaseTable()
{
  return reinterpret_cast<mediso::TriangleCaseTable>(vtkMarchingCubesTriangleCases::GetCases());
}

void SMPFor(std::int64_t begin, std::int64_t end, const mediso::RangeBody& body)
{
  if (begin >= end)
  {
    return;
  }
  // About 8 tasks per thread: enough to balance blocks of uneven work, few
  // enough that the thread pool's per-task cost stays small against the work.
  const vtkIdType threads = std::max(1, vtkSMPTools::GetEstimatedNumberOfThreads());
  const vtkIdType grain = std::max<vtkIdType>(1, (end - begin) / (8 * threads));
  vtkSMPTools::For(begin, end, grain, [&](vtkIdType b, vtkIdType e) { body(b, e); });
}

// Output layout flags that change the bytes and content of a surface.
struct OutputFlags
{
  bool Normals;
  bool Scalars;
  bool BlockIds;
  bool operator==(const OutputFlags& o) const
  {
    return this->Normals == o.Normals && this->Scalars == o.Scalars && this->BlockIds == o.BlockIds;
  }
};

// Bytes the output vtkPolyData holds for a surface of this size.
double SurfaceBytes(double points, double triangles, const OutputFlags& flags)
{
  const double id = (points < 2147483647.0 && 3 * triangles < 2147483647.0) ? 4.0 : 8.0;
  double perPoint = 12.0 + (flags.Normals ? 12.0 : 0.0) + (flags.Scalars ? 4.0 : 0.0);
  double perTriangle = 4.0 * id + (flags.BlockIds ? 4.0 : 0.0); // 3 ids + 1 offset
  return points * perPoint + triangles * perTriangle + id;
}

// An output vtkPolyData sized for `points` and `triangles`, with raw pointers
// to fill. Connectivity is 32-bit when it fits.
struct SurfaceArrays
{
  vtkSmartPointer<vtkPolyData> Surface;
  float* Points = nullptr;
  float* Normals = nullptr;
  float* Scalars = nullptr;
  std::int32_t* BlockIds = nullptr;
  std::int32_t* Connectivity32 = nullptr;
  std::int64_t* Connectivity64 = nullptr;
};

SurfaceArrays AllocateSurface(std::int64_t points, std::int64_t triangles, const OutputFlags& flags)
{
  SurfaceArrays out;
  out.Surface = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkFloatArray> coords;
  coords->SetNumberOfComponents(3);
  coords->SetNumberOfTuples(points);
  out.Points = coords->GetPointer(0);
  vtkNew<vtkPoints> pts;
  pts->SetData(coords);
  out.Surface->SetPoints(pts);
  if (flags.Normals)
  {
    vtkNew<vtkFloatArray> normals;
    normals->SetName("Normals");
    normals->SetNumberOfComponents(3);
    normals->SetNumberOfTuples(points);
    out.Normals = normals->GetPointer(0);
    out.Surface->GetPointData()->SetNormals(normals);
  }
  if (flags.Scalars)
  {
    vtkNew<vtkFloatArray> scalars;
    scalars->SetName("Isovalue");
    scalars->SetNumberOfTuples(points);
    out.Scalars = scalars->GetPointer(0);
    out.Surface->GetPointData()->SetScalars(scalars);
  }
  if (flags.BlockIds)
  {
    vtkNew<vtkIntArray> ids;
    ids->SetName("BlockId");
    ids->SetNumberOfTuples(triangles);
    out.BlockIds = reinterpret_cast<std::int32_t*>(ids->GetPointer(0));
    out.Surface->GetCellData()->AddArray(ids);
  }
  vtkNew<vtkCellArray> polys;
  const bool small = points < std::numeric_limits<std::int32_t>::max() &&
    3 * triangles < std::numeric_limits<std::int32_t>::max();
  auto fillOffsets = [triangles](auto* offsets) {
    vtkSMPTools::For(0, triangles + 1, [offsets](vtkIdType b, vtkIdType e) {
      for (vtkIdType i = b; i < e; ++i)
      {
        offsets[i] = static_cast<std::remove_pointer_t<decltype(offsets)>>(3 * i);
      }
    });
  };
  if (small)
  {
    vtkNew<vtkTypeInt32Array> offsets, connectivity;
    offsets->SetNumberOfValues(triangles + 1);
    connectivity->SetNumberOfValues(3 * triangles);
    fillOffsets(offsets->GetPointer(0));
    out.Connectivity32 = connectivity->GetPointer(0);
    polys->SetData(offsets, connectivity);
  }
  else
  {
    vtkNew<vtkTypeInt64Array> offsets, connectivity;
    offsets->SetNumberOfValues(triangles + 1);
    connectivity->SetNumberOfValues(3 * triangles);
    fillOffsets(offsets->GetPointer(0));
    // vtkTypeInt64 is long long, std::int64_t long: same 64-bit representation.
    out.Connectivity64 = reinterpret_cast<std::int64_t*>(connectivity->GetPointer(0));
    polys->SetData(offsets, connectivity);
  }
  out.Surface->SetPolys(polys);
  return out;
}

template <typename F>
bool DispatchScalarType(int type, F&& f)
{
  switch (type)
  {
    case VTK_CHAR:
    case VTK_SIGNED_CHAR:
      f(std::int8_t{});
      return true;
    case VTK_UNSIGNED_CHAR:
      f(std::uint8_t{});
      return true;
    case VTK_SHORT:
      f(std::int16_t{});
      return true;
    case VTK_UNSIGNED_SHORT:
      f(std::uint16_t{});
      return true;
    case VTK_INT:
      f(std::int32_t{});
      return true;
    case VTK_UNSIGNED_INT:
      f(std::uint32_t{});
      return true;
    case VTK_FLOAT:
      f(float{});
      return true;
    case VTK_DOUBLE:
      f(double{});
      return true;
    default:
      return false;
  }
}

using Key = std::pair<double, int>; // (isovalue, level)

struct Counts
{
  double Points = 0;
  double Triangles = 0;
  double Cubes = 0; ///< Cubes visited to extract the pair (cost model).
};

// A level's samples as a small contiguous volume of their own, with its block
// ranges (built once per input, the first time the level is extracted).
struct CoarseLevelBase
{
  virtual ~CoarseLevelBase() = default;
  mediso::BlockRanges Ranges;
};
template <typename T>
struct CoarseLevel : CoarseLevelBase
{
  std::vector<T> Values;
  mediso::Volume<T> Volume;
};

struct CacheEntry
{
  vtkSmartPointer<vtkPolyData> Surface;
  double Bytes = 0;
  std::uint64_t LastUse = 0;
};

double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
} // namespace

struct vtkBlockLODContour::vtkInternals
{
  // What the block ranges and the cache were computed from.
  vtkImageData* Input = nullptr;
  vtkDataArray* Array = nullptr;
  vtkMTimeType ArrayMTime = 0;
  int Extent[6] = { 0, -1, 0, -1, 0, -1 };
  int WholeExtent[6] = { 0, -1, 0, -1, 0, -1 };
  double Origin[3] = { 0, 0, 0 };
  double Spacing[3] = { 1, 1, 1 };
  int ScalarType = -1;
  const void* Data = nullptr;
  int OwnedCells[6] = { 0, -1, 0, -1, 0, -1 };
  bool RangesValid = false;
  mediso::BlockRanges Ranges;
  std::unique_ptr<CoarseLevelBase> Coarse[mediso::NumberOfLevels - 1];
  bool WarnedNaN = false;

  OutputFlags CacheFlags{ true, false, false };
  std::map<Key, CacheEntry> Cache;
  std::map<Key, Counts> Exact;   // exact counts of every planned pair
  std::map<Key, Counts> Sampled; // sampled estimates, kept until the input changes
  std::vector<std::pair<double, std::vector<std::int32_t>>> ActiveLists;
  std::uint64_t Clock = 0;

  // Cost model: seconds = A * cubes visited + B * triangles, least squares over
  // this filter's extractions (sums of the normal equations).
  double Sxx = 0, Sxy = 0, Syy = 0, Sxt = 0, Syt = 0;
  int CostSamples = 0;

  template <typename T>
  mediso::Volume<T> MakeVolume() const
  {
    mediso::Volume<T> v;
    v.Data = static_cast<const T*>(this->Data);
    for (int a = 0; a < 3; ++a)
    {
      v.Dims[a] = this->Extent[2 * a + 1] - this->Extent[2 * a] + 1;
      v.Origin[a] = this->Origin[a] + this->Spacing[a] * this->Extent[2 * a];
      v.Spacing[a] = this->Spacing[a];
      v.OwnedCells[2 * a] = this->OwnedCells[2 * a];
      v.OwnedCells[2 * a + 1] = this->OwnedCells[2 * a + 1];
    }
    if (this->IsPiece())
    {
      for (int a = 0; a < 3; ++a)
      {
        v.GlobalOffset[a] = this->Extent[2 * a] - this->WholeExtent[2 * a];
        v.GlobalDims[a] = this->WholeExtent[2 * a + 1] - this->WholeExtent[2 * a] + 1;
      }
    }
    return v;
  }

  // True when the input is a part of a larger whole extent (a parallel piece).
  bool IsPiece() const
  {
    for (int a = 0; a < 3; ++a)
    {
      if (this->WholeExtent[2 * a] > this->WholeExtent[2 * a + 1])
      {
        return false; // no whole extent known
      }
    }
    return !std::equal(this->Extent, this->Extent + 6, this->WholeExtent);
  }

  template <typename F>
  bool WithVolume(F&& f) const
  {
    return DispatchScalarType(this->ScalarType, [&](auto tag) {
      using T = decltype(tag);
      f(this->MakeVolume<T>());
    });
  }

  void ForgetInput()
  {
    this->RangesValid = false;
    for (auto& c : this->Coarse)
    {
      c.reset();
    }
    this->Cache.clear();
    this->Exact.clear();
    this->Sampled.clear();
    this->ActiveLists.clear();
    this->WarnedNaN = false;
  }

  // Cells that are not ghosts, as an inclusive cell index range per axis:
  // ghost layers of a structured piece are whole slabs at its faces. Without
  // a ghost array (a filter upstream dropped it), the piece's extent without
  // ghost layers (`zeroExtent`, when given) tells them.
  static void FindOwnedCells(
    vtkImageData* input, const int dims[3], const int* zeroExtent, int owned[6])
  {
    for (int a = 0; a < 3; ++a)
    {
      owned[2 * a] = 0;
      owned[2 * a + 1] = dims[a] - 2;
    }
    vtkUnsignedCharArray* ghosts = input->GetCellGhostArray();
    if (!ghosts)
    {
      if (zeroExtent)
      {
        const int* extent = input->GetExtent();
        for (int a = 0; a < 3; ++a)
        {
          owned[2 * a] = std::max(0, zeroExtent[2 * a] - extent[2 * a]);
          owned[2 * a + 1] = std::min(dims[a] - 2, zeroExtent[2 * a + 1] - 1 - extent[2 * a]);
        }
      }
      return;
    }
    const int cells[3] = { dims[0] - 1, dims[1] - 1, dims[2] - 1 };
    std::vector<char> real[3];
    for (int a = 0; a < 3; ++a)
    {
      real[a].assign(cells[a], 0);
    }
    const unsigned char* g = ghosts->GetPointer(0);
    vtkIdType id = 0;
    for (int k = 0; k < cells[2]; ++k)
      for (int j = 0; j < cells[1]; ++j)
        for (int i = 0; i < cells[0]; ++i, ++id)
          if (!(g[id] & vtkDataSetAttributes::DUPLICATECELL))
          {
            real[0][i] = real[1][j] = real[2][k] = 1;
          }
    for (int a = 0; a < 3; ++a)
    {
      int lo = 0, hi = cells[a] - 1;
      while (lo < hi && !real[a][lo])
      {
        ++lo;
      }
      while (hi > lo && !real[a][hi])
      {
        --hi;
      }
      owned[2 * a] = lo;
      owned[2 * a + 1] = hi;
    }
  }

  // Brings block ranges up to date with the input; returns true when they were recomputed.
  bool Refresh(
    vtkImageData* input, vtkDataArray* array, const int wholeExtent[6], const int* zeroExtent)
  {
    int extent[6];
    input->GetExtent(extent);
    int dims[3] = { extent[1] - extent[0] + 1, extent[3] - extent[2] + 1, extent[5] - extent[4] + 1 };
    int owned[6];
    FindOwnedCells(input, dims, zeroExtent, owned);
    double origin[3], spacing[3];
    input->GetOrigin(origin);
    input->GetSpacing(spacing);
    const bool same = this->RangesValid && input == this->Input && array == this->Array &&
      array->GetMTime() == this->ArrayMTime && std::equal(extent, extent + 6, this->Extent) &&
      std::equal(origin, origin + 3, this->Origin) && std::equal(spacing, spacing + 3, this->Spacing) &&
      std::equal(owned, owned + 6, this->OwnedCells) && array->GetVoidPointer(0) == this->Data &&
      std::equal(wholeExtent, wholeExtent + 6, this->WholeExtent);
    if (same)
    {
      return false;
    }
    this->ForgetInput();
    this->Input = input;
    this->Array = array;
    this->ArrayMTime = array->GetMTime();
    std::copy(extent, extent + 6, this->Extent);
    std::copy(wholeExtent, wholeExtent + 6, this->WholeExtent);
    std::copy(origin, origin + 3, this->Origin);
    std::copy(spacing, spacing + 3, this->Spacing);
    std::copy(owned, owned + 6, this->OwnedCells);
    this->ScalarType = array->GetDataType();
    this->Data = array->GetVoidPointer(0);
    this->WithVolume([&](const auto& volume) {
      mediso::ComputeBlockRanges(volume, this->Ranges, SMPFor);
    });
    this->RangesValid = true;
    return true;
  }

  // Runs f(volume, ranges) on the volume a level is extracted from: the full
  // volume at level 3, the level's coarse copy below (built on first use).
  template <typename F>
  void WithLevelVolume(int level, F&& f)
  {
    this->WithVolume([&](const auto& full) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(full.Data)>>;
      if (level == mediso::NumberOfLevels - 1)
      {
        f(full, this->Ranges);
        return;
      }
      auto& slot = this->Coarse[level];
      if (!slot)
      {
        auto coarse = std::make_unique<CoarseLevel<T>>();
        coarse->Volume = mediso::MakeCoarseCopy(full, level, coarse->Values, SMPFor);
        mediso::ComputeBlockRanges(coarse->Volume, coarse->Ranges, SMPFor);
        slot = std::move(coarse);
      }
      auto* coarse = static_cast<CoarseLevel<T>*>(slot.get());
      f(coarse->Volume, coarse->Ranges);
    });
  }

  // Active blocks of an isovalue (full-volume blocks), listed once and kept
  // for the last few isovalues: every estimate of every level uses them.
  const std::vector<std::int32_t>& ActiveBlocks(double iso)
  {
    for (auto& entry : this->ActiveLists)
    {
      if (entry.first == iso)
      {
        return entry.second;
      }
    }
    if (this->ActiveLists.size() >= 4)
    {
      this->ActiveLists.erase(this->ActiveLists.begin());
    }
    this->ActiveLists.emplace_back(iso, mediso::ListActiveBlocks(this->Ranges, iso));
    return this->ActiveLists.back().second;
  }

  std::int64_t CountActive(double iso)
  {
    return static_cast<std::int64_t>(this->ActiveBlocks(iso).size());
  }

  void RecordExact(const Key& key, const Counts& counts) { this->Exact[key] = counts; }

  void RecordCost(double cubes, double triangles, double seconds)
  {
    this->Sxx += cubes * cubes;
    this->Sxy += cubes * triangles;
    this->Syy += triangles * triangles;
    this->Sxt += cubes * seconds;
    this->Syt += triangles * seconds;
    ++this->CostSamples;
  }

  double PredictSeconds(double cubes, double triangles) const
  {
    // Defaults for a 2-core machine of this project's kind until measured.
    double a = 4.0e-9, b = 6.0e-8;
    const double det = this->Sxx * this->Syy - this->Sxy * this->Sxy;
    if (this->CostSamples >= 2 && det > 1e-12 * this->Sxx * this->Syy)
    {
      a = (this->Sxt * this->Syy - this->Syt * this->Sxy) / det;
      b = (this->Syt * this->Sxx - this->Sxt * this->Sxy) / det;
      if (a < 0 || b < 0)
      {
        // Degenerate fit (collinear samples): one rate per triangle-equivalent.
        const double scale = (this->Sxt + this->Syt) / (this->Sxx + this->Syy);
        a = std::max(0.0, scale);
        b = std::max(0.0, scale);
      }
    }
    else if (this->CostSamples == 1 && this->Sxx + this->Syy > 0)
    {
      const double predicted = std::sqrt(this->Sxx) * a + std::sqrt(this->Syy) * b;
      const double measured = this->Sxt / std::max(1e-30, std::sqrt(this->Sxx));
      if (predicted > 0)
      {
        const double f = measured / predicted;
        a *= f;
        b *= f;
      }
    }
    return a * cubes + b * triangles;
  }

  // Estimated counts, and how they were obtained (0 exact, 1 scaled, 2 sampled):
  // exact for a planned pair; the memoized sampled count; scaled from two
  // exact levels of the same isovalue, by that isovalue's own growth per
  // level (growth is about 4x for smooth surfaces but nearer 2x for thin
  // structures, so no global factor is trusted); otherwise a new count on
  // sampled blocks.
  Counts Estimate(double iso, int level, int& method)
  {
    const Key key(iso, level);
    auto exact = this->Exact.find(key);
    if (exact != this->Exact.end())
    {
      method = 0;
      return exact->second;
    }
    std::vector<int> known;
    for (int l = 0; l < mediso::NumberOfLevels; ++l)
    {
      auto it = this->Exact.find(Key(iso, l));
      if (it != this->Exact.end() && it->second.Triangles > 0)
      {
        known.push_back(l);
      }
    }
    // Scale only where counting would be approximate: with few active blocks
    // every block is counted, which is exact and cheap.
    if (known.size() >= 2 && !this->Sampled.count(key) && SampleStep(this->CountActive(iso)) > 1)
    {
      // The two known levels nearest to the requested one.
      std::sort(known.begin(), known.end(),
        [level](int a, int b) { return std::abs(a - level) < std::abs(b - level); });
      const Counts& a = this->Exact[Key(iso, known[0])];
      const Counts& b = this->Exact[Key(iso, known[1])];
      const double growth = std::pow(a.Triangles / b.Triangles, 1.0 / (known[0] - known[1]));
      const double f = std::pow(growth, level - known[0]);
      Counts c;
      c.Triangles = a.Triangles * f;
      c.Points = a.Points * f;
      c.Cubes = a.Cubes * std::pow(8.0, level - known[0]);
      method = 1;
      return c;
    }
    auto sampled = this->Sampled.find(key);
    if (sampled != this->Sampled.end())
    {
      method = 2;
      return sampled->second;
    }
    Counts c;
    int step = 1;
    if (level < mediso::NumberOfLevels - 1 && this->Coarse[level])
    {
      // The level's coarse copy exists: sample it (contiguous, cheap).
      this->WithLevelVolume(level, [&](const auto& volume, const mediso::BlockRanges& ranges) {
        const std::vector<std::int32_t> active = mediso::ListActiveBlocks(ranges, iso);
        step = SampleStep(static_cast<std::int64_t>(active.size()));
        const mediso::SampledCounts s =
          mediso::CountSampled(volume, ranges, VTKCaseTable(), active, iso, 3, step, SMPFor);
        c.Points = s.Points;
        c.Triangles = s.Triangles;
        c.Cubes = static_cast<double>(s.ActiveBlocks) * std::pow(mediso::BlockCells, 3);
      });
    }
    else
    {
      const std::vector<std::int32_t>& active = this->ActiveBlocks(iso);
      step = SampleStep(static_cast<std::int64_t>(active.size()));
      this->WithVolume([&](const auto& volume) {
        const mediso::SampledCounts s = mediso::CountSampled(
          volume, this->Ranges, VTKCaseTable(), active, iso, level, step, SMPFor);
        c.Points = s.Points;
        c.Triangles = s.Triangles;
        c.Cubes = static_cast<double>(s.ActiveBlocks) *
          std::pow(mediso::BlockCells / mediso::LevelStride(level), 3);
      });
    }
    method = 2;
    if (step == 1)
    {
      this->RecordExact(key, c); // every active block counted: the count is exact
    }
    else
    {
      this->Sampled[key] = c;
    }
    return c;
  }

  void Touch(CacheEntry& entry) { entry.LastUse = ++this->Clock; }

  void Evict(double limitBytes, const std::vector<Key>& keep)
  {
    double total = 0;
    for (const auto& e : this->Cache)
    {
      total += e.second.Bytes;
    }
    while (total > limitBytes && !this->Cache.empty())
    {
      auto victim = this->Cache.end();
      for (auto it = this->Cache.begin(); it != this->Cache.end(); ++it)
      {
        if (std::find(keep.begin(), keep.end(), it->first) != keep.end())
        {
          continue;
        }
        if (victim == this->Cache.end() || it->second.LastUse < victim->second.LastUse)
        {
          victim = it;
        }
      }
      if (victim == this->Cache.end())
      {
        break;
      }
      total -= victim->second.Bytes;
      this->Cache.erase(victim);
    }
  }
};

//------------------------------------------------------------------------------
vtkBlockLODContour::vtkBlockLODContour()
  : Internals(new vtkInternals)
{
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

vtkBlockLODContour::~vtkBlockLODContour() = default;

//------------------------------------------------------------------------------
void vtkBlockLODContour::SetLOD(int level)
{
  if (level < 0 || level >= mediso::NumberOfLevels)
  {
    vtkErrorMacro("LOD " << level << " is outside 0.." << mediso::NumberOfLevels - 1
                         << ": rejected, the level stays " << this->LOD << ".");
    return;
  }
  if (this->LOD != level)
  {
    this->LOD = level;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
vtkMTimeType vtkBlockLODContour::GetMTime()
{
  return std::max(this->Superclass::GetMTime(), this->ContourValues->GetMTime());
}

int vtkBlockLODContour::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!this->Superclass::RequestUpdateExtent(request, inputVector, outputVector))
  {
    return 0;
  }
  // Ghost layers beyond those asked for; the ghost cells make no triangles.
  // Level 3 needs one: gradients at a piece's faces see the neighbour's data.
  // A coarse level samples the whole volume's grid (every piece the same
  // samples); an owned cube of stride s reaches s points past the piece and
  // its normals s more, so a piece needs 2 * 8 - 1 layers for level 0. A
  // parallel run always asks for that many, whatever the level: changing the
  // level then keeps the input (and every cached surface). One piece asks for
  // one layer, which its whole extent ignores.
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  const int ghosts = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS());
  const int pieces = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES());
  const int extra = pieces > 1 ? 2 * mediso::LevelStride(0) - 1 : 1;
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), ghosts + extra);
  return 1;
}

int vtkBlockLODContour::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

void vtkBlockLODContour::ClearCache()
{
  this->Internals->Cache.clear();
}

double vtkBlockLODContour::GetCacheMegabytes()
{
  double total = 0;
  for (const auto& e : this->Internals->Cache)
  {
    total += e.second.Bytes;
  }
  return total / BytesPerMB;
}

//------------------------------------------------------------------------------
double vtkBlockLODContour::EstimateTriangles(double isovalue, int level)
{
  if (!this->Internals->RangesValid || level < 0 || level >= mediso::NumberOfLevels)
  {
    this->LastEstimateMethod = -1;
    return -1;
  }
  return this->Internals->Estimate(isovalue, level, this->LastEstimateMethod).Triangles;
}

double vtkBlockLODContour::EstimateMegabytes(double isovalue, int level)
{
  if (!this->Internals->RangesValid || level < 0 || level >= mediso::NumberOfLevels)
  {
    this->LastEstimateMethod = -1;
    return -1;
  }
  const Counts c = this->Internals->Estimate(isovalue, level, this->LastEstimateMethod);
  const OutputFlags flags{ this->ComputeNormals, this->ComputeScalars, this->GenerateBlockIds };
  return SurfaceBytes(c.Points, c.Triangles, flags) / BytesPerMB;
}

double vtkBlockLODContour::EstimateSeconds(double isovalue, int level)
{
  if (!this->Internals->RangesValid || level < 0 || level >= mediso::NumberOfLevels)
  {
    this->LastEstimateMethod = -1;
    return -1;
  }
  const Key key(isovalue, level);
  if (this->Internals->Cache.count(key))
  {
    this->LastEstimateMethod = 0;
    return 0.0; // served from the cache
  }
  const Counts c = this->Internals->Estimate(isovalue, level, this->LastEstimateMethod);
  return this->Internals->PredictSeconds(c.Cubes, c.Triangles);
}

//------------------------------------------------------------------------------
int vtkBlockLODContour::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0]);
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  this->ChosenLevel = -1;
  std::fill(this->EstimatedTriangles, this->EstimatedTriangles + 4, 0.0);
  std::fill(this->EstimatedMegabytes, this->EstimatedMegabytes + 4, 0.0);
  std::fill(this->EstimatedSeconds, this->EstimatedSeconds + 4, 0.0);
  vtkInternals& in = *this->Internals;
  if (!input || !output)
  {
    return 0;
  }

  // --- Input checks -----------------------------------------------------------
  vtkDataArray* array = this->GetInputArrayToProcess(0, inputVector);
  if (!array)
  {
    vtkErrorMacro("No point scalars to contour: the input has no point data array "
                  "(choose one with SetInputArrayToProcess). The output is empty.");
    return 1;
  }
  if (array->GetNumberOfComponents() != 1)
  {
    vtkErrorMacro("Array '" << (array->GetName() ? array->GetName() : "")
                            << "' has " << array->GetNumberOfComponents()
                            << " components; contouring needs one. The output is empty.");
    return 1;
  }
  int dims[3];
  input->GetDimensions(dims);
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2)
  {
    vtkErrorMacro("Input is " << dims[0] << " x " << dims[1] << " x " << dims[2]
                              << " points: isosurfaces need 3D image data with at least 2 "
                                 "points along each axis. The output is empty.");
    return 1;
  }
  if (input->GetDirectionMatrix() && !input->GetDirectionMatrix()->IsIdentity())
  {
    vtkErrorMacro("The input has a non-identity direction matrix, which this filter does not "
                  "support; resample it to an axis-aligned grid first. The output is empty.");
    return 1;
  }
  bool supported = DispatchScalarType(array->GetDataType(), [](auto) {});
  if (!supported || !array->HasStandardMemoryLayout() ||
    array->GetNumberOfTuples() != static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2])
  {
    vtkErrorMacro("Array '" << (array->GetName() ? array->GetName() : "") << "' of type "
                            << array->GetDataTypeAsString()
                            << " is not supported (use a contiguous point array of 8/16/32-bit "
                               "integers, float or double). The output is empty.");
    return 1;
  }
  const vtkIdType numValues = this->ContourValues->GetNumberOfContours();
  if (numValues < 1)
  {
    vtkDebugMacro("No isovalues: empty output.");
    return 1;
  }

  // --- Block ranges (once per input) --------------------------------------------
  int wholeExtent[6] = { 0, -1, 0, -1, 0, -1 };
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
  {
    inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), wholeExtent);
  }
  // The piece without ghost layers, for an input that lost its ghost array.
  int zeroExtent[6];
  const int* zero = nullptr;
  const int numPieces = inInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES())
    ? inInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES())
    : 1;
  if (numPieces > 1 && !input->GetCellGhostArray() && wholeExtent[0] <= wholeExtent[1])
  {
    vtkNew<vtkExtentTranslator> translator;
    translator->SetWholeExtent(wholeExtent);
    translator->SetPiece(inInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()));
    translator->SetNumberOfPieces(numPieces);
    translator->SetGhostLevel(0);
    translator->PieceToExtent();
    translator->GetExtent(zeroExtent);
    zero = zeroExtent;
  }
  if (in.Refresh(input, array, wholeExtent, zero))
  {
    ++this->NumberOfBlockRangeComputations;
  }
  this->UpdateProgress(0.1);
  if (in.Ranges.NaNCount > 0 && !in.WarnedNaN)
  {
    vtkWarningMacro("The input has NaN values: cubes touching them produce no surface.");
    in.WarnedNaN = true;
  }
  const double* range = in.Ranges.ValueRange;
  // A parallel piece may well lie outside an isovalue (all air, say): only a
  // whole volume warns about its range.
  const bool piece = in.IsPiece();
  if (!(range[0] < range[1]))
  {
    if (piece)
    {
      vtkDebugMacro("This piece is constant (" << range[0] << "): no surface here.");
    }
    else
    {
      vtkWarningMacro("The input is constant (" << range[0] << "): there is no isosurface.");
    }
    return 1;
  }
  const OutputFlags flags{ this->ComputeNormals, this->ComputeScalars, this->GenerateBlockIds };
  if (!(flags == in.CacheFlags))
  {
    in.Cache.clear();
    in.CacheFlags = flags;
  }

  std::vector<double> values;
  for (vtkIdType i = 0; i < numValues; ++i)
  {
    const double v = this->ContourValues->GetValue(static_cast<int>(i));
    if (!(v > range[0] && v <= range[1]))
    {
      if (piece)
      {
        vtkDebugMacro("Isovalue " << v << " is outside this piece's range.");
        continue;
      }
      vtkWarningMacro("Isovalue " << v << " is outside the data range (" << range[0] << ", "
                                  << range[1] << "]: it has no surface.");
      continue;
    }
    if (std::find(values.begin(), values.end(), v) == values.end())
    {
      values.push_back(v);
    }
  }
  if (values.empty())
  {
    return 1;
  }

  // --- Estimates and the level ----------------------------------------------------
  const double budgetBytes = this->MemoryBudget * BytesPerMB;
  int level = this->LOD;
  if (this->AutoLOD)
  {
    level = -1;
    double needLevel0 = 0;
    for (int l = mediso::NumberOfLevels - 1; l >= 0 && level < 0; --l)
    {
      double bytes = 0;
      for (double v : values)
      {
        int method;
        const Counts c = in.Estimate(v, l, method);
        bytes += SurfaceBytes(c.Points, c.Triangles, flags);
      }
      if (bytes <= budgetBytes)
      {
        level = l;
      }
      needLevel0 = bytes;
    }
    if (level < 0)
    {
      vtkErrorMacro("MemoryBudget " << this->MemoryBudget << " MB is too small: even level 0 needs "
                                    << needLevel0 / BytesPerMB << " MB. The output is empty.");
      return 1;
    }
  }

  // --- Pass 1 for every pair not cached: exact sizes before any allocation -------------
  const mediso::TriangleCaseTable cases = VTKCaseTable();
  auto abort = [this]() { return this->GetAbortExecute() != 0; };
  std::map<double, mediso::ExtractionPlan> plans;
  std::map<double, double> planSeconds;
  for (;;)
  {
    plans.clear();
    double bytes = 0;
    for (double v : values)
    {
      const Key key(v, level);
      auto cached = in.Cache.find(key);
      if (cached != in.Cache.end())
      {
        bytes += cached->second.Bytes;
        continue;
      }
      mediso::ExtractionPlan& plan = plans[v];
      const double start = Now();
      bool complete = true;
      // Marching cubes at stride 1 on the level's samples: the level's surface.
      in.WithLevelVolume(level, [&](const auto& volume, const mediso::BlockRanges& ranges) {
        complete = mediso::PlanExtraction(volume, ranges, cases, v, 3, plan, SMPFor, abort);
      });
      if (!complete || this->CheckAbort())
      {
        output->Initialize();
        return 1;
      }
      planSeconds[v] = Now() - start;
      Counts exact;
      exact.Points = static_cast<double>(plan.GetNumberOfPoints());
      exact.Triangles = static_cast<double>(plan.GetNumberOfTriangles());
      exact.Cubes = static_cast<double>(plan.ActiveBlocks.size()) * plan.CubesPerBlock;
      in.RecordExact(key, exact);
      bytes += SurfaceBytes(exact.Points, exact.Triangles, flags);
    }
    if (!this->AutoLOD || bytes <= budgetBytes)
    {
      break;
    }
    if (level == 0)
    {
      vtkErrorMacro("MemoryBudget " << this->MemoryBudget << " MB is too small: level 0 needs "
                                    << bytes / BytesPerMB << " MB. The output is empty.");
      return 1;
    }
    vtkWarningMacro("Level " << level << " needs " << bytes / BytesPerMB
                             << " MB, over the MemoryBudget of " << this->MemoryBudget
                             << " MB (the estimate was low): using level " << level - 1 << ".");
    --level;
  }
  this->ChosenLevel = level;
  // Estimates of every level for the first isovalue, reported after planning:
  // the planned level's is exact, and AutoLOD's were made while choosing.
  for (int l = 0; l < mediso::NumberOfLevels; ++l)
  {
    this->EstimatedTriangles[l] = this->EstimateTriangles(values[0], l);
    this->EstimatedMegabytes[l] = this->EstimateMegabytes(values[0], l);
    this->EstimatedSeconds[l] = this->EstimateSeconds(values[0], l);
  }
  this->UpdateProgress(0.5);

  // --- Pass 2: generate, cache -------------------------------------------------
  std::vector<vtkSmartPointer<vtkPolyData>> pieces;
  std::vector<Key> used;
  for (double v : values)
  {
    const Key key(v, level);
    used.push_back(key);
    auto cached = in.Cache.find(key);
    if (cached != in.Cache.end())
    {
      ++this->NumberOfCacheHits;
      in.Touch(cached->second);
      pieces.push_back(cached->second.Surface);
      continue;
    }
    const mediso::ExtractionPlan& plan = plans[v];
    const double start = Now();
    SurfaceArrays arrays =
      AllocateSurface(plan.GetNumberOfPoints(), plan.GetNumberOfTriangles(), flags);
    in.WithLevelVolume(level, [&](const auto& volume, const mediso::BlockRanges& ranges) {
      if (arrays.Connectivity32)
      {
        mediso::SurfaceBuffers<std::int32_t> buffers;
        buffers.Points = arrays.Points;
        buffers.Normals = arrays.Normals;
        buffers.Scalars = arrays.Scalars;
        buffers.BlockIds = arrays.BlockIds;
        buffers.Connectivity = arrays.Connectivity32;
        mediso::GenerateSurface(volume, ranges, cases, plan, buffers, SMPFor);
      }
      else
      {
        mediso::SurfaceBuffers<std::int64_t> buffers;
        buffers.Points = arrays.Points;
        buffers.Normals = arrays.Normals;
        buffers.Scalars = arrays.Scalars;
        buffers.BlockIds = arrays.BlockIds;
        buffers.Connectivity = arrays.Connectivity64;
        mediso::GenerateSurface(volume, ranges, cases, plan, buffers, SMPFor);
      }
    });
    ++this->NumberOfExtractions;
    const double seconds = planSeconds[v] + (Now() - start);
    in.RecordCost(static_cast<double>(plan.ActiveBlocks.size()) * plan.CubesPerBlock,
      static_cast<double>(plan.GetNumberOfTriangles()), seconds);
    pieces.push_back(arrays.Surface);
    if (this->CacheMemoryLimit > 0)
    {
      CacheEntry& entry = in.Cache[key];
      entry.Surface = arrays.Surface;
      entry.Bytes = SurfaceBytes(static_cast<double>(plan.GetNumberOfPoints()),
        static_cast<double>(plan.GetNumberOfTriangles()), flags);
      in.Touch(entry);
    }
    if (this->CheckAbort())
    {
      output->Initialize();
      return 1;
    }
  }
  in.Evict(this->CacheMemoryLimit * BytesPerMB, used);
  this->UpdateProgress(0.9);

  // --- Output ----------------------------------------------------------------------
  if (pieces.size() == 1)
  {
    output->ShallowCopy(pieces[0]);
  }
  else
  {
    std::int64_t points = 0, triangles = 0;
    for (const auto& p : pieces)
    {
      points += p->GetNumberOfPoints();
      triangles += p->GetNumberOfPolys();
    }
    SurfaceArrays all = AllocateSurface(points, triangles, flags);
    std::int64_t p0 = 0, t0 = 0;
    for (const auto& p : pieces)
    {
      const std::int64_t np = p->GetNumberOfPoints();
      const std::int64_t nt = p->GetNumberOfPolys();
      auto copy = [&](vtkDataArray* a, float* dst, int comps) {
        if (a && dst)
        {
          std::memcpy(dst + comps * p0, a->GetVoidPointer(0), sizeof(float) * comps * np);
        }
      };
      copy(p->GetPoints()->GetData(), all.Points, 3);
      copy(p->GetPointData()->GetNormals(), all.Normals, 3);
      copy(p->GetPointData()->GetScalars(), all.Scalars, 1);
      if (all.BlockIds)
      {
        std::memcpy(all.BlockIds + t0, p->GetCellData()->GetArray("BlockId")->GetVoidPointer(0),
          sizeof(std::int32_t) * nt);
      }
      vtkDataArray* conn = p->GetPolys()->GetConnectivityArray();
      for (std::int64_t i = 0; i < 3 * nt; ++i)
      {
        const std::int64_t id = static_cast<std::int64_t>(conn->GetComponent(i, 0)) + p0;
        if (all.Connectivity32)
        {
          all.Connectivity32[3 * t0 + i] = static_cast<std::int32_t>(id);
        }
        else
        {
          all.Connectivity64[3 * t0 + i] = id;
        }
      }
      p0 += np;
      t0 += nt;
    }
    output->ShallowCopy(all.Surface);
  }

  auto addField = [output](const char* name, const double* v, int n) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfValues(n);
    std::copy(v, v + n, a->GetPointer(0));
    output->GetFieldData()->AddArray(a);
  };
  const double chosen = level;
  addField("BlockLODLevel", &chosen, 1);
  addField("BlockLODEstimatedTriangles", this->EstimatedTriangles, 4);
  addField("BlockLODEstimatedMB", this->EstimatedMegabytes, 4);
  addField("BlockLODEstimatedSeconds", this->EstimatedSeconds, 4);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
void vtkBlockLODContour::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  this->ContourValues->PrintSelf(os, indent.GetNextIndent());
  os << indent << "LOD: " << this->LOD << "\n";
  os << indent << "AutoLOD: " << this->AutoLOD << "\n";
  os << indent << "MemoryBudget: " << this->MemoryBudget << " MB\n";
  os << indent << "ComputeNormals: " << this->ComputeNormals << "\n";
  os << indent << "ComputeScalars: " << this->ComputeScalars << "\n";
  os << indent << "GenerateBlockIds: " << this->GenerateBlockIds << "\n";
  os << indent << "CacheMemoryLimit: " << this->CacheMemoryLimit << " MB\n";
  os << indent << "ChosenLevel: " << this->ChosenLevel << "\n";
  os << indent << "NumberOfExtractions: " << this->NumberOfExtractions << "\n";
  os << indent << "NumberOfCacheHits: " << this->NumberOfCacheHits << "\n";
}
