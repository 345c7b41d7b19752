// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMedicalDICOMSeriesReader.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <vtksys/SystemTools.hxx>

#include <algorithm>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkMedicalDICOMSeriesReader);

//------------------------------------------------------------------------------
vtkMedicalDICOMSeriesReader::vtkMedicalDICOMSeriesReader() = default;

//------------------------------------------------------------------------------
vtkMedicalDICOMSeriesReader::~vtkMedicalDICOMSeriesReader() = default;

//------------------------------------------------------------------------------
void vtkMedicalDICOMSeriesReader::SetSeriesPath(const char* path)
{
  if (path && path[0] && !vtksys::SystemTools::FileIsDirectory(path))
  {
    this->SetDirectoryName(vtksys::SystemTools::GetFilenamePath(path).c_str());
  }
  else
  {
    this->SetDirectoryName(path);
  }
}

//------------------------------------------------------------------------------
int vtkMedicalDICOMSeriesReader::RequestInformation(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!this->Superclass::RequestInformation(request, inputVector, outputVector))
  {
    return 0;
  }
  // The superclass sorted the series by decreasing position: the last file
  // is the first slice of the image this reader makes.
  const int files = this->GetNumberOfDICOMFileNames();
  std::string first;
  if (files > 0)
  {
    first = this->GetDICOMFileName(files - 1);
  }
  else if (this->FileName)
  {
    first = this->FileName;
  }
  if (first.empty())
  {
    return 1;
  }
  vtkNew<vtkDICOMImageReader> slice;
  slice->SetFileName(first.c_str());
  slice->UpdateInformation();
  const float* position = slice->GetImagePositionPatient();
  const float* orientation = slice->GetImageOrientationPatient();
  const double* pixelSpacing = slice->GetPixelSpacing(); // DICOM order: rows, then columns

  double row[3] = { orientation[0], orientation[1], orientation[2] };
  double column[3] = { orientation[3], orientation[4], orientation[5] };
  if (vtkMath::Normalize(row) == 0.0 || vtkMath::Normalize(column) == 0.0)
  {
    // No Image Orientation (Patient): an axial slice.
    row[0] = 1.0;
    row[1] = row[2] = 0.0;
    column[1] = 1.0;
    column[0] = column[2] = 0.0;
  }
  double normal[3];
  vtkMath::Cross(row, column, normal);
  for (int i = 0; i < 3; ++i)
  {
    this->PatientOrigin[i] = position[i];
    this->PatientDirection[3 * i + 0] = row[i];
    this->PatientDirection[3 * i + 1] = column[i];
    this->PatientDirection[3 * i + 2] = normal[i];
  }
  this->PatientSpacing[0] = pixelSpacing[1] > 0.0 ? pixelSpacing[1] : 1.0;
  this->PatientSpacing[1] = pixelSpacing[0] > 0.0 ? pixelSpacing[0] : 1.0;
  // Between slice positions when there are several (the superclass's), else
  // the slice thickness.
  this->PatientSpacing[2] = files > 1 ? this->DataSpacing[2] : pixelSpacing[2];
  if (!(this->PatientSpacing[2] > 0.0))
  {
    this->PatientSpacing[2] = 1.0;
  }

  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  outInfo->Set(vtkDataObject::SPACING(), this->PatientSpacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), this->PatientOrigin, 3);
  outInfo->Set(vtkDataObject::DIRECTION(), this->PatientDirection, 9);
  return 1;
}

//------------------------------------------------------------------------------
int vtkMedicalDICOMSeriesReader::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!this->Superclass::RequestData(request, inputVector, outputVector))
  {
    return 0;
  }
  vtkImageData* image = vtkImageData::GetData(outputVector, 0);
  vtkDataArray* scalars = image ? image->GetPointData()->GetScalars() : nullptr;
  if (!scalars || scalars->GetNumberOfTuples() == 0)
  {
    return 1;
  }
  int extent[6];
  image->GetExtent(extent);
  int whole[6];
  outputVector->GetInformationObject(0)->Get(
    vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  if (!std::equal(extent, extent + 6, whole))
  {
    vtkErrorMacro("reads whole series only (requested extent differs from the whole extent).");
    image->Initialize();
    return 1;
  }

  // The superclass's voxel (i, j, k) is column i of row (rows - 1 - j) of the
  // (slices - 1 - k)-th slice in increasing position: reversing the order of
  // all the rows of the volume undoes both at once.
  const vtkIdType rowBytes = static_cast<vtkIdType>(extent[1] - extent[0] + 1) *
    scalars->GetNumberOfComponents() * scalars->GetDataTypeSize();
  const vtkIdType rows =
    static_cast<vtkIdType>(extent[3] - extent[2] + 1) * (extent[5] - extent[4] + 1);
  auto* bytes = static_cast<unsigned char*>(scalars->GetVoidPointer(0));
  std::vector<unsigned char> swap(static_cast<std::size_t>(rowBytes));
  for (vtkIdType r = 0; r < rows / 2; ++r)
  {
    unsigned char* a = bytes + r * rowBytes;
    unsigned char* b = bytes + (rows - 1 - r) * rowBytes;
    std::copy(a, a + rowBytes, swap.data());
    std::copy(b, b + rowBytes, a);
    std::copy(swap.data(), swap.data() + rowBytes, b);
  }
  scalars->Modified();
  image->SetSpacing(this->PatientSpacing);
  image->SetOrigin(this->PatientOrigin);
  image->SetDirectionMatrix(this->PatientDirection);
  return 1;
}

//------------------------------------------------------------------------------
void vtkMedicalDICOMSeriesReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "PatientOrigin: " << this->PatientOrigin[0] << " " << this->PatientOrigin[1]
     << " " << this->PatientOrigin[2] << "\n";
  os << indent << "PatientSpacing: " << this->PatientSpacing[0] << " " << this->PatientSpacing[1]
     << " " << this->PatientSpacing[2] << "\n";
}
