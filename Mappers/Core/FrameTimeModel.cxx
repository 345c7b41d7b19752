// SPDX-License-Identifier: BSD-3-Clause
#include "FrameTimeModel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mediso
{
namespace
{
// A floor for the prior's seconds of a frame, the divisor of its relative
// error (zero work with a zero prior must not give a frame infinite weight).
constexpr double MinimumSeconds = 1e-6;
// Weight of the pull towards the scaled prior, relative to the frames' total
// weight: small enough that frames spanning all three counts decide, large
// enough to fix the directions they leave open.
constexpr double PriorWeight = 1e-6;

using Vector3 = std::array<double, 3>;
using Matrix3 = std::array<Vector3, 3>;

// Solves the rows and columns of A, b named by `free` (Gaussian elimination
// with partial pivoting); false when singular. Others stay 0.
bool SolveSubset(const Matrix3& a, const Vector3& b, const std::array<bool, 3>& free, Vector3& x)
{
  int index[3];
  int n = 0;
  for (int j = 0; j < 3; ++j)
  {
    if (free[j])
    {
      index[n++] = j;
    }
  }
  double m[3][4];
  for (int r = 0; r < n; ++r)
  {
    for (int c = 0; c < n; ++c)
    {
      m[r][c] = a[index[r]][index[c]];
    }
    m[r][n] = b[index[r]];
  }
  for (int c = 0; c < n; ++c)
  {
    int pivot = c;
    for (int r = c + 1; r < n; ++r)
    {
      if (std::fabs(m[r][c]) > std::fabs(m[pivot][c]))
      {
        pivot = r;
      }
    }
    if (!(std::fabs(m[pivot][c]) > 0.0))
    {
      return false;
    }
    for (int k = 0; k <= n; ++k)
    {
      std::swap(m[c][k], m[pivot][k]);
    }
    for (int r = 0; r < n; ++r)
    {
      if (r != c)
      {
        const double f = m[r][c] / m[c][c];
        for (int k = c; k <= n; ++k)
        {
          m[r][k] -= f * m[c][k];
        }
      }
    }
  }
  x = { 0.0, 0.0, 0.0 };
  for (int r = 0; r < n; ++r)
  {
    x[index[r]] = m[r][n] / m[r][r];
  }
  return true;
}

double Finite(double value, double fallback)
{
  return std::isfinite(value) ? value : fallback;
}
} // namespace

double FrameTimeModel::Coefficients::Evaluate(const FrameWork& work) const
{
  const double seconds = this->Seconds + this->PerPrimitive * static_cast<double>(work.Primitives) +
    this->PerPixel * static_cast<double>(work.Pixels);
  if (!(seconds > 0.0))
  {
    return 0.0;
  }
  return std::isfinite(seconds) ? seconds : std::numeric_limits<double>::max();
}

std::uint64_t FrameTimeModel::ShadedPixels(int width, int height, double sampleDistance)
{
  if (width <= 0 || height <= 0 || !std::isfinite(sampleDistance) || !(sampleDistance > 0.0))
  {
    return 0;
  }
  const double pixels =
    static_cast<double>(width) * static_cast<double>(height) / (sampleDistance * sampleDistance);
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::floor(pixels)));
}

FrameTimeModel::Coefficients FrameTimeModel::Prior(FrameMethod method, bool translucent)
{
  // Software rasterisers, pessimistically: a host's first frames without
  // observations should come out coarse rather than late. Translucent frames
  // blend every layer (and the cell rasteriser sorts), hence the factors.
  Coefficients prior;
  if (method == FrameMethod::CellRasterisation)
  {
    prior.Seconds = 0.005;
    prior.PerPrimitive = 6e-7;
    prior.PerPixel = 4e-7;
  }
  else
  {
    prior.Seconds = 0.005;
    prior.PerPrimitive = 3e-7;
    prior.PerPixel = 1e-7;
  }
  if (translucent)
  {
    const double factor = method == FrameMethod::CellRasterisation ? 3.0 : 4.0;
    prior.Seconds *= factor;
    prior.PerPrimitive *= factor;
    prior.PerPixel *= factor;
  }
  return prior;
}

std::size_t FrameTimeModel::Key(FrameMethod method, bool translucent)
{
  const std::size_t m = method == FrameMethod::CellRasterisation ? 0 : 1;
  return 2 * m + (translucent ? 1 : 0);
}

void FrameTimeModel::Observe(const FrameWork& work, double seconds)
{
  if (!std::isfinite(seconds) || seconds < 0.0 ||
    (work.Method != FrameMethod::CellRasterisation && work.Method != FrameMethod::Triangles))
  {
    return;
  }
  Pair& pair = this->Pairs[Key(work.Method, work.Translucent)];
  pair.Samples.push_back(
    { static_cast<double>(work.Primitives), static_cast<double>(work.Pixels), seconds });
  while (pair.Samples.size() > HistoryLength)
  {
    pair.Samples.pop_front();
  }
  pair.Fitted = Solve(pair.Samples, Prior(work.Method, work.Translucent));
}

FrameTimeModel::Coefficients FrameTimeModel::Solve(
  const std::deque<Sample>& samples, const Coefficients& prior)
{
  // Rows in relative terms: frame i asks (a, b, c) . (1, P, X) / p_i = t_i /
  // p_i, p_i the prior's seconds for its work, weighted by recency. Dividing by
  // the prior rather than by the measured t_i makes a 10 ms frame count as
  // much as a 1 s one without favouring fits that predict too little (a
  // measured divisor penalises an overestimate of a frame more than the same
  // factor of underestimate, so a slower machine would be followed late).
  const std::size_t n = samples.size();
  std::vector<double> weight(n);
  std::vector<Vector3> row(n);
  std::vector<double> target(n);
  double totalWeight = 0.0;
  double w = 1.0;
  for (std::size_t k = n; k-- > 0;)
  {
    const Sample& s = samples[k];
    const double p =
      std::max(prior.Seconds + prior.PerPrimitive * s.Primitives + prior.PerPixel * s.Pixels,
        MinimumSeconds);
    weight[k] = w;
    row[k] = { 1.0 / p, s.Primitives / p, s.Pixels / p };
    target[k] = s.Seconds / p;
    totalWeight += w;
    w *= RecencyDecay;
  }
  Vector3 scale = { 0.0, 0.0, 0.0 };
  for (std::size_t k = 0; k < n; ++k)
  {
    for (int j = 0; j < 3; ++j)
    {
      scale[j] += weight[k] * row[k][j] * row[k][j];
    }
  }
  for (int j = 0; j < 3; ++j)
  {
    scale[j] = std::sqrt(scale[j] / totalWeight);
    if (!(scale[j] > 0.0) || !std::isfinite(scale[j]))
    {
      scale[j] = 1.0;
    }
  }

  // The prior's least-squares scale to these frames: each row of the prior
  // is 1, so it is the frames' weighted mean ratio to the prior.
  double ratio = 0.0;
  for (std::size_t k = 0; k < n; ++k)
  {
    ratio += weight[k] * target[k];
  }
  const double priorScale = Finite(ratio / totalWeight, 1.0);
  const Vector3 priorPhi = { priorScale * prior.Seconds * scale[0],
    priorScale * prior.PerPrimitive * scale[1], priorScale * prior.PerPixel * scale[2] };

  // Normal equations of the scaled problem with the ridge towards the prior.
  const double ridge = PriorWeight * totalWeight;
  Matrix3 a{};
  Vector3 b{};
  for (std::size_t k = 0; k < n; ++k)
  {
    Vector3 z;
    for (int j = 0; j < 3; ++j)
    {
      z[j] = row[k][j] / scale[j];
    }
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        a[r][c] += weight[k] * z[r] * z[c];
      }
      b[r] += weight[k] * z[r] * target[k];
    }
  }
  for (int j = 0; j < 3; ++j)
  {
    a[j][j] += ridge;
    b[j] += ridge * priorPhi[j];
  }

  // Non-negative least squares, exactly: the objective is strictly convex, so
  // its constrained minimum is the unconstrained minimum on some support of
  // the coefficients; of the 8 supports, the feasible one with the smallest
  // objective is it.
  Vector3 best = priorPhi;
  double bestObjective = std::numeric_limits<double>::infinity();
  for (int mask = 0; mask < 8; ++mask)
  {
    const std::array<bool, 3> free = { (mask & 1) != 0, (mask & 2) != 0, (mask & 4) != 0 };
    Vector3 phi;
    if (!SolveSubset(a, b, free, phi))
    {
      continue;
    }
    bool feasible = true;
    for (int j = 0; j < 3; ++j)
    {
      feasible = feasible && std::isfinite(phi[j]) && phi[j] >= 0.0;
    }
    if (!feasible)
    {
      continue;
    }
    double objective = 0.0;
    for (int r = 0; r < 3; ++r)
    {
      double ar = 0.0;
      for (int c = 0; c < 3; ++c)
      {
        ar += a[r][c] * phi[c];
      }
      objective += phi[r] * ar - 2.0 * b[r] * phi[r];
    }
    if (objective < bestObjective)
    {
      bestObjective = objective;
      best = phi;
    }
  }

  Coefficients fitted;
  fitted.Seconds = Finite(best[0] / scale[0], prior.Seconds);
  fitted.PerPrimitive = Finite(best[1] / scale[1], prior.PerPrimitive);
  fitted.PerPixel = Finite(best[2] / scale[2], prior.PerPixel);
  return fitted;
}

double FrameTimeModel::Predict(const FrameWork& work) const
{
  if (work.Method != FrameMethod::CellRasterisation && work.Method != FrameMethod::Triangles)
  {
    return Prior(FrameMethod::CellRasterisation, true).Evaluate(work);
  }
  return this->Fit(work.Method, work.Translucent).Evaluate(work);
}

bool FrameTimeModel::HasObservations(FrameMethod method, bool translucent) const
{
  return this->ObservationCount(method, translucent) > 0;
}

std::size_t FrameTimeModel::ObservationCount(FrameMethod method, bool translucent) const
{
  return this->Pairs[Key(method, translucent)].Samples.size();
}

FrameTimeModel::Coefficients FrameTimeModel::Fit(FrameMethod method, bool translucent) const
{
  const Pair& pair = this->Pairs[Key(method, translucent)];
  return pair.Samples.empty() ? Prior(method, translucent) : pair.Fitted;
}

void FrameTimeModel::Reset()
{
  for (Pair& pair : this->Pairs)
  {
    pair.Samples.clear();
    pair.Fitted = Coefficients();
  }
}

std::size_t FrameTimeModel::Choose(
  const std::vector<Candidate>& candidates, double budgetSeconds) const
{
  if (candidates.empty())
  {
    return 0;
  }
  for (std::size_t i = 0; i < candidates.size(); ++i)
  {
    if (this->Predict(candidates[i].Work) <= budgetSeconds)
    {
      return i;
    }
  }
  return candidates.size() - 1;
}

} // namespace mediso
