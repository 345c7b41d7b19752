// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMedicalPhantomSource.h"

#include "HeadPhantom.h"
#include "ProcessMemory.h"

#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkSMPThreadLocal.h"
#include "vtkSMPTools.h"
#include "vtkShortArray.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <sstream>
#include <vector>

#include <unistd.h>

vtkStandardNewMacro(vtkMedicalPhantomSource);

namespace
{
// Fills a range of z-slices of the requested extent; each thread keeps its
// own row buffer.
struct FillSlicesFunctor
{
  const mediso::HeadPhantom& Phantom;
  const int* Extent;
  std::int16_t* Out;
  vtkSMPThreadLocal<std::vector<double>> Rows;

  FillSlicesFunctor(const mediso::HeadPhantom& phantom, const int* extent, std::int16_t* out)
    : Phantom(phantom)
    , Extent(extent)
    , Out(out)
  {
  }

  void operator()(vtkIdType kBegin, vtkIdType kEnd)
  {
    std::vector<double>& row = this->Rows.Local();
    row.resize(static_cast<std::size_t>(this->Extent[1] - this->Extent[0] + 1));
    this->Phantom.FillSlices(this->Extent, static_cast<int>(kBegin), static_cast<int>(kEnd),
      this->Out, row.data());
  }
};

// Bytes generating a whole grid takes, as doubles so that absurd sizes
// cannot overflow: the int16 output, and one row of doubles per thread
// (FillSlicesFunctor's scratch).
double OutputBytes(const int dims[3])
{
  return static_cast<double>(dims[0]) * dims[1] * dims[2] * sizeof(std::int16_t);
}

double ScratchBytes(const int dims[3], int threads)
{
  return static_cast<double>(threads) * dims[0] * sizeof(double);
}
} // namespace

//------------------------------------------------------------------------------
vtkMedicalPhantomSource::vtkMedicalPhantomSource()
{
  this->SetNumberOfInputPorts(0);
}

//------------------------------------------------------------------------------
std::string vtkMedicalPhantomSource::CheckParameters()
{
  const mediso::HeadPhantom phantom(
    this->Dimensions, this->NoiseStandardDeviation, static_cast<std::uint32_t>(this->Seed));
  std::string reason = phantom.Validate();
  if (!reason.empty())
  {
    return reason;
  }
  std::ostringstream msg;
  for (int a = 0; a < 3; ++a)
  {
    if (!(this->Spacing[a] > 0.0) || !std::isfinite(this->Spacing[a]) ||
      !std::isfinite(this->Origin[a]))
    {
      msg << "spacing (" << this->Spacing[0] << ", " << this->Spacing[1] << ", "
          << this->Spacing[2] << ") must be positive and origin finite";
      return msg.str();
    }
  }
  // The user's bound, where it is tighter than what the process may still
  // allocate (physical memory, ulimit -v, cgroup: ProcessMemory.h).
  constexpr double BytesPerMB = 1.0e6;
  const mediso::MemoryAllowance allowance = mediso::ProcessMemoryAllowance();
  double limitMB = allowance.Bounded() ? static_cast<double>(allowance.Bytes) / BytesPerMB
                                       : std::numeric_limits<double>::infinity();
  std::string limitSource = "what the process may still allocate: " + allowance.Limit;
  if (this->MemoryLimit > 0.0 && this->MemoryLimit <= limitMB)
  {
    limitMB = this->MemoryLimit;
    limitSource = "the MemoryLimit property";
  }
  const int threads = std::max(1, vtkSMPTools::GetEstimatedNumberOfThreads());
  const double outputMB = OutputBytes(this->Dimensions) / BytesPerMB;
  const double scratchMB = ScratchBytes(this->Dimensions, threads) / BytesPerMB;
  if (outputMB + scratchMB > limitMB)
  {
    msg << "dimensions " << this->Dimensions[0] << " x " << this->Dimensions[1] << " x "
        << this->Dimensions[2] << " need " << outputMB + scratchMB << " MB (the output, "
        << outputMB << " MB, and a row of " << this->Dimensions[0] << " doubles for each of "
        << threads << " thread(s), " << scratchMB << " MB), more than " << limitMB << " MB ("
        << limitSource << ")";
    return msg.str();
  }
  return std::string();
}

//------------------------------------------------------------------------------
int vtkMedicalPhantomSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  const std::string reason = this->CheckParameters();
  int wholeExtent[6] = { 0, -1, 0, -1, 0, -1 };
  if (reason.empty())
  {
    for (int a = 0; a < 3; ++a)
    {
      wholeExtent[2 * a + 1] = this->Dimensions[a] - 1;
    }
  }
  else
  {
    vtkErrorMacro("Cannot generate the phantom: " << reason << ". The output is empty.");
  }
  this->ReportedProblem = reason;
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), wholeExtent, 6);
  outInfo->Set(vtkDataObject::SPACING(), this->Spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), this->Origin, 3);
  outInfo->Set(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT(), 1);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_SHORT, 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkMedicalPhantomSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkImageData* output = vtkImageData::GetData(outInfo);
  if (!output)
  {
    return 0;
  }
  output->Initialize();

  int extent[6];
  outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), extent);
  const std::string reason = this->CheckParameters();
  if (!reason.empty() || extent[0] > extent[1] || extent[2] > extent[3] || extent[4] > extent[5])
  {
    // An error RequestInformation reported is not said twice; an empty
    // request is not an error.
    if (!reason.empty() && this->ReportedProblem.empty())
    {
      vtkErrorMacro("Cannot generate the phantom: " << reason << ". The output is empty.");
      this->ReportedProblem = reason;
    }
    return 1;
  }

  output->SetExtent(extent);
  output->SetSpacing(this->Spacing);
  output->SetOrigin(this->Origin);
  vtkNew<vtkShortArray> scalars;
  scalars->SetName("HU");
  const vtkIdType numPoints = static_cast<vtkIdType>(extent[1] - extent[0] + 1) *
    (extent[3] - extent[2] + 1) * (extent[5] - extent[4] + 1);
  // RequestInformation's check was for the whole grid, a moment ago; the
  // allocation can still fail (another allocation since, a limit lowered).
  bool allocated = false;
  try
  {
    allocated = scalars->Allocate(numPoints) != 0;
  }
  catch (const std::bad_alloc&)
  {
    allocated = false;
  }
  if (!allocated)
  {
    vtkErrorMacro("Cannot generate the phantom: " << numPoints << " points ("
                                                  << numPoints * sizeof(std::int16_t) / 1.0e6
                                                  << " MB) could not be allocated. The output is "
                                                     "empty.");
    output->Initialize();
    return 1;
  }
  scalars->SetNumberOfTuples(numPoints);
  output->GetPointData()->SetScalars(scalars);

  const mediso::HeadPhantom phantom(
    this->Dimensions, this->NoiseStandardDeviation, static_cast<std::uint32_t>(this->Seed));
  FillSlicesFunctor fill(phantom, extent, scalars->GetPointer(0));

  // Slices go out in a few chunks so that progress and abort are reported
  // from this thread between parallel passes.
  const int numSlices = extent[5] - extent[4] + 1;
  const int numChunks = std::min(numSlices, 16);
  for (int chunk = 0; chunk < numChunks; ++chunk)
  {
    if (this->CheckAbort())
    {
      break;
    }
    const vtkIdType k0 = extent[4] + static_cast<vtkIdType>(numSlices) * chunk / numChunks;
    const vtkIdType k1 = extent[4] + static_cast<vtkIdType>(numSlices) * (chunk + 1) / numChunks;
    try
    {
      vtkSMPTools::For(k0, k1, 1, fill);
    }
    catch (const std::bad_alloc&)
    {
      // A thread's row of doubles, the last allocation left.
      vtkErrorMacro("Cannot generate the phantom: memory ran out for the rows of "
        << extent[1] - extent[0] + 1 << " doubles. The output is empty.");
      output->Initialize();
      return 1;
    }
    this->UpdateProgress(static_cast<double>(chunk + 1) / numChunks);
  }

  vtkNew<vtkIdTypeArray> producer;
  producer->SetName("ProducerProcessId");
  producer->InsertNextValue(static_cast<vtkIdType>(getpid()));
  output->GetFieldData()->AddArray(producer);
  return 1;
}

//------------------------------------------------------------------------------
void vtkMedicalPhantomSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: " << this->Dimensions[0] << " " << this->Dimensions[1] << " "
     << this->Dimensions[2] << "\n";
  os << indent << "Spacing: " << this->Spacing[0] << " " << this->Spacing[1] << " "
     << this->Spacing[2] << "\n";
  os << indent << "Origin: " << this->Origin[0] << " " << this->Origin[1] << " "
     << this->Origin[2] << "\n";
  os << indent << "NoiseStandardDeviation: " << this->NoiseStandardDeviation << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "MemoryLimit: " << this->MemoryLimit << " MB\n";
}
