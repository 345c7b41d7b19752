// SPDX-License-Identifier: BSD-3-Clause
#include "FrameFixedCost.h"

#include <algorithm>
#include <cmath>

namespace mediso
{

//------------------------------------------------------------------------------
void FrameFixedCost::Observe(double windowSeconds, double ownSeconds)
{
  if (!std::isfinite(windowSeconds) || !std::isfinite(ownSeconds) || windowSeconds < 0.0 ||
    ownSeconds < 0.0)
  {
    return;
  }
  this->Recent[this->Frames % HistoryLength] = std::max(0.0, windowSeconds - ownSeconds);
  ++this->Frames;
}

//------------------------------------------------------------------------------
double FrameFixedCost::Seconds() const
{
  const std::size_t kept = std::min(this->Frames, HistoryLength);
  if (kept == 0)
  {
    return 0.0;
  }
  std::array<double, HistoryLength> sorted = this->Recent;
  // The lower median of an even count: of two frames, a stalled one does not
  // decide (nor does the first frame's window creation, where a host counts it).
  const std::size_t middle = (kept - 1) / 2;
  std::nth_element(sorted.begin(), sorted.begin() + middle, sorted.begin() + kept);
  return sorted[middle];
}

//------------------------------------------------------------------------------
double FrameFixedCost::BudgetLeft(double budget) const
{
  if (!std::isfinite(budget))
  {
    return budget;
  }
  return std::max(0.0, budget - this->Seconds());
}

//------------------------------------------------------------------------------
void FrameFixedCost::Reset()
{
  this->Recent.fill(0.0);
  this->Frames = 0;
}

//------------------------------------------------------------------------------
void FrameTimeSpread::Observe(double predictedSeconds, double measuredSeconds)
{
  if (!std::isfinite(predictedSeconds) || !std::isfinite(measuredSeconds) ||
    !(predictedSeconds > 0.0) || !(measuredSeconds > 0.0))
  {
    return;
  }
  const double ratio = measuredSeconds / predictedSeconds;
  if (!std::isfinite(ratio))
  {
    return;
  }
  this->Recent[this->Frames % HistoryLength] = ratio;
  ++this->Frames;
}

//------------------------------------------------------------------------------
double FrameTimeSpread::Margin() const
{
  const std::size_t kept = std::min(this->Frames, HistoryLength);
  if (kept == 0)
  {
    return 0.0;
  }
  std::array<double, HistoryLength> sorted = this->Recent;
  // The nearest rank: of 9 ratios the 7th smallest, of 1 that one.
  const std::size_t rank =
    static_cast<std::size_t>(std::floor(Quantile * static_cast<double>(kept - 1) + 0.5));
  std::nth_element(sorted.begin(), sorted.begin() + rank, sorted.begin() + kept);
  return std::max(0.0, sorted[rank] - 1.0);
}

//------------------------------------------------------------------------------
double FrameTimeSpread::BudgetLeft(double budget) const
{
  if (!std::isfinite(budget) || budget < 0.0)
  {
    return budget;
  }
  return budget / (1.0 + this->Margin());
}

//------------------------------------------------------------------------------
void FrameTimeSpread::Reset()
{
  this->Recent.fill(0.0);
  this->Frames = 0;
}

} // namespace mediso
