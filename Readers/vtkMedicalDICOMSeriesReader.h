// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkMedicalDICOMSeriesReader
 * @brief   One DICOM series, read with DCMTK and placed in patient space, or a
 *          clear refusal.
 *
 * A folder of DICOM files often holds several series (a localizer and the
 * scan, or two reconstructions of one acquisition), slices can be missing
 * or unevenly spaced, and pixel data can be compressed. A reader that
 * stacks whatever files it finds gives, in each of those cases, a volume
 * that looks plausible and is wrong. This reader reads one series, checks
 * its geometry, and either gives its true values in their true place or
 * says why it does not.
 *
 * What it does, in order:
 *
 * 1. **Scan.** Every regular file of the folder of FileName (or of FileName
 *    itself when it is a folder) is opened with DCMTK up to its pixel data.
 *    Files that are not DICOM Part 10 files (no "DICM" at byte 128) and
 *    DICOM files without Pixel Data (DICOMDIR, structured reports,
 *    presentation states) are skipped without a message.
 * 2. **Choose a series.** The images are grouped by Series Instance UID.
 *    The series read is SeriesInstanceUID when set, else the series of the
 *    file opened, else (a folder opened) the series with the most slices.
 *    When the folder holds other series, one warning lists them (UID,
 *    Series Description, number of slices); they are never mixed in.
 * 3. **Frames.** A single-frame file is one slice; a multi-frame
 *    (enhanced CT/MR) file gives one slice per frame, with its position
 *    from the Per-frame Functional Groups (Plane Position Sequence), its
 *    orientation, pixel spacing and rescale from the per-frame or Shared
 *    Functional Groups (Plane Orientation, Pixel Measures, Pixel Value
 *    Transformation Sequences), falling back to the top-level attributes.
 * 4. **Check the slices.** Every slice must have the first one's Rows,
 *    Columns, Bits Allocated/Stored, Pixel Representation, Pixel Spacing
 *    and Image Orientation (Patient); one sample per pixel (MONOCHROME1/2);
 *    Bits Allocated 8 or 16. Anything else is refused with a message
 *    naming the file.
 * 5. **Order and space.** Slices are sorted by the projection of Image
 *    Position (Patient) on the slice normal (the cross product of the row
 *    and column direction cosines). With m the median step between
 *    neighbours and a tolerance of 1% of m, a step that differs from m by
 *    more than the tolerance is a gap (a whole multiple of m: slices
 *    missing) or uneven spacing; equal positions are duplicates; a slice
 *    whose position leaves the line through the first along the normal
 *    (gantry tilt, shear) is refused. Gaps and uneven spacing are refused
 *    with the positions named, unless ResampleUnevenSlices is on: then the
 *    volume is resampled onto an even grid from the first to the last
 *    position with a step as near m as fits (linear interpolation between
 *    the two neighbouring slices), and a warning says so. Duplicates and
 *    sheared stacks are always refused.
 * 6. **Decode.** Pixel data in any transfer syntax DCMTK decodes is read:
 *    the uncompressed ones (implicit and explicit VR, little and big
 *    endian, deflated), JPEG (baseline, extended, lossless, with DCMTK's
 *    dcmjpeg), JPEG-LS (dcmjpls) and RLE. The decoders are registered once
 *    per process. Any other transfer syntax (JPEG 2000, MPEG, HEVC...) is
 *    refused by name before decoding. Stored values are masked to Bits
 *    Stored (from High Bit) and sign-extended when Pixel Representation is
 *    1.
 * 7. **Rescale.** Each slice's Rescale Slope and Intercept (1 and 0 when
 *    absent) are applied to its own values. The output type is:
 *    - float when the slopes or intercepts differ between slices, are not
 *      integers, or the slices were resampled;
 *    - otherwise the smallest integer type that holds the rescaled values
 *      actually present: unsigned 8, 16, 32 bits when none is negative,
 *      else signed 8, 16, 32 bits, double beyond (a CT stored unsigned with intercept
 *      -1024 reads as signed 16-bit Hounsfield units).
 *
 * The pixels are decoded when the pipeline asks for information (the
 * output type depends on their values), once per change of the reader's
 * properties; the output then shares that array. Before allocating, the
 * decoded volume's bytes (and those of the rescaled copy, when one is made)
 * are checked against what the process may still allocate
 * (mediso::FitsInProcessMemory); when they do not fit, or an allocation
 * fails, the reader reports an error and gives an empty image.
 *
 * Placement, in DICOM patient coordinates (LPS, millimetres): voxel
 * (i, j, k) is column i and row j of the k-th slice in increasing position
 * along the normal; the origin is that first slice's Image Position
 * (Patient); the direction matrix's columns are the row direction, the
 * column direction and the normal; the spacing is Pixel Spacing (column
 * spacing along x, row spacing along y: DICOM stores them the other way
 * round) and the step between slices (Slice Thickness, else 1, for a single
 * slice). An axial series thus gives the same image as a MetaImage or NIfTI
 * export of it. The point array is named "DICOMImage".
 *
 * Every refusal is one vtkErrorMacro and an empty output; see
 * docs/readers.md for the messages. The slice rules of step 5 and the integer
 * type of step 7 are the readers' VTK-free core's (mediso::StackDICOMSlices,
 * mediso::DICOMIntegerType in Readers/Core/DICOMSeries.h), which the web page
 * reads an uncompressed DICOM folder with.
 *
 * @warning Files without the Part 10 preamble (bare datasets, ACR-NEMA) are
 * skipped. Colour images, Bits Allocated 1 or 32 and multi-frame files
 * without per-frame positions are refused. Slices are read whole; the
 * reader does not stream sub-extents.
 *
 * @sa vtkMedicalNIfTIReader
 */
#ifndef vtkMedicalDICOMSeriesReader_h
#define vtkMedicalDICOMSeriesReader_h

#include "MedicalIsosurfacesReadersModule.h" // For export macro
#include "vtkImageAlgorithm.h"
#include "vtkSmartPointer.h" // For the decoded volume

#include <string> // For the series summary

class vtkDataArray;
class vtkStringArray;

class MEDICALISOSURFACESREADERS_EXPORT vtkMedicalDICOMSeriesReader : public vtkImageAlgorithm
{
public:
  static vtkMedicalDICOMSeriesReader* New();
  vtkTypeMacro(vtkMedicalDICOMSeriesReader, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * A file of the series to read, or a folder. The files of its folder are
   * scanned; a file's own series is read (unless SeriesInstanceUID is set).
   */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  /**
   * The same as SetFileName (the name this reader had before it read with
   * DCMTK).
   */
  void SetSeriesPath(const char* path) { this->SetFileName(path); }

  ///@{
  /**
   * The Series Instance UID of the series to read from the folder. Empty
   * (the default): the series of the file opened, or, for a folder, the
   * series with the most slices. A UID the folder does not hold is an error
   * that lists the series it holds.
   */
  vtkSetStringMacro(SeriesInstanceUID);
  vtkGetStringMacro(SeriesInstanceUID);
  ///@}

  ///@{
  /**
   * Resample a series with missing or unevenly spaced slices onto an even
   * grid (linear interpolation along the normal, float output, one warning)
   * instead of refusing it. Off by default.
   */
  vtkSetMacro(ResampleUnevenSlices, vtkTypeBool);
  vtkGetMacro(ResampleUnevenSlices, vtkTypeBool);
  vtkBooleanMacro(ResampleUnevenSlices, vtkTypeBool);
  ///@}

  /**
   * After an update: one line per series of the folder, "UID | description
   * | N slices", the series read first. Empty before an update or after an
   * error in the scan.
   */
  vtkStringArray* GetSeriesInFolder();

  /// After an update: the UID of the series read (empty after an error).
  const char* GetSeriesRead() { return this->SeriesRead.c_str(); }

protected:
  vtkMedicalDICOMSeriesReader();
  ~vtkMedicalDICOMSeriesReader() override;

  int RequestInformation(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  char* FileName = nullptr;
  char* SeriesInstanceUID = nullptr;
  vtkTypeBool ResampleUnevenSlices = 0;

private:
  vtkMedicalDICOMSeriesReader(const vtkMedicalDICOMSeriesReader&) = delete;
  void operator=(const vtkMedicalDICOMSeriesReader&) = delete;

  // Scan, check, decode and rescale; an empty string or the error message.
  std::string ReadSeries();

  vtkSmartPointer<vtkDataArray> Volume;
  vtkSmartPointer<vtkStringArray> SeriesList;
  std::string SeriesRead;
  int Dimensions[3] = { 0, 0, 0 };
  double Origin[3] = { 0.0, 0.0, 0.0 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
};

#endif
