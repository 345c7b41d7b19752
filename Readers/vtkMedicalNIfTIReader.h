// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkMedicalNIfTIReader
 * @brief   NIfTI-1/2 images (.nii, .nii.gz, .hdr/.img) placed in their world space.
 *
 * vtkNIFTIImageReader reads the voxels (gzipped or not) and gives the
 * orientation only as matrices (GetSFormMatrix(), GetQFormMatrix()), with
 * the image at origin 0. This reader puts the orientation on the image
 * itself, so that ParaView shows it where the file says: origin and
 * direction matrix from the sform when the file has one (sform_code > 0),
 * else from the qform (qform_code > 0), else origin 0 and no rotation. The
 * world space is NIfTI's (x right, y anterior, z superior; RAS).
 *
 * Values: where the header gives a scale (scl_slope not 0 or 1, or
 * scl_inter not 0) the voxels are returned as float v * scl_slope + scl_inter,
 * the calibrated values; otherwise as stored.
 *
 * ParaView 5.11's own NIfTI reader (the AnalyzeNIfTIReaderWriter plugin)
 * takes only uncompressed files.
 *
 * @sa vtkNIFTIImageReader
 */
#ifndef vtkMedicalNIfTIReader_h
#define vtkMedicalNIfTIReader_h

#include "MedicalIsosurfacesReadersModule.h" // For export macro
#include "vtkNIFTIImageReader.h"

class MEDICALISOSURFACESREADERS_EXPORT vtkMedicalNIfTIReader : public vtkNIFTIImageReader
{
public:
  static vtkMedicalNIfTIReader* New();
  vtkTypeMacro(vtkMedicalNIfTIReader, vtkNIFTIImageReader);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Which matrix placed the image: "sform", "qform" or "none".
  const char* GetPlacement() const { return this->Placement; }

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

  double Origin[3] = { 0.0, 0.0, 0.0 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  const char* Placement = "none";
};

#endif
