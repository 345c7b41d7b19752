// SPDX-License-Identifier: BSD-3-Clause
// vtkBlockLODContour on images whose direction matrix is not the identity (an
// oblique scan, a NIfTI whose sform is turned), placed as VTK's image contour
// filters place theirs (by the image's index-to-physical matrix):
// - a turned direction (30 degrees about an oblique axis) and a mirrored one
//   (determinant -1), with an origin, odd sizes, a shifted extent and
//   anisotropic spacing: at level 3 the same points as vtkFlyingEdges3D on the
//   same input (within 1e-4 voxel, both ways), the same triangles with the
//   same winding (each triangle's corners mapped to FlyingEdges' points), and
//   the same normals (det(D) D n, so a mirror keeps FlyingEdges' orientation);
// - at every level, with 32- and 64-bit ids, the surface equals the
//   identity-direction surface placed by origin + D (x - origin): points and
//   normals value for value within float rounding, triangles identical; the
//   estimates are those of the identity input;
// - GenerateLevel gives the placed surface too, and the per-level cache is
//   kept while the direction stays (no extraction) and dropped when only the
//   direction changes (the surface moves with it);
// - a sheared, a singular and a non-finite direction: one error each, naming
//   the matrix as not orthonormal, and an empty output.
#include "MedicalTestUtilities.h"
#include "vtkBlockLODContour.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkStaticPointLocator.h"
#include "vtkTestErrorObserver.h"
#include "vtkTransform.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;

using Triangle = std::array<vtkIdType, 3>;

// The triangle's corners rotated so the smallest id comes first: the same
// triangle with the same winding gives the same key.
Triangle Canonical(vtkIdType a, vtkIdType b, vtkIdType c)
{
  if (b < a && b < c)
  {
    return { b, c, a };
  }
  if (c < a && c < b)
  {
    return { c, a, b };
  }
  return { a, b, c };
}

std::vector<Triangle> Triangles(vtkPolyData* surface, const std::vector<vtkIdType>* map)
{
  std::vector<Triangle> out;
  vtkCellArray* polys = surface->GetPolys();
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(n, ids);)
  {
    if (n != 3)
    {
      continue;
    }
    auto at = [&](int k) { return map ? (*map)[ids[k]] : ids[k]; };
    out.push_back(Canonical(at(0), at(1), at(2)));
  }
  std::sort(out.begin(), out.end());
  return out;
}

vtkSmartPointer<vtkImageData> Oriented(vtkImageData* source, const double direction[9])
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->ShallowCopy(source);
  image->SetDirectionMatrix(direction);
  return image;
}

vtkSmartPointer<vtkPolyData> Contour(vtkImageData* image, double isovalue, int level, bool compact)
{
  vtkNew<vtkBlockLODContour> lod;
  lod->SetInputData(image);
  lod->SetValue(0, isovalue);
  lod->SetLOD(level);
  lod->SetCompactIds(compact);
  lod->Update();
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->ShallowCopy(lod->GetOutput());
  return out;
}

// Level 3 against vtkFlyingEdges3D on the same oriented input.
void CompareWithFlyingEdges(const std::string& label, vtkImageData* image, double isovalue)
{
  vtkNew<vtkFlyingEdges3D> fe;
  fe->SetInputData(image);
  fe->SetValue(0, isovalue);
  fe->ComputeNormalsOn();
  fe->Update();
  vtkPolyData* b = fe->GetOutput();
  vtkSmartPointer<vtkPolyData> a = Contour(image, isovalue, 3, false);

  const double* spacing = image->GetSpacing();
  const double voxel = std::min(spacing[0], std::min(spacing[1], spacing[2]));
  vtkNew<vtkStaticPointLocator> locator;
  locator->SetDataSet(b);
  locator->BuildLocator();
  std::vector<vtkIdType> map(a->GetNumberOfPoints());
  std::vector<char> used(b->GetNumberOfPoints(), 0);
  double worst = 0, worstNormal = 0;
  vtkIdType reused = 0;
  vtkDataArray* na = a->GetPointData()->GetNormals();
  vtkDataArray* nb = b->GetPointData()->GetNormals();
  for (vtkIdType i = 0; i < a->GetNumberOfPoints(); ++i)
  {
    double x[3], y[3];
    a->GetPoint(i, x);
    const vtkIdType j = locator->FindClosestPoint(x);
    b->GetPoint(j, y);
    worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(x, y)) / voxel);
    map[i] = j;
    reused += used[j] ? 1 : 0;
    used[j] = 1;
    if (na && nb)
    {
      double u[3], v[3];
      na->GetTuple(i, u);
      nb->GetTuple(j, v);
      worstNormal = std::max(worstNormal, 1.0 - vtkMath::Dot(u, v));
    }
  }
  const std::vector<Triangle> ta = Triangles(a, &map);
  const std::vector<Triangle> tb = Triangles(b, nullptr);
  std::printf("%s iso %g: %lld vs FE %lld triangles, %lld vs %lld points, max "
              "vertex distance "
              "%.2e voxel, max 1 - n.n' %.2e\n",
    label.c_str(), isovalue, static_cast<long long>(ta.size()), static_cast<long long>(tb.size()),
    static_cast<long long>(a->GetNumberOfPoints()), static_cast<long long>(b->GetNumberOfPoints()),
    worst, worstNormal);
  Check(!tb.empty(), label + ": FlyingEdges made a surface");
  Check(a->GetNumberOfPoints() == b->GetNumberOfPoints() && reused == 0,
    label + ": one point for each of FlyingEdges' points");
  Check(worst <= 1e-4, label + ": every point within 1e-4 voxel of FlyingEdges' point");
  Check(ta == tb, label + ": the same triangles with the same winding as FlyingEdges");
  Check(na && nb && worstNormal <= 1e-3, label + ": the normals of FlyingEdges (1 - n.n' <= 1e-3)");
}

// The oriented surface against the identity-direction one placed by hand.
void ComparePlaced(const std::string& label, vtkPolyData* placed, vtkPolyData* plain,
  const double direction[9], const double origin[3], double voxel)
{
  const double sign = vtkMatrix3x3::Determinant(direction) < 0 ? -1.0 : 1.0;
  bool sameCounts = placed->GetNumberOfPoints() == plain->GetNumberOfPoints() &&
    placed->GetNumberOfPolys() == plain->GetNumberOfPolys() && plain->GetNumberOfPolys() > 0;
  Check(sameCounts, label + ": the identity surface's points and triangles");
  if (!sameCounts)
  {
    return;
  }
  double worst = 0, worstNormal = 0;
  vtkDataArray* np = placed->GetPointData()->GetNormals();
  vtkDataArray* nq = plain->GetPointData()->GetNormals();
  for (vtkIdType i = 0; i < plain->GetNumberOfPoints(); ++i)
  {
    double x[3], y[3], e[3];
    plain->GetPoint(i, x);
    placed->GetPoint(i, y);
    for (int r = 0; r < 3; ++r)
    {
      e[r] = origin[r];
      for (int c = 0; c < 3; ++c)
      {
        e[r] += direction[3 * r + c] * (x[c] - origin[c]);
      }
    }
    worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(e, y)) / voxel);
    if (np && nq)
    {
      double n[3], m[3], t[3];
      nq->GetTuple(i, n);
      np->GetTuple(i, m);
      for (int r = 0; r < 3; ++r)
      {
        t[r] = sign *
          (direction[3 * r] * n[0] + direction[3 * r + 1] * n[1] + direction[3 * r + 2] * n[2]);
      }
      worstNormal = std::max(worstNormal, std::sqrt(vtkMath::Distance2BetweenPoints(t, m)));
    }
  }
  Check(worst <= 1e-4, label + ": points are the identity's placed (within 1e-4 voxel)");
  Check(np && nq && worstNormal <= 1e-5, label + ": normals are det(D) D n of the identity's");
  Check(Triangles(placed, nullptr) == Triangles(plain, nullptr),
    label + ": the identity's triangles, in the same winding");
  Check(placed->GetPolys()->IsStorage64Bit() == plain->GetPolys()->IsStorage64Bit(),
    label + ": the same id width");
  // The ranges stored with the arrays (VTK's range cache) are those of the
  // placed values.
  double bounds[6];
  placed->GetPoints()->GetData()->GetRange(bounds, 0);
  double lo = std::numeric_limits<double>::max(), hi = -lo;
  for (vtkIdType i = 0; i < placed->GetNumberOfPoints(); ++i)
  {
    lo = std::min(lo, placed->GetPoint(i)[0]);
    hi = std::max(hi, placed->GetPoint(i)[0]);
  }
  Check(bounds[0] == lo && bounds[1] == hi, label + ": the points' cached range is the placed one");
}

void CountErrors(vtkImageData* image, const std::string& label)
{
  vtkNew<vtkBlockLODContour> lod;
  lod->SetInputData(image);
  lod->SetValue(0, 400.5);
  vtkNew<vtkTest::ErrorObserver> observer;
  lod->AddObserver(vtkCommand::ErrorEvent, observer);
  lod->AddObserver(vtkCommand::WarningEvent, observer);
  lod->Update();
  const std::string text = observer->GetErrorMessage();
  const std::string why = "is not orthonormal";
  const std::size_t first = text.find(why);
  // Said without VTK's "ERROR: In" header, which would fail the ctest.
  std::printf(
    "%s: ...%s", label.c_str(), first == std::string::npos ? "" : text.substr(first).c_str());
  Check(first != std::string::npos && text.find(why, first + 1) == std::string::npos &&
      !observer->GetWarning(),
    label + ": exactly one error, saying why");
  Check(lod->GetOutput()->GetNumberOfPoints() == 0, label + ": empty output");
}
} // namespace

int TestBlockLODContourOriented(int, char*[])
{
  vtkSMPTools::SetBackend("STDThread");

  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(61, 57, 53);
  phantom->SetSpacing(0.9, 0.8, 1.3);
  phantom->SetOrigin(-40, 12, 7);
  phantom->SetNoiseStandardDeviation(15);
  phantom->Update();
  vtkNew<vtkImageData> plain;
  plain->DeepCopy(phantom->GetOutput());
  plain->SetExtent(5, 65, -3, 53, 10, 62);
  const double* origin = plain->GetOrigin();
  const double voxel = 0.8;

  // 30 degrees about an oblique axis; its mirror image (x reversed first).
  vtkNew<vtkTransform> turn;
  turn->RotateWXYZ(30, 1, 2, 3);
  double turned[9], mirrored[9];
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      turned[3 * r + c] = turn->GetMatrix()->GetElement(r, c);
      mirrored[3 * r + c] = (c == 0 ? -1 : 1) * turned[3 * r + c];
    }
  }
  struct Case
  {
    const char* Name;
    const double* Direction;
  };
  const Case cases[] = { { "turned", turned }, { "mirrored", mirrored } };

  for (const Case& c : cases)
  {
    vtkSmartPointer<vtkImageData> image = Oriented(plain, c.Direction);
    for (double iso : { 400.5, -500.5 })
    {
      CompareWithFlyingEdges(c.Name, image, iso);
    }
    for (bool compact : { false, true })
    {
      for (int level = 0; level < 4; ++level)
      {
        const std::string label = std::string(c.Name) + " level " + std::to_string(level) +
          (compact ? " 32-bit ids" : " 64-bit ids");
        vtkSmartPointer<vtkPolyData> placed = Contour(image, 400.5, level, compact);
        vtkSmartPointer<vtkPolyData> identity = Contour(plain, 400.5, level, compact);
        ComparePlaced(label, placed, identity, c.Direction, origin, voxel);
      }
    }
  }

  // The estimator, GenerateLevel and the cache on a mirrored input.
  {
    vtkSmartPointer<vtkImageData> image = Oriented(plain, mirrored);
    vtkNew<vtkBlockLODContour> lod, ref;
    lod->SetInputData(image);
    ref->SetInputData(plain);
    for (vtkBlockLODContour* f : { lod.Get(), ref.Get() })
    {
      f->SetValue(0, 400.5);
      f->SetLOD(3);
      f->Update();
    }
    for (int level = 0; level < 4; ++level)
    {
      Check(lod->EstimateTriangles(400.5, level) == ref->EstimateTriangles(400.5, level),
        "the estimate of level " + std::to_string(level) + " is the identity input's");
    }
    vtkNew<vtkPolyData> generated;
    Check(lod->GenerateLevel(1, generated), "GenerateLevel(1) on the mirrored input");
    ComparePlaced(
      "GenerateLevel(1)", generated, Contour(plain, 400.5, 1, false), mirrored, origin, voxel);
    const int extractions = lod->GetNumberOfExtractions();
    lod->SetLOD(1);
    lod->Update();
    Check(lod->GetNumberOfExtractions() == extractions,
      "level 1 again under the same direction comes from the cache");
    ComparePlaced("level 1 from the cache", lod->GetOutput(), Contour(plain, 400.5, 1, false),
      mirrored, origin, voxel);
    // Only the direction changes (the same values): the cached surfaces are
    // dropped.
    image->SetDirectionMatrix(turned);
    lod->Modified();
    lod->Update();
    Check(
      lod->GetNumberOfExtractions() == extractions + 1, "a new direction makes the level again");
    ComparePlaced("level 1 after the direction changed", lod->GetOutput(),
      Contour(plain, 400.5, 1, false), turned, origin, voxel);
  }

  // Directions that are not a rotation or its mirror image.
  const double sheared[9] = { 1, 0.5, 0, 0, 1, 0, 0, 0, 1 };
  const double singular[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 0 };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double notFinite[9] = { 1, 0, 0, 0, nan, 0, 0, 0, 1 };
  CountErrors(Oriented(plain, sheared), "sheared");
  CountErrors(Oriented(plain, singular), "singular");
  CountErrors(Oriented(plain, notFinite), "non-finite");

  return medical_test::Finish("vtkBlockLODContour places oriented images as vtkFlyingEdges3D");
}
