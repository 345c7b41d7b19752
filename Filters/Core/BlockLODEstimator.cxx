// SPDX-License-Identifier: BSD-3-Clause
#include "BlockLODEstimator.h"

#include <algorithm>
#include <cmath>

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
  auto sampled = this->Sampled.find(key);
  if (sampled != this->Sampled.end())
  {
    return sampled->second;
  }
  if (this->Volume.ExactCountCost(isovalue, level) <= this->SampleBudget)
  {
    e.Counts = this->Volume.CountExact(isovalue, level);
    e.Method = EstimateMethod::Exact;
    this->RecordExact(isovalue, level, e.Counts);
    return e;
  }
  // The auxiliary level: the finest coarser level whose counts are exact, or
  // affordable to make exact.
  int aux = -1;
  for (int a = level - 1; a >= 0 && aux < 0; --a)
  {
    if (!this->HasExact(isovalue, a) && this->Volume.ExactCountCost(isovalue, a) <= this->SampleBudget)
    {
      this->RecordExact(isovalue, a, this->Volume.CountExact(isovalue, a));
    }
    aux = this->HasExact(isovalue, a) ? a : -1;
  }
  const double perBlock =
    BlockLODVolume::BlockCost(level) + (aux >= 0 ? BlockLODVolume::BlockCost(aux) : 0.0);
  const std::int64_t samples =
    std::max<std::int64_t>(MinimumSamples, static_cast<std::int64_t>(this->SampleBudget / perBlock));
  const BlockSums sums = this->Volume.CountSample(isovalue, level, aux, samples);
  const double active = static_cast<double>(this->Volume.ActiveBlocks(isovalue).size());
  const double expand = sums.Blocks > 0 ? active / static_cast<double>(sums.Blocks) : 0.0;
  if (aux >= 0)
  {
    // Ratio estimate on the blocks the auxiliary level cuts (its exact total
    // times the sample's ratio), plus the others scaled up from the sample.
    const SurfaceCounts& known = this->Exact[SurfaceKey{ isovalue, aux }];
    auto combine = [expand](double total, double sum, double auxSum, double rest) {
      return (auxSum > 0 ? total * sum / auxSum : expand * sum) + expand * rest;
    };
    e.Counts.Points = combine(known.Points, sums.Points, sums.AuxPoints, sums.RestPoints);
    e.Counts.Triangles =
      combine(known.Triangles, sums.Triangles, sums.AuxTriangles, sums.RestTriangles);
    e.Method = EstimateMethod::Scaled;
  }
  else
  {
    e.Counts.Points = expand * (sums.Points + sums.RestPoints);
    e.Counts.Triangles = expand * (sums.Triangles + sums.RestTriangles);
    e.Method = EstimateMethod::Sampled;
  }
  const double cubesPerAxis = BlockCells / LevelStride(level);
  e.Counts.Cubes = active * cubesPerAxis * cubesPerAxis * cubesPerAxis;
  this->Sampled[key] = e;
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
