// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkMedicalNIfTIReader
 * @brief   NIfTI-1/2 images (.nii, .nii.gz, .hdr/.img) placed in their world space,
 * in calibrated units, every header field checked against the file first.
 *
 * vtkNIFTIImageReader reads the voxels (gzipped or not) and gives the
 * orientation only as matrices (GetSFormMatrix(), GetQFormMatrix()), with
 * the image at origin 0. This reader puts the orientation on the image
 * itself, so that ParaView shows it where the file says: origin and
 * direction matrix from the sform when the file has one (sform_code > 0),
 * else from the qform (qform_code > 0), else origin 0 and no rotation. The
 * world space is NIfTI's (x right, y anterior, z superior; RAS).
 *
 * The work is done in three steps:
 *
 * 1. **The header, checked against the file** (RequestInformation, before
 *    anything is allocated). The header (348 bytes for NIfTI-1 and
 *    Analyze 7.5, 540 for NIfTI-2, either byte order, gzipped or not) is
 *    read here, and the file is refused, with one error and an empty output,
 *    when: dim[0] is not 1 to 7; a dimension is below 1 or above what a VTK
 *    extent holds; dim[5..7] are above 1 (vectors); the datatype code is not
 *    NIfTI's; the datatype is one this reader does not take (BINARY,
 *    COMPLEX64/128/256, RGB24, RGBA32, FLOAT128: named in the message);
 *    bitpix differs from the datatype's size; vox_offset is negative, not
 *    finite, or inside the header of a single-file image; pixdim[1..3] is
 *    not finite; or the file (the uncompressed stream of a gzipped one) is
 *    shorter than vox_offset plus the voxels. docs/readers.md lists the
 *    messages.
 * 2. **The voxels as stored.** The superclass reads them in the stored type;
 *    before that, the bytes are checked against what the process may still
 *    allocate (mediso::ProcessMemoryAllowance(): physical memory, ulimit -v,
 *    cgroup). A read that fails (a file truncated after the check) gives one
 *    error and an empty output, never a partly filled volume.
 * 3. **Calibration**, when the header has a scale (scl_slope finite and not
 *    0, and not slope 1 with intercept 0), by a fixed rule on the header,
 *    so that the type announced before reading is the type produced:
 *    - slope 1, an integral intercept and a stored 8- or 16-bit integer
 *      type: integers v + scl_inter, as VTK_SHORT when the whole stored
 *      range shifted by the intercept fits 16 bits, else VTK_INT (an int16
 *      CT with intercept -1024 reads as VTK_INT in exact Hounsfield units);
 *    - otherwise v * scl_slope + scl_inter as VTK_FLOAT for stored 8- and
 *      16-bit integers and FLOAT32, VTK_DOUBLE for 32- and 64-bit integers
 *      and FLOAT64 (float holds 24 bits of mantissa).
 *    The array keeps the name "NIFTI". Without a scale, the stored type.
 *    A non-finite scl_slope means no scale and a non-finite scl_inter 0
 *    (as other NIfTI readers take them), each with a warning.
 *
 * A 4D image (dim[0] 4, dim[4] above 1) is a series of volumes in time:
 * the reader announces ParaView time steps (toffset + t * pixdim[4], or
 * 0, 1, 2... when pixdim[4] is not positive) and reads the one volume
 * each request asks for. A spacing pixdim[1..3] of 0 is read as 1, and a
 * negative one as its magnitude with that axis of the direction matrix
 * reversed (the voxels keep their place); each with a warning that says
 * the spacing used.
 *
 * ParaView 5.11's own NIfTI reader (the AnalyzeNIfTIReaderWriter plugin)
 * takes only uncompressed files.
 *
 * @warning TimeAsVector and PlanarRGB of the superclass are not supported
 * (time is read as time steps; RGB is refused).
 *
 * @sa vtkNIFTIImageReader, vtkMedicalDICOMSeriesReader
 */
#ifndef vtkMedicalNIfTIReader_h
#define vtkMedicalNIfTIReader_h

#include "MedicalIsosurfacesReadersModule.h" // For export macro
#include "vtkNIFTIImageReader.h"

#include <string> // For the reason a file was refused
#include <vector> // For the time steps

class MEDICALISOSURFACESREADERS_EXPORT vtkMedicalNIfTIReader : public vtkNIFTIImageReader
{
public:
  static vtkMedicalNIfTIReader* New();
  vtkTypeMacro(vtkMedicalNIfTIReader, vtkNIFTIImageReader);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Which matrix placed the image: "sform", "qform" or "none".
  const char* GetPlacement() const { return this->Placement; }

  /**
   * The VTK type of the output's scalars after the last RequestInformation
   * (the stored type, or the calibrated type of the rule above); 0 when the
   * file was refused.
   */
  int GetOutputScalarType() const { return this->OutputScalarType; }

protected:
  vtkMedicalNIfTIReader();
  ~vtkMedicalNIfTIReader() override;

  int RequestInformation(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

private:
  vtkMedicalNIfTIReader(const vtkMedicalNIfTIReader&) = delete;
  void operator=(const vtkMedicalNIfTIReader&) = delete;

  // Step 1 of the class comment: empty when the header and the file agree.
  std::string CheckFile();
  // Step 2 and 3 for a valid file; false (and `reason`) on failure.
  bool ReadVolume(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector, std::string& reason);

  double Origin[3] = { 0.0, 0.0, 0.0 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  const char* Placement = "none";

  // What the last RequestInformation found.
  bool Readable = false;
  std::string FileLabel;    // the file named in messages
  int StoredScalarType = 0; // as the superclass reads it
  int OutputScalarType = 0; // after calibration
  double Slope = 1.0;       // calibration applied: v * Slope + Intercept
  double Intercept = 0.0;
  bool Calibrate = false;
  unsigned long DataOffset = 0;  // vox_offset
  unsigned long VolumeBytes = 0; // bytes of one 3D volume in the file
  std::vector<double> TimeSteps; // empty for a 3D image
};

#endif
