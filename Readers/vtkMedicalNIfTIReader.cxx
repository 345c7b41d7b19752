// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMedicalNIfTIReader.h"

#include "NIfTIImage.h"
#include "ProcessMemory.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkErrorCode.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMatrix4x4.h"
#include "vtkMedicalVTKType.h"
#include "vtkNIFTIImageHeader.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"
#include "vtk_zlib.h"

#include <vtksys/SystemTools.hxx>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <new>
#include <sstream>

vtkStandardNewMacro(vtkMedicalNIfTIReader);

namespace
{
// The VTK type the superclass reads a stored datatype into (the core's table
// gives the rest).
int StoredVTKType(const mediso::NIfTIDataType& type)
{
  if (!type.Stored)
  {
    return type.Code == 1024 ? VTK_TYPE_INT64 : VTK_TYPE_UINT64;
  }
  switch (type.Type)
  {
    case mediso::ScalarType::Int8:
      return VTK_TYPE_INT8;
    case mediso::ScalarType::UInt8:
      return VTK_TYPE_UINT8;
    case mediso::ScalarType::Int16:
      return VTK_TYPE_INT16;
    case mediso::ScalarType::UInt16:
      return VTK_TYPE_UINT16;
    case mediso::ScalarType::Int32:
      return VTK_TYPE_INT32;
    case mediso::ScalarType::UInt32:
      return VTK_TYPE_UINT32;
    case mediso::ScalarType::Float32:
      return VTK_TYPE_FLOAT32;
    default:
      return VTK_TYPE_FLOAT64;
  }
}

struct GzCloser
{
  void operator()(gzFile_s* f) const { gzclose(f); }
};
using GzFile = std::unique_ptr<gzFile_s, GzCloser>;

// Reads the header of `path` (gzipped or not) and parses it with the core;
// empty string or the reason.
std::string ReadHeader(const std::string& path, mediso::NIfTIHeader& h)
{
  GzFile file(gzopen(path.c_str(), "rb"));
  if (!file)
  {
    return "the file cannot be opened";
  }
  unsigned char bytes[mediso::NIfTI2HeaderBytes] = {};
  int got = gzread(file.get(), bytes, mediso::NIfTI1HeaderBytes);
  if (got == mediso::NIfTI1HeaderBytes)
  {
    const int more = gzread(file.get(), bytes + mediso::NIfTI1HeaderBytes,
      mediso::NIfTI2HeaderBytes - mediso::NIfTI1HeaderBytes);
    if (more > 0)
    {
      got += more;
    }
  }
  return mediso::ParseNIfTIHeader(bytes, static_cast<std::size_t>(std::max(got, 0)), h);
}

// Whether `path` holds at least `needed` bytes, uncompressed; `held` is what it
// holds when not. A gzip member ends with its uncompressed size modulo 2^32
// (ISIZE); when that already covers `needed` the stream is not decompressed
// here (a stream cut short is then caught by the read itself).
bool HoldsBytes(const std::string& path, std::uint64_t needed, std::uint64_t& held, bool& gzipped)
{
  std::ifstream in(path, std::ios::binary);
  unsigned char magic[2] = { 0, 0 };
  in.read(reinterpret_cast<char*>(magic), 2);
  gzipped = in.gcount() == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
  const std::uint64_t fileBytes = vtksys::SystemTools::FileLength(path);
  if (!gzipped)
  {
    held = fileBytes;
    return fileBytes >= needed;
  }
  if (fileBytes >= 18 && needed < (std::uint64_t(1) << 32))
  {
    unsigned char trailer[4];
    in.clear();
    in.seekg(-4, std::ios::end);
    in.read(reinterpret_cast<char*>(trailer), 4);
    const std::uint64_t isize = std::uint64_t(trailer[0]) | (std::uint64_t(trailer[1]) << 8) |
      (std::uint64_t(trailer[2]) << 16) | (std::uint64_t(trailer[3]) << 24);
    if (in.gcount() == 4 && isize >= needed)
    {
      held = isize;
      return true;
    }
  }
  // Several gzip members, more than 4 GiB, or a short stream: count.
  GzFile file(gzopen(path.c_str(), "rb"));
  held = 0;
  if (!file)
  {
    return false;
  }
  std::vector<char> chunk(1 << 20);
  while (held < needed)
  {
    const int got = gzread(file.get(), chunk.data(), static_cast<unsigned>(chunk.size()));
    if (got <= 0)
    {
      break;
    }
    held += static_cast<std::uint64_t>(got);
  }
  return held >= needed;
}

const char* AxisName(int axis)
{
  static const char* const names[] = { "x", "y", "z" };
  return names[axis];
}

template<typename In, typename Out>
void Calibrate(const In* in, Out* out, vtkIdType n, double slope, double intercept)
{
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        out[i] = static_cast<Out>(static_cast<double>(in[i]) * slope + intercept);
      }
    });
}

template<typename In>
void CalibrateTo(const In* in, vtkDataArray* out, vtkIdType n, double slope, double intercept)
{
  switch (out->GetDataType())
  {
    case VTK_SHORT:
      Calibrate(in, static_cast<short*>(out->GetVoidPointer(0)), n, slope, intercept);
      break;
    case VTK_INT:
      Calibrate(in, static_cast<int*>(out->GetVoidPointer(0)), n, slope, intercept);
      break;
    case VTK_FLOAT:
      Calibrate(in, static_cast<float*>(out->GetVoidPointer(0)), n, slope, intercept);
      break;
    default:
      Calibrate(in, static_cast<double*>(out->GetVoidPointer(0)), n, slope, intercept);
  }
}

// Collects what the superclass reports as errors while it runs, so that the
// reader says one thing, in its own words.
struct ErrorCapture
{
  vtkObject* Object;
  unsigned long Tag = 0;
  std::string Text;
  vtkNew<vtkCallbackCommand> Command;

  explicit ErrorCapture(vtkObject* object)
    : Object(object)
  {
    this->Command->SetClientData(this);
    this->Command->SetCallback(
      [](vtkObject*, unsigned long, void* clientData, void* callData)
      {
        auto* self = static_cast<ErrorCapture*>(clientData);
        if (callData && self->Text.empty())
        {
          self->Text = static_cast<const char*>(callData);
        }
      });
    // Before any observer of the user's, and the last to see the event.
    this->Command->SetAbortFlagOnExecute(1);
    this->Tag = object->AddObserver(vtkCommand::ErrorEvent, this->Command, 1000.0f);
  }
  ~ErrorCapture() { this->Object->RemoveObserver(this->Tag); }
  ErrorCapture(const ErrorCapture&) = delete;
  void operator=(const ErrorCapture&) = delete;
};
} // namespace

//------------------------------------------------------------------------------
vtkMedicalNIfTIReader::vtkMedicalNIfTIReader() = default;

//------------------------------------------------------------------------------
vtkMedicalNIfTIReader::~vtkMedicalNIfTIReader() = default;

//------------------------------------------------------------------------------
std::string vtkMedicalNIfTIReader::CheckFile()
{
  // The header's file and the voxels' file, found as the superclass finds them.
  std::string headerPath, imagePath;
  if (this->FileNames && this->FileNames->GetNumberOfValues() == 2)
  {
    for (vtkIdType i = 0; i < 2; ++i)
    {
      const std::string name = this->FileNames->GetValue(i);
      (CheckExtension(name.c_str(), ".hdr") ? headerPath : imagePath) = name;
    }
    this->FileLabel = headerPath;
    if (headerPath.empty() || imagePath.empty())
    {
      return "FileNames must hold one .hdr and one .img file";
    }
  }
  else
  {
    const char* name = this->GetFileName();
    if (!name || !*name)
    {
      this->FileLabel = "(no file)";
      return "no FileName is set";
    }
    this->FileLabel = name;
    char* found = ReplaceExtension(name, ".img", ".hdr");
    headerPath = found ? found : "";
    delete[] found;
    found = ReplaceExtension(name, ".hdr", ".img");
    imagePath = found ? found : "";
    delete[] found;
    if (headerPath.empty() || imagePath.empty())
    {
      return vtksys::SystemTools::FileExists(name)
        ? "the other file of its .hdr/.img pair does not exist"
        : "the file does not exist";
    }
  }

  mediso::NIfTIHeader h;
  std::string reason = ReadHeader(headerPath, h);
  std::int64_t dims[8] = {};
  if (reason.empty())
  {
    reason = mediso::CheckNIfTIHeader(h, dims);
  }
  if (!reason.empty())
  {
    return reason;
  }
  std::ostringstream msg;
  const mediso::NIfTIDataType* type = mediso::FindNIfTIDataType(h.DataType);

  // The voxels of one volume and of all of them, in bytes, without overflow.
  const long double volumeBytes = mediso::NIfTIVolumeBytes(h, dims);
  const long double allBytes = volumeBytes * dims[4] + h.VoxOffset;
  std::uint64_t held = 0;
  bool gzipped = false;
  if (allBytes > 9.0e18L ||
    !HoldsBytes(imagePath, static_cast<std::uint64_t>(allBytes), held, gzipped))
  {
    msg << "the header describes " << dims[1] << " x " << dims[2] << " x " << dims[3];
    if (dims[4] > 1)
    {
      msg << " x " << dims[4];
    }
    msg << " " << type->Name << " voxels (";
    if (allBytes > 9.0e18L)
    {
      msg << "more than 9e18 bytes";
    }
    else
    {
      msg << static_cast<std::uint64_t>(allBytes - h.VoxOffset) << " bytes from byte "
          << static_cast<std::uint64_t>(h.VoxOffset);
    }
    msg << "), but ";
    if (imagePath == headerPath)
    {
      msg << (gzipped ? "the uncompressed gzip stream" : "the file");
    }
    else
    {
      msg << (gzipped ? "the uncompressed gzip stream of " : "") << imagePath;
    }
    msg << " holds only " << held << " bytes";
    return msg.str();
  }

  // The checks passed: what RequestInformation and RequestData need.
  this->StoredScalarType = StoredVTKType(*type);
  this->DataOffset = static_cast<unsigned long>(h.VoxOffset);
  this->VolumeBytes = static_cast<unsigned long>(volumeBytes);
  std::vector<std::string> warnings;
  this->Calibrate = mediso::NIfTICalibration(h, this->Slope, this->Intercept, warnings);
  for (const std::string& warning : warnings)
  {
    vtkWarningMacro(<< this->FileLabel << ": " << warning);
  }
  this->OutputScalarType = this->Calibrate
    ? vtkMedicalVTKType(mediso::NIfTICalibratedType(h.DataType, this->Slope, this->Intercept))
    : this->StoredScalarType;

  this->TimeSteps.clear();
  if (dims[4] > 1 && !this->TimeAsVector)
  {
    const double step = h.PixDim[4] > 0.0 && std::isfinite(h.PixDim[4]) ? h.PixDim[4] : 1.0;
    const double start = std::isfinite(h.TOffset) && step == h.PixDim[4] ? h.TOffset : 0.0;
    for (std::int64_t t = 0; t < dims[4]; ++t)
    {
      this->TimeSteps.push_back(start + step * static_cast<double>(t));
    }
  }
  return std::string();
}

//------------------------------------------------------------------------------
int vtkMedicalNIfTIReader::RequestInformation(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  this->Readable = false;
  this->OutputScalarType = 0;
  this->TimeSteps.clear();
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  const int emptyExtent[6] = { 0, -1, 0, -1, 0, -1 };

  const std::string reason = this->CheckFile();
  if (!reason.empty())
  {
    vtkErrorMacro("Cannot read " << this->FileLabel << ": " << reason << ". The output is empty.");
    this->OutputScalarType = 0;
    outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), emptyExtent, 6);
    return 1;
  }
  if (!this->Superclass::RequestInformation(request, inputVector, outputVector))
  {
    // Its one error is said; nothing is read.
    this->OutputScalarType = 0;
    outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), emptyExtent, 6);
    return 1;
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
  // A spacing of 0 the superclass reads as 1; a negative one becomes its
  // magnitude along the reversed axis, so index times spacing along the
  // direction lands where it did.
  outInfo->Get(vtkDataObject::SPACING(), this->Spacing);
  for (int a = 0; a < 3; ++a)
  {
    const double stored = header ? header->GetPixDim(a + 1) : 1.0;
    if (stored == 0.0)
    {
      vtkWarningMacro(<< this->FileLabel << ": pixdim[" << a + 1 << "] (the spacing along "
                      << AxisName(a) << ") is 0; a spacing of " << this->Spacing[a] << " is used.");
    }
    else if (this->Spacing[a] < 0.0)
    {
      this->Spacing[a] = -this->Spacing[a];
      for (int r = 0; r < 3; ++r)
      {
        this->Direction[3 * r + a] = -this->Direction[3 * r + a];
      }
      vtkWarningMacro(<< this->FileLabel << ": pixdim[" << a + 1 << "] (the spacing along "
                      << AxisName(a) << ") is " << stored << "; a spacing of " << this->Spacing[a]
                      << " is used, along the reversed axis.");
    }
  }
  outInfo->Set(vtkDataObject::SPACING(), this->Spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), this->Origin, 3);
  outInfo->Set(vtkDataObject::DIRECTION(), this->Direction, 9);
  vtkDataObject::SetPointDataActiveScalarInfo(
    outInfo, this->OutputScalarType, this->GetNumberOfScalarComponents());
  if (!this->TimeSteps.empty())
  {
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), this->TimeSteps.data(),
      static_cast<int>(this->TimeSteps.size()));
    const double range[2] = { this->TimeSteps.front(), this->TimeSteps.back() };
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  }
  this->Readable = true;
  return 1;
}

//------------------------------------------------------------------------------
bool vtkMedicalNIfTIReader::ReadVolume(vtkInformation* request, vtkInformationVector** inputVector,
  vtkInformationVector* outputVector, std::string& reason)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  int extent[6];
  outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), extent);
  const std::uint64_t voxels = static_cast<std::uint64_t>(extent[1] - extent[0] + 1) *
    static_cast<std::uint64_t>(extent[3] - extent[2] + 1) *
    static_cast<std::uint64_t>(extent[5] - extent[4] + 1) *
    static_cast<std::uint64_t>(this->GetNumberOfScalarComponents());
  const int storedSize = vtkDataArray::GetDataTypeSize(this->StoredScalarType);
  const int outputSize = vtkDataArray::GetDataTypeSize(this->OutputScalarType);
  const std::uint64_t bytes = voxels * storedSize + (this->Calibrate ? voxels * outputSize : 0);
  if (!mediso::FitsInProcessMemory(
        bytes, this->Calibrate ? "the volume as stored and calibrated" : "the volume", reason))
  {
    return false;
  }

  // The time step asked for: the last one at or before the requested time.
  std::size_t step = 0;
  if (!this->TimeSteps.empty() &&
    outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    const double time = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
    while (step + 1 < this->TimeSteps.size() && this->TimeSteps[step + 1] <= time)
    {
      ++step;
    }
  }

  // The superclass allocates the type the pipeline information holds and
  // reads from HeaderSize on: the stored type, from the chosen volume. The
  // members are set directly, as Modified() here would re-execute the reader.
  vtkDataObject::SetPointDataActiveScalarInfo(
    outInfo, this->StoredScalarType, this->GetNumberOfScalarComponents());
  this->HeaderSize = this->DataOffset + this->VolumeBytes * step;
  int ok = 0;
  std::string superclassError;
  {
    ErrorCapture capture(this);
    ok = this->Superclass::RequestData(request, inputVector, outputVector);
    superclassError = capture.Text;
  }
  this->HeaderSize = this->DataOffset;
  vtkDataObject::SetPointDataActiveScalarInfo(
    outInfo, this->OutputScalarType, this->GetNumberOfScalarComponents());
  if (!ok)
  {
    if (this->GetErrorCode() == vtkErrorCode::PrematureEndOfFileError)
    {
      reason = "the file ends before the voxels the header describes do (it is "
               "truncated)";
    }
    else
    {
      const std::size_t colon = superclassError.rfind("): ");
      reason = "the voxels cannot be read (" +
        (colon == std::string::npos ? superclassError : superclassError.substr(colon + 3));
      while (!reason.empty() && (reason.back() == '\n' || reason.back() == '.'))
      {
        reason.pop_back();
      }
      reason += ")";
    }
    return false;
  }

  vtkImageData* image = vtkImageData::GetData(outInfo);
  vtkDataArray* stored = image->GetPointData()->GetScalars();
  if (this->Calibrate && stored)
  {
    vtkSmartPointer<vtkDataArray> calibrated =
      vtk::TakeSmartPointer(vtkDataArray::CreateDataArray(this->OutputScalarType));
    calibrated->SetName(stored->GetName());
    calibrated->SetNumberOfComponents(stored->GetNumberOfComponents());
    calibrated->SetNumberOfTuples(stored->GetNumberOfTuples());
    const vtkIdType n = stored->GetNumberOfValues();
    switch (stored->GetDataType())
    {
      vtkTemplateMacro(CalibrateTo(static_cast<const VTK_TT*>(stored->GetVoidPointer(0)),
        calibrated, n, this->Slope, this->Intercept));
    }
    image->GetPointData()->SetScalars(calibrated);
  }
  image->SetSpacing(this->Spacing);
  image->SetOrigin(this->Origin);
  image->SetDirectionMatrix(this->Direction);
  if (!this->TimeSteps.empty())
  {
    image->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), this->TimeSteps[step]);
  }
  return true;
}

//------------------------------------------------------------------------------
int vtkMedicalNIfTIReader::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* image = vtkImageData::GetData(outputVector, 0);
  if (!image)
  {
    return 0;
  }
  if (!this->Readable)
  {
    // The reason was said in RequestInformation.
    image->Initialize();
    return 1;
  }
  std::string reason;
  bool ok = false;
  try
  {
    ok = this->ReadVolume(request, inputVector, outputVector, reason);
  }
  catch (const std::bad_alloc&)
  {
    reason = "memory ran out while reading the voxels";
  }
  if (!ok)
  {
    image->Initialize();
    vtkErrorMacro("Cannot read " << this->FileLabel << ": " << reason << ". The output is empty.");
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkMedicalNIfTIReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Placement: " << this->Placement << "\n";
  os << indent << "OutputScalarType: " << this->OutputScalarType << "\n";
  os << indent << "TimeSteps: " << this->TimeSteps.size() << "\n";
}
