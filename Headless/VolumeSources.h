// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file VolumeSources.h
 * @brief Volumes mediso-render makes itself: the head phantom at any size and a linear resampling.
 *
 * The paper's GPU protocol runs on the 512-wide CT (the head CT resampled to 512x512x216) and on
 * the 512^3 phantom; as files they are 113 MB and 268 MB, more than can be carried to a machine
 * that has only a GPU driver. There mediso-render makes them from the 14 MB CT and from nothing:
 *
 * - `phantom:N` (in place of a file): the MedicalPhantom head (mediso::HeadPhantom, int16 HU, no
 *   noise, seed 1) on N^3 points with spacing 240 / (N - 1) mm and origin 0, the volume that
 *   `BenchmarkHistoPyramidIsoMapper --input phantomN` and `MedicalPhantom(Dimensions=[N]*3,
 *   Spacing=[240/(N-1)]*3)` make, value for value.
 * - `--resample WxHxD`: the volume resampled to W x H x D points over the same bounds (spacing
 *   scaled by (n - 1) / (m - 1) per axis), trilinear, integer types rounded half up and clamped
 *   to the type's range: what vtkImageReslice's linear mode gives (the benchmark's ct512).
 */
#ifndef MedicalIsosurfaces_VolumeSources_h
#define MedicalIsosurfaces_VolumeSources_h

#include "MetaImage.h"

#include <string>

namespace mediso
{
namespace headless
{

/// Largest N of `phantom:N` (2 GB of int16 values at 1024).
constexpr int MaximumPhantomSize = 2048;

/// Parses "phantom:N"; true (and n set) when `spec` names a phantom at all, with `error` set
/// when N is not a whole number in [2, MaximumPhantomSize].
bool ParsePhantomSpec(const std::string& spec, int& n, std::string& error);

/// The phantom on n^3 points (see the file's comment); false with the reason (memory).
bool MakePhantom(int n, MetaImage& image, std::string& error);

/// `input` resampled to `dimensions` points over its bounds; false with the reason.
bool Resample(const MetaImage& input, const int dimensions[3], MetaImage& output, std::string& error);

} // namespace headless
} // namespace mediso

#endif
