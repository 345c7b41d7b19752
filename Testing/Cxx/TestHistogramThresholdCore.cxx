// SPDX-License-Identifier: BSD-3-Clause
// The first isovalue's choice, exactly: Hounsfield ranges recognised, bins
// chosen, and Otsu's threshold of synthetic bimodal histograms (values worked
// out by hand from the between-class variance).
#include "HistogramThreshold.h"
#include "MedicalTestUtilities.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;

std::string Number(double value)
{
  char text[64];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}
}

int main()
{
  // Ranges: the head CT, the phantom, a CT rescaled to -1000, an MRI, a CT
  // without bone (no surface at 400 to start with), a range that is not HU.
  Check(mediso::LooksLikeHounsfieldUnits(-1024, 2986), "the head CT's range is HU");
  Check(mediso::LooksLikeHounsfieldUnits(-1000, 1100), "the phantom's range is HU");
  Check(mediso::LooksLikeHounsfieldUnits(-1000, 301), "a maximum just above 300 is HU");
  Check(!mediso::LooksLikeHounsfieldUnits(0, 255), "an MRI's uint8 range is not HU");
  Check(!mediso::LooksLikeHounsfieldUnits(-1024, 200), "no bone: not HU");
  Check(!mediso::LooksLikeHounsfieldUnits(-2000, 3000), "a minimum far below air: not HU");
  Check(!mediso::LooksLikeHounsfieldUnits(-899, 3000), "a minimum above -900: not HU");

  // Bins: one per integer for a small integer range, else 256 over the range.
  const mediso::HistogramBins bytes = mediso::HistogramBins::For(0, 255, true);
  Check(bytes.Count == 256 && bytes.Low == -0.5 && bytes.Width == 1.0,
    "uint8 values: 256 bins of one value, from -0.5");
  const mediso::HistogramBins wide = mediso::HistogramBins::For(-1024, 2986, true);
  Check(wide.Count == 256 && wide.Low == -1024 && wide.Width == 4010.0 / 256,
    "a wide integer range: 256 equal bins");
  Check(wide.BinOf(2986) == 255 && wide.BinOf(-1024) == 0 && wide.BinOf(-5000) == 0,
    "the maximum falls in the last bin, values below the range in the first");
  Check(mediso::HistogramBins::For(1, 0, false).Count == 0, "a reversed range has no bins");
  Check(mediso::HistogramBins::For(NAN, 1, false).Count == 0, "a NaN range has no bins");

  // A uint8 volume: background 20 +- 2 and tissue 200 +- 2. Every split
  // between the modes has the same variance; the lowest is taken: just above
  // the background's last value, 22.5.
  {
    std::vector<std::uint8_t> volume;
    for (int value : { 18, 19, 20, 20, 20, 21, 22 })
    {
      volume.insert(volume.end(), 100, static_cast<std::uint8_t>(value));
    }
    for (int value : { 198, 199, 200, 200, 201, 202 })
    {
      volume.insert(volume.end(), 60, static_cast<std::uint8_t>(value));
    }
    const mediso::HistogramBins bins = mediso::HistogramBins::For(18, 202, true);
    std::vector<std::uint64_t> counts(bins.Count, 0);
    mediso::AccumulateHistogram(volume.data(), volume.size(), 1, bins, counts.data());
    Check(counts[0] == 100 && counts[2] == 300 && counts[bins.Count - 1] == 60,
      "the histogram counts each value in its bin");
    double threshold = 0.0;
    const bool found = mediso::OtsuThreshold(counts, bins, threshold);
    Check(
      found && threshold == 22.5, "uint8 bimodal: threshold 22.5 (got " + Number(threshold) + ")");
  }

  // Three modes, the middle one small (40 values at 60): it joins the
  // background (20-22), which is nearer in mean; the split is after 60,
  // halfway to 61: 60.5.
  {
    const mediso::HistogramBins bins = mediso::HistogramBins::For(20, 122, true);
    std::vector<std::uint64_t> counts(bins.Count, 0);
    const int modes[][2] = { { 20, 300 }, { 21, 500 }, { 22, 300 }, { 60, 40 }, { 120, 100 },
      { 121, 250 }, { 122, 100 } };
    for (const auto& mode : modes)
    {
      counts[bins.BinOf(mode[0])] += static_cast<std::uint64_t>(mode[1]);
    }
    double threshold = 0.0;
    const bool found = mediso::OtsuThreshold(counts, bins, threshold);
    Check(
      found && threshold == 60.5, "three modes: threshold 60.5 (got " + Number(threshold) + ")");
  }

  // Float bins: modes at bins 1 and 9 with a small bump at bin 4; the best
  // split is after bin 4: Low + 5 Width = 5.
  {
    mediso::HistogramBins bins;
    bins.Low = 0.0;
    bins.Width = 1.0;
    bins.Count = 11;
    const std::vector<std::uint64_t> counts = { 10, 40, 10, 0, 5, 0, 0, 0, 2, 6, 2 };
    double threshold = 0.0;
    const bool found = mediso::OtsuThreshold(counts, bins, threshold);
    Check(found && threshold == 5.0, "float bins: threshold 5 (got " + Number(threshold) + ")");
  }

  // Nothing to split: one value, or no values.
  {
    const mediso::HistogramBins bins = mediso::HistogramBins::For(7, 7, true);
    std::vector<std::uint64_t> counts(bins.Count, 0);
    double threshold = -1.0;
    Check(!mediso::OtsuThreshold(counts, bins, threshold) && threshold == -1.0,
      "an empty histogram has no threshold");
    counts[0] = 1000;
    Check(!mediso::OtsuThreshold(counts, bins, threshold) && threshold == -1.0,
      "a constant volume has no threshold");
  }

  return medical_test::Finish("passed");
}
