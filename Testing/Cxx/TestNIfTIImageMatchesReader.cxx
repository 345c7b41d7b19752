// SPDX-License-Identifier: BSD-3-Clause
// The readers' VTK-free NIfTI core (Readers/Core/NIfTIImage.h: what the web page's WebAssembly
// module reads a dropped file with) against vtkMedicalNIfTIReader (ParaView and the server) on
// files this test writes: the same dimensions, spacing, origin, direction, scalar type and
// values (to the byte) for files placed by no matrix, an sform (turned, and mirrored without a
// qform: slices reversed), a qform (turned 45 degrees, qfac -1: slices reversed), both, a
// negative pixdim, scaled values (int16 and float results), big-endian NIfTI-2; and every bad
// header (truncated, sizeof_hdr wrong, dim[0] 0, a dimension 0, negative or past an int, an
// unknown or unsupported datatype, bitpix wrong, vox_offset inside the header, voxels missing)
// refused by both with the same message, the core's allocating nothing.
#include "MedicalTestUtilities.h"
#include "NIfTIImage.h"
#include "NIfTITestFiles.h"
#include "vtkMedicalCoreScalarType.h"
#include "vtkMedicalNIfTIReader.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkPointData.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;
using medical_test::PutBytes;

// A case: the header's fields (NIfTITestFiles.h), here of a 5x4x3 volume, and, > 0, the length
// the file is cut to.
struct Fields : medical_test::NIfTIFields
{
  Fields()
  {
    this->Dim[1] = 5;
    this->Dim[2] = 4;
    this->Dim[3] = 3;
  }
  std::size_t KeepBytes = 0;
};

// The header of `f`, then its voxels where they are few enough to write.
std::vector<unsigned char> File(const Fields& f)
{
  std::vector<unsigned char> b = medical_test::NIfTIHeader(f);
  const bool s = f.BigEndian;
  const double voxOffset = f.VoxOffset < 0 ? static_cast<double>(b.size()) : f.VoxOffset;
  // Voxels: 0, 37, 74, ... (mod 251 for one byte, 3000 else), in the file's byte order.
  long double voxels = 1;
  for (int i = 1; i <= 3; ++i)
  {
    voxels *= static_cast<long double>(std::max<std::int64_t>(f.Dim[i], 0));
  }
  const std::size_t bytes = static_cast<std::size_t>(std::max(f.BitPix, 8) / 8);
  if (voxels < (1u << 20))
  {
    const std::size_t n = static_cast<std::size_t>(voxels);
    std::vector<unsigned char> v(n * bytes, 0);
    for (std::size_t i = 0; i < n; ++i)
    {
      if (bytes == 1)
      {
        v[i] = static_cast<unsigned char>((37 * i) % 251);
      }
      else if (f.DataType == 16)
      {
        PutBytes<float>(v, 4 * i, static_cast<float>((37 * i) % 3000) * 0.25f, s);
      }
      else if (bytes == 2)
      {
        PutBytes<std::int16_t>(v, 2 * i, static_cast<std::int16_t>((37 * i) % 3000), s);
      }
    }
    b.resize(std::max(b.size(), static_cast<std::size_t>(voxOffset)), 0);
    b.insert(b.end(), v.begin(), v.end());
  }
  if (f.KeepBytes)
  {
    b.resize(f.KeepBytes);
  }
  return b;
}

struct Messages
{
  std::vector<std::string> Errors;
  std::vector<std::string> Warnings;
};

// A reader with its errors and warnings kept (the text after the object's name).
vtkSmartPointer<vtkMedicalNIfTIReader> Read(const std::string& path, Messages& messages)
{
  auto reader = vtkSmartPointer<vtkMedicalNIfTIReader>::New();
  vtkNew<vtkCallbackCommand> command;
  command->SetClientData(&messages);
  command->SetCallback(
    [](vtkObject*, unsigned long event, void* clientData, void* callData)
    {
      auto* m = static_cast<Messages*>(clientData);
      std::string text = callData ? static_cast<const char*>(callData) : "";
      const std::size_t at = text.find("): ");
      text = at == std::string::npos ? text : text.substr(at + 3);
      while (!text.empty() && (text.back() == '\n' || text.back() == ' '))
      {
        text.pop_back();
      }
      (event == vtkCommand::ErrorEvent ? m->Errors : m->Warnings).push_back(text);
    });
  reader->AddObserver(vtkCommand::ErrorEvent, command);
  reader->AddObserver(vtkCommand::WarningEvent, command);
  reader->SetFileName(path.c_str());
  reader->Update();
  return reader;
}

void Write(const std::string& path, const std::vector<unsigned char>& bytes)
{
  std::ofstream out(path, std::ios::binary);
  out.write(
    reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

bool Near(double a, double b)
{
  return std::fabs(a - b) <= 1e-5 * std::max(1.0, std::fabs(b));
}

void Same(const std::string& folder, const std::string& name, const Fields& f)
{
  const std::string path = folder + "/" + name + ".nii";
  const std::vector<unsigned char> bytes = File(f);
  Write(path, bytes);
  mediso::NIfTIImage core;
  std::string error;
  const bool ok = mediso::ReadNIfTI(bytes.data(), bytes.size(), core, error);
  Check(ok, name + ": the core reads it (" + error + ")");
  Messages messages;
  auto reader = Read(path, messages);
  vtkImageData* image = reader->GetOutput();
  Check(messages.Errors.empty(), name + ": the reader reads it");
  if (!ok || !messages.Errors.empty())
  {
    return;
  }
  int dims[3];
  image->GetDimensions(dims);
  const double* spacing = image->GetSpacing();
  const double* origin = image->GetOrigin();
  const double* direction = image->GetDirectionMatrix()->GetData();
  for (int a = 0; a < 3; ++a)
  {
    Check(dims[a] == core.Dimensions[a], name + ": dimension " + std::to_string(a));
    Check(Near(core.Placement.Spacing[a], spacing[a]),
      name + ": spacing " + std::to_string(a) + " " + std::to_string(core.Placement.Spacing[a]) +
        " vs " + std::to_string(spacing[a]));
    Check(Near(core.Placement.Origin[a], origin[a]),
      name + ": origin " + std::to_string(a) + " " + std::to_string(core.Placement.Origin[a]) +
        " vs " + std::to_string(origin[a]));
  }
  for (int i = 0; i < 9; ++i)
  {
    Check(Near(core.Placement.Direction[i], direction[i]),
      name + ": direction[" + std::to_string(i) + "] " +
        std::to_string(core.Placement.Direction[i]) + " vs " + std::to_string(direction[i]));
  }
  Check(std::string(core.Placement.Placement) == reader->GetPlacement(),
    name + ": placed by " + core.Placement.Placement + " vs " + reader->GetPlacement());
  vtkDataArray* scalars = image->GetPointData()->GetScalars();
  mediso::ScalarType type = mediso::ScalarType::UInt8;
  const bool known = scalars && vtkMedicalCoreScalarType(scalars->GetDataType(), type);
  Check(known && type == core.Type, name + ": the scalar type");
  if (known && type == core.Type)
  {
    const std::size_t n = core.Bytes.size();
    Check(
      static_cast<std::size_t>(scalars->GetNumberOfValues() * scalars->GetDataTypeSize()) == n &&
        std::memcmp(scalars->GetVoidPointer(0), core.Bytes.data(), n) == 0,
      name + ": the values, byte for byte");
  }
  Check(messages.Warnings.size() == core.Warnings.size(), name + ": as many warnings");
}

void Refused(const std::string& folder, const std::string& name, const Fields& f)
{
  const std::string path = folder + "/" + name + ".nii";
  const std::vector<unsigned char> bytes = File(f);
  Write(path, bytes);
  mediso::NIfTIImage core;
  std::string error;
  const bool ok = mediso::ReadNIfTI(bytes.data(), bytes.size(), core, error);
  Check(!ok && !error.empty() && core.Bytes.empty(), name + ": the core refuses it");
  Messages messages;
  auto reader = Read(path, messages);
  const std::string expected = "Cannot read " + path + ": " + error + ". The output is empty.";
  Check(messages.Errors.size() == 1 && messages.Errors[0] == expected,
    name + ": the reader says \"" + (messages.Errors.empty() ? "" : messages.Errors[0]) +
      "\", the core \"" + error + "\"");
  std::printf("%s: %s\n", name.c_str(), error.c_str());
}
} // namespace

int TestNIfTIImageMatchesReader(int argc, char* argv[])
{
  const std::string folder = argc > 1 ? argv[1] : ".";

  Same(folder, "none", Fields());
  Fields sform;
  sform.SFormCode = 1; // x = -0.75 j, y = 0.5 i, z = 2 k (+ translation): turned about z
  const double turned[3][4] = { { 0, -0.75, 0, 10 }, { 0.5, 0, 0, -20 }, { 0, 0, 2, 30 } };
  std::memcpy(sform.SRow, turned, sizeof(turned));
  Same(folder, "sform", sform);
  Fields mirrored;
  mirrored.SFormCode = 2; // x flipped: a negative determinant
  const double flip[3][4] = { { -0.5, 0, 0, 5 }, { 0, 0.75, 0, 6 }, { 0, 0, 2, 7 } };
  std::memcpy(mirrored.SRow, flip, sizeof(flip));
  Same(folder, "sform-mirrored", mirrored);
  Fields qform;
  qform.QFormCode = 1; // 45 degrees about z, qfac -1
  qform.Quatern[2] = std::sin(M_PI / 8);
  qform.PixDim[0] = -1.0;
  qform.QOffset[0] = 3;
  qform.QOffset[1] = -4;
  qform.QOffset[2] = 5;
  Same(folder, "qform-qfac", qform);
  Fields both = qform;
  both.SFormCode = 1;
  std::memcpy(both.SRow, turned, sizeof(turned));
  Same(folder, "qform-and-sform", both);
  Fields negative;
  negative.PixDim[2] = -0.75;
  Same(folder, "negative-pixdim", negative);
  Fields scaledCT;
  scaledCT.DataType = 2;
  scaledCT.BitPix = 8;
  scaledCT.Slope = 1.0;
  scaledCT.Intercept = -100.0;
  Same(folder, "scaled-int16", scaledCT);
  Fields scaledFloat;
  scaledFloat.Slope = 0.5;
  scaledFloat.Intercept = 3.0;
  Same(folder, "scaled-float", scaledFloat);
  Fields big;
  big.Version = 2;
  big.BigEndian = true;
  big.SFormCode = 1;
  std::memcpy(big.SRow, turned, sizeof(turned));
  Same(folder, "nifti2-big-endian", big);
  Fields floats;
  floats.DataType = 16;
  floats.BitPix = 32;
  Same(folder, "float32", floats);

  Fields truncatedHeader;
  truncatedHeader.KeepBytes = 100;
  Refused(folder, "truncated-header", truncatedHeader);
  Fields sizeOfHeader;
  sizeOfHeader.SizeOfHeader = 123;
  Refused(folder, "sizeof_hdr", sizeOfHeader);
  Fields noDims;
  noDims.Dim[0] = 0;
  Refused(folder, "dim0", noDims);
  Fields zero;
  zero.Dim[2] = 0;
  Refused(folder, "dimension-0", zero);
  Fields minus;
  minus.Dim[1] = -3;
  Refused(folder, "dimension-negative", minus);
  Fields huge;
  huge.Version = 2;
  huge.Dim[3] = std::int64_t(1) << 40;
  Refused(folder, "dimension-overflow", huge);
  // More voxels than 9e18 bytes (the reader says so without reading the file's length).
  Fields manyVoxels;
  manyVoxels.Version = 2;
  manyVoxels.Dim[1] = manyVoxels.Dim[2] = manyVoxels.Dim[3] = 2000000000;
  const std::vector<unsigned char> many = File(manyVoxels);
  mediso::NIfTIImage core;
  std::string error;
  Check(!mediso::ReadNIfTI(many.data(), many.size(), core, error) &&
      error.find("more than 9e18 bytes") != std::string::npos && core.Bytes.empty(),
    "voxels-overflow: the core refuses it (" + error + ")");
  Fields unknown;
  unknown.DataType = 3;
  Refused(folder, "datatype-unknown", unknown);
  Fields rgb;
  rgb.DataType = 128;
  rgb.BitPix = 24;
  Refused(folder, "datatype-rgb", rgb);
  Fields bitpix;
  bitpix.BitPix = 8;
  Refused(folder, "bitpix", bitpix);
  Fields offset;
  offset.VoxOffset = 10;
  Refused(folder, "vox_offset", offset);
  Fields cut;
  cut.KeepBytes = 352 + 50;
  Refused(folder, "voxels-missing", cut);
  return medical_test::Finish("the NIfTI core and vtkMedicalNIfTIReader agree");
}
