// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file HistogramThreshold.h
 * @brief Where a first isosurface goes (no VTK): Hounsfield units recognised
 * by their range, otherwise Otsu's threshold of the histogram.
 *
 * A first isovalue at the middle of the data range (ParaView's default) is
 * seldom a surface anyone wants: a CT's range runs from air (-1024 HU) to
 * metal or dense bone (2000-3000 HU), so the middle (about 1000 HU) cuts
 * through cortical bone only and draws a ragged cap. Two better starts:
 *
 * 1. **Hounsfield units.** A CT is recognised by its range alone:
 *    LooksLikeHounsfieldUnits() asks for a minimum near the value of air
 *    outside the body (-1024, the padding most scanners write; within
 *    [-1100, -900]) and a maximum above soft tissue (over 300, so bone is
 *    present). Skin (-500) and bone (400) are then known surfaces.
 * 2. **Otsu's threshold.** Anything else (MRI, microscopy, a float field)
 *    gets the value that best splits its histogram in two: OtsuThreshold()
 *    chooses the bin boundary that maximises the between-class variance
 *    w0 w1 (m0 - m1)^2 of the two classes it makes (N. Otsu, "A threshold
 *    selection method from gray-level histograms", IEEE Trans. SMC 9(1),
 *    1979). For an MRI head that boundary lies between the background and
 *    the tissue: the head's outline.
 *
 * HistogramBins chooses the bins: one per integer for integer data whose
 * range has at most `maxBins` values (so a uint8 image is counted exactly
 * and the threshold falls halfway between two integers), else `maxBins`
 * equal bins over the range.
 */
#ifndef MedicalIsosurfaces_HistogramThreshold_h
#define MedicalIsosurfaces_HistogramThreshold_h

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mediso
{

/// Skin and bone in Hounsfield units: the surfaces a CT starts with.
constexpr double SkinHounsfield = -500.0;
constexpr double BoneHounsfield = 400.0;

/// Whether a range [min, max] is a CT's in Hounsfield units (see the file's
/// comment).
bool LooksLikeHounsfieldUnits(double min, double max);

/// Equal bins over the values: bin i holds [Low + i Width, Low + (i + 1)
/// Width).
struct HistogramBins
{
  double Low = 0.0;
  double Width = 1.0;
  std::size_t Count = 0;

  /// Bins for values in [min, max] (integral: the values are integers). No bins
  /// (Count 0) for a range that is not finite or is reversed.
  static HistogramBins For(double min, double max, bool integral, std::size_t maxBins = 256);

  /// The bin of a value, values past either end clamped into the end bins.
  std::size_t BinOf(double value) const
  {
    const double at = std::floor((value - this->Low) / this->Width);
    if (!(at > 0.0))
    {
      return 0;
    }
    return at >= static_cast<double>(this->Count) ? this->Count - 1 : static_cast<std::size_t>(at);
  }
};

/// Adds `n` values, `stride` apart, to `counts` (bins.Count entries). NaNs are
/// skipped.
template <typename T>
void AccumulateHistogram(const T* values, std::size_t n, std::size_t stride,
  const HistogramBins& bins, std::uint64_t* counts)
{
  for (std::size_t i = 0; i < n; ++i)
  {
    const double value = static_cast<double>(values[i * stride]);
    if (value == value)
    {
      ++counts[bins.BinOf(value)];
    }
  }
}

/**
 * Otsu's threshold of a histogram: the value at the boundary between bins k
 * and k + 1 (bins.Low + (k + 1) bins.Width) for the k whose split maximises the
 * between-class variance; the lowest such k on ties (empty bins between two
 * modes leave several). Returns false, leaving `threshold` alone, when the
 * histogram has fewer than two non-empty bins (nothing to split).
 */
bool OtsuThreshold(
  const std::vector<std::uint64_t>& counts, const HistogramBins& bins, double& threshold);

}

#endif
