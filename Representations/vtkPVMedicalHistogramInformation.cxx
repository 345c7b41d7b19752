// SPDX-License-Identifier: BSD-3-Clause
#include "vtkPVMedicalHistogramInformation.h"

#include "vtkAlgorithm.h"
#include "vtkClientServerStream.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkExecutive.h"
#include "vtkInformation.h"
#include "vtkMultiProcessStream.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"

#include "HistogramThreshold.h"

#include <cstring>

vtkStandardNewMacro(vtkPVMedicalHistogramInformation);

//------------------------------------------------------------------------------
vtkPVMedicalHistogramInformation::vtkPVMedicalHistogramInformation()
{
  this->RootOnly = 0;
}

//------------------------------------------------------------------------------
vtkPVMedicalHistogramInformation::~vtkPVMedicalHistogramInformation() = default;

//------------------------------------------------------------------------------
void vtkPVMedicalHistogramInformation::SetBins(double low, double width, int count)
{
  this->Low = low;
  this->Width = width;
  this->BinCount = count;
}

//------------------------------------------------------------------------------
double vtkPVMedicalHistogramInformation::GetCount(int bin) const
{
  return bin >= 0 && bin < this->GetNumberOfBins()
    ? static_cast<double>(this->Counts[static_cast<std::size_t>(bin)])
    : 0.0;
}

//------------------------------------------------------------------------------
bool vtkPVMedicalHistogramInformation::CountLeaf(vtkDataObject* leaf)
{
  auto* dataSet = vtkDataSet::SafeDownCast(leaf);
  if (!dataSet)
  {
    return false;
  }
  vtkPointData* points = dataSet->GetPointData();
  vtkDataArray* array =
    this->ArrayName.empty() ? points->GetScalars() : points->GetArray(this->ArrayName.c_str());
  if (!array || array->GetNumberOfComponents() != 1)
  {
    return false;
  }
  mediso::HistogramBins bins;
  bins.Low = this->Low;
  bins.Width = this->Width;
  bins.Count = static_cast<std::size_t>(this->BinCount);
  if (this->Counts.size() != bins.Count)
  {
    this->Counts.assign(bins.Count, 0);
  }
  std::vector<std::uint64_t> counts(bins.Count, 0);
  const auto n = static_cast<std::size_t>(array->GetNumberOfTuples());
  if (array->HasStandardMemoryLayout())
  {
    switch (array->GetDataType())
    {
      vtkTemplateMacro(mediso::AccumulateHistogram(
        static_cast<const VTK_TT*>(array->GetVoidPointer(0)), n, 1, bins, counts.data()));
      default:
        return false;
    }
  }
  else
  {
    for (std::size_t i = 0; i < n; ++i)
    {
      const double value = array->GetComponent(static_cast<vtkIdType>(i), 0);
      if (value == value)
      {
        ++counts[bins.BinOf(value)];
      }
    }
  }
  for (std::size_t i = 0; i < bins.Count; ++i)
  {
    this->Counts[i] += counts[i];
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkPVMedicalHistogramInformation::CopyFromObject(vtkObject* object)
{
  this->Counts.clear();
  auto* algorithm = vtkAlgorithm::SafeDownCast(object);
  if (!algorithm || this->BinCount <= 0 || !(this->Width > 0.0) ||
    std::strcmp(algorithm->GetClassName(), "vtkPVNullSource") == 0)
  {
    return;
  }
  // As vtkPVDataInformation: the output as it is, without a pipeline pass.
  vtkInformation* outInfo = algorithm->GetExecutive()->GetOutputInformation(this->PortNumber);
  vtkDataObject* output = outInfo ? vtkDataObject::GetData(outInfo) : nullptr;
  if (auto* composite = vtkCompositeDataSet::SafeDownCast(output))
  {
    for (vtkDataSet* leaf : vtkCompositeDataSet::GetDataSets<vtkDataSet>(composite))
    {
      this->CountLeaf(leaf);
    }
  }
  else if (output)
  {
    this->CountLeaf(output);
  }
}

//------------------------------------------------------------------------------
void vtkPVMedicalHistogramInformation::AddInformation(vtkPVInformation* other)
{
  auto* histogram = vtkPVMedicalHistogramInformation::SafeDownCast(other);
  if (!histogram || histogram->Counts.empty())
  {
    return;
  }
  if (this->Counts.empty())
  {
    this->Counts = histogram->Counts;
    return;
  }
  if (this->Counts.size() == histogram->Counts.size())
  {
    for (std::size_t i = 0; i < this->Counts.size(); ++i)
    {
      this->Counts[i] += histogram->Counts[i];
    }
  }
}

//------------------------------------------------------------------------------
void vtkPVMedicalHistogramInformation::CopyToStream(vtkClientServerStream* stream)
{
  stream->Reset();
  *stream << vtkClientServerStream::Reply << static_cast<int>(this->Counts.size());
  if (!this->Counts.empty())
  {
    *stream << vtkClientServerStream::InsertArray(
      this->Counts.data(), static_cast<int>(this->Counts.size()));
  }
  *stream << vtkClientServerStream::End;
}

//------------------------------------------------------------------------------
void vtkPVMedicalHistogramInformation::CopyFromStream(const vtkClientServerStream* stream)
{
  this->Counts.clear();
  int count = 0;
  if (!stream->GetArgument(0, 0, &count) || count <= 0)
  {
    return;
  }
  this->Counts.resize(static_cast<std::size_t>(count));
  if (!stream->GetArgument(0, 1, this->Counts.data(), static_cast<vtkTypeUInt32>(count)))
  {
    this->Counts.clear();
  }
}

//------------------------------------------------------------------------------
void vtkPVMedicalHistogramInformation::CopyParametersToStream(vtkMultiProcessStream& stream)
{
  stream << 0x4d48 << this->PortNumber << this->ArrayName << this->Low << this->Width
         << this->BinCount;
}

//------------------------------------------------------------------------------
void vtkPVMedicalHistogramInformation::CopyParametersFromStream(vtkMultiProcessStream& stream)
{
  int magic = 0;
  stream >> magic >> this->PortNumber >> this->ArrayName >> this->Low >> this->Width >>
    this->BinCount;
}

//------------------------------------------------------------------------------
void vtkPVMedicalHistogramInformation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "PortNumber: " << this->PortNumber << "\n";
  os << indent << "ArrayName: " << this->ArrayName << "\n";
  os << indent << "Bins: " << this->BinCount << " from " << this->Low << ", width " << this->Width
     << "\n";
  os << indent << "NumberOfBins gathered: " << this->Counts.size() << "\n";
}
