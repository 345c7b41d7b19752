// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMedicalNIfTIReader.h"

#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMatrix4x4.h"
#include "vtkNIFTIImageHeader.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkSMPTools.h"

vtkStandardNewMacro(vtkMedicalNIfTIReader);

//------------------------------------------------------------------------------
vtkMedicalNIfTIReader::vtkMedicalNIfTIReader() = default;

//------------------------------------------------------------------------------
vtkMedicalNIfTIReader::~vtkMedicalNIfTIReader() = default;

//------------------------------------------------------------------------------
int vtkMedicalNIfTIReader::RequestInformation(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!this->Superclass::RequestInformation(request, inputVector, outputVector))
  {
    return 0;
  }
  // The superclass's matrices map its output's coordinates (index times
  // spacing, origin 0, slices already reordered for qfac) to the world:
  // their translation is the origin, their rotation the direction.
  vtkNIFTIImageHeader* header = this->GetNIFTIHeader();
  vtkMatrix4x4* matrix = nullptr;
  this->Placement = "none";
  if (header && header->GetSFormCode() > 0 && this->GetSFormMatrix())
  {
    matrix = this->GetSFormMatrix();
    this->Placement = "sform";
  }
  else if (header && header->GetQFormCode() > 0 && this->GetQFormMatrix())
  {
    matrix = this->GetQFormMatrix();
    this->Placement = "qform";
  }
  for (int r = 0; r < 3; ++r)
  {
    this->Origin[r] = matrix ? matrix->GetElement(r, 3) : 0.0;
    for (int c = 0; c < 3; ++c)
    {
      this->Direction[3 * r + c] = matrix ? matrix->GetElement(r, c) : (r == c ? 1.0 : 0.0);
    }
  }
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  outInfo->Set(vtkDataObject::ORIGIN(), this->Origin, 3);
  outInfo->Set(vtkDataObject::DIRECTION(), this->Direction, 9);
  if (this->GetRescaleSlope() != 0.0 &&
    (this->GetRescaleSlope() != 1.0 || this->GetRescaleIntercept() != 0.0))
  {
    vtkDataObject::SetPointDataActiveScalarInfo(
      outInfo, VTK_FLOAT, this->GetNumberOfScalarComponents());
  }
  return 1;
}

//------------------------------------------------------------------------------
int vtkMedicalNIfTIReader::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!this->Superclass::RequestData(request, inputVector, outputVector))
  {
    return 0;
  }
  vtkImageData* image = vtkImageData::GetData(outputVector, 0);
  if (!image)
  {
    return 1;
  }
  image->SetOrigin(this->Origin);
  image->SetDirectionMatrix(this->Direction);

  const double slope = this->GetRescaleSlope();
  const double intercept = this->GetRescaleIntercept();
  vtkDataArray* stored = image->GetPointData()->GetScalars();
  if (stored && slope != 0.0 && (slope != 1.0 || intercept != 0.0))
  {
    vtkNew<vtkFloatArray> calibrated;
    calibrated->SetName(stored->GetName());
    calibrated->SetNumberOfComponents(stored->GetNumberOfComponents());
    calibrated->SetNumberOfTuples(stored->GetNumberOfTuples());
    const int components = stored->GetNumberOfComponents();
    vtkSMPTools::For(0, stored->GetNumberOfTuples(),
      [&](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType t = begin; t < end; ++t)
        {
          for (int c = 0; c < components; ++c)
          {
            calibrated->SetTypedComponent(
              t, c, static_cast<float>(stored->GetComponent(t, c) * slope + intercept));
          }
        }
      });
    image->GetPointData()->SetScalars(calibrated);
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkMedicalNIfTIReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Placement: " << this->Placement << "\n";
}
