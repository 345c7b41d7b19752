// SPDX-License-Identifier: BSD-3-Clause
#include "FrameFixedCost.h"

#include <algorithm>
#include <cmath>

namespace mediso
{

//------------------------------------------------------------------------------
void RecentFrameValues::Push(double value)
{
  this->Recent[this->Frames % HistoryLength] = value;
  ++this->Frames;
}

std::size_t RecentFrameValues::Kept() const
{
  return std::min(this->Frames, HistoryLength);
}

double RecentFrameValues::Smallest(std::size_t rank) const
{
  const std::size_t kept = this->Kept();
  if (kept == 0)
  {
    return 0.0;
  }
  rank = std::min(rank, kept - 1);
  std::array<double, HistoryLength> sorted = this->Recent;
  std::nth_element(sorted.begin(), sorted.begin() + rank, sorted.begin() + kept);
  return sorted[rank];
}

void RecentFrameValues::Reset()
{
  this->Recent.fill(0.0);
  this->Frames = 0;
}

//------------------------------------------------------------------------------
void FrameFixedCost::Observe(double windowSeconds, double ownSeconds)
{
  if (!std::isfinite(windowSeconds) || !std::isfinite(ownSeconds) || windowSeconds < 0.0 ||
    ownSeconds < 0.0)
  {
    return;
  }
  this->Differences.Push(std::max(0.0, windowSeconds - ownSeconds));
}

double FrameFixedCost::Seconds() const
{
  const std::size_t kept = this->Differences.Kept();
  // The lower median of an even count: of two frames, a stalled one does not
  // decide (nor does the first frame's window creation, where a host counts it).
  return kept == 0 ? 0.0 : this->Differences.Smallest((kept - 1) / 2);
}

double FrameFixedCost::BudgetLeft(double budget) const
{
  if (!std::isfinite(budget))
  {
    return budget;
  }
  return std::max(0.0, budget - this->Seconds());
}

//------------------------------------------------------------------------------
void FrameTimeSpread::Observe(
  double predictedSeconds, double measuredSeconds, double budgetSeconds)
{
  if (!std::isfinite(predictedSeconds) || !std::isfinite(measuredSeconds) ||
    !(predictedSeconds > 0.0) || !(measuredSeconds > 0.0))
  {
    return;
  }
  const double scale = std::isfinite(budgetSeconds) && budgetSeconds > predictedSeconds
    ? budgetSeconds
    : predictedSeconds;
  const double ratio = 1.0 + (measuredSeconds - predictedSeconds) / scale;
  if (!std::isfinite(ratio))
  {
    return;
  }
  this->Ratios.Push(ratio);
}

double FrameTimeSpread::Margin() const
{
  const std::size_t kept = this->Ratios.Kept();
  if (kept == 0)
  {
    return 0.0;
  }
  // The nearest rank: of 9 ratios the 7th smallest, of 1 that one.
  const std::size_t rank =
    static_cast<std::size_t>(std::floor(Quantile * static_cast<double>(kept - 1) + 0.5));
  return std::max(0.0, this->Ratios.Smallest(rank) - 1.0);
}

double FrameTimeSpread::BudgetLeft(double budget) const
{
  if (!std::isfinite(budget) || budget < 0.0)
  {
    return budget;
  }
  return budget / (1.0 + this->Margin());
}

} // namespace mediso
