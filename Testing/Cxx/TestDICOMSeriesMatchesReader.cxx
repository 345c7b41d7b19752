// SPDX-License-Identifier: BSD-3-Clause
// The readers' VTK-free DICOM series core (mediso::ReadDICOMSeries, the web
// page's) against vtkMedicalDICOMSeriesReader on every folder of the reader's
// generated corpus (Testing/Python/dicom_corpus.py) and on a few folders this
// test damages from it. For each folder both read the same files:
//
// - both read: the same dimensions, spacing, origin, direction (exactly), the
//   same scalar type and the same values, byte for byte;
// - the reader reads, the core refuses: allowed only with the core's own
//   "not read in the page" refusal (compressed, big endian, multi-frame);
// - the reader refuses: the core refuses with the same message (the uneven
//   spacing message's last sentence, the reader's option, aside);
// - the core reads what the reader refuses: a failure, always.
//
// The folders that must read (axial, shuffled order, oblique, rescaled per
// slice, 8-bit implicit VR, two series, junk beside the series) and those
// the page must refuse by name are listed, so that a corpus that stops
// writing them fails the test. Messages are caught by an observer, never
// printed.
//
//   TestDICOMSeriesMatchesReader dicom_corpus.py OUT
//
// Exit 125 (skipped) when /usr/bin/python3 cannot write the corpus.
#include "DICOMSeries.h"
#include "vtkMedicalDICOMSeriesReader.h"
#include "vtkMedicalVTKType.h"

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkTestErrorObserver.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace
{
namespace fs = std::filesystem;

// What each folder must give: "read" (both read it, identically), "page" (the
// reader reads it, the core refuses it by name), or "refused" (both refuse,
// with this text in both messages).
struct Expected
{
  const char* Folder;
  const char* Outcome;
  const char* Text;
};

const Expected Cases[] = {
  { "plain", "read", nullptr },
  { "two_series", "read", nullptr },
  { "slopes", "read", nullptr },
  { "junk", "read", nullptr },
  { "shuffled", "read", nullptr },
  { "oblique", "read", nullptr },
  { "mr8", "read", nullptr },
  { "missing_rows", "read", nullptr },
  { "high_bits", "read", nullptr },
  { "rle", "page", "\"RLE Lossless\" (1.2.840.10008.1.2.5) is not read in the page" },
  { "jpeg_lossless", "page", "(1.2.840.10008.1.2.4.70) is not read in the page" },
  { "jpegls", "page", "(1.2.840.10008.1.2.4.80) is not read in the page" },
  { "bigendian", "page", "\"Explicit VR Big Endian\" (1.2.840.10008.1.2.2) is not read" },
  { "multiframe", "page", "a multi-frame (enhanced) image is not read in the page" },
  { "jpeg2000", "refused", "JPEG 2000 (Lossless only)" },
  { "gap", "refused", "(1 slice missing)" },
  { "uneven", "refused", "a step of 3 mm between 4 mm" },
  { "duplicate", "refused", "duplicate slices are not read" },
  { "mixed_size", "refused", "slices of different sizes" },
  { "tilted", "refused", "a gantry tilt or a sheared stack" },
  { "mixed_orientation", "refused", "slices of different orientations" },
  { "rgb", "refused", "only greyscale (MONOCHROME1/2)" },
  { "truncated", "refused", "(1 slice missing)" },
  { "short_pixels", "refused", "Pixel Data holds 100 bytes, 384 expected" },
  { "missing_position", "refused", "no Image Position (Patient)" },
  { "header_cut", "refused", "no DICOM image files in the folder" },
};

struct ReaderResult
{
  std::string Error;
  vtkSmartPointer<vtkImageData> Image;
};

ReaderResult RunReader(const std::string& folder)
{
  vtkNew<vtkMedicalDICOMSeriesReader> reader;
  vtkNew<vtkTest::ErrorObserver> observer;
  reader->AddObserver(vtkCommand::ErrorEvent, observer);
  reader->AddObserver(vtkCommand::WarningEvent, observer);
  reader->SetFileName(folder.c_str());
  reader->Update();
  ReaderResult result;
  result.Error = observer->GetError() ? observer->GetErrorMessage() : std::string();
  // The message itself, without VTK's "ERROR: In file, line" and object prefix.
  const std::size_t object = result.Error.find("vtkMedicalDICOMSeriesReader (");
  const std::size_t text = result.Error.find("): ", object == std::string::npos ? 0 : object);
  if (object != std::string::npos && text != std::string::npos)
  {
    result.Error = result.Error.substr(text + 3);
  }
  while (!result.Error.empty() && std::isspace(static_cast<unsigned char>(result.Error.back())))
  {
    result.Error.pop_back();
  }
  result.Image = reader->GetOutput();
  return result;
}

std::vector<unsigned char> Slurp(const fs::path& path)
{
  std::ifstream file(path, std::ios::binary);
  return std::vector<unsigned char>(
    std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

// The core on the regular files of `folder`, as the page hands them over.
std::string RunCore(const std::string& folder, mediso::DICOMSeriesVolume& volume)
{
  std::vector<std::vector<unsigned char>> contents;
  std::vector<std::string> names;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder))
  {
    if (entry.is_regular_file())
    {
      contents.push_back(Slurp(entry.path()));
      names.push_back(entry.path().filename().string());
    }
  }
  std::vector<mediso::DICOMFileBytes> files(contents.size());
  for (std::size_t i = 0; i < contents.size(); ++i)
  {
    files[i].Name = names[i];
    files[i].Bytes = contents[i].data();
    files[i].Size = contents[i].size();
  }
  return mediso::ReadDICOMSeries(folder, files, volume);
}

// The uneven-spacing refusal ends with what each host offers instead.
std::string WithoutOffer(std::string message)
{
  for (const char* offer : { " Turn ResampleUnevenSlices on", " The page does not resample" })
  {
    const std::size_t at = message.find(offer);
    if (at != std::string::npos)
    {
      message.erase(at);
    }
  }
  return message;
}

bool Compare(const std::string& folder, const Expected& expected, std::string& why)
{
  const ReaderResult reader = RunReader(folder);
  mediso::DICOMSeriesVolume volume;
  const std::string coreError = RunCore(folder, volume);
  const std::string outcome = expected.Outcome;
  if (!reader.Error.empty() && coreError.empty())
  {
    why = "the core reads what the reader refuses [" + reader.Error + "]";
    return false;
  }
  if (outcome == "page")
  {
    if (!reader.Error.empty())
    {
      why = "the reader refuses it [" + reader.Error + "]";
      return false;
    }
    if (coreError.find(expected.Text) == std::string::npos || !volume.Values.empty())
    {
      why = "the core's refusal [" + coreError + "]";
      return false;
    }
    return true;
  }
  if (outcome == "refused")
  {
    if (reader.Error.find(expected.Text) == std::string::npos ||
      (coreError.find(expected.Text) == std::string::npos &&
        coreError.find("is not read in the page") == std::string::npos) ||
      !volume.Values.empty())
    {
      why = "reader [" + reader.Error + "], core [" + coreError + "]";
      return false;
    }
    if (coreError.find("is not read in the page") == std::string::npos &&
      WithoutOffer(coreError) != WithoutOffer(reader.Error))
    {
      why = "different messages: reader [" + reader.Error + "], core [" + coreError + "]";
      return false;
    }
    return true;
  }
  if (!reader.Error.empty() || !coreError.empty())
  {
    why = "reader [" + reader.Error + "], core [" + coreError + "]";
    return false;
  }
  vtkImageData* image = reader.Image;
  int dims[3];
  image->GetDimensions(dims);
  for (int c = 0; c < 3; ++c)
  {
    if (dims[c] != volume.Dimensions[c] || image->GetSpacing()[c] != volume.Spacing[c] ||
      image->GetOrigin()[c] != volume.Origin[c])
    {
      why = "different dimensions, spacing or origin along axis " + std::to_string(c);
      return false;
    }
  }
  for (int e = 0; e < 9; ++e)
  {
    if (image->GetDirectionMatrix()->GetData()[e] != volume.Direction[e])
    {
      why = "different direction matrix";
      return false;
    }
  }
  vtkDataArray* scalars = image->GetPointData()->GetScalars();
  if (!scalars || scalars->GetDataType() != vtkMedicalVTKType(volume.Type))
  {
    why =
      std::string("different types: reader ") + (scalars ? scalars->GetDataTypeAsString() : "none");
    return false;
  }
  const std::size_t bytes =
    static_cast<std::size_t>(scalars->GetNumberOfValues()) * scalars->GetDataTypeSize();
  if (bytes != volume.Values.size() ||
    std::memcmp(scalars->GetVoidPointer(0), volume.Values.data(), bytes) != 0)
  {
    why = "different values";
    return false;
  }
  return true;
}

// A copy of the plain series with `tag` (little endian group, element)
// renamed to `renamed` in `file`: the attribute is then absent for both.
bool RenameTag(const fs::path& file, const unsigned char tag[4], const unsigned char renamed[4])
{
  std::vector<unsigned char> bytes = Slurp(file);
  auto found = std::search(bytes.begin() + 132, bytes.end(), tag, tag + 4);
  if (found == bytes.end())
  {
    return false;
  }
  std::copy(renamed, renamed + 4, found);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(
    reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return static_cast<bool>(out);
}

bool Damage(const std::string& corpus)
{
  const fs::path plain = fs::path(corpus) / "plain";
  for (const char* name :
    { "missing_rows", "missing_position", "header_cut", "high_bits", "pixel_ob" })
  {
    fs::remove_all(fs::path(corpus) / name);
    fs::copy(plain, fs::path(corpus) / name);
  }
  // Rows (0028,0010) renamed to (0028,0012), a retired tag: that file is
  // not an image for either, and the other five are an even series.
  const unsigned char rows[4] = { 0x28, 0x00, 0x10, 0x00 };
  const unsigned char rowsRenamed[4] = { 0x28, 0x00, 0x12, 0x00 };
  // Image Position (Patient) (0020,0032) to Image Position (0020,0030).
  const unsigned char position[4] = { 0x20, 0x00, 0x32, 0x00 };
  const unsigned char positionRenamed[4] = { 0x20, 0x00, 0x30, 0x00 };
  bool ok = RenameTag(fs::path(corpus) / "missing_rows" / "slice_000.dcm", rows, rowsRenamed) &&
    RenameTag(fs::path(corpus) / "missing_position" / "slice_003.dcm", position, positionRenamed);
  // Bits above Bits Stored (12) set in every stored value: masked by both.
  for (const fs::directory_entry& entry : fs::directory_iterator(fs::path(corpus) / "high_bits"))
  {
    std::vector<unsigned char> bytes = Slurp(entry.path());
    const unsigned char pixelData[8] = { 0xE0, 0x7F, 0x10, 0x00, 'O', 'W', 0, 0 };
    auto found = std::search(bytes.begin(), bytes.end(), pixelData, pixelData + 8);
    if (found == bytes.end())
    {
      return false;
    }
    for (auto at = found + 12; at + 1 < bytes.end(); at += 2)
    {
      at[1] |= 0xF0;
    }
    std::ofstream out(entry.path(), std::ios::binary | std::ios::trunc);
    out.write(
      reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  // 16-bit Pixel Data under VR OB instead of OW (left unlisted: whatever the reader makes of
  // it, the core must not read it otherwise).
  for (const fs::directory_entry& entry : fs::directory_iterator(fs::path(corpus) / "pixel_ob"))
  {
    const unsigned char ow[6] = { 0xE0, 0x7F, 0x10, 0x00, 'O', 'W' };
    const unsigned char ob[6] = { 0xE0, 0x7F, 0x10, 0x00, 'O', 'B' };
    std::vector<unsigned char> bytes = Slurp(entry.path());
    auto found = std::search(bytes.begin(), bytes.end(), ow, ow + 6);
    if (found == bytes.end())
    {
      return false;
    }
    std::copy(ob, ob + 6, found);
    std::ofstream out(entry.path(), std::ios::binary | std::ios::trunc);
    out.write(
      reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  // Every file cut inside its header: nothing left to read.
  for (const fs::directory_entry& entry : fs::directory_iterator(fs::path(corpus) / "header_cut"))
  {
    fs::resize_file(entry.path(), 300);
  }
  return ok;
}
} // namespace

int main(int argc, char* argv[])
{
  if (argc != 3)
  {
    std::printf("usage: %s dicom_corpus.py OUT\n", argv[0]);
    return 2;
  }
  const std::string corpus = std::string(argv[2]) + "/dicom_corpus_core";
  const std::string command =
    std::string("/usr/bin/python3 '") + argv[1] + "' '" + corpus + "' > /dev/null";
  const int status = std::system(command.c_str());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 3 || code == 4 || code == 127)
  {
    std::printf("SKIP: /usr/bin/python3 cannot write the DICOM corpus (exit %d)\n", code);
    return 125;
  }
  if (code != 0)
  {
    std::printf("FAILED: the corpus writer exited with %d\n", code);
    return 1;
  }
  if (!Damage(corpus))
  {
    std::printf("FAILED: could not damage copies of the plain series\n");
    return 1;
  }
  int failures = 0;
  std::map<std::string, bool> listed;
  for (const Expected& c : Cases)
  {
    listed[c.Folder] = true;
    const std::string folder = corpus + "/" + c.Folder;
    std::string why;
    if (!fs::is_directory(folder))
    {
      why = "no such folder in the corpus";
    }
    if (why.empty() && Compare(folder, c, why))
    {
      std::printf("ok: %s (%s)\n", c.Folder, c.Outcome);
    }
    else
    {
      ++failures;
      std::printf("FAILED: %s (%s): %s\n", c.Folder, c.Outcome, why.c_str());
    }
  }
  // Every other folder of the corpus: the core never reads what the reader
  // refuses, and reads identically what both read.
  for (const fs::directory_entry& entry : fs::directory_iterator(corpus))
  {
    const std::string name = entry.path().filename().string();
    if (!entry.is_directory() || name == "expected" || listed.count(name))
    {
      continue;
    }
    const ReaderResult reader = RunReader(entry.path().string());
    mediso::DICOMSeriesVolume volume;
    const std::string coreError = RunCore(entry.path().string(), volume);
    std::string why;
    if (reader.Error.empty() && coreError.empty())
    {
      const Expected same = { name.c_str(), "read", nullptr };
      if (!Compare(entry.path().string(), same, why))
      {
        ++failures;
        std::printf("FAILED: %s (unlisted, both read): %s\n", name.c_str(), why.c_str());
        continue;
      }
    }
    else if (!reader.Error.empty() && coreError.empty())
    {
      ++failures;
      std::printf("FAILED: %s (unlisted): the core reads what the reader refuses [%s]\n",
        name.c_str(), reader.Error.c_str());
      continue;
    }
    std::printf("ok: %s (unlisted): reader [%s], core [%s]\n", name.c_str(), reader.Error.c_str(),
      coreError.c_str());
  }
  if (failures)
  {
    std::printf("%d case(s) failed\n", failures);
    return 1;
  }
  return 0;
}
