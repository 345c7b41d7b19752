// SPDX-License-Identifier: BSD-3-Clause
#include "MetaImage.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

namespace mediso
{
namespace headless
{
namespace
{
std::string Trim(const std::string& s)
{
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a])))
  {
    ++a;
  }
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1])))
  {
    --b;
  }
  return s.substr(a, b - a);
}

std::string Lower(std::string s)
{
  std::transform(s.begin(), s.end(), s.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool ParseNumbers(const std::string& text, std::size_t count, double* out)
{
  std::istringstream in(text);
  for (std::size_t i = 0; i < count; ++i)
  {
    if (!(in >> out[i]) || !std::isfinite(out[i]))
    {
      return false;
    }
  }
  std::string rest;
  return !(in >> rest);
}

bool ParseBool(const std::string& text, bool& value)
{
  const std::string v = Lower(text);
  if (v == "true" || v == "1")
  {
    value = true;
    return true;
  }
  if (v == "false" || v == "0")
  {
    value = false;
    return true;
  }
  return false;
}

bool ElementTypeOf(const std::string& name, ScalarType& type)
{
  static const std::map<std::string, ScalarType> types = { { "MET_CHAR", ScalarType::Int8 },
    { "MET_UCHAR", ScalarType::UInt8 }, { "MET_SHORT", ScalarType::Int16 },
    { "MET_USHORT", ScalarType::UInt16 }, { "MET_INT", ScalarType::Int32 },
    { "MET_UINT", ScalarType::UInt32 }, { "MET_LONG", ScalarType::Int32 },
    { "MET_ULONG", ScalarType::UInt32 }, { "MET_FLOAT", ScalarType::Float32 },
    { "MET_DOUBLE", ScalarType::Float64 } };
  const auto it = types.find(name);
  if (it == types.end())
  {
    return false;
  }
  type = it->second;
  return true;
}

std::string Directory(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

bool LittleEndianMachine()
{
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}
} // namespace

const char* MetaElementType(ScalarType type)
{
  switch (type)
  {
    case ScalarType::Int8:
      return "MET_CHAR";
    case ScalarType::UInt8:
      return "MET_UCHAR";
    case ScalarType::Int16:
      return "MET_SHORT";
    case ScalarType::UInt16:
      return "MET_USHORT";
    case ScalarType::Int32:
      return "MET_INT";
    case ScalarType::UInt32:
      return "MET_UINT";
    case ScalarType::Float32:
      return "MET_FLOAT";
    default:
      return "MET_DOUBLE";
  }
}

void MetaImage::GetRange(double range[2]) const
{
  range[0] = HUGE_VAL;
  range[1] = -HUGE_VAL;
  VisitScalarType(this->Type,
    [&](auto tag)
    {
      using T = decltype(tag);
      const T* v = reinterpret_cast<const T*>(this->Bytes.data());
      const std::int64_t n = this->GetNumberOfPoints();
      for (std::int64_t i = 0; i < n; ++i)
      {
        const double d = static_cast<double>(v[i]);
        if (d < range[0])
        {
          range[0] = d;
        }
        if (d > range[1])
        {
          range[1] = d;
        }
      }
    });
}

bool ReadMetaImage(const std::string& path, MetaImage& image, std::string& error)
{
  std::ifstream file(path, std::ios::binary);
  if (!file)
  {
    error = path + ": cannot be opened";
    return false;
  }
  // The header: text lines up to and including ElementDataFile.
  std::map<std::string, std::string> fields;
  std::string line, dataFile;
  std::streamoff dataOffset = 0;
  for (int lines = 0; std::getline(file, line); ++lines)
  {
    if (lines > 200 || line.size() > 4096)
    {
      error = path + ": not a MetaImage header (no ElementDataFile in its first lines)";
      return false;
    }
    const std::size_t eq = line.find('=');
    if (eq == std::string::npos)
    {
      if (Trim(line).empty())
      {
        continue;
      }
      std::string shown = Trim(line).substr(0, 40);
      for (char& c : shown)
      {
        c = std::isprint(static_cast<unsigned char>(c)) ? c : '?';
      }
      error = path + ": not a MetaImage header (line " + std::to_string(lines + 1) + ": \"" +
        shown + "\")";
      return false;
    }
    const std::string key = Trim(line.substr(0, eq));
    const std::string value = Trim(line.substr(eq + 1));
    if (key == "ElementDataFile")
    {
      dataFile = value;
      dataOffset = file.tellg();
      break;
    }
    fields[key] = value;
  }
  if (dataFile.empty())
  {
    error = path + ": not a MetaImage (no ElementDataFile line)";
    return false;
  }
  auto field = [&](std::initializer_list<const char*> names, std::string& value) -> bool
  {
    for (const char* name : names)
    {
      const auto it = fields.find(name);
      if (it != fields.end())
      {
        value = it->second;
        return true;
      }
    }
    return false;
  };
  std::string value;
  if (field({ "ObjectType" }, value) && Lower(value) != "image")
  {
    error = path + ": ObjectType " + value + " is not an image";
    return false;
  }
  if (!field({ "NDims" }, value) || Trim(value) != "3")
  {
    error = path + ": only 3D images are supported (NDims " + (value.empty() ? "missing" : value) + ")";
    return false;
  }
  double dims[3];
  if (!field({ "DimSize" }, value) || !ParseNumbers(value, 3, dims))
  {
    error = path + ": DimSize must be 3 numbers";
    return false;
  }
  for (int a = 0; a < 3; ++a)
  {
    if (dims[a] < 1 || dims[a] > 65536 || dims[a] != std::floor(dims[a]))
    {
      error = path + ": DimSize " + value + " is not a size (1 to 65536 per axis)";
      return false;
    }
    image.Dimensions[a] = static_cast<int>(dims[a]);
  }
  if (!field({ "ElementType" }, value) || !ElementTypeOf(value, image.Type))
  {
    error = path + ": ElementType " + (value.empty() ? "missing" : value) +
      " is not supported (MET_CHAR, MET_UCHAR, MET_SHORT, MET_USHORT, MET_INT, MET_UINT, "
      "MET_FLOAT, MET_DOUBLE)";
    return false;
  }
  if (field({ "ElementNumberOfChannels" }, value) && Trim(value) != "1")
  {
    error = path + ": " + value + " channels per element; one is needed";
    return false;
  }
  bool flag = false;
  if (field({ "CompressedData" }, value) && (!ParseBool(value, flag) || flag))
  {
    error = path + ": compressed MetaImage data is not supported (write it uncompressed)";
    return false;
  }
  bool bigEndian = false;
  if (field({ "BinaryDataByteOrderMSB", "ElementByteOrderMSB" }, value) && !ParseBool(value, bigEndian))
  {
    error = path + ": BinaryDataByteOrderMSB must be True or False";
    return false;
  }
  if (field({ "ElementSpacing", "ElementSize" }, value) && !ParseNumbers(value, 3, image.Spacing))
  {
    error = path + ": ElementSpacing must be 3 numbers";
    return false;
  }
  for (double s : image.Spacing)
  {
    if (!(s > 0.0))
    {
      error = path + ": ElementSpacing " + value + " must be positive";
      return false;
    }
  }
  if (field({ "Offset", "Origin", "Position" }, value) && !ParseNumbers(value, 3, image.Origin))
  {
    error = path + ": Offset must be 3 numbers";
    return false;
  }
  if (field({ "TransformMatrix", "Rotation", "Orientation" }, value))
  {
    double m[9];
    if (!ParseNumbers(value, 9, m))
    {
      error = path + ": TransformMatrix must be 9 numbers";
      return false;
    }
    // MetaImage lists the matrix row by row with the axes as columns.
    std::copy(m, m + 9, image.Direction);
  }
  // HeaderSize: bytes to skip before the data; -1: the data are the file's last bytes.
  std::int64_t headerSize = 0;
  if (field({ "HeaderSize" }, value))
  {
    double h;
    if (!ParseNumbers(value, 1, &h) || h < -1)
    {
      error = path + ": HeaderSize must be a number";
      return false;
    }
    headerSize = static_cast<std::int64_t>(h);
  }

  // The data: after the header (LOCAL) or in a file beside it.
  const int valueBytes = ScalarTypeSize(image.Type);
  const std::int64_t points = image.GetNumberOfPoints();
  const std::int64_t bytes = points * valueBytes;
  std::ifstream separate;
  std::istream* in = &file;
  std::string where = path;
  std::streamoff start = dataOffset;
  if (Lower(dataFile) != "local")
  {
    if (dataFile.find_first_of("%*?") != std::string::npos || Lower(dataFile).rfind("list", 0) == 0)
    {
      error = path + ": ElementDataFile " + dataFile + " (a file list) is not supported";
      return false;
    }
    where = dataFile[0] == '/' ? dataFile : Directory(path) + dataFile;
    separate.open(where, std::ios::binary);
    if (!separate)
    {
      error = path + ": its data file " + where + " cannot be opened";
      return false;
    }
    in = &separate;
    start = 0;
  }
  in->seekg(0, std::ios::end);
  const std::streamoff size = in->tellg();
  if (headerSize == -1)
  {
    start = size - bytes;
  }
  else if (headerSize > 0)
  {
    start += headerSize;
  }
  if (start < 0 || size - start < bytes)
  {
    error = where + ": holds " + std::to_string(std::max<std::streamoff>(0, size - start)) +
      " bytes of data, " + std::to_string(bytes) + " are needed for " +
      std::to_string(image.Dimensions[0]) + "x" + std::to_string(image.Dimensions[1]) + "x" +
      std::to_string(image.Dimensions[2]) + " " + MetaElementType(image.Type);
    return false;
  }
  image.Bytes.resize(static_cast<std::size_t>(bytes));
  in->seekg(start);
  in->read(reinterpret_cast<char*>(image.Bytes.data()), bytes);
  if (!*in)
  {
    error = where + ": reading the data failed";
    return false;
  }
  if (bigEndian == LittleEndianMachine() && valueBytes > 1)
  {
    for (std::int64_t i = 0; i < points; ++i)
    {
      std::reverse(image.Bytes.begin() + i * valueBytes, image.Bytes.begin() + (i + 1) * valueBytes);
    }
  }
  return true;
}

bool WriteMetaImage(const std::string& path, const MetaImage& image, std::string& error)
{
  std::ofstream out(path, std::ios::binary);
  if (!out)
  {
    error = path + ": cannot be written";
    return false;
  }
  const double* s = image.Spacing;
  const double* o = image.Origin;
  const double* m = image.Direction;
  char header[1024];
  std::snprintf(header, sizeof(header),
    "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = %s\n"
    "CompressedData = False\nTransformMatrix = %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g "
    "%.17g\nOffset = %.17g %.17g %.17g\nElementSpacing = %.17g %.17g %.17g\nDimSize = %d %d %d\n"
    "ElementType = %s\nElementDataFile = LOCAL\n",
    LittleEndianMachine() ? "False" : "True", m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8],
    o[0], o[1], o[2], s[0], s[1], s[2], image.Dimensions[0], image.Dimensions[1],
    image.Dimensions[2], MetaElementType(image.Type));
  out << header;
  out.write(reinterpret_cast<const char*>(image.Bytes.data()),
    static_cast<std::streamsize>(image.Bytes.size()));
  if (!out)
  {
    error = path + ": writing failed";
    return false;
  }
  return true;
}

} // namespace headless
} // namespace mediso
