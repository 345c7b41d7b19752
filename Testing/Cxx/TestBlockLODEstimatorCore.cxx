// SPDX-License-Identifier: BSD-3-Clause
// Unit test of the VTK-free block LOD volume and estimator
// (Filters/Core/BlockLODVolume.h, BlockLODEstimator.h), without VTK. The
// marching-cubes table is the tests' own (FanCaseTable.h; the core takes the
// table as data), so that exact counts can be recomputed here by brute force.
// - Plan's exact points and triangles equal a brute-force count over every
//   cube of each level's sample grid (with NaN voxels and a size that is no
//   multiple of 8);
// - estimates per level: exact (every active block counted) on a small volume;
//   on a large one, exact, or by ratio to an exact coarser level, or sampled,
//   as the budget allows, each within its tolerance of a brute-force count;
//   recorded exact counts returned and used as the ratio's level;
// - the cost model reproduces a linear law from its samples, rescales its
//   defaults from one sample and stays non-negative on collinear samples;
// - the byte layout and the AutoLOD level choice;
// - SetVolume recomputes only for a changed description.
#include "BlockLODEstimator.h"
#include "BlockLODVolume.h"
#include "FanCaseTable.h"
#include "MedicalTestUtilities.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;

using medical_test::Corner;
const medical_test::FanTable& Table = medical_test::FanCases;

struct Field
{
  int Dims[3];
  std::vector<float> Values;
  float At(int i, int j, int k) const
  {
    return this->Values[(static_cast<std::size_t>(k) * this->Dims[1] + j) * this->Dims[0] + i];
  }
};

// A sphere's distance field with deterministic noise, and a few NaN voxels.
Field MakeField(int nx, int ny, int nz, double radius, double noise, bool nans)
{
  Field f{ { nx, ny, nz }, {} };
  f.Values.resize(static_cast<std::size_t>(nx) * ny * nz);
  std::uint32_t state = 2463534242u;
  std::size_t id = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i, ++id)
      {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        const double u = (state & 0xFFFFFF) / double(0xFFFFFF) - 0.5;
        const double x = i - 0.5 * nx + 0.3, y = j - 0.5 * ny + 0.1, z = k - 0.5 * nz + 0.2;
        f.Values[id] = static_cast<float>(std::sqrt(x * x + y * y + z * z) - radius + noise * u);
        if (nans && id % 997 == 5)
        {
          f.Values[id] = std::nanf("");
        }
      }
  return f;
}

// Points and triangles of a level by brute force over its sample grid.
void BruteForce(const Field& f, double iso, int level, double& points, double& triangles)
{
  const int stride = mediso::LevelStride(level);
  std::vector<int> samples[3];
  for (int a = 0; a < 3; ++a)
  {
    for (int p = 0; p < f.Dims[a] - 1; p += stride)
    {
      samples[a].push_back(p);
    }
    samples[a].push_back(f.Dims[a] - 1);
  }
  const int n[3] = { static_cast<int>(samples[0].size()), static_cast<int>(samples[1].size()),
    static_cast<int>(samples[2].size()) };
  auto value = [&](int i, int j, int k) { return f.At(samples[0][i], samples[1][j], samples[2][k]); };
  points = triangles = 0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        const float v = value(i, j, k);
        const int l[3] = { i, j, k };
        for (int a = 0; a < 3; ++a)
        {
          if (l[a] + 1 < n[a])
          {
            const float w = value(i + (a == 0), j + (a == 1), k + (a == 2));
            if (!std::isnan(v) && !std::isnan(w) && (v >= iso) != (w >= iso))
            {
              ++points;
            }
          }
        }
        if (i + 1 < n[0] && j + 1 < n[1] && k + 1 < n[2])
        {
          int index = 0;
          bool nan = false;
          for (int c = 0; c < 8; ++c)
          {
            const float w = value(i + Corner[c][0], j + Corner[c][1], k + Corner[c][2]);
            nan |= std::isnan(w);
            index |= (w >= iso ? 1 : 0) << c;
          }
          triangles += nan ? 0 : Table.Count[index];
        }
      }
}

mediso::VolumeDescription Describe(const Field& f)
{
  mediso::VolumeDescription d;
  d.Type = mediso::ScalarType::Float32;
  d.Data = f.Values.data();
  for (int a = 0; a < 3; ++a)
  {
    d.Dims[a] = f.Dims[a];
  }
  return d;
}

void TestPlanCounts()
{
  const Field f = MakeField(61, 53, 47, 17.0, 1.5, /*nans=*/true);
  mediso::BlockLODVolume volume(Table.Cases, mediso::SerialFor);
  Check(volume.SetVolume(Describe(f)), "a new volume computes block ranges");
  Check(volume.GetRanges().NaNCount > 0, "NaN voxels are counted");
  for (double iso : { -3.0, 0.0, 4.5 })
  {
    for (int level = 0; level < mediso::NumberOfLevels; ++level)
    {
      double points, triangles;
      BruteForce(f, iso, level, points, triangles);
      mediso::ExtractionPlan plan;
      Check(volume.Plan(iso, level, plan), "a plan without abort completes");
      const mediso::SurfaceCounts c = mediso::BlockLODVolume::CountsOf(plan);
      std::printf("plan iso %g level %d: %g points, %g triangles (brute force %g, %g)\n", iso,
        level, c.Points, c.Triangles, points, triangles);
      Check(c.Points == points && c.Triangles == triangles,
        "plan counts equal brute force at iso " + std::to_string(iso) + " level " +
          std::to_string(level));
    }
  }
  // Aborting stops the plan.
  mediso::ExtractionPlan plan;
  Check(!volume.Plan(0.0, 3, plan, [] { return true; }), "an abort stops the plan");
}

void TestEstimates()
{
  // Small volume: every level counted on every active block: exact.
  {
    const Field f = MakeField(40, 37, 35, 11.0, 0.5, false);
    mediso::BlockLODVolume volume(Table.Cases, mediso::SerialFor);
    volume.SetVolume(Describe(f));
    mediso::BlockLODEstimator estimator(volume);
    for (int level = 0; level < mediso::NumberOfLevels; ++level)
    {
      double points, triangles;
      BruteForce(f, 0.0, level, points, triangles);
      const mediso::SurfaceEstimate e = estimator.Estimate(0.0, level);
      Check(e.Method == mediso::EstimateMethod::Exact && e.Counts.Triangles == triangles &&
          e.Counts.Points == points,
        "small volume: exact counts at level " + std::to_string(level));
      Check(estimator.HasExact(0.0, level), "an exact count is remembered");
      // Cubes visited: what the plan of the pair visits (levels 0 and 1 are
      // counted on the coarse copies the plans read).
      mediso::ExtractionPlan plan;
      volume.Plan(0.0, level, plan);
      const double planned = mediso::BlockLODVolume::CountsOf(plan).Cubes;
      const double fullBlocks = static_cast<double>(volume.ActiveBlocks(0.0).size()) * 512;
      Check(level == 2 || e.Counts.Cubes == (level == 3 ? fullBlocks : planned),
        "estimated cubes are the cubes the plan visits, level " + std::to_string(level));
    }
  }

  // Large noisy volume (more active blocks than the budget counts at level 3).
  const Field f = MakeField(161, 150, 140, 62.0, 3.0, false);
  mediso::BlockLODVolume volume(Table.Cases, mediso::SerialFor);
  volume.SetVolume(Describe(f));
  const double iso = 0.25;
  const std::int64_t active = static_cast<std::int64_t>(volume.ActiveBlocks(iso).size());
  std::printf("large volume: %lld active blocks of %lld\n", static_cast<long long>(active),
    static_cast<long long>(volume.GetRanges().GetNumberOfBlocks()));
  double exact[4];
  for (int level = 0; level < mediso::NumberOfLevels; ++level)
  {
    double points;
    BruteForce(f, iso, level, points, exact[level]);
  }
  const char* methods[] = { "exact", "ratio to an exact coarser level", "sampled" };
  // Budgets: the default (levels 0-2 exact, level 3 by ratio to level 2), a
  // small one (level 1 exact, levels 2-3 by ratio to it), none (sampled).
  const double budgets[] = { mediso::BlockLODEstimator::DefaultSampleBudget, 3000.0, 0.0 };
  const mediso::EstimateMethod expected[3][4] = {
    { mediso::EstimateMethod::Exact, mediso::EstimateMethod::Exact, mediso::EstimateMethod::Exact,
      mediso::EstimateMethod::Scaled },
    { mediso::EstimateMethod::Exact, mediso::EstimateMethod::Exact, mediso::EstimateMethod::Scaled,
      mediso::EstimateMethod::Scaled },
    { mediso::EstimateMethod::Sampled, mediso::EstimateMethod::Sampled,
      mediso::EstimateMethod::Sampled, mediso::EstimateMethod::Sampled }
  };
  const double tolerance[3] = { 0.03, 0.06, 0.10 };
  for (int b = 0; b < 3; ++b)
  {
    mediso::BlockLODEstimator estimator(volume);
    estimator.SetSampleBudget(budgets[b]);
    for (int level = 0; level < mediso::NumberOfLevels; ++level)
    {
      const mediso::SurfaceEstimate e = estimator.Estimate(iso, level);
      const double error = (e.Counts.Triangles - exact[level]) / exact[level];
      std::printf("budget %g, level %d: %.0f triangles (%s), exact %.0f (%+.2f%%)\n", budgets[b],
        level, e.Counts.Triangles, methods[static_cast<int>(e.Method)], exact[level], 100 * error);
      Check(e.Method == expected[b][level],
        "budget " + std::to_string(budgets[b]) + ", level " + std::to_string(level) + ": method");
      Check(std::fabs(error) <= tolerance[b],
        "budget " + std::to_string(budgets[b]) + ", level " + std::to_string(level) + ": error");
      Check(estimator.Estimate(iso, level).Counts.Triangles == e.Counts.Triangles,
        "an estimate is kept, not recounted");
    }
  }

  // A recorded exact count of a coarser level is the auxiliary even when the
  // budget pays for nothing.
  const double iso2 = -0.75;
  mediso::ExtractionPlan plan;
  volume.Plan(iso2, 1, plan);
  const mediso::SurfaceCounts c1 = mediso::BlockLODVolume::CountsOf(plan);
  mediso::BlockLODEstimator estimator(volume);
  estimator.SetSampleBudget(0.0);
  estimator.RecordExact(iso2, 1, c1);
  Check(estimator.Estimate(iso2, 1).Method == mediso::EstimateMethod::Exact &&
      estimator.Estimate(iso2, 1).Counts.Triangles == c1.Triangles,
    "a recorded pair is exact");
  Check(estimator.Estimate(iso2, 3).Method == mediso::EstimateMethod::Scaled,
    "a recorded coarser level scales the sample");
  Check(estimator.Estimate(iso2, 0).Method == mediso::EstimateMethod::Sampled,
    "no coarser level below level 0: plain sample");

  // Reset forgets every count.
  estimator.Reset();
  Check(!estimator.HasExact(iso2, 1), "Reset forgets exact counts");
}

void TestCostModel()
{
  using mediso::CostModel;
  CostModel model;
  Check(model.Predict(3, 1e6, 1e5) == 1e6 * CostModel::DefaultSecondsPerCube +
        1e5 * CostModel::DefaultSecondsPerTriangle + CostModel::DefaultSecondsPerUpdate,
    "defaults before any record");
  const double first = 2.0 * model.Predict(3, 2e6, 1e5);
  model.Record(3, 2e6, 1e5, first);
  Check(std::fabs(model.Predict(3, 2e6, 1e5) - first) < 1e-12,
    "one record: the defaults scaled to its time");

  // A law with a fixed part is recovered from records of it, the oldest
  // weighing least (they fade) but still consistent.
  const double a = 3e-9, b = 7e-8, c = 2e-3;
  CostModel fit;
  const double samples[][2] = { { 1e6, 2e4 }, { 4e6, 1e5 }, { 2.5e5, 9e4 }, { 8e6, 3e5 },
    { 3e6, 5e5 } };
  for (const auto& s : samples)
  {
    fit.Record(3, s[0], s[1], a * s[0] + b * s[1] + c);
  }
  const double predicted = fit.Predict(3, 3e6, 2e5);
  Check(std::fabs(predicted - (a * 3e6 + b * 2e5 + c)) < 1e-9 * predicted,
    "a linear law with a fixed part is recovered from its records");

  // The fit follows a change of the machine's speed: after enough records at
  // twice the time, predictions are near twice the law.
  for (int k = 0; k < 200; ++k)
  {
    const auto& s = samples[k % 5];
    fit.Record(3, s[0], s[1], 2 * (a * s[0] + b * s[1] + c));
  }
  const double slower = fit.Predict(3, 3e6, 2e5);
  Check(std::fabs(slower / (2 * (a * 3e6 + b * 2e5 + c)) - 1) < 0.01,
    "older records fade: the fit follows a slower machine");

  // Records far off the fit (a disturbed update, or a clock glitch) count a
  // tenth: the fit stays near the law.
  CostModel steady;
  for (int k = 0; k < 20; ++k)
  {
    const auto& s = samples[k % 5];
    steady.Record(3, s[0], s[1], a * s[0] + b * s[1] + c);
  }
  for (int k = 0; k < 3; ++k)
  {
    steady.Record(3, 3e6, 2e5, 0.2 * (a * 3e6 + b * 2e5 + c));
  }
  const double kept = steady.Predict(3, 3e6, 2e5) / (a * 3e6 + b * 2e5 + c);
  std::printf("after three records at 0.2x the law: prediction %.2fx the law\n", kept);
  Check(std::fabs(kept - 1) < 0.2, "records far off the fit count little");

  // Before a level has records, the defaults scaled to all records; then to
  // its own; then its own fit.
  CostModel levels;
  for (const auto& s : samples)
  {
    levels.Record(1, s[0], s[1], 3 * (a * s[0] + b * s[1] + c));
  }
  Check(std::fabs(levels.Predict(1, 3e6, 2e5) / (3 * (a * 3e6 + b * 2e5 + c)) - 1) < 1e-6,
    "a level with enough records: its own fit");
  const double unseen = levels.Predict(2, 3e6, 2e5);
  levels.Record(2, 1e6, 1e5, 0.5 * levels.Predict(2, 1e6, 1e5));
  Check(std::fabs(levels.Predict(2, 3e6, 2e5) / unseen - 0.5) < 1e-6,
    "a level's first record rescales the defaults for that level");

  // Records that cannot separate the terms (one size only) still predict that size.
  CostModel collinear;
  for (int k = 0; k < 5; ++k)
  {
    collinear.Record(3, 1e6, 1e5, 0.01);
  }
  Check(std::fabs(collinear.Predict(3, 1e6, 1e5) - 0.01) < 1e-6, "collinear records: their time");
  Check(collinear.Predict(3, 2e6, 2e5) > 0, "never a negative time");
}

void TestLayoutAndLevel()
{
  mediso::SurfaceLayout layout; // normals, offsets, 64-bit ids
  Check(layout.Bytes(10, 20) == 10 * 24 + 20 * 32 + 8, "points, normals, 64-bit ids and offsets");
  layout.IdBytes = 4;
  Check(layout.Bytes(10, 20) == 10 * 24 + 20 * 16 + 4, "32-bit ids and offsets while they fit");
  layout.Scalars = layout.BlockIds = true;
  Check(layout.Bytes(10, 20) == 10 * 28 + 20 * 20 + 4, "scalars and block ids add 4 bytes each");
  layout.Offsets = false;
  layout.Normals = layout.Scalars = layout.BlockIds = false;
  Check(layout.Bytes(10, 20) == 10 * 12 + 20 * 12, "an index buffer: 3 ids per triangle");
  Check(!mediso::SurfaceLayout::NeedsWideIds(1e6, 7e8) &&
      mediso::SurfaceLayout::NeedsWideIds(1e6, 7.2e8),
    "64-bit ids once 3 x triangles passes INT32_MAX");
  mediso::SurfaceLayout compact;
  compact.IdBytes = 4;
  Check(compact.Bytes(1e6, 7.2e8) == 1e6 * 24 + 7.2e8 * 32 + 8,
    "compact ids widen to 64 bits past INT32_MAX");

  const Field f = MakeField(40, 37, 35, 11.0, 0.5, false);
  mediso::BlockLODVolume volume(Table.Cases, mediso::SerialFor);
  volume.SetVolume(Describe(f));
  mediso::BlockLODEstimator estimator(volume);
  const mediso::SurfaceLayout vtkLayout;
  const std::vector<double> values = { -2.0, 3.0 };
  double bytes[4];
  for (int level = 0; level < 4; ++level)
  {
    bytes[level] = 0;
    for (double v : values)
    {
      bytes[level] += vtkLayout.Bytes(estimator.Estimate(v, level).Counts);
    }
  }
  double level0 = 0;
  Check(estimator.ChooseLevel(values, bytes[3], vtkLayout, level0) == 3, "a budget of level 3 fits level 3");
  Check(estimator.ChooseLevel(values, bytes[3] - 1, vtkLayout, level0) == 2, "one byte less: level 2");
  Check(estimator.ChooseLevel(values, bytes[1], vtkLayout, level0) == 1, "budget of level 1: level 1");
  Check(estimator.ChooseLevel(values, bytes[0] - 1, vtkLayout, level0) == -1 && level0 == bytes[0],
    "nothing fits: -1 and level 0's bytes");

  // SetVolume recomputes only for a changed description.
  Check(!volume.SetVolume(Describe(f)), "the same volume keeps its block ranges");
  mediso::VolumeDescription moved = Describe(f);
  moved.Origin[1] = 2.5;
  Check(volume.SetVolume(moved), "a moved volume recomputes");
  moved.Stamp = 7;
  Check(volume.SetVolume(moved), "a new stamp (values changed in place) recomputes");
}
} // namespace

int main()
{
  TestPlanCounts();
  TestEstimates();
  TestCostModel();
  TestLayoutAndLevel();
  return medical_test::Finish("BlockLOD volume and estimator core: all checks passed");
}
