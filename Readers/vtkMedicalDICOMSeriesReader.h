// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkMedicalDICOMSeriesReader
 * @brief   A DICOM series (one file per slice) placed in patient space.
 *
 * vtkDICOMImageReader reads the slices of the first series in a directory,
 * sorted by their position along the slice normal, and applies Rescale Slope
 * and Rescale Intercept (a CT then reads in Hounsfield units). It leaves the
 * geometry to the caller: its image has origin 0, no direction, the rows of
 * each slice reversed (DICOM's first row is the top one) and the slices in
 * decreasing position, so that surfaces come out mirrored and displaced
 * against the same scan in another format.
 *
 * This reader puts the image where the files say, in DICOM patient
 * coordinates (LPS, millimetres): the voxel (i, j, k) is column i and row j
 * of the k-th slice in increasing position along the normal (the cross
 * product of the two Image Orientation (Patient) vectors); the origin is
 * Image Position (Patient) of the first of those slices; the direction
 * matrix's columns are the row direction, the column direction and the
 * normal; the spacing is Pixel Spacing (column spacing along x, row spacing
 * along y, as DICOM stores them the other way round) and the distance
 * between neighbouring slice positions. An axial series thus gives the same
 * image as a MetaImage or NIfTI export of it. The reordering is one pass
 * over the rows (the whole volume's row order reversed).
 *
 * Limitations: those of vtkDICOMImageReader (uncompressed transfer syntaxes,
 * one series per directory, evenly spaced slices).
 *
 * @sa vtkDICOMImageReader
 */
#ifndef vtkMedicalDICOMSeriesReader_h
#define vtkMedicalDICOMSeriesReader_h

#include "MedicalIsosurfacesReadersModule.h" // For export macro
#include "vtkDICOMImageReader.h"

class MEDICALISOSURFACESREADERS_EXPORT vtkMedicalDICOMSeriesReader : public vtkDICOMImageReader
{
public:
  static vtkMedicalDICOMSeriesReader* New();
  vtkTypeMacro(vtkMedicalDICOMSeriesReader, vtkDICOMImageReader);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * The series to read: its directory, or any file in it (as a file dialog
   * gives). Sets the superclass's DirectoryName.
   */
  void SetSeriesPath(const char* path);

protected:
  vtkMedicalDICOMSeriesReader();
  ~vtkMedicalDICOMSeriesReader() override;

  int RequestInformation(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

private:
  vtkMedicalDICOMSeriesReader(const vtkMedicalDICOMSeriesReader&) = delete;
  void operator=(const vtkMedicalDICOMSeriesReader&) = delete;

  double PatientOrigin[3] = { 0.0, 0.0, 0.0 };
  double PatientSpacing[3] = { 1.0, 1.0, 1.0 };
  double PatientDirection[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
};

#endif
