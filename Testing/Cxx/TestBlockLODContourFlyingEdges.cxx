// SPDX-License-Identifier: BSD-3-Clause
// At level 3 vtkBlockLODContour's surface is vtkFlyingEdges3D's surface:
// triangle count within 0.5%, total area within 0.5%, every vertex of each
// surface within 1e-4 voxel of a vertex of the other. Checked on the phantom
// (odd sizes, a non-zero extent, spacing and origin, several scalar types) and
// on the real head CT when it is cached (ct_head.mha in
// medical_test::DataDirectory()).
//
// Degenerate-triangle policy: both filters create one point per cut edge and
// keep every triangle of the case table, so the counts are expected to match
// exactly; the 0.5% tolerance is the issue's.
#include "MedicalTestUtilities.h"
#include "vtkBlockLODContour.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageCast.h"
#include "vtkImageData.h"
#include "vtkMassProperties.h"
#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkStaticPointLocator.h"
#include "vtkTriangleFilter.h"
#include "vtkTrivialProducer.h"
#include <vtksys/SystemTools.hxx>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace
{
using medical_test::Check;
double Area(vtkPolyData* pd)
{
  vtkNew<vtkMassProperties> mass;
  mass->SetInputData(pd);
  mass->Update();
  return mass->GetSurfaceArea();
}

// Largest distance from a point of `a` to the nearest point of `b`.
double MaxNearestDistance(vtkPolyData* a, vtkPolyData* b)
{
  vtkNew<vtkStaticPointLocator> locator;
  locator->SetDataSet(b);
  locator->BuildLocator();
  double worst = 0;
  double x[3], y[3];
  for (vtkIdType i = 0; i < a->GetNumberOfPoints(); ++i)
  {
    a->GetPoint(i, x);
    const vtkIdType j = locator->FindClosestPoint(x);
    b->GetPoint(j, y);
    worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(x, y)));
  }
  return worst;
}

void Compare(const std::string& label, vtkImageData* image, double isovalue)
{
  vtkNew<vtkTrivialProducer> producer;
  producer->SetOutput(image);

  vtkNew<vtkFlyingEdges3D> fe;
  fe->SetInputConnection(producer->GetOutputPort());
  fe->SetValue(0, isovalue);
  fe->ComputeNormalsOff();
  fe->Update();

  vtkNew<vtkBlockLODContour> lod;
  lod->SetInputConnection(producer->GetOutputPort());
  lod->SetValue(0, isovalue);
  lod->SetLOD(3);
  lod->Update();

  vtkPolyData* a = lod->GetOutput();
  vtkPolyData* b = fe->GetOutput();
  const double ta = static_cast<double>(a->GetNumberOfPolys());
  const double tb = static_cast<double>(b->GetNumberOfPolys());
  const double areaA = Area(a);
  const double areaB = Area(b);
  double spacing[3];
  image->GetSpacing(spacing);
  const double voxel = std::min(spacing[0], std::min(spacing[1], spacing[2]));
  const double dAB = MaxNearestDistance(a, b) / voxel;
  const double dBA = MaxNearestDistance(b, a) / voxel;
  std::printf("%s iso %g: triangles %.0f vs FE %.0f, points %lld vs %lld, area %.6g vs %.6g, "
              "max vertex distance %.2e / %.2e voxel\n",
    label.c_str(), isovalue, ta, tb, static_cast<long long>(a->GetNumberOfPoints()),
    static_cast<long long>(b->GetNumberOfPoints()), areaA, areaB, dAB, dBA);
  Check(tb > 0, label + ": FlyingEdges made a surface");
  Check(std::fabs(ta - tb) <= 0.005 * tb, label + ": triangle count within 0.5%");
  Check(std::fabs(areaA - areaB) <= 0.005 * areaB, label + ": area within 0.5%");
  Check(dAB <= 1e-4 && dBA <= 1e-4, label + ": vertices within 1e-4 voxel");
  Check(a->GetPointData()->GetNormals() != nullptr, label + ": normals present");
}
} // namespace

int TestBlockLODContourFlyingEdges(int, char*[])
{
  vtkSMPTools::SetBackend("STDThread");

  // Phantom with odd sizes (not multiples of 8), a shifted extent, anisotropic spacing.
  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(83, 91, 67);
  phantom->SetSpacing(0.9, 0.8, 1.3);
  phantom->SetOrigin(-40, 12, 7);
  phantom->SetNoiseStandardDeviation(15);
  phantom->Update();
  vtkNew<vtkImageData> shifted;
  shifted->DeepCopy(phantom->GetOutput());
  shifted->SetExtent(5, 87, -3, 87, 10, 76);
  for (double iso : { -500.0, 400.0, 35.5 })
  {
    Compare("phantom int16", shifted, iso);
  }

  // The same volume in the other supported types.
  const int types[] = { VTK_UNSIGNED_SHORT, VTK_INT, VTK_FLOAT, VTK_DOUBLE };
  for (int type : types)
  {
    vtkNew<vtkImageCast> cast;
    cast->SetInputConnection(phantom->GetOutputPort());
    cast->SetOutputScalarType(type);
    if (type == VTK_UNSIGNED_SHORT)
    {
      // Shift into the unsigned range first.
      vtkNew<vtkImageData> positive;
      positive->DeepCopy(phantom->GetOutput());
      vtkDataArray* s = positive->GetPointData()->GetScalars();
      for (vtkIdType i = 0; i < s->GetNumberOfTuples(); ++i)
      {
        s->SetTuple1(i, s->GetTuple1(i) + 1024);
      }
      cast->SetInputData(positive);
      cast->Update();
      Compare(std::string("phantom ") + vtkImageScalarTypeNameMacro(type), cast->GetOutput(), 524);
      continue;
    }
    cast->Update();
    Compare(std::string("phantom ") + vtkImageScalarTypeNameMacro(type), cast->GetOutput(), 400.25);
  }
  vtkNew<vtkImageCast> toUChar;
  toUChar->SetInputConnection(phantom->GetOutputPort());
  toUChar->ClampOverflowOn();
  toUChar->SetOutputScalarTypeToUnsignedChar();
  toUChar->Update();
  Compare("phantom uint8 (clamped)", toUChar->GetOutput(), 20.5);

  // The real head CT, when cached.
  const std::string ct = medical_test::DataFile("ct_head.mha");
  if (vtksys::SystemTools::FileExists(ct))
  {
    vtkNew<vtkMetaImageReader> reader;
    reader->SetFileName(ct.c_str());
    reader->Update();
    for (double iso : { -500.0, 400.0 })
    {
      Compare("real CT", reader->GetOutput(), iso);
    }
  }
  else
  {
    std::printf("real CT not cached (%s): compared on the phantom only\n", ct.c_str());
  }

  return medical_test::Finish("vtkBlockLODContour level 3 equals vtkFlyingEdges3D");
}
