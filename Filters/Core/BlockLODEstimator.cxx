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
  const double id = this->IdBytesFor(points, triangles);
  const double perPoint = 12.0 + (this->Normals ? 12.0 : 0.0) + (this->Scalars ? 4.0 : 0.0);
  const double perTriangle =
    (this->Offsets ? 4.0 : 3.0) * id + (this->BlockIds ? 4.0 : 0.0); // ids (+ offset)
  return points * perPoint + triangles * perTriangle + (this->Offsets ? id : 0.0);
}

double CostModel::Default(double cubes, double triangles)
{
  return DefaultSecondsPerCube * cubes + DefaultSecondsPerTriangle * triangles +
    DefaultSecondsPerUpdate;
}

void CostModel::Fit::Record(double cubes, double triangles, double seconds, double weight)
{
  const double x[3] = { cubes, triangles, 1.0 };
  const double w = weight;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      this->Normal[i][j] = Memory * this->Normal[i][j] + w * x[i] * x[j];
    }
    this->Right[i] = Memory * this->Right[i] + w * x[i] * seconds;
  }
  const double guess = Default(cubes, triangles);
  this->ScaleNumerator = Memory * this->ScaleNumerator + w * guess * seconds;
  this->ScaleDenominator = Memory * this->ScaleDenominator + w * guess * guess;
  ++this->Samples;
}

bool CostModel::Fit::Solve(double abc[3]) const
{
  if (this->Samples < MinimumRecords)
  {
    return false;
  }
  // Gauss-Jordan elimination with partial pivoting.
  double m[3][4];
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      m[i][j] = this->Normal[i][j];
    }
    m[i][3] = this->Right[i];
  }
  for (int c = 0; c < 3; ++c)
  {
    int pivot = c;
    for (int r = c + 1; r < 3; ++r)
    {
      pivot = std::fabs(m[r][c]) > std::fabs(m[pivot][c]) ? r : pivot;
    }
    std::swap(m[c], m[pivot]);
    // Relative to the column's own scale (cubes are ~1e6, the constant 1).
    if (!(std::fabs(m[c][c]) > 1e-12 * std::fabs(this->Normal[c][c])))
    {
      return false;
    }
    for (int r = 0; r < 3; ++r)
    {
      if (r != c)
      {
        const double f = m[r][c] / m[c][c];
        for (int k = c; k < 4; ++k)
        {
          m[r][k] -= f * m[c][k];
        }
      }
    }
  }
  for (int i = 0; i < 3; ++i)
  {
    abc[i] = m[i][3] / m[i][i];
    if (!(abc[i] >= 0))
    {
      return false;
    }
  }
  return true;
}

void CostModel::Record(int level, double cubes, double triangles, double seconds)
{
  if (!(seconds > 0) || level < 0 || level >= NumberOfLevels)
  {
    return;
  }
  // Relative errors: weights 1 / seconds^2, seconds no less than the
  // prediction so that a spuriously fast record does not weigh the most.
  const double expected = std::max(1e-6, this->Predict(level, cubes, triangles));
  const double ratio = seconds / expected;
  const double scale = std::max(seconds, expected);
  double weight = 1.0 / (scale * scale);
  if (this->Levels[level].Samples >= 3 && (ratio > 2.0 || ratio < 0.5))
  {
    weight *= OutlierWeight;
  }
  this->Levels[level].Record(cubes, triangles, seconds, weight);
  this->All.Record(cubes, triangles, seconds, weight);
}

double CostModel::Predict(int level, double cubes, double triangles) const
{
  if (level < 0 || level >= NumberOfLevels)
  {
    return -1.0;
  }
  // The defaults scaled to the level's records (or to all records before the
  // level has one): one parameter, stable from the first record.
  const Fit& own = this->Levels[level];
  const Fit& scaleFit = own.ScaleDenominator > 0 ? own : this->All;
  const double scale =
    scaleFit.ScaleDenominator > 0 ? scaleFit.ScaleNumerator / scaleFit.ScaleDenominator : 1.0;
  const double scaled = scale * Default(cubes, triangles);
  // The level's own three-term fit once it has enough records, unless it
  // strays far from the scaled defaults (a fit of few, noisy records).
  double abc[3];
  if (own.Solve(abc))
  {
    const double fitted = abc[0] * cubes + abc[1] * triangles + abc[2];
    if (fitted > scaled / 3 && fitted < scaled * 3)
    {
      return fitted;
    }
  }
  return scaled;
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

double BlockLODEstimator::EstimateSeconds(double isovalue, int level, const CostModel& model)
{
  const SurfaceEstimate e = this->Estimate(isovalue, level);
  return e.Method == EstimateMethod::None ? -1.0 : model.Predict(level, e.Counts);
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
