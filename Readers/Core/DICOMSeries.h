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
 * The slice rules (StackDICOMSlices) and the integer output type
 * (DICOMIntegerType) are the reader's own: it calls them. The rest is written
 * again here over the parser's attributes, and TestDICOMSeriesMatchesReader
 * runs both on every folder of the reader's test corpus and requires the same
 * volume, byte for byte, or the same refusal.
 */
#ifndef MedicalIsosurfaces_DICOMSeries_h
#define MedicalIsosurfaces_DICOMSeries_h

#include "ScalarTypes.h"

#include <cstddef>
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
