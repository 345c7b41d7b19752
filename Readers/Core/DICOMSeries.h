// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file DICOMSeries.h
 * @brief One DICOM series from the bytes of a folder's files, without VTK or
 * DCMTK: the web page's reading of a dropped or picked DICOM folder, held to
 * the rules of vtkMedicalDICOMSeriesReader (ParaView, the server), so that a
 * folder gives the page exactly the volume the reader gives, or a refusal.
 *
 * A scan read silently wrong is the worst thing a viewer can do, and a second
 * DICOM reader is the easiest place to make one. This one therefore reads a
 * narrow subset and refuses everything else with one sentence:
 *
 * - **Read:** DICOM Part 10 files (preamble, "DICM", a group 2 in explicit VR
 *   little endian) whose transfer syntax is Implicit VR Little Endian
 *   (1.2.840.10008.1.2) or Explicit VR Little Endian (1.2.840.10008.1.2.1),
 *   single frame, greyscale (MONOCHROME1/2), Bits Allocated 8 or 16.
 * - **Refused, naming the file:** any other transfer syntax (compressed, big
 *   endian, deflated: the reader decodes some of those with DCMTK's codecs,
 *   this code decodes none), multi-frame files and files with functional
 *   group sequences (their per-frame placement is the reader's alone), and
 *   every refusal of the reader itself, in the reader's words.
 *
 * The tag parser walks the data set element by element, top level only,
 * skipping sequences of defined or undefined length (items, item and
 * sequence delimiters; explicit VR's UN of undefined length as implicit VR),
 * and stops at Pixel Data. An attribute the rules use under another VR than
 * its dictionary's (explicit VR), and a file that ends inside an element, are
 * refused: the reader skips a file DCMTK cannot parse, but whether DCMTK
 * parses what this parser does not is not known here.
 *
 * The series rules are the reader's, step by step (see
 * vtkMedicalDICOMSeriesReader.h): files sorted by name; files without the
 * preamble or without Rows, Columns and Pixel Data skipped; images grouped by
 * Series Instance UID, the series with the most slices read and the others
 * named in a warning; every file checked against the first (size, pixel
 * format, greyscale, bits), every slice against the first (orientation, pixel
 * spacing, rescale slope not 0); slices sorted along the normal of Image
 * Orientation (Patient) (ties by Instance Number), duplicates, a sheared or
 * tilted stack, gaps and uneven steps (1% of the median step) refused; stored
 * values masked to Bits Stored from High Bit and sign-extended; each slice's
 * Rescale Slope and Intercept applied, into float when they differ between
 * slices or are not integers, else into the smallest integer type holding
 * the rescaled values present. Placement in LPS millimetres: origin the first
 * slice's Image Position (Patient), direction columns the row direction, the
 * column direction and the normal, spacing Pixel Spacing swapped into
 * (column, row) and the mean step between slices. The reader's option to
 * resample uneven slices is not offered: the page refuses them as the reader
 * does by default.
 *
 * The rules below the parser are the reader's own: it calls them (the
 * per-file checks, the grouping into series, the unpacking of stored values,
 * the slice rules StackDICOMSlices, the rescaling and its output type), and
 * reads only the tags (DCMTK), the multi-frame placement, the compressed
 * syntaxes and the resampling itself. TestDICOMSeriesMatchesReader runs both
 * on every folder of the reader's test corpus and requires the same volume,
 * byte for byte, or the same refusal.
 */
#ifndef MedicalIsosurfaces_DICOMSeries_h
#define MedicalIsosurfaces_DICOMSeries_h

#include "ScalarTypes.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mediso
{

/// One file of the folder: its name (no folder part) and its bytes.
struct DICOMFileBytes
{
  std::string Name;
  const unsigned char* Bytes = nullptr;
  std::size_t Size = 0;
};

/// The series read: the voxels (column fastest, then row, then slice in
/// increasing position along the normal) and their place.
struct DICOMSeriesVolume
{
  int Dimensions[3] = { 0, 0, 0 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  double Origin[3] = { 0.0, 0.0, 0.0 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 }; ///< row-major, columns the axes
  ScalarType Type = ScalarType::UInt8;
  std::vector<unsigned char> Values; ///< Dimensions' product values of Type
  std::string SeriesUID;
  std::vector<std::string> Warnings; ///< what the reader would warn about
};

/// What the per-file rules see of one image file (the reader's Instance and
/// the page's are this and what their own decoding needs).
struct DICOMImageFormat
{
  std::string Name; ///< the file, in messages
  std::string SeriesUID;
  std::string SeriesDescription;
  std::uint16_t Rows = 0, Columns = 0, BitsAllocated = 0, BitsStored = 0, HighBit = 0;
  std::uint16_t PixelRepresentation = 0, SamplesPerPixel = 1;
  std::string Photometric;
  unsigned long Frames = 1;
};

/// The bytes of pixel data the image needs (every frame).
std::uint64_t DICOMPixelBytes(const DICOMImageFormat& image);

/// The message for pixel data of `have` bytes, fewer than DICOMPixelBytes.
std::string DICOMShortPixelData(const DICOMImageFormat& image, std::uint64_t have);

/// The image's own pixel format: greyscale, Bits Allocated 8 or 16, Bits
/// Stored and High Bit inside it, not empty. Returns "" or the reason.
std::string CheckDICOMImageFormat(const DICOMImageFormat& image);

/// The image against the series' first: the same size and pixel format.
/// Returns "" or the reason.
std::string CheckDICOMImageLikeFirst(const DICOMImageFormat& image, const DICOMImageFormat& first);

/// One series of a folder: its images (indices into the caller's list) and
/// its slices (frames).
struct DICOMSeriesGroup
{
  std::string UID;
  std::string Description;
  std::vector<std::size_t> Instances;
  std::size_t Slices = 0;
};

/// The images grouped by Series Instance UID, the series with the most
/// slices first (ties in the order first seen), so that every list of series
/// reads the same way.
std::vector<DICOMSeriesGroup> GroupDICOMSeries(const std::vector<const DICOMImageFormat*>& images);

/// A series in messages: its UID, description and slice count.
std::string DescribeDICOMSeries(const DICOMSeriesGroup& series);

/**
 * The stored values of `count` pixels: the word of pixel p (`word(p)`, the
 * Bits Allocated container in host order) shifted down from High Bit, masked
 * to Bits Stored and sign-extended when Pixel Representation is 1, into
 * `out`, widening [least, greatest] to the values met.
 */
template <typename Stored, typename Word>
void UnpackDICOMValues(const DICOMImageFormat& image, std::size_t count, Word word, Stored* out,
  std::int64_t& least, std::int64_t& greatest)
{
  const unsigned shift = image.HighBit + 1u - image.BitsStored;
  const std::uint32_t mask = image.BitsStored >= 32 ? 0xffffffffu : ((1u << image.BitsStored) - 1u);
  const std::uint32_t sign = 1u << (image.BitsStored - 1u);
  const bool isSigned = image.PixelRepresentation == 1;
  for (std::size_t p = 0; p < count; ++p)
  {
    const std::uint32_t bits = (static_cast<std::uint32_t>(word(p)) >> shift) & mask;
    std::int64_t value = bits;
    if (isSigned && (bits & sign))
    {
      value -= static_cast<std::int64_t>(mask) + 1;
    }
    out[p] = static_cast<Stored>(value);
    least = std::min(least, value);
    greatest = std::max(greatest, value);
  }
}

/**
 * The output type of rescaled slices whose stored values of slice k lie in
 * [least[k], greatest[k]]: Float32 when the slopes and intercepts differ
 * between slices or are not integers, else DICOMIntegerType of the rescaled
 * range.
 */
ScalarType DICOMRescaledType(const std::vector<double>& slopes,
  const std::vector<double>& intercepts, const std::vector<std::int64_t>& least,
  const std::vector<std::int64_t>& greatest);

/// Slice k of `in` (sliceSize values each) times slopes[k] plus
/// intercepts[k], into `out`.
template <typename In, typename Out>
void RescaleDICOMSlices(const In* in, Out* out, std::size_t sliceSize,
  const std::vector<double>& slopes, const std::vector<double>& intercepts)
{
  for (std::size_t k = 0; k < slopes.size(); ++k)
  {
    const In* from = in + k * sliceSize;
    Out* to = out + k * sliceSize;
    const double slope = slopes[k];
    const double intercept = intercepts[k];
    for (std::size_t p = 0; p < sliceSize; ++p)
    {
      to[p] = static_cast<Out>(slope * static_cast<double>(from[p]) + intercept);
    }
  }
}

/// The gaps and uneven steps of a stack in a message: the first five, then
/// how many more.
std::string DICOMUnevenList(const std::vector<std::string>& uneven);

/// One slice as the series rules see it (a single-frame file, or one frame of
/// a multi-frame file in vtkMedicalDICOMSeriesReader).
struct DICOMSlice
{
  std::string Name; ///< the file (and frame), in messages
  bool HasPosition = false;
  bool HasOrientation = false;
  bool HasPixelSpacing = false;
  double Position[3] = { 0, 0, 0 };
  double Orientation[6] = { 1, 0, 0, 0, 1, 0 };
  double PixelSpacing[2] = { 1, 1 }; ///< DICOM order: between rows, between columns
  double Slope = 1.0;
  double Intercept = 0.0;
  long InstanceNumber = 0;
};

/// The slices ordered and spaced along the normal.
struct DICOMStack
{
  std::vector<std::size_t> Order; ///< indices of the slices, in increasing position
  std::vector<double> Distances;  ///< along the normal, in that order
  double Row[3] = { 1, 0, 0 };
  double Column[3] = { 0, 1, 0 };
  double Normal[3] = { 0, 0, 1 };
  double Median = 0.0;             ///< median step
  std::vector<std::string> Uneven; ///< gaps and uneven steps, in words (not refused here)
  bool ValidPixelSpacing = false;
};

/**
 * The slice rules, shared with vtkMedicalDICOMSeriesReader: every slice
 * checked against the first (orientation, pixel spacing, position and
 * orientation present when there are several, slope not 0), sorted along the
 * normal (ties by Instance Number), duplicates and a tilted or sheared stack
 * refused; gaps and uneven steps listed in `stack.Uneven` for the caller to
 * refuse or resample. Returns "" or the reason.
 */
std::string StackDICOMSlices(const std::vector<DICOMSlice>& slices, DICOMStack& stack);

/**
 * Where the volume of a stack lies, in LPS millimetres: the origin at
 * `first`'s Image Position (Patient) (0 without one), the axes (columns of
 * the row-major `direction`) the stack's row, column and normal, the spacing
 * Pixel Spacing swapped into (column, row) (1 mm without a valid one) and
 * `step` between the `slices` slices, or for one slice `thickness` (Slice
 * Thickness; 1 mm when not positive).
 */
void PlaceDICOMStack(const DICOMStack& stack, const DICOMSlice& first, std::size_t slices,
  double step, double thickness, double origin[3], double direction[9], double spacing[3]);

/// The smallest integer type that holds every value in [least, greatest]
/// (unsigned when least >= 0), Float64 beyond 32 bits: the reader's output
/// type for integral rescaling.
ScalarType DICOMIntegerType(double least, double greatest);

/**
 * Reads the series of `files` (the regular files of one folder; `folder`
 * names it in messages). Returns "" and fills `volume`, or the reason it is
 * not read (then `volume` is left empty).
 */
std::string ReadDICOMSeries(
  const std::string& folder, std::vector<DICOMFileBytes> files, DICOMSeriesVolume& volume);

/// The name of a transfer syntax UID ("" when unknown), for messages.
const char* DICOMTransferSyntaxName(const std::string& uid);

} // namespace mediso

#endif
