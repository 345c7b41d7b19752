// SPDX-License-Identifier: BSD-3-Clause
// What vtkBlockLODContour's output hands downstream (ParaView's representation,
// mappers), so that they neither convert nor read it again:
// - the cell array is VTK's own 64-bit storage by default (read in place by
//   mappers), 32-bit with CompactIds, and both hold the same triangles;
// - the points', normals' and scalars' value ranges are in VTK's range cache
//   (per component, finite or not, and of the length) and equal ranges
//   computed afresh from the values, for one isovalue, for two merged into one
//   output, and for a surface served from the cache;
// - the triangle offsets (one run shared by every surface) are 0, 3, 6, ...,
//   and a cell added to one output leaves every other surface's offsets alone;
// - with a full cache (a drag), every output equals a fresh filter's, and an
//   earlier output held downstream keeps its values (its memory not reused).
#include "MedicalTestUtilities.h"
#include "vtkBlockLODContour.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace
{
using medical_test::Check;

// The array's values in a new array (no cached ranges).
vtkSmartPointer<vtkFloatArray> Fresh(vtkDataArray* a)
{
  auto copy = vtkSmartPointer<vtkFloatArray>::New();
  copy->SetNumberOfComponents(a->GetNumberOfComponents());
  copy->SetNumberOfTuples(a->GetNumberOfTuples());
  std::memcpy(copy->GetVoidPointer(0), a->GetVoidPointer(0),
    sizeof(float) * a->GetNumberOfValues());
  return copy;
}

void CheckRanges(vtkDataArray* a, const std::string& label)
{
  Check(a != nullptr, label + ": array present");
  if (!a)
  {
    return;
  }
  vtkInformation* info = a->GetInformation();
  Check(info->Has(vtkAbstractArray::PER_COMPONENT()) &&
      info->Has(vtkAbstractArray::PER_FINITE_COMPONENT()) &&
      info->Has(vtkDataArray::L2_NORM_RANGE()) && info->Has(vtkDataArray::L2_NORM_FINITE_RANGE()),
    label + ": ranges cached with the array");
  vtkSmartPointer<vtkFloatArray> fresh = Fresh(a);
  double worst = 0;
  for (int c = -1; c < a->GetNumberOfComponents(); ++c)
  {
    double cached[2], computed[2], finite[2];
    a->GetRange(cached, c);
    a->GetFiniteRange(finite, c);
    fresh->GetRange(computed, c);
    for (int k = 0; k < 2; ++k)
    {
      // Components are exact; lengths may differ in the last bits (double
      // against VTK's own accumulation).
      const double tolerance = c < 0 ? 1e-6 * (1 + std::fabs(computed[k])) : 0.0;
      worst = std::fmax(worst, std::fabs(cached[k] - computed[k]));
      Check(std::fabs(cached[k] - computed[k]) <= tolerance && cached[k] == finite[k],
        label + ": cached range of component " + std::to_string(c) + " equals the values'");
    }
  }
  std::printf("%s: cached ranges match the values (largest difference %g)\n", label.c_str(), worst);
}

void CheckOutput(vtkPolyData* pd, const std::string& label)
{
  CheckRanges(pd->GetPoints()->GetData(), label + ", points");
  CheckRanges(pd->GetPointData()->GetNormals(), label + ", normals");
  CheckRanges(pd->GetPointData()->GetScalars(), label + ", scalars");
}

// Offsets 0, 3, 6, ... of a triangle surface.
// Every value of two arrays (of any type) equal, bit for bit.
bool SameValues(vtkDataArray* a, vtkDataArray* b)
{
  return a && b && a->GetDataType() == b->GetDataType() &&
    a->GetNumberOfValues() == b->GetNumberOfValues() &&
    std::memcmp(a->GetVoidPointer(0), b->GetVoidPointer(0),
      static_cast<std::size_t>(a->GetNumberOfValues()) * a->GetDataTypeSize()) == 0;
}

// Points, normals, scalars, block ids and triangles equal.
bool SameSurface(vtkPolyData* a, vtkPolyData* b)
{
  return a->GetNumberOfPoints() > 0 &&
    SameValues(a->GetPoints()->GetData(), b->GetPoints()->GetData()) &&
    SameValues(a->GetPointData()->GetNormals(), b->GetPointData()->GetNormals()) &&
    SameValues(a->GetPointData()->GetScalars(), b->GetPointData()->GetScalars()) &&
    SameValues(a->GetCellData()->GetArray("BlockId"), b->GetCellData()->GetArray("BlockId")) &&
    SameValues(a->GetPolys()->GetConnectivityArray(), b->GetPolys()->GetConnectivityArray());
}

bool TriangleOffsets(vtkCellArray* polys)
{
  vtkDataArray* offsets = polys->GetOffsetsArray();
  for (vtkIdType i = 0; i < offsets->GetNumberOfValues(); ++i)
  {
    if (offsets->GetComponent(i, 0) != 3.0 * i)
    {
      return false;
    }
  }
  return offsets->GetNumberOfValues() == polys->GetNumberOfCells() + 1;
}
} // namespace

int TestBlockLODContourOutput(int, char*[])
{
  vtkSMPTools::SetBackend("STDThread");
  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(70, 66, 61);
  phantom->SetNoiseStandardDeviation(10);

  vtkNew<vtkBlockLODContour> lod;
  lod->SetInputConnection(phantom->GetOutputPort());
  lod->SetValue(0, 400.0);
  lod->ComputeScalarsOn();
  lod->Update();
  vtkPolyData* out = lod->GetOutput();
  Check(out->GetPolys()->IsStorage64Bit(), "default: 64-bit cell array (vtkIdType)");
  CheckOutput(out, "one isovalue");
  const vtkIdType triangles = out->GetNumberOfPolys();

  // Compact ids: 32-bit storage, the same triangles.
  vtkNew<vtkBlockLODContour> compact;
  compact->SetInputConnection(phantom->GetOutputPort());
  compact->SetValue(0, 400.0);
  compact->CompactIdsOn();
  compact->Update();
  vtkCellArray* a = out->GetPolys();
  vtkCellArray* b = compact->GetOutput()->GetPolys();
  Check(!b->IsStorage64Bit(), "CompactIds: 32-bit cell array");
  bool same = a->GetNumberOfCells() == b->GetNumberOfCells();
  for (vtkIdType i = 0; same && i < a->GetNumberOfConnectivityIds(); ++i)
  {
    same = a->GetConnectivityArray()->GetComponent(i, 0) ==
      b->GetConnectivityArray()->GetComponent(i, 0);
  }
  Check(same, "CompactIds: the same triangles");
  Check(TriangleOffsets(a) && TriangleOffsets(b), "offsets 0, 3, 6, ... (64- and 32-bit)");

  // A quad appended to another filter's output: its offsets grow into memory
  // of their own, the shared ones stay those of triangles.
  {
    vtkNew<vtkBlockLODContour> other;
    other->SetInputConnection(phantom->GetOutputPort());
    other->SetValue(0, -500.0);
    other->Update();
    vtkPolyData* edited = other->GetOutput();
    const vtkIdType quad[4] = { 0, 1, 2, 3 };
    const vtkIdType cells = edited->GetPolys()->GetNumberOfCells();
    edited->GetPolys()->InsertNextCell(4, quad);
    vtkDataArray* offsets = edited->GetPolys()->GetOffsetsArray();
    Check(edited->GetPolys()->GetNumberOfCells() == cells + 1 &&
        offsets->GetComponent(cells + 1, 0) == 3.0 * cells + 4,
      "a cell appended to an output is its own");
    Check(TriangleOffsets(a) && TriangleOffsets(b), "the other surfaces' offsets are unchanged");
  }

  // Two isovalues merged into one output, then served from the cache.
  lod->SetNumberOfContours(2);
  lod->SetValue(0, 400.0);
  lod->SetValue(1, -500.0);
  lod->Update();
  Check(lod->GetOutput()->GetNumberOfPolys() > triangles, "two isovalues: more triangles");
  CheckOutput(lod->GetOutput(), "two isovalues");
  lod->SetNumberOfContours(1);
  lod->SetValue(0, 400.0);
  lod->Update();
  Check(lod->GetNumberOfCacheHits() > 0, "the last update was served from the cache");
  CheckOutput(lod->GetOutput(), "cache hit");

  // Changes with a full cache, as while an isovalue is dragged: the surfaces
  // the cache drops lend their memory to the new ones. Every output equals a
  // fresh filter's, and an earlier output still held downstream (a shallow
  // copy: its arrays shared) is never written into.
  {
    auto make = [&phantom](double iso)
    {
      auto f = vtkSmartPointer<vtkBlockLODContour>::New();
      f->SetInputConnection(phantom->GetOutputPort());
      f->SetValue(0, iso);
      f->ComputeScalarsOn();
      f->GenerateBlockIdsOn();
      return f;
    };
    vtkSmartPointer<vtkBlockLODContour> drag = make(390.0);
    drag->Update();
    // Room for about two surfaces.
    drag->SetCacheMemoryLimit(2.5 * drag->GetOutput()->GetActualMemorySize() * 1024.0 / 1.0e6);
    vtkNew<vtkPolyData> held, snapshot;
    bool same = true;
    for (int k = 0; k < 12; ++k)
    {
      // Bone and skin in turn: surfaces of different sizes (buffers grown and
      // shrunk).
      const double iso = (k % 2 ? -500.0 : 400.0) + 7.0 * k;
      drag->SetValue(0, iso);
      drag->Update();
      vtkSmartPointer<vtkBlockLODContour> fresh = make(iso);
      fresh->Update();
      same = same && SameSurface(drag->GetOutput(), fresh->GetOutput());
      if (k == 1)
      {
        held->ShallowCopy(drag->GetOutput());
        snapshot->DeepCopy(drag->GetOutput());
      }
    }
    Check(drag->GetNumberOfCacheHits() == 0 && drag->GetCacheMegabytes() > 0,
      "a drag of new isovalues");
    Check(same, "with a full cache every output equals a fresh filter's");
    Check(SameSurface(held, snapshot), "an output held downstream is never reused");
  }

  return medical_test::Finish("vtkBlockLODContour output: all checks passed");
}
