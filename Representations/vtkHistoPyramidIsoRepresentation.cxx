// SPDX-License-Identifier: BSD-3-Clause
#include "vtkHistoPyramidIsoRepresentation.h"

#include "vtkHistoPyramidIsoMapper.h"
#include "vtkObjectFactory.h"
#include "vtkPVLODVolume.h"

vtkStandardNewMacro(vtkHistoPyramidIsoRepresentation);

//------------------------------------------------------------------------------
vtkHistoPyramidIsoRepresentation::vtkHistoPyramidIsoRepresentation()
{
  // The base class made a vtkMultiBlockVolumeMapper; nothing has used it yet
  // (inputs and parameters reach the mapper in RequestData and at render time).
  this->VolumeMapper = this->IsoMapper.GetPointer();
}

//------------------------------------------------------------------------------
vtkHistoPyramidIsoRepresentation::~vtkHistoPyramidIsoRepresentation() = default;

//------------------------------------------------------------------------------
vtkHistoPyramidIsoMapper* vtkHistoPyramidIsoRepresentation::GetIsoMapper()
{
  return this->IsoMapper;
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetForceCPUFallback(bool force)
{
  this->IsoMapper->SetForceCPUFallback(force);
}

//------------------------------------------------------------------------------
bool vtkHistoPyramidIsoRepresentation::GetForceCPUFallback()
{
  return this->IsoMapper->GetForceCPUFallback();
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetAllowPointFootprint(bool allow)
{
  this->IsoMapper->SetAllowPointFootprint(allow);
}

//------------------------------------------------------------------------------
bool vtkHistoPyramidIsoRepresentation::GetAllowPointFootprint()
{
  return this->IsoMapper->GetAllowPointFootprint();
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetFirstHitPass(bool use)
{
  this->IsoMapper->SetFirstHitPass(use);
}

//------------------------------------------------------------------------------
bool vtkHistoPyramidIsoRepresentation::GetFirstHitPass()
{
  return this->IsoMapper->GetFirstHitPass();
}

//------------------------------------------------------------------------------
const char* vtkHistoPyramidIsoRepresentation::GetFootprint()
{
  return this->IsoMapper->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath
    ? this->IsoMapper->GetLastFootprintAsString()
    : "none";
}

//------------------------------------------------------------------------------
const char* vtkHistoPyramidIsoRepresentation::GetRenderPath()
{
  return this->IsoMapper->GetLastRenderPathAsString();
}

//------------------------------------------------------------------------------
const char* vtkHistoPyramidIsoRepresentation::GetFallbackReason()
{
  return this->IsoMapper->GetFallbackReason().c_str();
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetNumberOfPrimitives()
{
  return static_cast<double>(this->IsoMapper->GetNumberOfPrimitives());
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetNumberOfFallbackTriangles()
{
  return static_cast<double>(this->IsoMapper->GetNumberOfFallbackTriangles());
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetNumberOfPyramidBuilds()
{
  return static_cast<double>(this->IsoMapper->GetNumberOfPyramidBuilds());
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetGPUMemoryBytes()
{
  return static_cast<double>(this->IsoMapper->GetGPUMemoryBytes());
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetFrameBufferBytes()
{
  return static_cast<double>(this->IsoMapper->GetFrameBufferBytes());
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::UpdateMapperParameters()
{
  this->Superclass::UpdateMapperParameters();

  // The base class hides the volume when no colour array is chosen (volume
  // mappers need one). An isosurface needs only scalars: use the active ones.
  // This runs only for a visible representation, so showing the actor here
  // never overrides the user's Visibility.
  if (!this->Actor->GetVisibility())
  {
    this->IsoMapper->SetScalarModeToUsePointData();
    this->IsoMapper->SelectScalarArray(static_cast<const char*>(nullptr));
    this->Actor->SetVisibility(true);
  }
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "RenderPath: " << this->GetRenderPath() << "\n";
  os << indent << "Footprint: " << this->GetFootprint() << "\n";
  os << indent << "FallbackReason: " << this->IsoMapper->GetFallbackReason() << "\n";
  os << indent << "NumberOfPrimitives: " << this->IsoMapper->GetNumberOfPrimitives() << "\n";
  os << indent << "IsoMapper:\n";
  this->IsoMapper->PrintSelf(os, indent.GetNextIndent());
}
