// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file LocalVolume.cxx
 * @brief A file dropped on the page, read by the readers' VTK-free cores in the page's
 * WebAssembly module: no server round trip, and the same rules as the server's readers.
 *
 * The page (Web/static/local.js) writes the dropped files into the module's in-memory file
 * system (MEMFS, under /local; a `.gz` already decompressed by the browser's
 * DecompressionStream) and calls `readLocalVolume(path)`:
 * - `.nii`: mediso::ReadNIfTI (Readers/Core/NIfTIImage.h), the header checks, calibration and
 *   placement that vtkMedicalNIfTIReader uses on the server (TestNIfTIImageMatchesReader
 *   compares the two); world space RAS.
 * - `.mha`, `.mhd` (its data file written beside it): mediso::headless::ReadMetaImage
 *   (Headless/MetaImage.h, the reader mediso-render uses), its TransformMatrix as the direction;
 *   world space LPS, as ITK and the server take it.
 * - a DICOM folder (`readLocalDICOM(folder, name)`: the folder's files written under it):
 *   mediso::ReadDICOMSeries (Readers/Core/DICOMSeries.h), vtkMedicalDICOMSeriesReader's rules over
 *   uncompressed little-endian single-frame files (TestDICOMSeriesMatchesReader compares the two),
 *   anything else refused by name; world space LPS.
 *
 * The answer is what the server's /api/datasets says of a volume (dims, spacing, origin,
 * direction, type, range, bytes, format {name, space}) and, in `pointer`, the values (x fastest,
 * in the type named) in the module's heap, which the page copies out and frees; or `{error}`.
 */
#include "DICOMSeries.h"
#include "MetaImage.h"
#include "NIfTIImage.h"
#include "ScalarTypes.h"

#include <emscripten/bind.h>
#include <emscripten/val.h>

#include <cmath>
#include <dirent.h>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace
{
using emscripten::val;

val Numbers(const double* v, int n)
{
  val out = val::array();
  for (int i = 0; i < n; ++i)
  {
    out.call<void>("push", v[i]);
  }
  return out;
}

val Failure(const std::string& error)
{
  val out = val::object();
  out.set("error", error);
  return out;
}

bool EndsWith(const std::string& s, const char* suffix)
{
  const std::size_t n = std::strlen(suffix);
  if (s.size() < n)
  {
    return false;
  }
  for (std::size_t i = 0; i < n; ++i)
  {
    const char c = s[s.size() - n + i];
    if ((c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c) != suffix[i])
    {
      return false;
    }
  }
  return true;
}

// The answer for a read volume: its facts, and its values copied into the module's heap.
val Describe(const int dims[3], const double spacing[3], const double origin[3],
  const double direction[9], mediso::ScalarType type, const std::vector<unsigned char>& bytes,
  const char* format, const char* space, const std::vector<std::string>& warnings)
{
  double range[2] = { HUGE_VAL, -HUGE_VAL };
  const std::size_t n = bytes.size() / static_cast<std::size_t>(mediso::ScalarTypeSize(type));
  mediso::VisitScalarType(type,
    [&](auto tag)
    {
      using T = decltype(tag);
      for (std::size_t i = 0; i < n; ++i)
      {
        T v;
        std::memcpy(&v, bytes.data() + i * sizeof(T), sizeof(T));
        const double d = static_cast<double>(v);
        range[0] = d < range[0] ? d : range[0]; // NaN is left out
        range[1] = d > range[1] ? d : range[1];
      }
    });
  if (!(range[0] <= range[1]))
  {
    return Failure("its values are all NaN");
  }
  void* pointer = std::malloc(bytes.size());
  if (!pointer)
  {
    return Failure("the page's memory ran out for its " + std::to_string(bytes.size()) + " bytes");
  }
  std::memcpy(pointer, bytes.data(), bytes.size());
  const double dimensions[3] = { double(dims[0]), double(dims[1]), double(dims[2]) };
  val out = val::object();
  out.set("dims", Numbers(dimensions, 3));
  out.set("spacing", Numbers(spacing, 3));
  out.set("origin", Numbers(origin, 3));
  out.set("direction", Numbers(direction, 9));
  out.set("type", std::string(mediso::ScalarTypeName(type)));
  out.set("range", Numbers(range, 2));
  out.set("bytes", static_cast<double>(bytes.size()));
  val f = val::object();
  f.set("name", std::string(format));
  f.set("space", std::string(space));
  out.set("format", f);
  val said = val::array();
  for (const std::string& w : warnings)
  {
    said.call<void>("push", w);
  }
  out.set("warnings", said);
  out.set("pointer", reinterpret_cast<std::uintptr_t>(pointer));
  return out;
}

/// The volume of the file at `path` in the module's file system, or {error}.
val ReadLocalVolume(const std::string& path)
{
  if (EndsWith(path, ".nii"))
  {
    std::ifstream in(path, std::ios::binary);
    std::vector<unsigned char> bytes(
      (std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    mediso::NIfTIImage image;
    std::string error;
    if (!mediso::ReadNIfTI(bytes.data(), bytes.size(), image, error))
    {
      return Failure(error);
    }
    bytes = std::vector<unsigned char>(); // the file's copy, before the values are copied
    const auto& p = image.Placement;
    return Describe(image.Dimensions, p.Spacing, p.Origin, p.Direction, image.Type, image.Bytes,
      "NIfTI", "RAS", image.Warnings);
  }
  if (EndsWith(path, ".mha") || EndsWith(path, ".mhd"))
  {
    mediso::headless::MetaImage image;
    std::string error;
    if (!mediso::headless::ReadMetaImage(path, image, error))
    {
      // The reader names the file by its path in the module's file system.
      const std::size_t at = error.find(path);
      return Failure(at == 0 ? error.substr(path.size() + 2) : error);
    }
    return Describe(image.Dimensions, image.Spacing, image.Origin, image.Direction, image.Type,
      image.Bytes, "MetaImage", "LPS", {});
  }
  return Failure("not a file the page reads (.nii, .nii.gz, .mha, .mhd with its data file)");
}

/// The series of the DICOM folder at `folder` in the module's file system (its regular files,
/// not its subfolders, as the server's reader scans a folder), or {error}. `name` names the
/// folder in messages.
val ReadLocalDICOM(const std::string& folder, const std::string& name)
{
  DIR* directory = opendir(folder.c_str());
  if (!directory)
  {
    return Failure("the folder cannot be listed");
  }
  std::vector<std::string> names;
  while (const dirent* entry = readdir(directory))
  {
    const std::string file = entry->d_name;
    if (file != "." && file != ".." && entry->d_type == DT_REG)
    {
      names.push_back(file);
    }
  }
  closedir(directory);
  std::vector<std::vector<unsigned char>> contents(names.size());
  std::vector<mediso::DICOMFileBytes> files(names.size());
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    std::ifstream in(folder + "/" + names[i], std::ios::binary);
    contents[i].assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    files[i].Name = names[i];
    files[i].Bytes = contents[i].data();
    files[i].Size = contents[i].size();
  }
  mediso::DICOMSeriesVolume volume;
  const std::string error = mediso::ReadDICOMSeries(name, files, volume);
  contents.clear(); // the files' copies, before the values are copied
  if (!error.empty())
  {
    return Failure(error);
  }
  return Describe(volume.Dimensions, volume.Spacing, volume.Origin, volume.Direction, volume.Type,
    volume.Values, "DICOM", "LPS", volume.Warnings);
}
} // namespace

EMSCRIPTEN_BINDINGS(mediso_local_volume)
{
  emscripten::function("readLocalVolume", &ReadLocalVolume);
  emscripten::function("readLocalDICOM", &ReadLocalDICOM);
}
