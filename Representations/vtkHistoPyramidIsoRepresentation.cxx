// SPDX-License-Identifier: BSD-3-Clause
#include "vtkHistoPyramidIsoRepresentation.h"

#include "vtkCellData.h"
#include "vtkContourValues.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkFieldData.h"
#include "vtkHistoPyramidIsoMapper.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMatrix4x4.h"
#include "vtkMultiProcessController.h"
#include "vtkObjectFactory.h"
#include "vtkPVLODVolume.h"
#include "vtkPlaneCollection.h"
#include "vtkPointData.h"
#include "vtkRectilinearGrid.h"
#include "vtkResampleToImage.h"
#include "vtkVolumeProperty.h"

#include "ProcessMemory.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <new>
#include <sstream>
#include <vector>

namespace
{
// Whether the coordinates are evenly spaced (relative tolerance 1e-6 of the
// axis' extent), and their spacing then.
bool EvenSpacing(vtkDataArray* coordinates, double& spacing)
{
  const vtkIdType n = coordinates->GetNumberOfTuples();
  if (n < 2)
  {
    spacing = 1.0;
    return true;
  }
  const double first = coordinates->GetComponent(0, 0);
  const double last = coordinates->GetComponent(n - 1, 0);
  spacing = (last - first) / static_cast<double>(n - 1);
  const double tolerance = 1e-6 * std::abs(last - first);
  for (vtkIdType i = 1; i < n - 1; ++i)
  {
    if (std::abs(coordinates->GetComponent(i, 0) - (first + spacing * i)) > tolerance)
    {
      return false;
    }
  }
  return true;
}
}

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
void vtkHistoPyramidIsoRepresentation::SetInteractiveAdjust(bool adjust)
{
  this->IsoMapper->SetInteractiveAdjust(adjust);
}

//------------------------------------------------------------------------------
bool vtkHistoPyramidIsoRepresentation::GetInteractiveAdjust()
{
  return this->IsoMapper->GetInteractiveAdjust();
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetInteractiveFrameBudget(double seconds)
{
  this->IsoMapper->SetInteractiveFrameBudget(seconds);
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetInteractiveFrameBudget()
{
  return this->IsoMapper->GetInteractiveFrameBudget();
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetInteractiveTriangleLevels(bool use)
{
  this->IsoMapper->SetInteractiveTriangleLevels(use);
}

//------------------------------------------------------------------------------
bool vtkHistoPyramidIsoRepresentation::GetInteractiveTriangleLevels()
{
  return this->IsoMapper->GetInteractiveTriangleLevels();
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetInteractiveVolumeLevels(bool use)
{
  this->IsoMapper->SetInteractiveVolumeLevels(use);
}

//------------------------------------------------------------------------------
bool vtkHistoPyramidIsoRepresentation::GetInteractiveVolumeLevels()
{
  return this->IsoMapper->GetInteractiveVolumeLevels();
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetLastInteractive()
{
  return this->IsoMapper->GetLastInteractive() ? 1.0 : 0.0;
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetLastSampleDistance()
{
  return this->IsoMapper->GetLastSampleDistance();
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetLastLevel()
{
  return static_cast<double>(this->IsoMapper->GetLastLevel());
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetLastPredictedSeconds()
{
  return this->IsoMapper->GetLastPredictedSeconds();
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetLastMeasuredSeconds()
{
  return this->IsoMapper->GetLastMeasuredSeconds();
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetWindowFixedSeconds()
{
  return this->IsoMapper->GetWindowFixedSeconds();
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetDiffuseColor(double r, double g, double b)
{
  this->IsoMapper->SetSolidColor(r, g, b);
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetOpacity(double opacity)
{
  this->IsoMapper->SetOpacity(opacity);
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetColorEachSurface(bool each)
{
  if (this->ColorEachSurface != each)
  {
    this->ColorEachSurface = each;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetNumberOfSurfaceColors(int number)
{
  this->IsoMapper->SetNumberOfSurfaceColors(number);
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetSurfaceColor(int i, double r, double g, double b)
{
  this->IsoMapper->SetSurfaceColor(i, r, g, b);
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetNumberOfSurfaceOpacities(int number)
{
  this->IsoMapper->SetNumberOfSurfaceOpacities(number);
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetSurfaceOpacity(int i, double opacity)
{
  this->IsoMapper->SetSurfaceOpacity(i, opacity);
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
void vtkHistoPyramidIsoRepresentation::SetGPUMemoryBudget(double megabytes)
{
  if (megabytes != this->IsoMapper->GetGPUMemoryBudget())
  {
    this->IsoMapper->SetGPUMemoryBudget(megabytes);
    this->Modified();
  }
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetGPUMemoryBudget()
{
  return this->IsoMapper->GetGPUMemoryBudget();
}

//------------------------------------------------------------------------------
double* vtkHistoPyramidIsoRepresentation::GetLastBricks()
{
  this->LastBricks[0] = static_cast<double>(this->IsoMapper->GetLastBricks());
  this->LastBricks[1] = static_cast<double>(this->IsoMapper->GetLastActiveBricks());
  this->LastBricks[2] = static_cast<double>(this->IsoMapper->GetLastResidentBricks());
  return this->LastBricks;
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetBrickPoolSlots()
{
  return static_cast<double>(this->IsoMapper->GetLastBrickPoolSlots());
}

//------------------------------------------------------------------------------
const char* vtkHistoPyramidIsoRepresentation::GetBrickPoolReason()
{
  return this->IsoMapper->GetLastBrickPoolReason().c_str();
}

//------------------------------------------------------------------------------
const char* vtkHistoPyramidIsoRepresentation::GetFallbackReason()
{
  return this->IsoMapper->GetFallbackReason().c_str();
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetNumberOfPrimitives()
{
  return static_cast<double>(this->IsoMapper->GetGPUStats().Primitives);
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetNumberOfFallbackTriangles()
{
  return static_cast<double>(this->IsoMapper->GetNumberOfFallbackTriangles());
}

//------------------------------------------------------------------------------
double vtkHistoPyramidIsoRepresentation::GetNumberOfPyramidBuilds()
{
  return static_cast<double>(this->IsoMapper->GetGPUStats().PyramidBuilds);
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
int vtkHistoPyramidIsoRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!this->Superclass::RequestData(request, inputVector, outputVector))
  {
    return 0;
  }
  if (auto* image = vtkImageData::SafeDownCast(this->Cache))
  {
    // Points at one place along an axis (or nowhere) have no surface between
    // them; said here, once per update, since such data may never reach the
    // mapper (a non-finite spacing makes non-finite bounds, which the view culls).
    const std::string spacingProblem = vtkHistoPyramidIsoMapper::CheckSpacing(image->GetSpacing());
    if (!spacingProblem.empty())
    {
      vtkErrorMacro(<< spacingProblem);
      this->Cache = nullptr;
      this->IsoMapper->RemoveAllInputConnections(0);
    }
    return 1;
  }
  auto* grid = vtkRectilinearGrid::SafeDownCast(this->Cache);
  if (!grid)
  {
    return 1;
  }
  int extent[6];
  grid->GetExtent(extent);
  vtkDataArray* axes[3] = { grid->GetXCoordinates(), grid->GetYCoordinates(),
    grid->GetZCoordinates() };
  double spacing[3];
  bool even = true;
  for (int a = 0; a < 3; ++a)
  {
    even = axes[a] && EvenSpacing(axes[a], spacing[a]) && even;
  }
  vtkNew<vtkImageData> image;
  if (even)
  {
    // The same points and data, described by origin and spacing.
    image->SetExtent(extent);
    image->SetSpacing(spacing);
    image->SetOrigin(axes[0]->GetComponent(0, 0) - spacing[0] * extent[0],
      axes[1]->GetComponent(0, 0) - spacing[1] * extent[2],
      axes[2]->GetComponent(0, 0) - spacing[2] * extent[4]);
    image->GetPointData()->ShallowCopy(grid->GetPointData());
    image->GetCellData()->ShallowCopy(grid->GetCellData());
    image->GetFieldData()->ShallowCopy(grid->GetFieldData());
  }
  else
  {
    // Uneven coordinates: sample onto an even grid as fine as the finest
    // spacing along each axis, at most 4 times the axis' points and 1024.
    int dimensions[3];
    for (int a = 0; a < 3; ++a)
    {
      const vtkIdType n = axes[a] ? axes[a]->GetNumberOfTuples() : 1;
      double finest = VTK_DOUBLE_MAX;
      for (vtkIdType i = 1; i < n; ++i)
      {
        finest = std::min(
          finest, std::abs(axes[a]->GetComponent(i, 0) - axes[a]->GetComponent(i - 1, 0)));
      }
      const double length =
        n > 1 ? std::abs(axes[a]->GetComponent(n - 1, 0) - axes[a]->GetComponent(0, 0)) : 0.0;
      double wanted = finest > 0.0 ? std::ceil(length / finest) + 1.0 : static_cast<double>(n);
      wanted = std::min({ wanted, 4.0 * static_cast<double>(n), 1024.0 });
      dimensions[a] = std::max(static_cast<int>(n), static_cast<int>(wanted));
    }
    // The resampled copy of every point and cell array, and the mask
    // vtkResampleToImage adds, must fit in what the process may allocate.
    std::uint64_t bytesPerPoint = 1;
    for (vtkDataSetAttributes* arrays : { static_cast<vtkDataSetAttributes*>(grid->GetPointData()),
           static_cast<vtkDataSetAttributes*>(grid->GetCellData()) })
    {
      for (int i = 0; i < arrays->GetNumberOfArrays(); ++i)
      {
        vtkDataArray* array = arrays->GetArray(i);
        bytesPerPoint += array
          ? static_cast<std::uint64_t>(array->GetDataTypeSize()) * array->GetNumberOfComponents()
          : 0;
      }
    }
    std::string memoryProblem;
    if (!mediso::FitsInProcessMemory(
          static_cast<std::uint64_t>(dimensions[0]) * dimensions[1] * dimensions[2] * bytesPerPoint,
          "the rectilinear grid resampled onto an even grid", memoryProblem))
    {
      vtkErrorMacro(<< "HistoPyramid Isosurface cannot draw this rectilinear grid: "
                    << memoryProblem << ".");
      this->Cache = nullptr;
      this->IsoMapper->RemoveAllInputConnections(0);
      return 1;
    }
    vtkNew<vtkResampleToImage> resample;
    resample->SetInputDataObject(grid);
    resample->SetSamplingDimensions(dimensions);
    try
    {
      resample->Update();
    }
    catch (const std::bad_alloc&)
    {
      vtkErrorMacro(<< "HistoPyramid Isosurface cannot draw this rectilinear grid: memory ran "
                       "out while resampling it onto an even grid.");
      this->Cache = nullptr;
      this->IsoMapper->RemoveAllInputConnections(0);
      return 1;
    }
    image->ShallowCopy(resample->GetOutput());
    // vtkResampleToImage marks the points it could not sample; every point
    // of a rectilinear grid's box can be, so the mask carries nothing.
    image->GetPointData()->RemoveArray("vtkValidPointMask");
    std::ostringstream msg;
    msg << "HistoPyramid Isosurface draws image data: this rectilinear grid's coordinates are "
           "not evenly spaced, so it was resampled onto an even "
        << dimensions[0] << "x" << dimensions[1] << "x" << dimensions[2]
        << " grid (the surfaces are those of the resampled data; Resample To Image "
           "chooses the grid yourself).";
    if (msg.str() != this->LastResampleMessage)
    {
      this->LastResampleMessage = msg.str();
      vtkWarningMacro(<< msg.str());
    }
  }
  this->Cache = image;
  this->IsoMapper->SetInputData(image);
  return 1;
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetClipPlane(bool use)
{
  if (use != this->ClipPlane)
  {
    this->ClipPlane = use;
    this->Modified(); // read at render time (UpdateMapperParameters)
  }
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetClipPlaneOrigin(double x, double y, double z)
{
  this->ClipPlaneOrigin[0] = x;
  this->ClipPlaneOrigin[1] = y;
  this->ClipPlaneOrigin[2] = z;
  this->Modified(); // read at render time (UpdateMapperParameters)
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetClipPlaneNormal(double x, double y, double z)
{
  this->ClipPlaneNormal[0] = x;
  this->ClipPlaneNormal[1] = y;
  this->ClipPlaneNormal[2] = z;
  this->Modified(); // read at render time (UpdateMapperParameters)
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::SetClipPlaneInvert(bool invert)
{
  if (invert != this->ClipPlaneInvert)
  {
    this->ClipPlaneInvert = invert;
    this->Modified(); // read at render time (UpdateMapperParameters)
  }
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::UpdateMapperParameters()
{
  this->Superclass::UpdateMapperParameters();

  // The clipping plane, in world coordinates (the display's transform moves
  // the data), with its normal towards the kept side as the mapper takes it.
  if (this->ClipPlane)
  {
    const double sign = this->ClipPlaneInvert ? -1.0 : 1.0;
    const double* n = this->ClipPlaneNormal;
    const double* o = this->ClipPlaneOrigin;
    vtkMatrix4x4* dataToWorld = this->Actor->GetMatrix();
    vtkNew<vtkMatrix4x4> worldToData;
    vtkMatrix4x4::Invert(dataToWorld, worldToData);
    const std::vector<vtkOpenGLHistoPyramidIsosurfaces::Plane> world =
      vtkOpenGLHistoPyramidIsosurfaces::PullBackPlanes(
        { { sign * n[0], sign * n[1], sign * n[2],
          -sign * (n[0] * o[0] + n[1] * o[1] + n[2] * o[2]) } },
        worldToData);
    const auto& p = world[0];
    const double norm2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    if (norm2 > 0.0 && std::isfinite(norm2) && std::isfinite(p[3]))
    {
      this->MapperClipPlane->SetNormal(p[0], p[1], p[2]);
      this->MapperClipPlane->SetOrigin(
        -p[3] * p[0] / norm2, -p[3] * p[1] / norm2, -p[3] * p[2] / norm2);
    }
    else
    {
      this->MapperClipPlane->SetNormal(0.0, 0.0, 0.0); // the mapper says it is ignored
    }
    vtkPlaneCollection* planes = this->IsoMapper->GetClippingPlanes();
    if (!planes || !planes->IsItemPresent(this->MapperClipPlane))
    {
      this->IsoMapper->AddClippingPlane(this->MapperClipPlane);
    }
  }
  else if (this->IsoMapper->GetClippingPlanes() &&
    this->IsoMapper->GetClippingPlanes()->IsItemPresent(this->MapperClipPlane))
  {
    this->IsoMapper->RemoveClippingPlane(this->MapperClipPlane);
  }

  // The base class hides the volume when no colour array is chosen (volume
  // mappers need one). An isosurface needs only scalars: use the active ones,
  // in the solid colour. This runs only for a visible representation, so
  // showing the actor here never overrides the user's Visibility.
  const bool solid = !this->Actor->GetVisibility();
  if (solid)
  {
    this->IsoMapper->SetScalarModeToUsePointData();
    this->IsoMapper->SelectScalarArray(static_cast<const char*>(nullptr));
    this->Actor->SetVisibility(true);
  }
  // Said once per change of values, array or range, not per render.
  const std::string outside = this->IsovaluesOutsideRange();
  if (outside != this->LastRangeMessage)
  {
    this->LastRangeMessage = outside;
    if (!outside.empty())
    {
      vtkWarningMacro(<< outside);
    }
  }
  this->IsoMapper->SetColorSource(this->ColorEachSurface
      ? vtkHistoPyramidIsoMapper::SurfaceColors
      : (solid ? vtkHistoPyramidIsoMapper::SolidColors
               : vtkHistoPyramidIsoMapper::TransferFunctionColors));
}

//------------------------------------------------------------------------------
std::string vtkHistoPyramidIsoRepresentation::IsovaluesOutsideRange()
{
  auto* controller = vtkMultiProcessController::GetGlobalController();
  auto* input = vtkDataSet::SafeDownCast(this->IsoMapper->GetInputDataObject(0, 0));
  if ((controller && controller->GetNumberOfProcesses() > 1) || !input)
  {
    return std::string();
  }
  int cellFlag = 0;
  vtkDataArray* array = vtkDataArray::SafeDownCast(vtkAbstractMapper::GetScalars(input,
    this->IsoMapper->GetScalarMode(), this->IsoMapper->GetArrayAccessMode(),
    this->IsoMapper->GetArrayId(), this->IsoMapper->GetArrayName(), cellFlag));
  if (!array || cellFlag != 0 || array->GetNumberOfComponents() != 1 ||
    array->GetNumberOfTuples() == 0)
  {
    return std::string();
  }
  double range[2];
  array->GetRange(range, 0);
  vtkContourValues* values = this->Property->GetIsoSurfaceValues();
  return OutsideRangeMessage(
    values->GetValues(), values->GetNumberOfContours(), range, array->GetName());
}

//------------------------------------------------------------------------------
std::string vtkHistoPyramidIsoRepresentation::OutsideRangeMessage(
  const double* values, int count, const double range[2], const char* arrayName)
{
  std::ostringstream outside;
  int n = 0;
  for (int i = 0; i < count; ++i)
  {
    if (values[i] < range[0] || values[i] > range[1])
    {
      outside << (n++ ? ", " : "") << values[i];
    }
  }
  if (n == 0)
  {
    return std::string();
  }
  std::ostringstream message;
  message << "HistoPyramid Isosurface: isovalue" << (n > 1 ? "s " : " ") << outside.str()
          << (n > 1 ? " are" : " is") << " outside the range [" << range[0] << ", " << range[1]
          << "] of the array \"" << (arrayName ? arrayName : "") << "\": no surface is drawn for "
          << (n > 1 ? "them" : "it") << ".";
  return message.str();
}

//------------------------------------------------------------------------------
vtkDoubleArray* vtkHistoPyramidIsoRepresentation::GetSurfaceLooks()
{
  // The colouring as UpdateMapperParameters() sets it, from the properties
  // alone: in client/server mode the client's copy, which ParaView reads
  // information from, never renders.
  vtkInformation* array = this->GetInputArrayInformation(0);
  const char* name = array && array->Has(vtkDataObject::FIELD_NAME())
    ? array->Get(vtkDataObject::FIELD_NAME())
    : nullptr;
  this->IsoMapper->SetColorSource(this->ColorEachSurface
      ? vtkHistoPyramidIsoMapper::SurfaceColors
      : ((name && name[0]) ? vtkHistoPyramidIsoMapper::TransferFunctionColors
                           : vtkHistoPyramidIsoMapper::SolidColors));
  vtkContourValues* values = this->Property->GetIsoSurfaceValues();
  const int count = values->GetNumberOfContours();
  this->SurfaceLooks->SetNumberOfComponents(4);
  this->SurfaceLooks->SetNumberOfTuples(count);
  for (int i = 0; i < count; ++i)
  {
    double look[4];
    this->IsoMapper->GetSurfaceLook(this->Property, i, values->GetValue(i), look, look[3]);
    this->SurfaceLooks->SetTypedTuple(i, look);
  }
  return this->SurfaceLooks;
}

//------------------------------------------------------------------------------
void vtkHistoPyramidIsoRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "RenderPath: " << this->GetRenderPath() << "\n";
  os << indent << "Footprint: " << this->GetFootprint() << "\n";
  os << indent << "FallbackReason: " << this->IsoMapper->GetFallbackReason() << "\n";
  os << indent << "BrickPoolSlots: " << this->IsoMapper->GetLastBrickPoolSlots() << "\n";
  os << indent << "BrickPoolReason: " << this->IsoMapper->GetLastBrickPoolReason() << "\n";
  os << indent << "NumberOfPrimitives: " << this->IsoMapper->GetNumberOfPrimitives() << "\n";
  os << indent << "IsoMapper:\n";
  this->IsoMapper->PrintSelf(os, indent.GetNextIndent());
}
