// SPDX-License-Identifier: BSD-3-Clause
// vtkMedicalNIfTIReader on a corpus of NIfTI files this test writes itself
// (one case per ctest test; the case is the first argument, the folder to
// write in the second): scaled integers read as calibrated values, 4D files
// as time steps, odd spacings said in one warning, and every malformed file
// (zero or negative dimensions, unknown or unsupported datatypes, a header
// far larger than its file, truncation, a bad vox_offset...) refused with one
// exact error and an empty output, never a crash or a partly filled volume.
// The test observes the reader's errors and warnings itself, so nothing
// reaches the output window (and ctest's fail pattern) unless unexpected.
#include "AddressSpaceLimit.h"
#include "MedicalTestUtilities.h"
#include "NIfTITestFiles.h"
#include "vtkMedicalNIfTIReader.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtk_zlib.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;

// --- Writing NIfTI files ------------------------------------------------------

// The header fields the corpus varies (NIfTITestFiles.h), the header and its 4 extension bytes.
using Fields = medical_test::NIfTIFields;
using medical_test::NIfTIHeader;
using medical_test::PutBytes;

// int16 voxels 0, 37, 74, ... (mod 3000), in the file's byte order.
std::vector<unsigned char> Int16Voxels(std::size_t count, bool bigEndian, int first = 0)
{
  std::vector<unsigned char> bytes(2 * count);
  for (std::size_t i = 0; i < count; ++i)
  {
    PutBytes<std::int16_t>(
      bytes, 2 * i, static_cast<std::int16_t>((first + 37 * i) % 3000), bigEndian);
  }
  return bytes;
}

std::size_t Voxels(const Fields& f)
{
  std::size_t n = 1;
  for (int i = 1; i <= f.Dim[0] && i <= 4; ++i)
  {
    n *= static_cast<std::size_t>(std::max<std::int64_t>(f.Dim[i], 0));
  }
  return n;
}

void Append(std::vector<unsigned char>& to, const std::vector<unsigned char>& more)
{
  to.insert(to.end(), more.begin(), more.end());
}

void WritePlain(const std::string& path, const std::vector<unsigned char>& bytes)
{
  std::ofstream out(path, std::ios::binary);
  out.write(
    reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

void WriteGzip(const std::string& path, const std::vector<unsigned char>& bytes)
{
  gzFile out = gzopen(path.c_str(), "wb");
  gzwrite(out, bytes.data(), static_cast<unsigned>(bytes.size()));
  gzclose(out);
}

// A well-formed int16 file of `f` with the corpus's voxels.
std::vector<unsigned char> Int16File(const Fields& f)
{
  std::vector<unsigned char> bytes = NIfTIHeader(f);
  Append(bytes, Int16Voxels(Voxels(f), f.BigEndian));
  return bytes;
}

// --- Reading them back --------------------------------------------------------

// The reader's errors and warnings, each as the text after the object's name.
struct Messages
{
  std::vector<std::string> Errors;
  std::vector<std::string> Warnings;
};

std::string Trimmed(const std::string& text)
{
  // "ERROR: In file, line N\nvtkMedicalNIfTIReader (0x...): message\n\n"
  const std::size_t at = text.find("): ");
  std::string message = at == std::string::npos ? text : text.substr(at + 3);
  while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
  {
    message.pop_back();
  }
  return message;
}

void Observe(vtkObject* object, Messages& messages)
{
  vtkNew<vtkCallbackCommand> command;
  command->SetClientData(&messages);
  command->SetCallback(
    [](vtkObject*, unsigned long event, void* clientData, void* callData)
    {
      auto* m = static_cast<Messages*>(clientData);
      const std::string text = Trimmed(callData ? static_cast<const char*>(callData) : "");
      (event == vtkCommand::ErrorEvent ? m->Errors : m->Warnings).push_back(text);
    });
  object->AddObserver(vtkCommand::ErrorEvent, command);
  object->AddObserver(vtkCommand::WarningEvent, command);
}

// Reads `path`; the messages said while reading go to `messages`.
vtkSmartPointer<vtkMedicalNIfTIReader> Read(const std::string& path, Messages& messages)
{
  auto reader = vtkSmartPointer<vtkMedicalNIfTIReader>::New();
  Observe(reader, messages);
  reader->SetFileName(path.c_str());
  reader->Update();
  return reader;
}

std::string Joined(const std::vector<std::string>& texts)
{
  std::string all;
  for (const std::string& t : texts)
  {
    all += "\n    " + t;
  }
  return all.empty() ? " (none)" : all;
}

// The file is refused with exactly `reason` and the output is empty.
void ExpectRefused(const std::string& path, const std::string& reason)
{
  Messages messages;
  auto reader = Read(path, messages);
  const std::string expected = "Cannot read " + path + ": " + reason + ". The output is empty.";
  Check(messages.Errors.size() == 1 && messages.Errors[0] == expected,
    "one error: \"" + expected + "\"; got:" + Joined(messages.Errors));
  Check(messages.Warnings.empty(), "no warning; got:" + Joined(messages.Warnings));
  vtkImageData* out = reader->GetOutput();
  Check(out->GetNumberOfPoints() == 0 && out->GetPointData()->GetScalars() == nullptr,
    "the output is empty (" + std::to_string(out->GetNumberOfPoints()) + " points)");
}

// The file reads with no message, as `type`, with values f(i) at every voxel.
void ExpectValues(
  const std::string& path, int type, const std::function<double(vtkIdType)>& f, const int dims[3])
{
  Messages messages;
  auto reader = Read(path, messages);
  Check(messages.Errors.empty() && messages.Warnings.empty(),
    "no message; got:" + Joined(messages.Errors) + Joined(messages.Warnings));
  vtkImageData* out = reader->GetOutput();
  int got[3];
  out->GetDimensions(got);
  Check(std::equal(dims, dims + 3, got),
    "dimensions " + std::to_string(got[0]) + "x" + std::to_string(got[1]) + "x" +
      std::to_string(got[2]));
  vtkDataArray* scalars = out->GetPointData()->GetScalars();
  if (!scalars)
  {
    Check(false, "the output has scalars");
    return;
  }
  Check(scalars->GetDataType() == type && reader->GetOutputScalarType() == type,
    std::string("the scalars are ") + vtkImageScalarTypeNameMacro(type) + ", got " +
      scalars->GetDataTypeAsString());
  Check(std::string(scalars->GetName() ? scalars->GetName() : "") == "NIFTI",
    "the array is named NIFTI");
  vtkIdType wrong = 0;
  for (vtkIdType i = 0; i < scalars->GetNumberOfTuples(); ++i)
  {
    if (scalars->GetComponent(i, 0) != f(i))
    {
      if (wrong++ == 0)
      {
        std::printf("first wrong voxel %lld: %g, expected %g\n", static_cast<long long>(i),
          scalars->GetComponent(i, 0), f(i));
      }
    }
  }
  Check(wrong == 0, std::to_string(wrong) + " voxel(s) differ from the true values");
}

double Stored(vtkIdType i)
{
  return static_cast<double>((37 * i) % 3000);
}

int Dims[3] = { 4, 3, 2 };

// --- The cases ----------------------------------------------------------------

std::map<std::string, std::function<void(const std::string&)>> Cases()
{
  std::map<std::string, std::function<void(const std::string&)>> cases;

  // A CT as NIfTI stores it: int16 with slope 1 and intercept -1024 reads as
  // exact Hounsfield units; int16 shifted by -1024 needs 32 bits.
  cases["ScaledCT"] = [](const std::string& dir)
  {
    Fields f;
    f.Slope = 1.0;
    f.Intercept = -1024.0;
    WritePlain(dir + "/ct.nii", Int16File(f));
    ExpectValues(
      dir + "/ct.nii", VTK_INT, [](vtkIdType i) { return Stored(i) - 1024.0; }, Dims);
    WriteGzip(dir + "/ct.nii.gz", Int16File(f));
    ExpectValues(
      dir + "/ct.nii.gz", VTK_INT, [](vtkIdType i) { return Stored(i) - 1024.0; }, Dims);
    // The same, big-endian.
    f.BigEndian = true;
    WritePlain(dir + "/ct-big-endian.nii", Int16File(f));
    ExpectValues(
      dir + "/ct-big-endian.nii", VTK_INT, [](vtkIdType i) { return Stored(i) - 1024.0; }, Dims);
    // NIfTI-2.
    f.BigEndian = false;
    f.Version = 2;
    WritePlain(dir + "/ct-nifti2.nii", Int16File(f));
    ExpectValues(
      dir + "/ct-nifti2.nii", VTK_INT, [](vtkIdType i) { return Stored(i) - 1024.0; }, Dims);
  };

  // A slope other than 1: float values.
  cases["ScaledHalf"] = [](const std::string& dir)
  {
    Fields f;
    f.Slope = 0.5;
    f.Intercept = 10.0;
    WritePlain(dir + "/half.nii", Int16File(f));
    ExpectValues(
      dir + "/half.nii", VTK_FLOAT, [](vtkIdType i) { return Stored(i) * 0.5 + 10.0; }, Dims);
  };

  // uint8 with an integral intercept fits int16; no scale leaves the stored type.
  cases["ScaledNarrow"] = [](const std::string& dir)
  {
    Fields f;
    f.DataType = 2; // UINT8
    f.BitPix = 8;
    f.Slope = 1.0;
    f.Intercept = -100.0;
    std::vector<unsigned char> bytes = NIfTIHeader(f);
    for (std::size_t i = 0; i < Voxels(f); ++i)
    {
      bytes.push_back(static_cast<unsigned char>((7 * i) % 256));
    }
    WritePlain(dir + "/shifted-uint8.nii", bytes);
    ExpectValues(
      dir + "/shifted-uint8.nii", VTK_SHORT,
      [](vtkIdType i) { return static_cast<double>((7 * i) % 256) - 100.0; }, Dims);
    f.Slope = 0.0; // no scale
    bytes = NIfTIHeader(f);
    for (std::size_t i = 0; i < Voxels(f); ++i)
    {
      bytes.push_back(static_cast<unsigned char>((7 * i) % 256));
    }
    WritePlain(dir + "/plain-uint8.nii", bytes);
    ExpectValues(
      dir + "/plain-uint8.nii", VTK_UNSIGNED_CHAR,
      [](vtkIdType i) { return static_cast<double>((7 * i) % 256); }, Dims);
  };

  // 4 volumes in time, 2 s apart from 10 s: time steps, each read on request.
  cases["FourD"] = [](const std::string& dir)
  {
    Fields f;
    f.Dim[0] = 4;
    f.Dim[4] = 4;
    f.PixDim[4] = 2.0;
    f.TOffset = 10.0;
    const std::size_t volume = Voxels(f) / 4;
    std::vector<unsigned char> bytes = NIfTIHeader(f);
    for (int t = 0; t < 4; ++t)
    {
      Append(bytes, Int16Voxels(volume, false, 1000 * t));
    }
    const std::string path = dir + "/4d.nii";
    WritePlain(path, bytes);
    Messages messages;
    vtkNew<vtkMedicalNIfTIReader> reader;
    Observe(reader, messages);
    reader->SetFileName(path.c_str());
    reader->UpdateInformation();
    vtkInformation* info = reader->GetOutputInformation(0);
    const int n = info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
    const double* steps = info->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
    Check(n == 4 && steps[0] == 10.0 && steps[1] == 12.0 && steps[2] == 14.0 && steps[3] == 16.0,
      "time steps 10, 12, 14, 16 (" + std::to_string(n) + " steps)");
    for (int t : { 2, 0, 3 })
    {
      reader->UpdateTimeStep(10.0 + 2.0 * t + 0.5);
      vtkDataArray* scalars = reader->GetOutput()->GetPointData()->GetScalars();
      vtkIdType wrong = scalars ? 0 : 1;
      for (vtkIdType i = 0; scalars && i < scalars->GetNumberOfTuples(); ++i)
      {
        wrong += scalars->GetComponent(i, 0) != static_cast<double>((1000 * t + 37 * i) % 3000);
      }
      Check(wrong == 0 && scalars->GetNumberOfTuples() == 24,
        "time " + std::to_string(10.0 + 2.0 * t + 0.5) + " reads volume " + std::to_string(t));
      Check(reader->GetOutput()->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP()) ==
          10.0 + 2.0 * t,
        "the output's time is the volume's");
    }
    Check(messages.Errors.empty() && messages.Warnings.empty(),
      "no message; got:" + Joined(messages.Errors) + Joined(messages.Warnings));
  };

  // A spacing of 0 is read as 1, a negative one as its magnitude along the
  // reversed axis; each said once.
  cases["PixDim"] = [](const std::string& dir)
  {
    Fields f;
    f.PixDim[2] = 0.0;
    f.PixDim[3] = -2.0;
    const std::string path = dir + "/pixdim.nii";
    WritePlain(path, Int16File(f));
    Messages messages;
    auto reader = Read(path, messages);
    const std::vector<std::string> expected = {
      path + ": pixdim[2] (the spacing along y) is 0; a spacing of 1 is used.",
      path +
        ": pixdim[3] (the spacing along z) is -2; a spacing of 2 is used, along the reversed axis."
    };
    Check(messages.Errors.empty(), "no error; got:" + Joined(messages.Errors));
    Check(messages.Warnings == expected,
      "the two warnings:" + Joined(expected) + "\n  got:" + Joined(messages.Warnings));
    vtkImageData* out = reader->GetOutput();
    const double* spacing = out->GetSpacing();
    Check(spacing[0] == 0.5 && spacing[1] == 1.0 && spacing[2] == 2.0, "spacing 0.5, 1, 2");
    const double* d = out->GetDirectionMatrix()->GetData();
    Check(d[0] == 1 && d[4] == 1 && d[8] == -1, "the z axis reversed");
    vtkDataArray* scalars = out->GetPointData()->GetScalars();
    Check(
      scalars && scalars->GetDataType() == VTK_SHORT && scalars->GetComponent(5, 0) == Stored(5),
      "the stored int16 values");
  };

  // A .hdr/.img pair ("ni1", voxels from byte 0 of the .img), opened by
  // either name; a short .img is refused naming its own size.
  cases["Pair"] = [](const std::string& dir)
  {
    Fields f;
    f.Slope = 1.0;
    f.Intercept = -1024.0;
    f.VoxOffset = 0.0;
    std::vector<unsigned char> header = NIfTIHeader(f);
    header.resize(348);
    std::memcpy(header.data() + 344, "ni1", 4);
    WritePlain(dir + "/ct.hdr", header);
    WritePlain(dir + "/ct.img", Int16Voxels(Voxels(f), false));
    for (const char* name : { "/ct.hdr", "/ct.img" })
    {
      ExpectValues(
        dir + name, VTK_INT, [](vtkIdType i) { return Stored(i) - 1024.0; }, Dims);
    }
    std::vector<unsigned char> half = Int16Voxels(Voxels(f) / 2, false);
    WritePlain(dir + "/ct.img", half);
    ExpectRefused(dir + "/ct.hdr",
      "the header describes 4 x 3 x 2 INT16 voxels (48 bytes from byte 0), but " + dir +
        "/ct.img holds only 24 bytes");
  };

  // A non-finite scale is no scale (as other readers take it), said once; a
  // non-finite spacing is refused.
  cases["NonFinite"] = [](const std::string& dir)
  {
    Fields f;
    f.Slope = std::nan("");
    const std::string path = dir + "/nan-slope.nii";
    WritePlain(path, Int16File(f));
    Messages messages;
    auto reader = Read(path, messages);
    const std::string expected = path + ": scl_slope is nan; the voxels are read unscaled.";
    Check(
      messages.Errors.empty() && messages.Warnings.size() == 1 && messages.Warnings[0] == expected,
      "one warning: \"" + expected + "\"; got:" + Joined(messages.Errors) +
        Joined(messages.Warnings));
    vtkDataArray* scalars = reader->GetOutput()->GetPointData()->GetScalars();
    Check(
      scalars && scalars->GetDataType() == VTK_SHORT && scalars->GetComponent(7, 0) == Stored(7),
      "the stored int16 values");
    f.Slope = 1.0;
    f.PixDim[1] = std::nan("");
    WritePlain(dir + "/nan-pixdim.nii", Int16File(f));
    ExpectRefused(dir + "/nan-pixdim.nii", "pixdim[1] (the spacing along x) is nan");
  };

  // --- Refused files --------------------------------------------------------
  cases["ZeroDimension"] = [](const std::string& dir)
  {
    Fields f;
    f.Dim[2] = 0;
    WritePlain(dir + "/zero.nii", Int16File(f));
    ExpectRefused(dir + "/zero.nii", "dim[2] is 0; every dimension must be at least 1");
    f.Dim[2] = 3;
    f.Dim[3] = -5;
    WritePlain(dir + "/negative.nii", NIfTIHeader(f));
    ExpectRefused(dir + "/negative.nii", "dim[3] is -5; every dimension must be at least 1");
  };
  cases["DimensionCount"] = [](const std::string& dir)
  {
    Fields f;
    f.Dim[0] = 9;
    WritePlain(dir + "/ndim9.nii", Int16File(f));
    ExpectRefused(
      dir + "/ndim9.nii", "dim[0] (the number of dimensions) is 9; NIfTI allows 1 to 7");
    f.Dim[0] = 0;
    WritePlain(dir + "/ndim0.nii", Int16File(f));
    ExpectRefused(
      dir + "/ndim0.nii", "dim[0] (the number of dimensions) is 0; NIfTI allows 1 to 7");
    f.Dim[0] = 5;
    f.Dim[5] = 3;
    WritePlain(dir + "/vector.nii", Int16File(f));
    ExpectRefused(dir + "/vector.nii",
      "dim[5] is 3: vectors and dimensions beyond time (dim[5..7] above 1) are not read");
  };
  cases["UnknownDataType"] = [](const std::string& dir)
  {
    Fields f;
    f.DataType = 999;
    WritePlain(dir + "/unknown.nii", Int16File(f));
    ExpectRefused(dir + "/unknown.nii", "datatype code 999 is not a NIfTI datatype");
  };
  cases["UnsupportedDataType"] = [](const std::string& dir)
  {
    Fields f;
    f.DataType = 32; // COMPLEX64
    f.BitPix = 64;
    WritePlain(dir + "/complex.nii", Int16File(f));
    ExpectRefused(dir + "/complex.nii",
      "datatype COMPLEX64 (32) is not read: one real number per voxel is needed");
    f.DataType = 128; // RGB24
    f.BitPix = 24;
    WritePlain(dir + "/rgb.nii", Int16File(f));
    ExpectRefused(
      dir + "/rgb.nii", "datatype RGB24 (128) is not read: one real number per voxel is needed");
  };
  cases["BitPix"] = [](const std::string& dir)
  {
    Fields f;
    f.BitPix = 8;
    WritePlain(dir + "/bitpix.nii", Int16File(f));
    ExpectRefused(dir + "/bitpix.nii", "bitpix is 8 but datatype INT16 has 16 bits per voxel");
  };
  // 32767^3 int16 voxels announced by a file of 27 KB: refused before any
  // allocation (it used to abort with std::bad_alloc).
  cases["HeaderBeyondFile"] = [](const std::string& dir)
  {
    Fields f;
    f.Dim[1] = f.Dim[2] = f.Dim[3] = 32767;
    std::vector<unsigned char> bytes = NIfTIHeader(f);
    Append(bytes, Int16Voxels(13500, false));
    WritePlain(dir + "/huge.nii", bytes);
    ExpectRefused(dir + "/huge.nii",
      "the header describes 32767 x 32767 x 32767 INT16 voxels (70362301923326 bytes from byte "
      "352), but the file holds only 27352 bytes");
    WriteGzip(dir + "/huge.nii.gz", bytes);
    ExpectRefused(dir + "/huge.nii.gz",
      "the header describes 32767 x 32767 x 32767 INT16 voxels (70362301923326 bytes from byte "
      "352), but the uncompressed gzip stream holds only 27352 bytes");
  };
  // Half the voxels: plain, gzipped, and a gzip stream cut in the middle
  // (whose size field is lost, so the read itself finds the end).
  cases["Truncated"] = [](const std::string& dir)
  {
    Fields f;
    f.Dim[1] = f.Dim[2] = f.Dim[3] = 10;
    std::vector<unsigned char> bytes = Int16File(f);
    std::vector<unsigned char> half(bytes.begin(), bytes.begin() + 352 + 1000);
    WritePlain(dir + "/truncated.nii", half);
    ExpectRefused(dir + "/truncated.nii",
      "the header describes 10 x 10 x 10 INT16 voxels (2000 bytes from byte 352), but the file "
      "holds only 1352 bytes");
    WriteGzip(dir + "/truncated.nii.gz", half);
    ExpectRefused(dir + "/truncated.nii.gz",
      "the header describes 10 x 10 x 10 INT16 voxels (2000 bytes from byte 352), but the "
      "uncompressed gzip stream holds only 1352 bytes");
    // Voxels that do not compress, so that the cut falls among them.
    for (std::size_t i = 352; i < bytes.size(); ++i)
    {
      bytes[i] = static_cast<unsigned char>((i * 2654435761u) >> 13);
    }
    WriteGzip(dir + "/cut.nii.gz", bytes);
    std::ifstream in(dir + "/cut.nii.gz", std::ios::binary);
    std::vector<unsigned char> gz(
      (std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    gz.resize(gz.size() - 600);
    WritePlain(dir + "/cut.nii.gz", gz);
    ExpectRefused(dir + "/cut.nii.gz",
      "the file ends before the voxels the header describes do (it is truncated)");
  };
  cases["VoxOffset"] = [](const std::string& dir)
  {
    Fields f;
    f.VoxOffset = 100.0;
    WritePlain(dir + "/inside-header.nii", Int16File(f));
    ExpectRefused(dir + "/inside-header.nii",
      "vox_offset is 100; the voxels of a single-file NIfTI-1 image start after its 348-byte "
      "header");
    f.VoxOffset = 1.0e6;
    WritePlain(dir + "/beyond.nii", Int16File(f));
    ExpectRefused(dir + "/beyond.nii",
      "the header describes 4 x 3 x 2 INT16 voxels (48 bytes from byte 1000000), but the file "
      "holds only 400 bytes");
  };
  cases["NotNIfTI"] = [](const std::string& dir)
  {
    WritePlain(dir + "/text.nii", std::vector<unsigned char>(400, 'a'));
    ExpectRefused(dir + "/text.nii",
      "this is not a NIfTI-1, NIfTI-2 or Analyze 7.5 header (its first field, sizeof_hdr, is "
      "1633771873; 348 or 540 expected)");
    WritePlain(dir + "/empty.nii", std::vector<unsigned char>());
    ExpectRefused(dir + "/empty.nii", "the file is too short for a NIfTI header (0 bytes)");
    Fields f;
    std::vector<unsigned char> header = NIfTIHeader(f);
    header.resize(200);
    WritePlain(dir + "/short-header.nii", header);
    ExpectRefused(
      dir + "/short-header.nii", "the file ends inside its 348-byte header (200 bytes)");
    ExpectRefused(dir + "/missing.nii", "the file does not exist");
  };
  // The volume must fit in what the process may still allocate: under an
  // address-space limit (ulimit -v) the test sets on itself, a 64 MB volume
  // is refused before reading, naming the limit.
  cases["Memory"] = [](const std::string& dir)
  {
    Fields f;
    f.Dim[1] = f.Dim[2] = 400;
    f.Dim[3] = 200;
    f.Slope = 0.5;
    const std::string path = dir + "/large.nii";
    WritePlain(path, Int16File(f));
    const medical_test::AddressSpaceLimit limit(48ULL << 20);
    Check(limit.IsSet(), "address-space limit set");
    Messages messages;
    auto reader = Read(path, messages);
    const std::string start = "Cannot read " + path +
      ": the volume as stored and calibrated (192.0 MB) does not fit in the ";
    const std::string end =
      " MB the process may still allocate (the process's address-space limit (ulimit -v)). The "
      "output is empty.";
    Check(messages.Errors.size() == 1 && messages.Errors[0].rfind(start, 0) == 0 &&
        messages.Errors[0].size() > end.size() &&
        messages.Errors[0].compare(messages.Errors[0].size() - end.size(), end.size(), end) == 0,
      "one error naming the limit; got:" + Joined(messages.Errors));
    Check(reader->GetOutput()->GetNumberOfPoints() == 0, "the output is empty");
  };
  return cases;
}
} // namespace

int TestMedicalNIfTIReaderCorpus(int argc, char* argv[])
{
  const auto cases = Cases();
  const auto it = argc > 2 ? cases.find(argv[1]) : cases.end();
  if (it == cases.end())
  {
    std::printf("usage: TestMedicalNIfTIReaderCorpus CASE FOLDER; cases:");
    for (const auto& c : cases)
    {
      std::printf(" %s", c.first.c_str());
    }
    std::printf("\n");
    return 1;
  }
  it->second(argv[2]);
  return medical_test::Finish("the NIfTI case reads as it should");
}
