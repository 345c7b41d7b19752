// SPDX-License-Identifier: BSD-3-Clause
#include "vtkBlockLODContour.h"

#include "BlockLODSurfaces.h"
#include "LargeBuffers.h"
#include "ProcessMemory.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkExtentTranslator.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationDoubleVectorKey.h"
#include "vtkInformationInformationVectorKey.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMarchingCubesTriangleCases.h"
#include "vtkMatrix3x3.h"
#include "vtkMedicalCoreScalarType.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPThreadLocal.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkTypeInt32Array.h"
#include "vtkTypeInt64Array.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWeakPointer.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <new>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

vtkStandardNewMacro(vtkBlockLODContour);

namespace
{
constexpr double BytesPerMB = 1.0e6;

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

// The cell offsets of a triangle surface are 0, 3, 6, ...: the same values for
// every surface. One process-wide, read-only run of them (per id width) backs
// the offsets array of every surface the filter makes, as VTK 9.4's affine
// offsets do, so that an isovalue change neither writes nor faults in 8 (or 4)
// fresh bytes per triangle: on a noisy MRI with half its blocks active that
// was a tenth of the warm change. Each surface's array is a view of the run's
// first values; the run is freed when the last view goes and it is no longer
// the newest (vtkBuffer calls Release when an array lets its memory go, and
// copies the values out first if anything grows the array).
class SharedTriangleOffsets
{
public:
  // An array of the offsets of `triangles` triangles, or null when memory ran
  // out (the caller then makes an array of its own, which reports it).
  template <typename ArrayT>
  vtkSmartPointer<ArrayT> View(vtkIdType triangles)
  {
    using ValueT = typename ArrayT::ValueType;
    constexpr int width = sizeof(ValueT) == 4 ? 0 : 1;
    const vtkIdType values = triangles + 1;
    ValueT* run = nullptr;
    {
      std::lock_guard<std::mutex> lock(this->Mutex);
      Run* current = this->Newest[width] ? &this->Runs[this->Newest[width]] : nullptr;
      if (!current || current->Values < values)
      {
        // Grown with a little room, so that a sweep of slowly growing
        // surfaces does not write a new run at every step.
        const vtkIdType room = current ? current->Values + current->Values / 16 : 0;
        const vtkIdType n = std::max(values, room);
        ValueT* fresh = new (std::nothrow) ValueT[n];
        if (!fresh)
        {
          return nullptr;
        }
        vtkSMPTools::For(0, n, [fresh](vtkIdType b, vtkIdType e) {
          for (vtkIdType i = b; i < e; ++i)
          {
            fresh[i] = static_cast<ValueT>(3 * i);
          }
        });
        void* previous = this->Newest[width];
        this->Newest[width] = fresh;
        current = &this->Runs[fresh];
        current->Values = n;
        current->Width = width;
        if (previous && this->Runs[previous].Views == 0)
        {
          this->Free(previous);
        }
      }
      ++current->Views;
      run = static_cast<ValueT*>(this->Newest[width]);
    }
    auto array = vtkSmartPointer<ArrayT>::New();
    array->SetArray(run, values, 0, ArrayT::VTK_DATA_ARRAY_USER_DEFINED);
    array->SetArrayFreeFunction(&SharedTriangleOffsets::Release);
    return array;
  }

private:
  struct Run
  {
    vtkIdType Values = 0;
    int Width = 0;
    int Views = 0;
  };

  static void Release(void* pointer);

  void Free(void* pointer)
  {
    if (this->Runs[pointer].Width == 0)
    {
      delete[] static_cast<std::int32_t*>(pointer);
    }
    else
    {
      delete[] static_cast<vtkTypeInt64*>(pointer);
    }
    this->Runs.erase(pointer);
  }

  std::mutex Mutex;
  std::map<void*, Run> Runs;
  void* Newest[2] = { nullptr, nullptr }; // 32-bit, 64-bit
};

// Never destroyed: arrays that outlive static destruction (a surface held by
// a Python global, say) still release into it.
SharedTriangleOffsets* const TriangleOffsets = new SharedTriangleOffsets;

void SharedTriangleOffsets::Release(void* pointer)
{
  SharedTriangleOffsets& shared = *TriangleOffsets;
  std::lock_guard<std::mutex> lock(shared.Mutex);
  auto run = shared.Runs.find(pointer);
  if (run == shared.Runs.end())
  {
    return;
  }
  --run->second.Views;
  const bool newest = shared.Newest[run->second.Width] == pointer;
  if (run->second.Views == 0)
  {
    if (newest)
    {
      shared.Newest[run->second.Width] = nullptr;
    }
    shared.Free(pointer);
  }
}

// An array of `values` values in `memory` from mediso::LargeBuffers (the
// process's), which the array gives back there when it lets it go: arrays of
// 32 MiB and more, which glibc would map afresh for every surface and unmap
// when freed, reuse the pages of those released before them (LargeBuffers.h).
// Anything that grows such an array copies it out first (vtkBuffer does so
// for memory with a free function of its own).
template <typename ArrayT>
void AdoptLargeBuffer(ArrayT* array, void* memory, vtkIdType values)
{
  using ValueT = typename ArrayT::ValueType;
  array->SetArray(static_cast<ValueT*>(memory), values, 0, ArrayT::VTK_DATA_ARRAY_USER_DEFINED);
  array->SetArrayFreeFunction(&mediso::LargeBuffers::ReleaseToProcess);
}

// Memory of the surfaces the cache drops during one update, for the update's
// new surfaces (SurfaceMaker::Recycle in BlockLODSurfaces.h). A fresh output
// buffer costs a page fault and a page the kernel zeroes per 4 KB: on a noisy
// MRI with half its blocks active that is a third of a warm change, and
// vtkFlyingEdges3D pays it too. Once the cache is full, as while an isovalue
// is dragged, every new surface makes it drop the oldest: its buffers, resized
// with realloc (which keeps their mapped pages: mremap for large blocks), take
// the new surface's values instead of being unmapped while fresh ones fault
// in. Only buffers that nothing outside the dropped surface holds are taken
// (a shallow copy shares the arrays, or their vtkPoints and vtkCellArray); the
// shared triangle offsets never are. What the update does not use is freed
// with the pool, at the update's end.
class SpareBuffers
{
public:
  SpareBuffers() = default;
  SpareBuffers(const SpareBuffers&) = delete;
  SpareBuffers& operator=(const SpareBuffers&) = delete;
  ~SpareBuffers()
  {
    for (const Buffer& b : this->Buffers)
    {
      if (b.Large)
      {
        mediso::LargeBuffers::Process().Release(b.Pointer);
      }
      else
      {
        free(b.Pointer);
      }
    }
  }

  // Takes the buffers of a dropped surface that only it holds.
  void Take(vtkPolyData* surface)
  {
    if (!surface || surface->GetReferenceCount() != 1)
    {
      return;
    }
    vtkPoints* points = surface->GetPoints();
    if (points && points->GetReferenceCount() == 1)
    {
      this->TakeArray(points->GetData());
    }
    for (vtkDataSetAttributes* attributes :
      { static_cast<vtkDataSetAttributes*>(surface->GetPointData()),
        static_cast<vtkDataSetAttributes*>(surface->GetCellData()) })
    {
      for (int a = 0; a < attributes->GetNumberOfArrays(); ++a)
      {
        this->TakeArray(attributes->GetAbstractArray(a));
      }
    }
    vtkCellArray* polys = surface->GetPolys();
    if (polys && polys->GetReferenceCount() == 1)
    {
      this->TakeArray(polys->GetConnectivityArray());
    }
  }

  // Gives `array` `tuples` tuples, in a spare buffer when one is big enough
  // (or, the largest, at least half as big: realloc and mremap keep its pages
  // and add the rest), else in new memory (LargeBuffers for a large array);
  // the values are left unset, as SetNumberOfTuples leaves them.
  template <typename ArrayT>
  void Size(ArrayT* array, vtkIdType tuples)
  {
    using ValueT = typename ArrayT::ValueType;
    const vtkIdType values = tuples * array->GetNumberOfComponents();
    const std::size_t bytes = static_cast<std::size_t>(values) * sizeof(ValueT);
    // The smallest spare that fits, else the largest that is half as big.
    const std::size_t none = this->Buffers.size();
    std::size_t fitting = none, largest = none;
    for (std::size_t b = 0; b < this->Buffers.size(); ++b)
    {
      const std::size_t has = this->Buffers[b].Bytes;
      if (has >= bytes)
      {
        fitting = fitting == none || has < this->Buffers[fitting].Bytes ? b : fitting;
      }
      else if (2 * has >= bytes)
      {
        largest = largest == none || has > this->Buffers[largest].Bytes ? b : largest;
      }
    }
    const std::size_t best = fitting != none ? fitting : largest;
    if (values > 0 && best != none)
    {
      const Buffer spare = this->Buffers[best];
      if (spare.Large)
      {
        if (void* memory = mediso::LargeBuffers::Process().Resize(spare.Pointer, bytes))
        {
          this->Buffers.erase(this->Buffers.begin() + static_cast<std::ptrdiff_t>(best));
          AdoptLargeBuffer(array, memory, values);
          return;
        }
      }
      else if (void* memory = realloc(spare.Pointer, bytes))
      {
        this->Buffers.erase(this->Buffers.begin() + static_cast<std::ptrdiff_t>(best));
        array->SetArray(static_cast<ValueT*>(memory), values, 0, ArrayT::VTK_DATA_ARRAY_FREE);
        return;
      }
    }
    if (void* memory = mediso::LargeBuffers::Process().Allocate(bytes))
    {
      AdoptLargeBuffer(array, memory, values);
      return;
    }
    array->SetNumberOfTuples(tuples);
  }

private:
  struct Buffer
  {
    void* Pointer;
    std::size_t Bytes;
    bool Large; // from LargeBuffers, else from malloc
  };

  void TakeArray(vtkAbstractArray* array)
  {
    if (array && array->GetReferenceCount() == 1)
    {
      this->TakeAs<float>(array) || this->TakeAs<int>(array) || this->TakeAs<vtkTypeInt64>(array);
    }
  }

  // The arrays of the filter's surfaces are allocated by vtkBuffer with malloc,
  // or by LargeBuffers (Size() above): their memory may be resized and freed
  // here, each kind by its own functions.
  template <typename ValueT>
  bool TakeAs(vtkAbstractArray* array)
  {
    auto* typed = vtkAOSDataArrayTemplate<ValueT>::FastDownCast(array);
    if (!typed)
    {
      return false;
    }
    ValueT* memory = typed->GetPointer(0);
    const vtkIdType size = typed->GetSize();
    if (memory && size > 0)
    {
      const std::size_t mapped = mediso::LargeBuffers::Process().Capacity(memory);
      typed->SetArray(memory, size, 1); // the array no longer frees it
      this->Buffers.push_back(mapped > 0
          ? Buffer{ memory, mapped, true }
          : Buffer{ memory, static_cast<std::size_t>(size) * sizeof(ValueT), false });
    }
    return true;
  }

  std::vector<Buffer> Buffers;
};

// VTK's arrays report a failed allocation and stay empty (they do not throw):
// Valid() is false then. `spares` (may be null): memory to reuse, the largest
// array (the connectivity) served first.
SurfaceArrays AllocateSurface(std::int64_t points, std::int64_t triangles,
  const mediso::SurfaceLayout& layout, SpareBuffers* spares = nullptr)
{
  SpareBuffers none;
  SpareBuffers& memory = spares ? *spares : none;
  SurfaceArrays out;
  out.Surface = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkCellArray> polys;
  const bool small =
    layout.IdBytesFor(static_cast<double>(points), static_cast<double>(triangles)) == 4;
  // The shared offsets, or (memory ran out) an array of its own that reports it.
  auto offsetsFor = [triangles](auto* typeTag) {
    using ArrayT = std::remove_pointer_t<decltype(typeTag)>;
    vtkSmartPointer<ArrayT> offsets = TriangleOffsets->View<ArrayT>(triangles);
    if (!offsets)
    {
      offsets = vtkSmartPointer<ArrayT>::New();
      offsets->SetNumberOfValues(triangles + 1);
    }
    return offsets;
  };
  if (small)
  {
    vtkSmartPointer<vtkTypeInt32Array> offsets =
      offsetsFor(static_cast<vtkTypeInt32Array*>(nullptr));
    vtkNew<vtkTypeInt32Array> connectivity;
    memory.Size(connectivity.Get(), 3 * triangles);
    out.Connectivity32 = connectivity->GetPointer(0);
    polys->SetData(offsets, connectivity);
  }
  else
  {
    vtkSmartPointer<vtkTypeInt64Array> offsets =
      offsetsFor(static_cast<vtkTypeInt64Array*>(nullptr));
    vtkNew<vtkTypeInt64Array> connectivity;
    memory.Size(connectivity.Get(), 3 * triangles);
    // vtkTypeInt64 is long long, std::int64_t long: same 64-bit representation.
    out.Connectivity64 = reinterpret_cast<std::int64_t*>(connectivity->GetPointer(0));
    polys->SetData(offsets, connectivity);
  }
  out.Surface->SetPolys(polys);
  vtkNew<vtkFloatArray> coords;
  coords->SetNumberOfComponents(3);
  memory.Size(coords.Get(), points);
  out.Points = coords->GetPointer(0);
  vtkNew<vtkPoints> pts;
  pts->SetData(coords);
  out.Surface->SetPoints(pts);
  if (layout.Normals)
  {
    vtkNew<vtkFloatArray> normals;
    normals->SetName("Normals");
    normals->SetNumberOfComponents(3);
    memory.Size(normals.Get(), points);
    out.Normals = normals->GetPointer(0);
    out.Surface->GetPointData()->SetNormals(normals);
  }
  if (layout.Scalars)
  {
    vtkNew<vtkFloatArray> scalars;
    scalars->SetName("Isovalue");
    memory.Size(scalars.Get(), points);
    out.Scalars = scalars->GetPointer(0);
    out.Surface->GetPointData()->SetScalars(scalars);
  }
  if (layout.BlockIds)
  {
    vtkNew<vtkIntArray> ids;
    ids->SetName("BlockId");
    memory.Size(ids.Get(), triangles);
    out.BlockIds = reinterpret_cast<std::int32_t*>(ids->GetPointer(0));
    out.Surface->GetCellData()->AddArray(ids);
  }
  return out;
}

bool Valid(const SurfaceArrays& a, std::int64_t points, std::int64_t triangles)
{
  vtkPolyData* s = a.Surface;
  vtkCellArray* polys = s->GetPolys();
  return s->GetNumberOfPoints() == points && polys->GetNumberOfCells() == triangles &&
    polys->GetConnectivityArray()->GetNumberOfValues() == 3 * triangles &&
    (!a.Normals || s->GetPointData()->GetNormals()->GetNumberOfTuples() == points) &&
    (!a.Scalars || s->GetPointData()->GetScalars()->GetNumberOfTuples() == points) &&
    (!a.BlockIds || s->GetCellData()->GetArray("BlockId")->GetNumberOfTuples() == triangles);
}

// "its point arrays: 'a' (1 component), 'b' (3 components)", or "it has no
// point arrays", for messages about the array to contour.
std::string DescribeArrays(vtkFieldData* data, const char* kind)
{
  std::ostringstream text;
  int listed = 0;
  for (int i = 0; i < data->GetNumberOfArrays(); ++i)
  {
    vtkAbstractArray* a = data->GetAbstractArray(i);
    if (!a)
    {
      continue;
    }
    text << (listed++ ? ", '" : "'") << (a->GetName() ? a->GetName() : "(unnamed)") << "' ("
         << a->GetNumberOfComponents()
         << (a->GetNumberOfComponents() == 1 ? " component" : " components")
         << (vtkArrayDownCast<vtkDataArray>(a) ? "" : ", not numeric") << ")";
  }
  if (listed == 0)
  {
    return std::string("it has no ") + kind + " arrays";
  }
  return std::string("its ") + kind + (listed == 1 ? " array: " : " arrays: ") + text.str();
}

// Bytes of the output the filter's options make (what estimates in MB count).
mediso::SurfaceLayout OutputLayout(vtkBlockLODContour* self)
{
  mediso::SurfaceLayout layout;
  layout.Normals = self->GetComputeNormals();
  layout.Scalars = self->GetComputeScalars();
  layout.BlockIds = self->GetGenerateBlockIds();
  layout.Offsets = true; // vtkCellArray: offsets and connectivity
  layout.IdBytes = self->GetCompactIds() ? 4 : 8;
  return layout;
}

// The cost model of EstimateSeconds(): it describes the machine, not an input,
// so every filter of the process learns into and predicts from the same one
// (made on first use, shared by the filters' surfaces units).
std::shared_ptr<mediso::SharedCostModel> ProcessCostModel()
{
  static const std::shared_ptr<mediso::SharedCostModel> model =
    std::make_shared<mediso::SharedCostModel>();
  return model;
}

// "  (the process may still allocate 12.3 MB: the process's address-space
// limit (ulimit -v))", for a message about memory that ran out.
std::string DescribeAllowance()
{
  const mediso::MemoryAllowance allowance = mediso::ProcessMemoryAllowance();
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(1);
  if (allowance.Bounded())
  {
    text << " (the process may still allocate " << static_cast<double>(allowance.Bytes) / BytesPerMB
         << " MB: " << allowance.Limit << ")";
  }
  return text.str();
}

// Stores a vector array's ranges in VTK's range cache (per component and of
// the length, finite or not: the array holds only finite values).
void CacheRanges(vtkDataArray* array, const mediso::VectorRange& range)
{
  if (!array || range.IsEmpty())
  {
    return;
  }
  vtkInformation* info = array->GetInformation();
  for (vtkInformationInformationVectorKey* key :
    { vtkAbstractArray::PER_COMPONENT(), vtkAbstractArray::PER_FINITE_COMPONENT() })
  {
    vtkNew<vtkInformationVector> components;
    components->SetNumberOfInformationObjects(3);
    for (int c = 0; c < 3; ++c)
    {
      const double r[2] = { range.Min[c], range.Max[c] };
      components->GetInformationObject(c)->Set(vtkDataArray::COMPONENT_RANGE(), r, 2);
    }
    info->Set(key, components);
  }
  const double length[2] = { std::sqrt(range.MinLength2), std::sqrt(range.MaxLength2) };
  info->Set(vtkDataArray::L2_NORM_RANGE(), length, 2);
  info->Set(vtkDataArray::L2_NORM_FINITE_RANGE(), length, 2);
}

// The same for a one-component array of a known range.
void CacheRanges(vtkDataArray* array, double lo, double hi)
{
  if (!array)
  {
    return;
  }
  vtkInformation* info = array->GetInformation();
  const double r[2] = { lo, hi };
  for (vtkInformationInformationVectorKey* key :
    { vtkAbstractArray::PER_COMPONENT(), vtkAbstractArray::PER_FINITE_COMPONENT() })
  {
    vtkNew<vtkInformationVector> components;
    components->SetNumberOfInformationObjects(1);
    components->GetInformationObject(0)->Set(vtkDataArray::COMPONENT_RANGE(), r, 2);
    info->Set(key, components);
  }
  info->Set(vtkDataArray::L2_NORM_RANGE(), r, 2);
  info->Set(vtkDataArray::L2_NORM_FINITE_RANGE(), r, 2);
}

// The cached ranges of a 3-component array as a VectorRange (GetRange reads
// the cache; the array is read only where a range is not cached).
mediso::VectorRange RangesOf(vtkDataArray* array)
{
  mediso::VectorRange range;
  if (!array || array->GetNumberOfTuples() == 0)
  {
    return range;
  }
  double r[2];
  for (int c = 0; c < 3; ++c)
  {
    array->GetRange(r, c);
    range.Min[c] = r[0];
    range.Max[c] = r[1];
  }
  array->GetRange(r, -1);
  range.MinLength2 = r[0] * r[0];
  range.MaxLength2 = r[1] * r[1];
  return range;
}

double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Where the surfaces go in the world. The core makes them on the grid without
// its direction (origin + index x spacing); VTK's image contour filters
// (vtkFlyingEdges3D, vtkContourFilter) contour that way too and then place
// their output by the image's index-to-physical matrix (vtkImageTransform):
// a point x goes to origin + D (x - origin) for the direction D, a normal n
// to det(D) D n. The triangles keep their order, so for a mirror image
// (det -1) the normals turn with the faces' winding, as VTK's do. Surfaces
// are placed once, when made, so that a cached one is ready as it is.
struct Placement
{
  bool Identity = true;
  double Matrix[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 }; // row-major
  double Offset[3] = { 0, 0, 0 };
  double Sign = 1; // det(D): +1 or -1 for an orthonormal direction

  static Placement Of(vtkImageData* image)
  {
    Placement p;
    vtkMatrix3x3* direction = image->GetDirectionMatrix();
    if (!direction || direction->IsIdentity())
    {
      return p;
    }
    p.Identity = false;
    std::copy(direction->GetData(), direction->GetData() + 9, p.Matrix);
    p.Sign = direction->Determinant() < 0 ? -1.0 : 1.0;
    const double* o = image->GetOrigin();
    for (int r = 0; r < 3; ++r)
    {
      const double* m = p.Matrix + 3 * r;
      p.Offset[r] = o[r] - (m[0] * o[0] + m[1] * o[1] + m[2] * o[2]);
    }
    return p;
  }

  bool operator==(const Placement& o) const
  {
    return this->Identity == o.Identity && std::equal(this->Matrix, this->Matrix + 9, o.Matrix) &&
      std::equal(this->Offset, this->Offset + 3, o.Offset);
  }
  bool operator!=(const Placement& o) const { return !(*this == o); }

  // Places a surface made by the core in place, and stores the ranges of its
  // points and normals as placed.
  void Apply(vtkPolyData* surface) const
  {
    vtkFloatArray* points = vtkFloatArray::FastDownCast(surface->GetPoints()->GetData());
    vtkFloatArray* normals = vtkFloatArray::FastDownCast(surface->GetPointData()->GetNormals());
    float* x = points ? points->GetPointer(0) : nullptr;
    float* n = normals ? normals->GetPointer(0) : nullptr;
    const vtkIdType count = surface->GetNumberOfPoints();
    vtkSMPThreadLocal<mediso::SurfaceRanges> local;
    vtkSMPTools::For(0, count,
      [&](vtkIdType begin, vtkIdType end)
      {
        mediso::SurfaceRanges& ranges = local.Local();
        const double* m = this->Matrix;
        for (vtkIdType i = begin; i < end; ++i)
        {
          if (x)
          {
            float* p = x + 3 * i;
            const double a = p[0], b = p[1], c = p[2];
            for (int r = 0; r < 3; ++r)
            {
              p[r] = static_cast<float>(
                m[3 * r] * a + m[3 * r + 1] * b + m[3 * r + 2] * c + this->Offset[r]);
            }
            ranges.Points.Add(p);
          }
          if (n)
          {
            float* q = n + 3 * i;
            double t[3];
            for (int r = 0; r < 3; ++r)
            {
              t[r] = this->Sign * (m[3 * r] * q[0] + m[3 * r + 1] * q[1] + m[3 * r + 2] * q[2]);
            }
            // D is orthonormal within CheckInput's tolerance: the length is
            // kept but for that error, which this takes out.
            const double length = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
            const double scale = length > 0 ? 1.0 / length : 0.0;
            for (int r = 0; r < 3; ++r)
            {
              q[r] = static_cast<float>(t[r] * scale);
            }
            ranges.Normals.Add(q);
          }
        }
      });
    mediso::SurfaceRanges all;
    for (const mediso::SurfaceRanges& r : local)
    {
      all.Points.Merge(r.Points);
      all.Normals.Merge(r.Normals);
    }
    if (points)
    {
      points->Modified();
      CacheRanges(points, all.Points);
    }
    if (normals)
    {
      normals->Modified();
      CacheRanges(normals, all.Normals);
    }
  }
};

// How far a direction may be from orthonormal (each entry of D^T D against
// the identity's): the rounding of a header's cosines, well below what would
// tilt a normal visibly.
constexpr double OrthonormalTolerance = 1e-3;
} // namespace

struct vtkBlockLODContour::vtkInternals
{
  // The core's volume, estimator, cache and planning (Filters/Core/BlockLODSurfaces.h).
  mediso::BlockLODSurfaces<vtkSmartPointer<vtkPolyData>> Surfaces{ VTKCaseTable(), SMPFor,
    ProcessCostModel() };
  bool WarnedMissing = false; // NaN or infinite values, once per input
  // Where the cached surfaces were placed (the input's direction and origin).
  Placement Placed;

  // What the last successful update made, for GenerateLevel: its isovalues,
  // the array they were read from (and its time then), and when.
  std::vector<double> LastValues;
  vtkWeakPointer<vtkDataArray> LastArray;
  vtkMTimeType LastArrayTime = 0;
  vtkTimeStamp LastUpdate;

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

  // The core's description of the input: its values, place, own cells and,
  // for a parallel piece, its place in the whole extent.
  static mediso::VolumeDescription Describe(
    vtkImageData* input, vtkDataArray* array, vtkInformation* inInfo)
  {
    mediso::VolumeDescription d;
    vtkMedicalCoreScalarType(array->GetDataType(), d.Type);
    d.Data = array->GetVoidPointer(0);
    d.Stamp = array->GetMTime();
    int extent[6];
    input->GetExtent(extent);
    double origin[3], spacing[3];
    input->GetOrigin(origin);
    input->GetSpacing(spacing);
    for (int a = 0; a < 3; ++a)
    {
      d.Dims[a] = extent[2 * a + 1] - extent[2 * a] + 1;
      d.Spacing[a] = spacing[a];
      d.Origin[a] = origin[a] + spacing[a] * extent[2 * a];
    }
    int whole[6] = { 0, -1, 0, -1, 0, -1 };
    if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
    {
      inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
    }
    const bool wholeKnown = whole[0] <= whole[1] && whole[2] <= whole[3] && whole[4] <= whole[5];
    // The piece without ghost layers, for an input that lost its ghost array.
    int zeroExtent[6];
    const int* zero = nullptr;
    const int pieces = inInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES())
      ? inInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES())
      : 1;
    if (pieces > 1 && !input->GetCellGhostArray() && wholeKnown)
    {
      vtkNew<vtkExtentTranslator> translator;
      translator->SetWholeExtent(whole);
      translator->SetPiece(inInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()));
      translator->SetNumberOfPieces(pieces);
      translator->SetGhostLevel(0);
      translator->PieceToExtent();
      translator->GetExtent(zeroExtent);
      zero = zeroExtent;
    }
    FindOwnedCells(input, d.Dims, zero, d.OwnedCells);
    if (wholeKnown && !std::equal(extent, extent + 6, whole))
    {
      for (int a = 0; a < 3; ++a)
      {
        d.GlobalOffset[a] = extent[2 * a] - whole[2 * a];
        d.GlobalDims[a] = whole[2 * a + 1] - whole[2 * a] + 1;
      }
    }
    return d;
  }

  // Adopts the input; true when its block ranges were computed (a new input:
  // counts and surfaces of the old one are forgotten).
  bool Refresh(const mediso::VolumeDescription& description)
  {
    if (!this->Surfaces.SetVolume(description))
    {
      return false;
    }
    this->WarnedMissing = false;
    return true;
  }

  // How the filter's output arrays are made from the core's plans.
  // `spares`: where the surfaces the cache drops leave their memory (lives
  // for the update); `placement`: where each new surface is put.
  static mediso::SurfaceMaker<vtkSmartPointer<vtkPolyData>> Maker(
    const mediso::SurfaceLayout& layout, SpareBuffers* spares, const Placement& placement)
  {
    mediso::SurfaceMaker<vtkSmartPointer<vtkPolyData>> maker;
    maker.Recycle = [spares](vtkSmartPointer<vtkPolyData>& evicted) { spares->Take(evicted); };
    maker.Allocate = [layout, spares](const mediso::SurfaceKey&, std::int64_t points,
                       std::int64_t triangles, vtkSmartPointer<vtkPolyData>& surface,
                       mediso::SurfaceTarget& target)
    {
      SurfaceArrays arrays = AllocateSurface(points, triangles, layout, spares);
      if (!Valid(arrays, points, triangles))
      {
        return false;
      }
      surface = arrays.Surface;
      target.UseWide = arrays.Connectivity64 != nullptr;
      target.Narrow.Connectivity = arrays.Connectivity32;
      target.Wide.Connectivity = arrays.Connectivity64;
      target.Narrow.Points = target.Wide.Points = arrays.Points;
      target.Narrow.Normals = target.Wide.Normals = arrays.Normals;
      target.Narrow.Scalars = target.Wide.Scalars = arrays.Scalars;
      target.Narrow.BlockIds = target.Wide.BlockIds = arrays.BlockIds;
      return true;
    };
    maker.Finish = [placement](const mediso::SurfaceKey& key, vtkSmartPointer<vtkPolyData>& surface,
                     const mediso::SurfaceRanges& written)
    {
      if (placement.Identity)
      {
        CacheRanges(surface->GetPoints()->GetData(), written.Points);
        CacheRanges(surface->GetPointData()->GetNormals(), written.Normals);
      }
      else
      {
        placement.Apply(surface);
      }
      const double iso = static_cast<float>(key.Isovalue); // the scalars' value, as stored
      CacheRanges(surface->GetPointData()->GetScalars(), iso, iso);
    };
    return maker;
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
  this->Internals->Surfaces.ClearCache();
}

double vtkBlockLODContour::GetCacheMegabytes()
{
  return this->Internals->Surfaces.GetCacheBytes() / BytesPerMB;
}

//------------------------------------------------------------------------------
double vtkBlockLODContour::EstimateTriangles(double isovalue, int level)
{
  const mediso::SurfaceEstimate e = this->Internals->Surfaces.Estimate(isovalue, level);
  this->LastEstimateMethod = static_cast<int>(e.Method);
  return e.Method == mediso::EstimateMethod::None ? -1.0 : e.Counts.Triangles;
}

double vtkBlockLODContour::EstimateMegabytes(double isovalue, int level)
{
  const mediso::SurfaceEstimate e = this->Internals->Surfaces.Estimate(isovalue, level);
  this->LastEstimateMethod = static_cast<int>(e.Method);
  return e.Method == mediso::EstimateMethod::None
    ? -1.0
    : OutputLayout(this).Bytes(e.Counts) / BytesPerMB;
}

double vtkBlockLODContour::EstimateSeconds(double isovalue, int level)
{
  mediso::EstimateMethod method = mediso::EstimateMethod::None;
  const double seconds = this->Internals->Surfaces.EstimateSeconds(isovalue, level, &method);
  this->LastEstimateMethod = static_cast<int>(method);
  return seconds;
}

//------------------------------------------------------------------------------
double* vtkBlockLODContour::GetCurrentEstimatedSeconds()
{
  const int n = this->ContourValues->GetNumberOfContours();
  for (int level = 0; level < 4; ++level)
  {
    double sum = n > 0 ? 0.0 : -1.0;
    for (int i = 0; i < n && sum >= 0.0; ++i)
    {
      const double seconds = this->EstimateSeconds(this->ContourValues->GetValue(i), level);
      sum = seconds < 0.0 ? -1.0 : sum + seconds;
    }
    this->CurrentEstimatedSeconds[level] = sum;
  }
  return this->CurrentEstimatedSeconds;
}

double* vtkBlockLODContour::GetCurrentEstimatedMegabytes()
{
  const int n = this->ContourValues->GetNumberOfContours();
  for (int level = 0; level < 4; ++level)
  {
    double sum = n > 0 ? 0.0 : -1.0;
    for (int i = 0; i < n && sum >= 0.0; ++i)
    {
      const double mb = this->EstimateMegabytes(this->ContourValues->GetValue(i), level);
      sum = mb < 0.0 ? -1.0 : sum + mb;
    }
    this->CurrentEstimatedMegabytes[level] = sum;
  }
  return this->CurrentEstimatedMegabytes;
}

double* vtkBlockLODContour::GetCurrentEstimatedTriangles()
{
  const int n = this->ContourValues->GetNumberOfContours();
  for (int level = 0; level < 4; ++level)
  {
    double sum = n > 0 ? 0.0 : -1.0;
    for (int i = 0; i < n && sum >= 0.0; ++i)
    {
      const mediso::SurfaceEstimate e =
        this->Internals->Surfaces.Estimate(this->ContourValues->GetValue(i), level);
      sum = e.Method == mediso::EstimateMethod::None ? -1.0 : sum + e.Counts.Triangles;
    }
    this->CurrentEstimatedTriangles[level] = sum;
  }
  return this->CurrentEstimatedTriangles;
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
  if (!input || !output)
  {
    return 0;
  }
  // A failed allocation is checked for before it is made (BlockLODSurfaces.h,
  // and before the output is assembled); this is the last resort.
  const char* step = "checking the input";
  try
  {
    this->Execute(inputVector, input, output, step);
  }
  catch (const std::bad_alloc&)
  {
    output->Initialize();
    this->ChosenLevel = -1;
    vtkErrorMacro("The process ran out of memory while " << step << DescribeAllowance()
                                                         << ". The output is empty.");
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkBlockLODContour::Execute(
  vtkInformationVector** inputVector, vtkImageData* input, vtkPolyData* output, const char*& step)
{
  vtkInternals& in = *this->Internals;
  const double start = Now();
  in.LastValues.clear();
  in.LastArray = nullptr;

  // Check: an array the core can read, on a grid it can contour.
  vtkDataArray* array = this->CheckInput(input, inputVector);
  if (!array || this->ContourValues->GetNumberOfContours() < 1)
  {
    return;
  }
  // Refresh block ranges (kept while the input stays the same).
  step = "computing the block ranges";
  if (in.Refresh(vtkInternals::Describe(input, array, inputVector[0]->GetInformationObject(0))))
  {
    ++this->NumberOfBlockRangeComputations;
  }
  // The same values under another direction: the counts hold, the cached
  // surfaces lie elsewhere.
  const Placement placement = Placement::Of(input);
  if (placement != in.Placed)
  {
    in.Surfaces.ClearCache();
    in.Placed = placement;
  }
  this->UpdateProgress(0.1);
  const std::vector<double> values = this->IsovaluesWithSurface();
  if (values.empty())
  {
    return;
  }
  // Choose the level, plan it (exact sizes before any allocation), generate
  // (BlockLODSurfaces), then assemble the output.
  step = "making the surfaces";
  const mediso::SurfaceLayout layout = OutputLayout(this);
  in.Surfaces.SetLayout(layout);
  in.Surfaces.SetCacheLimit(this->CacheMemoryLimit * BytesPerMB);
  mediso::LevelChoice choice;
  choice.Level = this->AutoLOD ? mediso::LevelChoice::Auto : this->LOD;
  choice.BudgetBytes = this->MemoryBudget * BytesPerMB;
  mediso::UpdateHooks hooks;
  hooks.PollAbort = [this]() { return this->GetAbortExecute() != 0; };
  // A progress event between steps (each isovalue's plan, each surface) lets an observer
  // that watches for a newer request (medical_isosurfaces.RefineAfterChange, the GUI's abort
  // button) set AbortExecute while the update runs; the core then stops between blocks.
  hooks.CheckAbort = [this]()
  {
    this->UpdateProgress(this->GetProgress());
    return this->CheckAbort();
  };
  hooks.Planned = [this, &values](int level)
  {
    this->ChosenLevel = level;
    this->ReportEstimates(values[0]);
    this->UpdateProgress(0.5);
  };
  SpareBuffers spares;
  const mediso::SurfacesUpdate update =
    in.Surfaces.Update(values, choice, vtkInternals::Maker(layout, &spares, in.Placed), hooks);
  this->NumberOfExtractions += update.Extractions;
  this->NumberOfCacheHits += update.CacheHits;
  this->ReportUpdate(update);
  if (update.Status != mediso::SurfacesUpdate::Outcome::Done)
  {
    if (update.Status == mediso::SurfacesUpdate::Outcome::OutOfMemory)
    {
      this->ChosenLevel = -1; // nothing was made
    }
    output->Initialize();
    return;
  }
  this->UpdateProgress(0.9);
  step = "assembling the output";
  if (!this->AssembleOutput(output, this->ChosenLevel))
  {
    output->Initialize();
    this->ChosenLevel = -1;
    return;
  }
  in.LastValues = values;
  in.LastArray = array;
  in.LastArrayTime = array->GetMTime();
  in.LastUpdate.Modified();
  // The cost model learns from updates that extracted something and did no
  // one-time work (block ranges, coarse copies).
  in.Surfaces.RecordCost(update, Now() - start);
  this->UpdateProgress(1.0);
}

//------------------------------------------------------------------------------
vtkDataArray* vtkBlockLODContour::ChooseArray(vtkImageData* input, vtkInformationVector** inputVector)
{
  vtkInformation* chosen = this->GetInputArrayInformation(0);
  const char* name =
    chosen->Has(vtkDataObject::FIELD_NAME()) ? chosen->Get(vtkDataObject::FIELD_NAME()) : nullptr;
  vtkPointData* pd = input->GetPointData();
  if (name && *name)
  {
    // An array chosen by name (ContourBy): it must be one of the point arrays.
    vtkDataArray* array = this->GetInputArrayToProcess(0, inputVector);
    if (array && pd->GetArray(name) == array)
    {
      return array;
    }
    if (input->GetCellData()->GetAbstractArray(name))
    {
      vtkErrorMacro("'" << name << "' is a cell array; contouring needs a point array (apply "
                    "Cell Data to Point Data first). The output is empty.");
    }
    else if (pd->GetAbstractArray(name))
    {
      vtkErrorMacro("Point array '" << name << "' is not numeric. The output is empty.");
    }
    else
    {
      vtkErrorMacro("ContourBy names the point array '"
        << name << "', which the input does not have (" << DescribeArrays(pd, "point")
        << "). The output is empty.");
    }
    return nullptr;
  }

  // None chosen (ParaView leaves ContourBy empty until the input has run):
  // the active point scalars when they have one component, else the only
  // one-component point array.
  vtkDataArray* active = pd->GetScalars();
  if (active && active->GetNumberOfComponents() == 1)
  {
    return active;
  }
  std::vector<vtkDataArray*> single;
  int numeric = 0;
  vtkDataArray* only = nullptr; // the numeric array, when there is one
  for (int i = 0; i < pd->GetNumberOfArrays(); ++i)
  {
    if (vtkDataArray* a = pd->GetArray(i))
    {
      ++numeric;
      only = a;
      if (a->GetNumberOfComponents() == 1)
      {
        single.push_back(a);
      }
    }
  }
  if (single.size() == 1)
  {
    return single[0];
  }
  if (numeric == 0)
  {
    vtkErrorMacro("No point scalars to contour: the input has no point data arrays"
      << (input->GetCellData()->GetNumberOfArrays() > 0
             ? " (" + DescribeArrays(input->GetCellData(), "cell") +
               "; apply Cell Data to Point Data first)"
             : std::string())
      << ". The output is empty.");
  }
  else if (single.empty())
  {
    std::ostringstream what;
    if (numeric == 1)
    {
      what << "the input's only point array, '" << (only->GetName() ? only->GetName() : "(unnamed)")
           << "', has " << only->GetNumberOfComponents() << " components";
    }
    else
    {
      what << "none of the input's point arrays has one component (" << DescribeArrays(pd, "point")
           << ")";
    }
    vtkErrorMacro("No array chosen to contour, and "
      << what.str()
      << ": contouring needs a one-component array (extract a component first, e.g. with a "
         "Calculator). The output is empty.");
  }
  else
  {
    vtkErrorMacro("No array chosen to contour, and the input has several one-component point "
                  "arrays and no active scalars ("
      << DescribeArrays(pd, "point")
      << "): choose one with ContourBy (SetInputArrayToProcess). The output is empty.");
  }
  return nullptr;
}

//------------------------------------------------------------------------------
vtkDataArray* vtkBlockLODContour::CheckInput(vtkImageData* input, vtkInformationVector** inputVector)
{
  vtkDataArray* array = this->ChooseArray(input, inputVector);
  if (!array)
  {
    return nullptr;
  }
  const std::string name = array->GetName() ? array->GetName() : "(unnamed)";
  if (array->GetNumberOfComponents() != 1)
  {
    vtkErrorMacro("Array '" << name << "' has " << array->GetNumberOfComponents()
                            << " components; contouring needs one. The output is empty.");
    return nullptr;
  }
  int dims[3];
  input->GetDimensions(dims);
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2)
  {
    vtkErrorMacro("Input is " << dims[0] << " x " << dims[1] << " x " << dims[2]
                              << " points: isosurfaces need 3D image data with at least 2 "
                                 "points along each axis. The output is empty.");
    return nullptr;
  }
  const double* spacing = input->GetSpacing();
  const double* origin = input->GetOrigin();
  for (int a = 0; a < 3; ++a)
  {
    if (!(spacing[a] != 0 && std::isfinite(spacing[a]) && std::isfinite(origin[a])))
    {
      vtkErrorMacro("The input's spacing (" << spacing[0] << ", " << spacing[1] << ", "
        << spacing[2] << ") or origin (" << origin[0] << ", " << origin[1] << ", " << origin[2]
        << ") has a zero or non-finite component: the surface would have no extent or "
           "non-finite points. The output is empty.");
      return nullptr;
    }
  }
  // A direction places the surface (Placement); it must be a rotation or a
  // mirror image of one, for the normals and the faces' winding to follow it.
  if (vtkMatrix3x3* direction = input->GetDirectionMatrix())
  {
    const double* d = direction->GetData();
    double worst = std::isfinite(direction->Determinant()) ? 0.0 : HUGE_VAL;
    for (int a = 0; a < 3; ++a)
    {
      for (int b = 0; b < 3; ++b)
      {
        const double dot = d[a] * d[b] + d[3 + a] * d[3 + b] + d[6 + a] * d[6 + b];
        const double error = std::fabs(dot - (a == b ? 1.0 : 0.0));
        worst = std::isfinite(error) ? std::max(worst, error) : HUGE_VAL;
      }
    }
    if (worst > OrthonormalTolerance)
    {
      vtkErrorMacro("The input's direction matrix ("
        << d[0] << ", " << d[1] << ", " << d[2] << "; " << d[3] << ", " << d[4] << ", " << d[5]
        << "; " << d[6] << ", " << d[7] << ", " << d[8] << ") is not orthonormal (determinant "
        << direction->Determinant()
        << "): its columns must be unit vectors at right angles, a rotation or its mirror "
           "image, for the surface's normals and orientation to follow it. Resample the image "
           "to an orthonormal grid first. The output is empty.");
      return nullptr;
    }
  }
  mediso::ScalarType type;
  if (!vtkMedicalCoreScalarType(array->GetDataType(), type) || !array->HasStandardMemoryLayout() ||
    array->GetNumberOfTuples() != static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2])
  {
    vtkErrorMacro("Array '" << name << "' of type " << array->GetDataTypeAsString()
                            << " is not supported (use a contiguous point array of 8/16/32-bit "
                               "integers, float or double). The output is empty.");
    return nullptr;
  }
  if (this->ContourValues->GetNumberOfContours() < 1)
  {
    vtkDebugMacro("No isovalues: empty output.");
  }
  return array;
}

//------------------------------------------------------------------------------
std::vector<double> vtkBlockLODContour::IsovaluesWithSurface()
{
  vtkInternals& in = *this->Internals;
  const mediso::BlockRanges& ranges = in.Surfaces.GetVolume().GetRanges();
  std::vector<double> values;
  // A parallel piece may well lie outside an isovalue (all air, say): only a
  // whole volume warns about its range.
  const bool piece = in.Surfaces.GetVolume().GetDescription().IsPiece();
  if (!ranges.HasFiniteValues())
  {
    if (piece)
    {
      vtkDebugMacro("This piece has no finite values: no surface here.");
    }
    else
    {
      vtkWarningMacro("The input has no finite values (every point is NaN or infinite): there "
                      "is no isosurface.");
    }
    return values;
  }
  if ((ranges.NaNCount > 0 || ranges.InfiniteCount > 0) && !in.WarnedMissing)
  {
    vtkWarningMacro("The input has "
      << (ranges.NaNCount > 0 ? (ranges.InfiniteCount > 0 ? "NaN and infinite" : "NaN")
                              : "infinite")
      << " values: cubes touching them produce no surface.");
    in.WarnedMissing = true;
  }
  const double* range = ranges.ValueRange;
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
    return values;
  }
  const vtkIdType numValues = this->ContourValues->GetNumberOfContours();
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
  return values;
}

//------------------------------------------------------------------------------
void vtkBlockLODContour::ReportUpdate(const mediso::SurfacesUpdate& update)
{
  // With AutoLOD the choice fits the budget, or what the process may still
  // allocate when that is less: the messages name the one that bound.
  const bool processBound = this->AutoLOD && update.ChoiceBytes < this->MemoryBudget * BytesPerMB;
  std::ostringstream allowance;
  if (processBound)
  {
    allowance << update.ChoiceBytes / BytesPerMB << " MB the process may still allocate ("
              << update.Allowance.Limit << ")";
  }
  for (const auto& dropped : update.Dropped)
  {
    if (processBound)
    {
      vtkWarningMacro("Level " << dropped.first << " needs " << dropped.second / BytesPerMB
                               << " MB, over the " << allowance.str()
                               << " (the estimate was low): using level " << dropped.first - 1
                               << ".");
    }
    else
    {
      vtkWarningMacro("Level " << dropped.first << " needs " << dropped.second / BytesPerMB
                               << " MB, over the MemoryBudget of " << this->MemoryBudget
                               << " MB (the estimate was low): using level " << dropped.first - 1
                               << ".");
    }
  }
  using Outcome = mediso::SurfacesUpdate::Outcome;
  if (update.Status == Outcome::NothingFits)
  {
    const char* needs = update.Level0Planned ? "level 0 needs " : "even level 0 needs ";
    if (processBound)
    {
      vtkErrorMacro("MemoryBudget "
        << this->MemoryBudget << " MB is more than the " << allowance.str() << ", and " << needs
        << update.Level0Bytes / BytesPerMB << " MB. The output is empty.");
    }
    else
    {
      vtkErrorMacro("MemoryBudget " << this->MemoryBudget << " MB is too small: " << needs
                                    << update.Level0Bytes / BytesPerMB
                                    << " MB. The output is empty.");
    }
  }
  else if (update.Status == Outcome::OutOfMemory)
  {
    std::string message = update.Message;
    message[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(message[0])));
    vtkErrorMacro(<< message << ". The output is empty.");
  }
  else if (update.Status == Outcome::Done && update.LimitedByProcess)
  {
    vtkWarningMacro("Level " << update.BudgetLevel << " fits the MemoryBudget of "
                             << this->MemoryBudget << " MB but not the " << allowance.str()
                             << ": using level " << update.Level << ".");
  }
}

//------------------------------------------------------------------------------
void vtkBlockLODContour::ReportEstimates(double isovalue)
{
  // After planning: the planned level's estimate is exact, AutoLOD's were
  // made while choosing.
  for (int l = 0; l < mediso::NumberOfLevels; ++l)
  {
    this->EstimatedTriangles[l] = this->EstimateTriangles(isovalue, l);
    this->EstimatedMegabytes[l] = this->EstimateMegabytes(isovalue, l);
    this->EstimatedSeconds[l] = this->EstimateSeconds(isovalue, l);
  }
}

//------------------------------------------------------------------------------
bool vtkBlockLODContour::AssembleOutput(vtkPolyData* output, int level)
{
  const std::vector<vtkSmartPointer<vtkPolyData>>& pieces = this->Internals->Surfaces.GetSurfaces();
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
    // One more copy of every surface: checked before it is made.
    const mediso::SurfaceLayout layout = OutputLayout(this);
    const double bytes = layout.Bytes(static_cast<double>(points), static_cast<double>(triangles));
    std::string message;
    if (bytes >= mediso::BlockLODSurfacesBase::LargeAllocationBytes &&
      !mediso::FitsInProcessMemory(static_cast<std::uint64_t>(bytes), "The output", message))
    {
      vtkErrorMacro(<< message << ". The output is empty.");
      return false;
    }
    SurfaceArrays all = AllocateSurface(points, triangles, layout);
    if (!Valid(all, points, triangles))
    {
      vtkErrorMacro("The output (" << bytes / BytesPerMB
                                   << " MB) could not be allocated. The output is empty.");
      return false;
    }
    mediso::SurfaceRanges merged;
    double scalars[2] = { 1e300, -1e300 };
    std::int64_t p0 = 0, t0 = 0;
    for (const auto& p : pieces)
    {
      merged.Points.Merge(RangesOf(p->GetPoints()->GetData()));
      merged.Normals.Merge(RangesOf(p->GetPointData()->GetNormals()));
      if (vtkDataArray* s = p->GetPointData()->GetScalars())
      {
        const double* r = s->GetRange();
        scalars[0] = std::min(scalars[0], r[0]);
        scalars[1] = std::max(scalars[1], r[1]);
      }
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
      // The piece's ids shifted by its first point (each piece is stored in
      // the width the merged surface has or a narrower one).
      auto shift = [&](const auto* from, auto* to) {
        vtkSMPTools::For(0, 3 * nt, [&](vtkIdType b, vtkIdType e) {
          for (vtkIdType i = b; i < e; ++i)
          {
            to[3 * t0 + i] = static_cast<std::remove_reference_t<decltype(*to)>>(from[i] + p0);
          }
        });
      };
      vtkDataArray* conn = p->GetPolys()->GetConnectivityArray();
      vtkTypeInt32Array* conn32 = vtkTypeInt32Array::FastDownCast(conn);
      vtkTypeInt64Array* conn64 = vtkTypeInt64Array::FastDownCast(conn);
      if (all.Connectivity32 && conn32)
      {
        shift(conn32->GetPointer(0), all.Connectivity32);
      }
      else if (all.Connectivity64 && conn32)
      {
        shift(conn32->GetPointer(0), all.Connectivity64);
      }
      else if (all.Connectivity64 && conn64)
      {
        shift(conn64->GetPointer(0), all.Connectivity64);
      }
      p0 += np;
      t0 += nt;
    }
    CacheRanges(all.Surface->GetPoints()->GetData(), merged.Points);
    CacheRanges(all.Surface->GetPointData()->GetNormals(), merged.Normals);
    CacheRanges(all.Surface->GetPointData()->GetScalars(), scalars[0], scalars[1]);
    output->ShallowCopy(all.Surface);
  }

  auto addField = [output](const char* name, const double* v, int n) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfValues(n);
    std::copy(v, v + n, a->GetPointer(0));
    output->GetFieldData()->AddArray(a);
  };
  const double made = level;
  addField("BlockLODLevel", &made, 1);
  addField("BlockLODEstimatedTriangles", this->EstimatedTriangles, 4);
  addField("BlockLODEstimatedMB", this->EstimatedMegabytes, 4);
  addField("BlockLODEstimatedSeconds", this->EstimatedSeconds, 4);
  return true;
}

//------------------------------------------------------------------------------
bool vtkBlockLODContour::HasCurrentOutput()
{
  const vtkInternals& in = *this->Internals;
  // The core's volume still describes the input array's memory only while the
  // array lives unchanged; the isovalues and options only while the filter
  // has not been modified since.
  return !in.LastValues.empty() && in.LastArray && in.LastArray->GetMTime() == in.LastArrayTime &&
    this->GetMTime() < in.LastUpdate.GetMTime();
}

//------------------------------------------------------------------------------
double vtkBlockLODContour::EstimateLevelTriangles(int level)
{
  if (level < 0 || level >= mediso::NumberOfLevels || !this->HasCurrentOutput())
  {
    return -1.0;
  }
  double triangles = 0.0;
  for (double value : this->Internals->LastValues)
  {
    const mediso::SurfaceEstimate e = this->Internals->Surfaces.Estimate(value, level);
    if (e.Method == mediso::EstimateMethod::None)
    {
      return -1.0;
    }
    triangles += e.Counts.Triangles;
  }
  return triangles;
}

//------------------------------------------------------------------------------
bool vtkBlockLODContour::GenerateLevel(int level, vtkPolyData* output)
{
  if (!output)
  {
    return false;
  }
  output->Initialize();
  if (level < 0 || level >= mediso::NumberOfLevels || !this->HasCurrentOutput())
  {
    return false;
  }
  vtkInternals& in = *this->Internals;
  // The update's choices, at a fixed level: the core serves cached pairs and
  // plans and extracts the others, checking memory as for the output.
  const mediso::SurfaceLayout layout = OutputLayout(this);
  mediso::LevelChoice choice;
  choice.Level = level;
  mediso::UpdateHooks hooks;
  SpareBuffers spares;
  try
  {
    const mediso::SurfacesUpdate update = in.Surfaces.Update(
      in.LastValues, choice, vtkInternals::Maker(layout, &spares, in.Placed), hooks);
    this->NumberOfExtractions += update.Extractions;
    this->NumberOfCacheHits += update.CacheHits;
    if (update.Status != mediso::SurfacesUpdate::Outcome::Done)
    {
      if (update.Status == mediso::SurfacesUpdate::Outcome::OutOfMemory)
      {
        vtkWarningMacro("Level " << level << " of the surfaces could not be made: "
                                 << update.Message << ".");
      }
      return false;
    }
    if (!this->AssembleOutput(output, level))
    {
      output->Initialize();
      return false;
    }
  }
  catch (const std::bad_alloc&)
  {
    output->Initialize();
    vtkWarningMacro("The process ran out of memory while making level "
      << level << " of the surfaces" << DescribeAllowance() << ".");
    return false;
  }
  return true;
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
