// SPDX-License-Identifier: BSD-3-Clause
#include "HistogramThreshold.h"

namespace mediso
{

bool LooksLikeHounsfieldUnits(double min, double max)
{
  // Air padding: -1024 on most scanners, -1000 or a little below after
  // rescaling; bone (and so a maximum above 300) in any head or body CT.
  return min >= -1100.0 && min <= -900.0 && max > 300.0;
}

HistogramBins HistogramBins::For(double min, double max, bool integral, std::size_t maxBins)
{
  HistogramBins bins;
  if (!std::isfinite(min) || !std::isfinite(max) || min > max || maxBins == 0)
  {
    return bins;
  }
  const double values = max - min + 1.0;
  if (integral && values <= static_cast<double>(maxBins))
  {
    // One bin per integer, centred on it: a boundary lies halfway between two
    // values.
    bins.Low = min - 0.5;
    bins.Width = 1.0;
    bins.Count = static_cast<std::size_t>(values);
  }
  else
  {
    bins.Low = min;
    bins.Count = maxBins;
    bins.Width = max > min ? (max - min) / static_cast<double>(maxBins) : 1.0;
  }
  return bins;
}

bool OtsuThreshold(
  const std::vector<std::uint64_t>& counts, const HistogramBins& bins, double& threshold)
{
  double total = 0.0;
  double totalMoment = 0.0;
  std::size_t occupied = 0;
  for (std::size_t i = 0; i < counts.size(); ++i)
  {
    total += static_cast<double>(counts[i]);
    totalMoment += static_cast<double>(i) * static_cast<double>(counts[i]);
    occupied += counts[i] > 0 ? 1 : 0;
  }
  if (occupied < 2)
  {
    return false;
  }
  // Bin indices stand for the values: the variance is in bin units, which
  // does not change where its maximum is.
  double below = 0.0;
  double belowMoment = 0.0;
  double best = -1.0;
  std::size_t bestSplit = 0;
  for (std::size_t k = 0; k + 1 < counts.size(); ++k)
  {
    below += static_cast<double>(counts[k]);
    belowMoment += static_cast<double>(k) * static_cast<double>(counts[k]);
    const double above = total - below;
    if (below == 0.0 || above == 0.0)
    {
      continue;
    }
    const double difference = belowMoment / below - (totalMoment - belowMoment) / above;
    const double between = below * above * difference * difference;
    if (between > best)
    {
      best = between;
      bestSplit = k;
    }
  }
  threshold = bins.Low + static_cast<double>(bestSplit + 1) * bins.Width;
  return true;
}

}
