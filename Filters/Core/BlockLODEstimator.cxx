// SPDX-License-Identifier: BSD-3-Clause
#include "BlockLODEstimator.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace mediso
{

bool SurfaceLayout::NeedsWideIds(double points, double triangles)
{
  const double limit = 2147483647.0; // INT32_MAX
  return !(points < limit && 3 * triangles < limit);
}

double SurfaceLayout::Bytes(double points, double triangles) const
{
  const double id = NeedsWideIds(points, triangles) ? 8.0 : 4.0;
  const double perPoint = 12.0 + (this->Normals ? 12.0 : 0.0) + (this->Scalars ? 4.0 : 0.0);
  const double perTriangle =
    (this->Offsets ? 4.0 : 3.0) * id + (this->BlockIds ? 4.0 : 0.0); // ids (+ offset)
  return points * perPoint + triangles * perTriangle + (this->Offsets ? id : 0.0);
}

void CostModel::Record(double cubes, double triangles, double seconds)
{
  this->Sxx += cubes * cubes;
  this->Sxy += cubes * triangles;
  this->Syy += triangles * triangles;
  this->Sxt += cubes * seconds;
  this->Syt += triangles * seconds;
  ++this->Samples;
}

double CostModel::Predict(double cubes, double triangles) const
{
  double a = DefaultSecondsPerCube, b = DefaultSecondsPerTriangle;
  const double det = this->Sxx * this->Syy - this->Sxy * this->Sxy;
  if (this->Samples >= 2 && det > 1e-12 * this->Sxx * this->Syy)
  {
    a = (this->Sxt * this->Syy - this->Syt * this->Sxy) / det;
    b = (this->Syt * this->Sxx - this->Sxt * this->Sxy) / det;
    if (a < 0 || b < 0)
    {
      // Degenerate fit (nearly collinear samples): one rate per cube-or-triangle.
      const double scale = (this->Sxt + this->Syt) / (this->Sxx + this->Syy);
      a = std::max(0.0, scale);
      b = std::max(0.0, scale);
    }
  }
  else if (this->Samples == 1 && this->Sxx + this->Syy > 0)
  {
    // One sample: keep the defaults' ratio, match its time.
    const double predicted = std::sqrt(this->Sxx) * a + std::sqrt(this->Syy) * b;
    const double measured = this->Sxt / std::max(1e-30, std::sqrt(this->Sxx));
    if (predicted > 0 && this->Sxx > 0)
    {
      const double f = measured / predicted;
      a *= f;
      b *= f;
    }
  }
  return a * cubes + b * triangles;
}

BlockLODEstimator::BlockLODEstimator(BlockLODVolume& volume)
  : Volume(volume)
{
}

void BlockLODEstimator::Reset()
{
  this->Exact.clear();
  this->Sampled.clear();
}

void BlockLODEstimator::RecordExact(double isovalue, int level, const SurfaceCounts& counts)
{
  this->Exact[SurfaceKey{ isovalue, level }] = counts;
}

bool BlockLODEstimator::HasExact(double isovalue, int level) const
{
  return this->Exact.count(SurfaceKey{ isovalue, level }) > 0;
}

SurfaceEstimate BlockLODEstimator::Estimate(double isovalue, int level)
{
  SurfaceEstimate e;
  if (!this->Volume.IsValid() || level < 0 || level >= NumberOfLevels)
  {
    return e;
  }
  const SurfaceKey key{ isovalue, level };
  auto exact = this->Exact.find(key);
  if (exact != this->Exact.end())
  {
    e.Counts = exact->second;
    e.Method = EstimateMethod::Exact;
    return e;
  }
  std::vector<int> known;
  for (int l = 0; l < NumberOfLevels; ++l)
  {
    auto it = this->Exact.find(SurfaceKey{ isovalue, l });
    if (it != this->Exact.end() && it->second.Triangles > 0)
    {
      known.push_back(l);
    }
  }
  // Scale only where counting would be approximate: with few active blocks
  // every block is counted, which is exact and cheap.
  const std::int64_t active =
    static_cast<std::int64_t>(this->Volume.ActiveBlocks(isovalue).size());
  if (known.size() >= 2 && !this->Sampled.count(key) && active / SampleBlocks > 1)
  {
    // The two known levels nearest to the requested one, the finer first on a tie.
    std::sort(known.begin(), known.end(), [level](int a, int b) {
      const int da = std::abs(a - level), db = std::abs(b - level);
      return da < db || (da == db && a > b);
    });
    const SurfaceCounts& a = this->Exact[SurfaceKey{ isovalue, known[0] }];
    const SurfaceCounts& b = this->Exact[SurfaceKey{ isovalue, known[1] }];
    const double growth = std::pow(a.Triangles / b.Triangles, 1.0 / (known[0] - known[1]));
    const double f = std::pow(growth, level - known[0]);
    e.Counts.Triangles = a.Triangles * f;
    e.Counts.Points = a.Points * f;
    e.Counts.Cubes = a.Cubes * std::pow(8.0, level - known[0]);
    e.Method = EstimateMethod::Scaled;
    return e;
  }
  e.Method = EstimateMethod::Sampled;
  auto sampled = this->Sampled.find(key);
  if (sampled != this->Sampled.end())
  {
    e.Counts = sampled->second;
    return e;
  }
  bool complete = false;
  e.Counts = this->Volume.CountSampled(isovalue, level, SampleBlocks, complete);
  if (complete)
  {
    this->RecordExact(isovalue, level, e.Counts); // every active block counted
  }
  else
  {
    this->Sampled[key] = e.Counts;
  }
  return e;
}

double BlockLODEstimator::EstimateSeconds(double isovalue, int level)
{
  const SurfaceEstimate e = this->Estimate(isovalue, level);
  return e.Method == EstimateMethod::None ? -1.0 : this->Cost.Predict(e.Counts);
}

int BlockLODEstimator::ChooseLevel(const std::vector<double>& isovalues, double budgetBytes,
  const SurfaceLayout& layout, double& level0Bytes)
{
  for (int level = NumberOfLevels - 1; level >= 0; --level)
  {
    double bytes = 0;
    for (double v : isovalues)
    {
      bytes += layout.Bytes(this->Estimate(v, level).Counts);
    }
    if (bytes <= budgetBytes)
    {
      return level;
    }
    level0Bytes = bytes;
  }
  return -1;
}

} // namespace mediso
