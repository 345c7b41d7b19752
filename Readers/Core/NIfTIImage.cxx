// SPDX-License-Identifier: BSD-3-Clause
#include "NIfTIImage.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <sstream>

namespace mediso
{
namespace
{
// nifti1.h's codes; the stored type where the cores have one.
const NIfTIDataType DataTypes[] = { { 1, "BINARY", 1, false, false, ScalarType::UInt8 },
  { 2, "UINT8", 8, true, true, ScalarType::UInt8 },
  { 4, "INT16", 16, true, true, ScalarType::Int16 },
  { 8, "INT32", 32, true, true, ScalarType::Int32 },
  { 16, "FLOAT32", 32, true, true, ScalarType::Float32 },
  { 32, "COMPLEX64", 64, false, false, ScalarType::UInt8 },
  { 64, "FLOAT64", 64, true, true, ScalarType::Float64 },
  { 128, "RGB24", 24, false, false, ScalarType::UInt8 },
  { 256, "INT8", 8, true, true, ScalarType::Int8 },
  { 512, "UINT16", 16, true, true, ScalarType::UInt16 },
  { 768, "UINT32", 32, true, true, ScalarType::UInt32 },
  { 1024, "INT64", 64, true, false, ScalarType::Float64 },
  { 1280, "UINT64", 64, true, false, ScalarType::Float64 },
  { 1536, "FLOAT128", 128, false, false, ScalarType::UInt8 },
  { 1792, "COMPLEX128", 128, false, false, ScalarType::UInt8 },
  { 2048, "COMPLEX256", 256, false, false, ScalarType::UInt8 },
  { 2304, "RGBA32", 32, false, false, ScalarType::UInt8 } };

template<typename T>
T Field(const unsigned char* bytes, std::size_t offset, bool swap)
{
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, bytes + offset, sizeof(T));
  if (swap)
  {
    std::reverse(raw, raw + sizeof(T));
  }
  T value;
  std::memcpy(&value, raw, sizeof(T));
  return value;
}

const char* AxisName(int axis)
{
  static const char* const names[] = { "x", "y", "z" };
  return names[axis];
}

// The stored value v of type T as a double (byte order already native).
template<typename T>
double Stored(const unsigned char* p)
{
  T v;
  std::memcpy(&v, p, sizeof(T));
  return static_cast<double>(v);
}

double StoredValue(int code, const unsigned char* p)
{
  switch (code)
  {
    case 2:
      return Stored<std::uint8_t>(p);
    case 4:
      return Stored<std::int16_t>(p);
    case 8:
      return Stored<std::int32_t>(p);
    case 16:
      return Stored<float>(p);
    case 64:
      return Stored<double>(p);
    case 256:
      return Stored<std::int8_t>(p);
    case 512:
      return Stored<std::uint16_t>(p);
    case 768:
      return Stored<std::uint32_t>(p);
    case 1024:
      return Stored<std::int64_t>(p);
    default:
      return Stored<std::uint64_t>(p);
  }
}
} // namespace

const NIfTIDataType* FindNIfTIDataType(int code)
{
  for (const NIfTIDataType& t : DataTypes)
  {
    if (t.Code == code)
    {
      return &t;
    }
  }
  return nullptr;
}

std::string ParseNIfTIHeader(const unsigned char* bytes, std::size_t got, NIfTIHeader& h)
{
  if (got < 4)
  {
    return "the file is too short for a NIfTI header (" + std::to_string(got) + " bytes)";
  }
  const std::int32_t size = Field<std::int32_t>(bytes, 0, false);
  const std::int32_t swappedSize = Field<std::int32_t>(bytes, 0, true);
  if (size == NIfTI1HeaderBytes || size == NIfTI2HeaderBytes)
  {
    h.Swap = false;
  }
  else if (swappedSize == NIfTI1HeaderBytes || swappedSize == NIfTI2HeaderBytes)
  {
    h.Swap = true;
  }
  else
  {
    return "this is not a NIfTI-1, NIfTI-2 or Analyze 7.5 header (its first "
           "field, sizeof_hdr, "
           "is " +
      std::to_string(size) + "; 348 or 540 expected)";
  }
  const bool swap = h.Swap;
  const std::size_t headerBytes = static_cast<std::size_t>(swap ? swappedSize : size);
  if (got < headerBytes)
  {
    return "the file ends inside its " + std::to_string(headerBytes) + "-byte header (" +
      std::to_string(got) + " bytes)";
  }
  if (headerBytes == NIfTI2HeaderBytes)
  {
    if (std::memcmp(bytes + 4, "n+2", 4) != 0 && std::memcmp(bytes + 4, "ni2", 4) != 0)
    {
      return "the 540-byte header lacks NIfTI-2's magic (\"n+2\" or \"ni2\")";
    }
    h.Version = 2;
    h.SingleFile = bytes[5] == '+';
    h.DataType = Field<std::int16_t>(bytes, 12, swap);
    h.BitPix = Field<std::int16_t>(bytes, 14, swap);
    for (int i = 0; i < 8; ++i)
    {
      h.Dim[i] = Field<std::int64_t>(bytes, 16 + 8 * i, swap);
      h.PixDim[i] = Field<double>(bytes, 104 + 8 * i, swap);
    }
    h.VoxOffset = static_cast<double>(Field<std::int64_t>(bytes, 168, swap));
    h.Slope = Field<double>(bytes, 176, swap);
    h.Intercept = Field<double>(bytes, 184, swap);
    h.TOffset = Field<double>(bytes, 216, swap);
    h.QFormCode = Field<std::int32_t>(bytes, 344, swap);
    h.SFormCode = Field<std::int32_t>(bytes, 348, swap);
    for (int i = 0; i < 3; ++i)
    {
      h.Quatern[i] = Field<double>(bytes, 352 + 8 * i, swap);
      h.QOffset[i] = Field<double>(bytes, 376 + 8 * i, swap);
      for (int c = 0; c < 4; ++c)
      {
        h.SRow[i][c] = Field<double>(bytes, 400 + 32 * i + 8 * c, swap);
      }
    }
    return std::string();
  }
  const bool nifti1 =
    std::memcmp(bytes + 344, "n+1", 4) == 0 || std::memcmp(bytes + 344, "ni1", 4) == 0;
  h.Version = nifti1 ? 1 : 0;
  h.SingleFile = nifti1 && bytes[345] == '+';
  h.DataType = Field<std::int16_t>(bytes, 70, swap);
  h.BitPix = Field<std::int16_t>(bytes, 72, swap);
  for (int i = 0; i < 8; ++i)
  {
    h.Dim[i] = Field<std::int16_t>(bytes, 40 + 2 * i, swap);
    h.PixDim[i] = Field<float>(bytes, 76 + 4 * i, swap);
  }
  h.VoxOffset = Field<float>(bytes, 108, swap);
  // Analyze 7.5 has no scale and no orientation (VTK's reader ignores those
  // bytes too).
  if (nifti1)
  {
    h.Slope = Field<float>(bytes, 112, swap);
    h.Intercept = Field<float>(bytes, 116, swap);
    h.TOffset = Field<float>(bytes, 136, swap);
    h.QFormCode = Field<std::int16_t>(bytes, 252, swap);
    h.SFormCode = Field<std::int16_t>(bytes, 254, swap);
    for (int i = 0; i < 3; ++i)
    {
      h.Quatern[i] = Field<float>(bytes, 256 + 4 * i, swap);
      h.QOffset[i] = Field<float>(bytes, 268 + 4 * i, swap);
      for (int c = 0; c < 4; ++c)
      {
        h.SRow[i][c] = Field<float>(bytes, 280 + 16 * i + 4 * c, swap);
      }
    }
  }
  return std::string();
}

std::string CheckNIfTIHeader(const NIfTIHeader& h, std::int64_t dims[8])
{
  std::ostringstream msg;
  const std::int64_t ndim = h.Dim[0];
  if (ndim < 1 || ndim > 7)
  {
    msg << "dim[0] (the number of dimensions) is " << ndim << "; NIfTI allows 1 to 7";
    return msg.str();
  }
  dims[0] = ndim;
  for (int i = 1; i < 8; ++i)
  {
    dims[i] = 1;
  }
  for (int i = 1; i <= ndim; ++i)
  {
    if (h.Dim[i] < 1)
    {
      msg << "dim[" << i << "] is " << h.Dim[i] << "; every dimension must be at least 1";
      return msg.str();
    }
    if (h.Dim[i] > std::numeric_limits<int>::max())
    {
      msg << "dim[" << i << "] is " << h.Dim[i] << ", more than a VTK extent holds ("
          << std::numeric_limits<int>::max() << ")";
      return msg.str();
    }
    dims[i] = h.Dim[i];
  }
  for (int i = 5; i <= 7; ++i)
  {
    if (dims[i] > 1)
    {
      msg << "dim[" << i << "] is " << dims[i]
          << ": vectors and dimensions beyond time (dim[5..7] above 1) are not "
             "read";
      return msg.str();
    }
  }
  const NIfTIDataType* type = FindNIfTIDataType(h.DataType);
  if (!type)
  {
    msg << "datatype code " << h.DataType << " is not a NIfTI datatype";
    return msg.str();
  }
  if (!type->Real)
  {
    msg << "datatype " << type->Name << " (" << type->Code
        << ") is not read: one real number per voxel is needed";
    return msg.str();
  }
  if (h.BitPix != type->Bits)
  {
    msg << "bitpix is " << h.BitPix << " but datatype " << type->Name << " has " << type->Bits
        << " bits per voxel";
    return msg.str();
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(h.PixDim[a + 1]))
    {
      msg << "pixdim[" << a + 1 << "] (the spacing along " << AxisName(a) << ") is "
          << h.PixDim[a + 1];
      return msg.str();
    }
  }
  const double minOffset =
    h.SingleFile ? (h.Version == 2 ? NIfTI2HeaderBytes : NIfTI1HeaderBytes) : 0;
  if (!std::isfinite(h.VoxOffset) || h.VoxOffset < minOffset ||
    h.VoxOffset != std::floor(h.VoxOffset) || h.VoxOffset > 9.0e18)
  {
    msg << "vox_offset is " << h.VoxOffset;
    if (h.SingleFile)
    {
      msg << "; the voxels of a single-file NIfTI-" << h.Version << " image start after its "
          << minOffset << "-byte header";
    }
    else
    {
      msg << ": not a byte offset";
    }
    return msg.str();
  }
  return std::string();
}

long double NIfTIVolumeBytes(const NIfTIHeader& h, const std::int64_t dims[8])
{
  const NIfTIDataType* type = FindNIfTIDataType(h.DataType);
  const long double bytesPerVoxel = type ? type->Bits / 8 : 0;
  return static_cast<long double>(dims[1]) * dims[2] * dims[3] * bytesPerVoxel;
}

bool NIfTICalibration(
  const NIfTIHeader& h, double& slope, double& intercept, std::vector<std::string>& warnings)
{
  slope = h.Slope;
  intercept = h.Intercept;
  if (!std::isfinite(slope))
  {
    std::ostringstream msg;
    msg << "scl_slope is " << slope << "; the voxels are read unscaled.";
    warnings.push_back(msg.str());
    slope = 0.0;
  }
  if (slope != 0.0 && !std::isfinite(intercept))
  {
    std::ostringstream msg;
    msg << "scl_inter is " << intercept << "; 0 is used.";
    warnings.push_back(msg.str());
    intercept = 0.0;
  }
  const bool scaled = slope != 0.0 && (slope != 1.0 || intercept != 0.0);
  if (!scaled)
  {
    slope = 1.0;
    intercept = 0.0;
  }
  return scaled;
}

ScalarType NIfTICalibratedType(int code, double slope, double intercept)
{
  double lo = 0.0, hi = 0.0;
  bool small = true;
  switch (code)
  {
    case 256: // INT8
      lo = -128.0;
      hi = 127.0;
      break;
    case 2: // UINT8
      hi = 255.0;
      break;
    case 4: // INT16
      lo = -32768.0;
      hi = 32767.0;
      break;
    case 512: // UINT16
      hi = 65535.0;
      break;
    default:
      small = false;
  }
  if (small && slope == 1.0 && intercept == std::floor(intercept))
  {
    if (lo + intercept >= -32768.0 && hi + intercept <= 32767.0)
    {
      return ScalarType::Int16;
    }
    if (lo + intercept >= -2147483648.0 && hi + intercept <= 2147483647.0)
    {
      return ScalarType::Int32;
    }
  }
  return (small || code == 16) ? ScalarType::Float32 : ScalarType::Float64;
}

void NIfTIPlacement(
  const NIfTIHeader& h, NIfTIPlacementResult& p, std::vector<std::string>& warnings)
{
  // VTK's reader: spacing pixdim[1..3] (0 read as 1), origin 0, and a matrix M
  // from its data coordinates to RAS whose translation is the origin and
  // rotation the direction.
  double pixdim[3];
  for (int a = 0; a < 3; ++a)
  {
    pixdim[a] = h.PixDim[a + 1] == 0.0 ? 1.0 : h.PixDim[a + 1];
  }
  double m[3][4] = { { 1, 0, 0, 0 }, { 0, 1, 0, 0 }, { 0, 0, 1, 0 } };
  const std::int64_t slices = h.Dim[0] >= 3 ? h.Dim[3] : 1;
  bool reverse = false;
  p.Placement = "none";
  double q[3][3] = {};
  const bool qform = h.Version > 0 && h.QFormCode > 0;
  if (qform)
  {
    // The rotation of the unit quaternion (a, b, c, d), a from the other three.
    const double b = h.Quatern[0], c = h.Quatern[1], d = h.Quatern[2];
    double a = 1.0 - b * b - c * c - d * d;
    a = a > 0.0 ? std::sqrt(a) : 0.0;
    const double n = a * a + b * b + c * c + d * d;
    const double f = 2.0 / n, s = (a * a - b * b - c * c - d * d) / n;
    q[0][0] = b * b * f + s;
    q[0][1] = (b * c - a * d) * f;
    q[0][2] = (b * d + a * c) * f;
    q[1][0] = (b * c + a * d) * f;
    q[1][1] = c * c * f + s;
    q[1][2] = (c * d - a * b) * f;
    q[2][0] = (b * d - a * c) * f;
    q[2][1] = (c * d + a * b) * f;
    q[2][2] = d * d * f + s;
    // Values within rounding of 0 are 0, and each row a unit vector (as VTK
    // does).
    for (auto& row : q)
    {
      double norm = 0.0;
      for (double& v : row)
      {
        v = std::fabs(v) < 2.384185791015625e-07 ? 0.0 : v;
        norm += v * v;
      }
      norm = std::sqrt(norm);
      for (double& v : row)
      {
        v = norm > 0.0 ? v / norm : v;
      }
    }
    reverse = h.PixDim[0] < 0.0;
  }
  if (h.Version > 0 && h.SFormCode > 0)
  {
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        m[r][c] = h.SRow[r][c] / pixdim[c];
      }
      m[r][3] = h.SRow[r][3];
    }
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
      m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
      m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (det < 0.0 && !qform)
    {
      reverse = true;
    }
    if (reverse)
    {
      for (int r = 0; r < 3; ++r)
      {
        m[r][2] = -m[r][2];
        m[r][3] += h.SRow[r][2] * static_cast<double>(slices - 1);
      }
    }
    const double turned = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
      m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
      m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (turned < 0.0)
    {
      // qfac -1 reversed the slices, and the sform did not expect it (VTK warns too).
      warnings.push_back("the sform is a mirror image of the qform (qfac -1); the sform is used.");
    }
    p.Placement = "sform";
  }
  else if (qform)
  {
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        m[r][c] = q[r][c];
      }
      m[r][3] =
        h.QOffset[r] - (reverse ? q[r][2] * pixdim[2] * static_cast<double>(slices - 1) : 0.0);
    }
    p.Placement = "qform";
  }
  p.ReverseSlices = reverse;
  for (int r = 0; r < 3; ++r)
  {
    p.Origin[r] = m[r][3];
    for (int c = 0; c < 3; ++c)
    {
      p.Direction[3 * r + c] = m[r][c];
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    p.Spacing[a] = pixdim[a];
    std::ostringstream msg;
    if (h.PixDim[a + 1] == 0.0)
    {
      msg << "pixdim[" << a + 1 << "] (the spacing along " << AxisName(a)
          << ") is 0; a spacing of 1 is used.";
      warnings.push_back(msg.str());
    }
    else if (pixdim[a] < 0.0)
    {
      p.Spacing[a] = -pixdim[a];
      for (int r = 0; r < 3; ++r)
      {
        p.Direction[3 * r + a] = -p.Direction[3 * r + a];
      }
      msg << "pixdim[" << a + 1 << "] (the spacing along " << AxisName(a) << ") is "
          << h.PixDim[a + 1] << "; a spacing of " << p.Spacing[a]
          << " is used, along the reversed axis.";
      warnings.push_back(msg.str());
    }
  }
}

bool ReadNIfTI(const unsigned char* bytes, std::size_t size, NIfTIImage& image, std::string& error)
{
  NIfTIHeader h;
  error = ParseNIfTIHeader(bytes, std::min<std::size_t>(size, NIfTI2HeaderBytes), h);
  std::int64_t dims[8] = {};
  if (error.empty())
  {
    error = CheckNIfTIHeader(h, dims);
  }
  if (!error.empty())
  {
    return false;
  }
  if (!h.SingleFile)
  {
    error = "a .hdr/.img pair (or an Analyze 7.5 header) is not read here: it "
            "needs its .img "
            "file; open it through the server";
    return false;
  }
  const NIfTIDataType* type = FindNIfTIDataType(h.DataType);
  const long double volumeBytes = NIfTIVolumeBytes(h, dims);
  const long double needed = volumeBytes + h.VoxOffset;
  if (needed > static_cast<long double>(size))
  {
    std::ostringstream msg;
    msg << "the header describes " << dims[1] << " x " << dims[2] << " x " << dims[3] << " "
        << type->Name << " voxels (";
    if (needed > 9.0e18L)
    {
      msg << "more than 9e18 bytes";
    }
    else
    {
      msg << static_cast<std::uint64_t>(volumeBytes) << " bytes from byte "
          << static_cast<std::uint64_t>(h.VoxOffset);
    }
    msg << "), but the file holds only " << size << " bytes";
    error = msg.str();
    return false;
  }
  double slope = 1.0, intercept = 0.0;
  const bool scaled = NIfTICalibration(h, slope, intercept, image.Warnings);
  if (!scaled && !type->Stored)
  {
    error = std::string("datatype ") + type->Name +
      " is not read here (the page's cores take "
      "8-, 16- and 32-bit integers and floats)";
    return false;
  }
  image.Type = scaled ? NIfTICalibratedType(type->Code, slope, intercept) : type->Type;
  NIfTIPlacement(h, image.Placement, image.Warnings);
  for (int a = 0; a < 3; ++a)
  {
    image.Dimensions[a] = static_cast<int>(dims[a + 1]);
  }
  const std::size_t stored = static_cast<std::size_t>(type->Bits / 8);
  const std::size_t out = static_cast<std::size_t>(ScalarTypeSize(image.Type));
  const std::size_t slice = static_cast<std::size_t>(dims[1]) * static_cast<std::size_t>(dims[2]);
  const std::size_t nz = static_cast<std::size_t>(dims[3]);
  // Calibration may widen the values (uint8 to float32): within what this process addresses
  // (a 32-bit size_t in the page's WebAssembly).
  const long double outBytes = volumeBytes / static_cast<long double>(stored) * out;
  if (outBytes > static_cast<long double>(std::numeric_limits<std::size_t>::max() / 2))
  {
    std::ostringstream msg;
    msg << "its " << ScalarTypeName(image.Type) << " values would take " << outBytes
        << " bytes, more than this process can address";
    error = msg.str();
    return false;
  }
  try
  {
    image.Bytes.resize(slice * nz * out);
  }
  catch (const std::bad_alloc&)
  {
    error = "memory ran out while reading the voxels";
    return false;
  }
  const unsigned char* voxels = bytes + static_cast<std::size_t>(h.VoxOffset);
  unsigned char value[8];
  for (std::size_t k = 0; k < nz; ++k)
  {
    const std::size_t fileSlice = image.Placement.ReverseSlices ? nz - 1 - k : k;
    const unsigned char* in = voxels + fileSlice * slice * stored;
    unsigned char* o = image.Bytes.data() + k * slice * out;
    for (std::size_t i = 0; i < slice; ++i, in += stored, o += out)
    {
      std::memcpy(value, in, stored);
      if (h.Swap)
      {
        std::reverse(value, value + stored);
      }
      if (!scaled)
      {
        std::memcpy(o, value, stored);
        continue;
      }
      const double v = StoredValue(type->Code, value) * slope + intercept;
      VisitScalarType(image.Type,
        [&](auto tag)
        {
          using T = decltype(tag);
          const T t = static_cast<T>(v);
          std::memcpy(o, &t, sizeof(T));
        });
    }
  }
  return true;
}

} // namespace mediso
