// SPDX-License-Identifier: BSD-3-Clause
// Unit test of the CPU HistoPyramid model (Mappers/Core/HistoPyramid), without
// VTK: totals, level sums, exact enumeration of every primitive once, and the
// front-to-back order of the traversal along rays from many eye positions
// (inside, outside and far away from the volume).
#include "MedicalTestUtilities.h"

#include "HeadPhantom.h"
#include "HistoPyramid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace
{
using medical_test::Check;

// Every (cell, rank) pair appears exactly once; returns, per cell, the first
// traversal index (or -1).
std::vector<std::int64_t> Enumerate(const mediso::HistoPyramid& pyramid, const int cells[3],
  const std::vector<std::uint32_t>& counts, const double eye[3], bool& exact)
{
  std::vector<std::int64_t> first(counts.size(), -1);
  std::vector<std::uint32_t> seen(counts.size(), 0);
  exact = true;
  for (std::uint64_t index = 0; index < pyramid.GetTotal(); ++index)
  {
    int cell[3];
    int rank;
    pyramid.Traverse(index, eye, cell, rank);
    if (cell[0] >= cells[0] || cell[1] >= cells[1] || cell[2] >= cells[2])
    {
      exact = false;
      continue;
    }
    const std::size_t id = (static_cast<std::size_t>(cell[2]) * cells[1] + cell[1]) * cells[0] + cell[0];
    exact &= rank == static_cast<int>(seen[id]); // ranks of a cell come in order 0, 1, ...
    ++seen[id];
    if (first[id] < 0)
    {
      first[id] = static_cast<std::int64_t>(index);
    }
  }
  exact &= seen == counts;
  return first;
}

// Along random rays from the eye, the cells with primitives must come out of
// the traversal in the order the ray meets them (what early-z needs).
int RayOrderViolations(const std::vector<std::int64_t>& first, const int cells[3],
  const double eye[3], std::mt19937& random)
{
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int violations = 0;
  for (int ray = 0; ray < 400; ++ray)
  {
    // Aim at a random point inside the volume.
    const double target[3] = { u(random) * cells[0], u(random) * cells[1], u(random) * cells[2] };
    double dir[3];
    double length = 0;
    for (int a = 0; a < 3; ++a)
    {
      dir[a] = target[a] - eye[a];
      length += dir[a] * dir[a];
    }
    length = std::sqrt(length);
    // Walk only the part of the ray inside the volume's box (slab test).
    double t0 = 0, t1 = HUGE_VAL;
    for (int a = 0; a < 3; ++a)
    {
      const double d = dir[a] / length;
      if (std::fabs(d) < 1e-12)
      {
        continue; // parallel to the slab; the target is inside it
      }
      double ta = (0 - eye[a]) / d, tb = (cells[a] - eye[a]) / d;
      if (ta > tb)
      {
        std::swap(ta, tb);
      }
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    std::int64_t last = -1;
    std::int64_t lastCell = -1;
    for (double t = t0; t < t1; t += 0.01)
    {
      int c[3];
      bool inside = true;
      for (int a = 0; a < 3; ++a)
      {
        const double x = eye[a] + dir[a] / length * t;
        c[a] = static_cast<int>(std::floor(x));
        inside &= c[a] >= 0 && c[a] < cells[a];
      }
      if (!inside)
      {
        continue;
      }
      const std::int64_t id = (static_cast<std::int64_t>(c[2]) * cells[1] + c[1]) * cells[0] + c[0];
      if (id == lastCell || first[id] < 0)
      {
        continue;
      }
      lastCell = id;
      violations += first[id] < last;
      last = first[id];
    }
  }
  return violations;
}

void TestRandomCounts()
{
  const int cells[3] = { 13, 7, 10 }; // not powers of two
  std::mt19937 random(7);
  std::uniform_int_distribution<int> value(0, 6);
  std::vector<std::uint32_t> counts(cells[0] * cells[1] * cells[2]);
  std::uint64_t sum = 0;
  for (auto& c : counts)
  {
    const int v = value(random);
    c = v > 3 ? 0 : static_cast<std::uint32_t>(v); // mostly empty, like a volume
    sum += c;
  }
  mediso::HistoPyramid pyramid;
  pyramid.Build(cells, counts);
  Check(pyramid.GetTotal() == sum, "top of the pyramid is the sum of the base");
  Check(pyramid.GetNumberOfLevels() == 5, "16x8x16 base: 5 levels");
  for (int level = 0; level < pyramid.GetNumberOfLevels(); ++level)
  {
    const int* size = pyramid.GetLevelSize(level);
    std::uint64_t levelSum = 0;
    for (int k = 0; k < size[2]; ++k)
      for (int j = 0; j < size[1]; ++j)
        for (int i = 0; i < size[0]; ++i)
          levelSum += pyramid.GetCount(level, i, j, k);
    Check(levelSum == sum, "every level sums to the total");
  }
  const double eyes[][3] = { { -20, -5, -30 }, { 30, 20, 40 }, { 6.3, 3.2, 4.9 }, { 6.5, -1e6, 5 },
    { -3, 4, 20 }, { 1e6, 2e5, -3e5 } };
  for (const auto& eye : eyes)
  {
    bool exact = false;
    const auto first = Enumerate(pyramid, cells, counts, eye, exact);
    Check(exact, "every primitive enumerated exactly once");
    const int violations = RayOrderViolations(first, cells, eye, random);
    std::printf("eye (%g, %g, %g): %llu primitives, %d front-to-back violations along 400 rays\n",
      eye[0], eye[1], eye[2], static_cast<unsigned long long>(pyramid.GetTotal()), violations);
    Check(violations == 0, "front-to-back along rays from the eye");
  }
}

void TestPhantomCrossings()
{
  // The base pass of the GPU mapper on a real-looking volume: cells crossed by
  // skin and bone isovalues, two primitives where both cross.
  const int points[3] = { 41, 37, 33 };
  const mediso::HeadPhantom phantom(points, 0.0, 1);
  std::vector<std::int16_t> data(static_cast<std::size_t>(points[0]) * points[1] * points[2]);
  for (int k = 0; k < points[2]; ++k)
    for (int j = 0; j < points[1]; ++j)
      for (int i = 0; i < points[0]; ++i)
        data[(static_cast<std::size_t>(k) * points[1] + j) * points[0] + i] = phantom.EvaluatePoint(i, j, k);
  const std::vector<double> isovalues = { -500.5, 400.5 };
  const auto counts = mediso::HistoPyramid::CountCrossings(data.data(), points, isovalues);
  // Brute force: a cell counts an isovalue when its corners straddle it.
  std::uint64_t expected = 0;
  for (int k = 0; k + 1 < points[2]; ++k)
    for (int j = 0; j + 1 < points[1]; ++j)
      for (int i = 0; i + 1 < points[0]; ++i)
        for (double iso : isovalues)
        {
          bool below = false, above = false;
          for (int c = 0; c < 8; ++c)
          {
            const double v = data[((k + (c >> 2)) * static_cast<std::size_t>(points[1]) + j +
                                    ((c >> 1) & 1)) * points[0] + i + (c & 1)];
            below |= v < iso;
            above |= v >= iso;
          }
          expected += below && above;
        }
  const int cells[3] = { points[0] - 1, points[1] - 1, points[2] - 1 };
  mediso::HistoPyramid pyramid;
  pyramid.Build(cells, counts);
  std::printf("phantom 41x37x33, isovalues -500.5 and 400.5: %llu primitives (brute force %llu)\n",
    static_cast<unsigned long long>(pyramid.GetTotal()), static_cast<unsigned long long>(expected));
  Check(pyramid.GetTotal() == expected && expected > 0, "pyramid total equals the brute-force count");
  std::mt19937 random(3);
  const double eye[3] = { 20, -60, 45 };
  bool exact = false;
  const auto first = Enumerate(pyramid, cells, counts, eye, exact);
  Check(exact, "phantom: every primitive enumerated exactly once");
  Check(RayOrderViolations(first, cells, eye, random) == 0, "phantom: front-to-back along rays");
}
} // namespace

int main()
{
  TestRandomCounts();
  TestPhantomCrossings();
  return medical_test::Finish("HistoPyramid core: all checks passed");
}
