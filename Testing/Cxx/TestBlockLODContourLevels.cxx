// SPDX-License-Identifier: BSD-3-Clause
// vtkBlockLODContour at every level of detail:
// - watertight on closed surfaces: every edge shared by exactly two triangles,
//   no two points at the same place (points merged across blocks), no
//   degenerate triangle (analytic sphere and torus, and the phantom padded
//   with air so that all its surfaces close);
// - on analytic distance fields, every vertex lies on the true surface within
//   h^2 / (4 r), h the level's cube edge and r the smallest radius of
//   curvature (linear interpolation along an edge is off by at most h^2 / (8 r));
// - triangle counts grow with the level;
// - the cache: a repeated (isovalue, level) costs no extraction (counters, not
//   clocks), a changed input is re-extracted;
// - parallel pieces (with the ghost layers the filter requests) give, at every
//   level, exactly the one-process triangles and block ids: none duplicated,
//   none missing, and the same normals at the pieces' faces (coarse levels
//   sample the whole volume's grid, not each piece's).
#include "MedicalTestUtilities.h"
#include "vtkBlockLODContour.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageConstantPad.h"
#include "vtkImageData.h"
#include "vtkImageTranslateExtent.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkTrivialProducer.h"

#include <algorithm>
#include <array>
#include <iterator>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

namespace
{
using medical_test::Check;
vtkSmartPointer<vtkImageData> Field(int n, double spacing, const std::function<double(double, double, double)>& f)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(n, n, n);
  image->SetSpacing(spacing, spacing, spacing);
  const double o = -0.5 * (n - 1) * spacing;
  image->SetOrigin(o, o, o);
  vtkNew<vtkFloatArray> s;
  s->SetName("f");
  s->SetNumberOfTuples(static_cast<vtkIdType>(n) * n * n);
  vtkIdType id = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        s->SetValue(id++, static_cast<float>(f(o + i * spacing, o + j * spacing, o + k * spacing)));
  image->GetPointData()->SetScalars(s);
  return image;
}

// Edge-manifold and merge checks on a closed triangle surface.
void CheckWatertight(vtkPolyData* pd, const std::string& label)
{
  std::unordered_map<std::uint64_t, int> edges;
  vtkIdType degenerate = 0;
  auto it = vtk::TakeSmartPointer(pd->GetPolys()->NewIterator());
  for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
  {
    vtkIdType n;
    const vtkIdType* ids;
    it->GetCurrentCell(n, ids);
    if (n != 3 || ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2])
    {
      ++degenerate;
      continue;
    }
    for (int e = 0; e < 3; ++e)
    {
      std::uint64_t a = ids[e], b = ids[(e + 1) % 3];
      if (a > b)
      {
        std::swap(a, b);
      }
      ++edges[(a << 32) | b];
    }
  }
  vtkIdType bad = 0;
  for (const auto& e : edges)
  {
    bad += e.second != 2;
  }
  // No two points at the same place: merged within and across blocks.
  std::map<std::array<float, 3>, vtkIdType> positions;
  vtkIdType duplicates = 0;
  vtkFloatArray* pts = vtkFloatArray::SafeDownCast(pd->GetPoints()->GetData());
  for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i)
  {
    const float* x = pts->GetPointer(3 * i);
    duplicates += !positions.emplace(std::array<float, 3>{ x[0], x[1], x[2] }, i).second;
  }
  std::printf("%s: %lld triangles, %zu edges, %lld not shared by exactly two, %lld duplicate "
              "points, %lld degenerate\n",
    label.c_str(), static_cast<long long>(pd->GetNumberOfPolys()), edges.size(),
    static_cast<long long>(bad), static_cast<long long>(duplicates),
    static_cast<long long>(degenerate));
  Check(pd->GetNumberOfPolys() > 0, label + ": non-empty");
  Check(bad == 0, label + ": every edge shared by exactly two triangles");
  Check(duplicates == 0, label + ": no duplicate points");
  Check(degenerate == 0, label + ": no degenerate triangles");
}

void TestAnalytic(const std::string& name, vtkImageData* image, double voxel, double minRadius,
  const std::function<double(double, double, double)>& distance)
{
  vtkNew<vtkBlockLODContour> lod;
  lod->SetInputData(image);
  lod->SetValue(0, 0.0);
  vtkIdType previous = 0;
  for (int level = 0; level < 4; ++level)
  {
    lod->SetLOD(level);
    lod->Update();
    vtkPolyData* pd = lod->GetOutput();
    const std::string label = name + " level " + std::to_string(level);
    CheckWatertight(pd, label);
    const double h = voxel * (8 >> level);
    const double tolerance = h * h / (4.0 * minRadius) + 1e-4 * voxel;
    double worst = 0;
    double x[3];
    for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i)
    {
      pd->GetPoint(i, x);
      worst = std::max(worst, std::fabs(distance(x[0], x[1], x[2])));
    }
    std::printf("%s: largest distance to the true surface %.4g (tolerance %.4g)\n", label.c_str(),
      worst, tolerance);
    Check(worst <= tolerance, label + ": vertices on the true surface");
    Check(pd->GetNumberOfPolys() > previous, label + ": more triangles than the level below");
    previous = pd->GetNumberOfPolys();
  }
}

void TestCache()
{
  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(70, 66, 61);
  vtkNew<vtkBlockLODContour> lod;
  lod->SetInputConnection(phantom->GetOutputPort());
  lod->SetValue(0, 400.0);
  lod->SetLOD(2);
  lod->Update();
  Check(lod->GetNumberOfExtractions() == 1, "first request extracts once");
  Check(lod->GetNumberOfBlockRangeComputations() == 1, "block ranges computed once");
  const vtkIdType triangles = lod->GetOutput()->GetNumberOfPolys();

  lod->SetLOD(3);
  lod->Update();
  lod->SetLOD(2);
  lod->Update();
  Check(lod->GetNumberOfExtractions() == 2, "returning to a cached level extracts nothing");
  Check(lod->GetNumberOfCacheHits() == 1, "one cache hit");
  Check(lod->GetOutput()->GetNumberOfPolys() == triangles, "cached surface is the same surface");

  lod->SetValue(0, -500.0);
  lod->Update();
  lod->SetValue(0, 400.0);
  lod->Update();
  Check(lod->GetNumberOfExtractions() == 3, "returning to a cached isovalue extracts nothing");
  Check(lod->GetNumberOfBlockRangeComputations() == 1, "isovalue changes reuse block ranges");

  // Several isovalues: the cached ones are reused, the new one extracted.
  lod->SetNumberOfContours(2);
  lod->SetValue(0, 400.0);
  lod->SetValue(1, 100.0);
  lod->Update();
  Check(lod->GetNumberOfExtractions() == 4, "only the new isovalue of a set is extracted");

  // A changed input invalidates ranges and cache.
  phantom->SetNoiseStandardDeviation(5.0);
  lod->SetNumberOfContours(1);
  lod->SetValue(0, 400.0);
  lod->Update();
  Check(lod->GetNumberOfBlockRangeComputations() == 2, "new input data: block ranges recomputed");
  Check(lod->GetNumberOfExtractions() == 5, "new input data: surface extracted again");

  // No caching at all when the limit is 0.
  lod->SetCacheMemoryLimit(0);
  lod->SetLOD(1);
  lod->Update();
  lod->SetLOD(0);
  lod->Update();
  lod->SetLOD(1);
  lod->Update();
  Check(lod->GetNumberOfExtractions() == 8, "CacheMemoryLimit 0 disables the cache");
  Check(lod->GetCacheMegabytes() == 0.0, "an empty cache holds nothing");
}
// Triangles as sorted vertex positions (quantised) and the block id (-1
// without one), for set comparisons.
using Triangle = std::array<std::array<long long, 3>, 4>;
std::array<long long, 3> Quantise(const double x[3])
{
  return { std::llround(x[0] * 1e4), std::llround(x[1] * 1e4), std::llround(x[2] * 1e4) };
}

void CollectTriangles(vtkPolyData* pd, std::multiset<Triangle>& out,
  std::map<std::array<long long, 3>, std::array<float, 3>>* normals)
{
  auto it = vtk::TakeSmartPointer(pd->GetPolys()->NewIterator());
  vtkDataArray* n = pd->GetPointData()->GetNormals();
  vtkDataArray* blockIds = pd->GetCellData()->GetArray("BlockId");
  vtkIdType cell = 0;
  for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
  {
    vtkIdType count;
    const vtkIdType* ids;
    it->GetCurrentCell(count, ids);
    Triangle t;
    for (int v = 0; v < 3; ++v)
    {
      double x[3];
      pd->GetPoint(ids[v], x);
      t[v] = Quantise(x);
      if (normals)
      {
        double nv[3];
        n->GetTuple(ids[v], nv);
        (*normals)[t[v]] = { static_cast<float>(nv[0]), static_cast<float>(nv[1]),
          static_cast<float>(nv[2]) };
      }
    }
    std::sort(t.begin(), t.begin() + 3);
    const long long block = blockIds ? static_cast<long long>(blockIds->GetTuple1(cell)) : -1;
    t[3] = { block, 0, 0 };
    ++cell;
    out.insert(t);
  }
}

// Pieces of a parallel run, at every level: the joined triangles (with their
// block ids) are exactly the one-process triangles and the normals the same.
// Sizes are no multiple of 8. Two inputs: the phantom (the executive marks
// its ghost cells), and the phantom with its whole extent moved off 0 (the
// coarse grid is the whole volume's, not the piece's) through a filter that
// drops the ghost array (the filter then finds the piece's own cells itself).
void TestPieces(vtkAlgorithm* input, const std::string& name)
{
  vtkNew<vtkBlockLODContour> lod;
  lod->SetInputConnection(input->GetOutputPort());
  lod->SetValue(0, 400.0);
  lod->GenerateBlockIdsOn();
  for (int level = 0; level < 4; ++level)
  {
    lod->SetLOD(level);
    lod->UpdatePiece(0, 1, 0);
    std::multiset<Triangle> whole;
    std::map<std::array<long long, 3>, std::array<float, 3>> wholeNormals;
    CollectTriangles(lod->GetOutput(), whole, &wholeNormals);
    for (int pieces : { 2, 3, 5 })
    {
      std::multiset<Triangle> joined;
      std::map<std::array<long long, 3>, std::array<float, 3>> normals;
      for (int p = 0; p < pieces; ++p)
      {
        lod->UpdatePiece(p, pieces, 0);
        CollectTriangles(lod->GetOutput(), joined, &normals);
      }
      const std::string label = name + ", level " + std::to_string(level) + ", " + std::to_string(pieces) + " pieces";
      std::printf("%s: %zu triangles joined, %zu in one piece\n", label.c_str(), joined.size(),
        whole.size());
      Check(!whole.empty(), label + ": the surface is not empty");
      if (joined != whole)
      {
        std::vector<Triangle> extra, missing;
        std::set_difference(joined.begin(), joined.end(), whole.begin(), whole.end(),
          std::back_inserter(extra));
        std::set_difference(whole.begin(), whole.end(), joined.begin(), joined.end(),
          std::back_inserter(missing));
        std::printf("  %zu not in the one-process surface, %zu missing\n", extra.size(),
          missing.size());
        for (std::size_t i = 0; i < std::min<std::size_t>(extra.size(), 3); ++i)
        {
          std::printf("  extra %lld %lld %lld block %lld / missing %lld %lld %lld block %lld\n",
            extra[i][0][0], extra[i][0][1], extra[i][0][2], extra[i][3][0],
            i < missing.size() ? missing[i][0][0] : 0, i < missing.size() ? missing[i][0][1] : 0,
            i < missing.size() ? missing[i][0][2] : 0, i < missing.size() ? missing[i][3][0] : 0);
        }
      }
      Check(joined == whole,
        label + ": the pieces' triangles and block ids are exactly the one-process ones");
      double worst = 1.0;
      for (const auto& n : normals)
      {
        auto w = wholeNormals.find(n.first);
        if (w != wholeNormals.end())
        {
          worst = std::min(worst, static_cast<double>(n.second[0] * w->second[0] +
                                    n.second[1] * w->second[1] + n.second[2] * w->second[2]));
        }
      }
      Check(worst > 0.99999, label + ": normals match the one-process normals");
    }
  }
}
} // namespace

int TestBlockLODContourLevels(int, char*[])
{
  vtkSMPTools::SetBackend("STDThread");

  // Sphere of radius 27 voxels; torus with radii 25 and 9 voxels (97^3, spacing 0.5).
  // Centres sit off the grid so that no sample lies exactly on the surface
  // (there a point would be shared by several edges: the documented
  // degenerate case, not a merging failure).
  const double spacing = 0.5;
  const double R = 27 * spacing;
  const double c[3] = { 0.13 * spacing, 0.071 * spacing, 0.047 * spacing };
  auto sphere = [R, c](double x, double y, double z) {
    x -= c[0], y -= c[1], z -= c[2];
    return std::sqrt(x * x + y * y + z * z) - R;
  };
  TestAnalytic("sphere", Field(97, spacing, sphere), spacing, R, sphere);
  const double big = 25 * spacing, small = 9 * spacing;
  auto torus = [big, small, c](double x, double y, double z) {
    x -= c[0], y -= c[1], z -= c[2];
    const double q = std::sqrt(x * x + y * y) - big;
    return std::sqrt(q * q + z * z) - small;
  };
  TestAnalytic("torus", Field(97, spacing, torus), spacing, small, torus);

  // The phantom padded with one layer of air: every surface closes.
  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(75, 82, 69);
  vtkNew<vtkImageConstantPad> pad;
  pad->SetInputConnection(phantom->GetOutputPort());
  pad->SetOutputWholeExtent(-1, 75, -1, 82, -1, 69);
  pad->SetConstant(-1000);
  pad->Update();
  vtkNew<vtkBlockLODContour> lod;
  lod->SetInputConnection(pad->GetOutputPort());
  for (double iso : { -500.5, 400.5 })
  {
    lod->SetValue(0, iso);
    for (int level = 0; level < 4; ++level)
    {
      lod->SetLOD(level);
      lod->Update();
      CheckWatertight(lod->GetOutput(),
        "phantom iso " + std::to_string(iso) + " level " + std::to_string(level));
    }
  }

  TestCache();
  vtkNew<vtkMedicalPhantomSource> noisy;
  noisy->SetDimensions(61, 57, 49);
  noisy->SetNoiseStandardDeviation(10);
  TestPieces(noisy, "phantom");
  vtkNew<vtkImageTranslateExtent> shift;
  shift->SetInputConnection(noisy->GetOutputPort());
  shift->SetTranslation(-3, 5, -11);
  TestPieces(shift, "phantom moved to extent (-3, 5, -11)");

  return medical_test::Finish("vtkBlockLODContour levels: all checks passed");
}
