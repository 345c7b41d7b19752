// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file NIfTITestFiles.h
 * @brief The NIfTI header the NIfTI tests write (standard C++ only): one
 * writer for NIfTI-1 and NIfTI-2, either byte order, with every field those
 * tests vary, so that a field's offset and type are stated once.
 *
 * The reader tests (TestMedicalNIfTIReaderCorpus, TestNIfTIImageMatchesReader)
 * build each case as an NIfTIFields with a few fields changed from the
 * defaults (a 4x3x2 int16 volume of spacing 0.5 x 0.75 x 2, no placement),
 * take NIfTIHeader() and append the voxels they need (or cut the bytes, for
 * the malformed cases). The Python tests have the same writer in
 * Testing/Python/nifti.py, the page's tests in webserver-harness.mjs.
 */
#ifndef NIfTITestFiles_h
#define NIfTITestFiles_h

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace medical_test
{
/// The header fields the tests vary; every other field is zero.
struct NIfTIFields
{
  int Version = 1; ///< 1 (348-byte header) or 2 (540 bytes)
  std::int64_t Dim[8] = { 3, 4, 3, 2, 1, 1, 1, 1 };
  double PixDim[8] = { 1.0, 0.5, 0.75, 2.0, 1.0, 1.0, 1.0, 1.0 };
  int SizeOfHeader = 0; ///< 0: the version's (a wrong one for the refusal cases)
  int DataType = 4;     ///< NIFTI_TYPE_INT16
  int BitPix = 16;
  double VoxOffset = -1.0; ///< -1: just after the header and its 4 extension bytes
  double Slope = 0.0;
  double Intercept = 0.0;
  double TOffset = 0.0;
  int QFormCode = 0;
  int SFormCode = 0;
  double Quatern[3] = { 0, 0, 0 }; ///< quatern_b, c, d
  double QOffset[3] = { 0, 0, 0 };
  double SRow[3][4] = { { 0, 0, 0, 0 }, { 0, 0, 0, 0 }, { 0, 0, 0, 0 } };
  bool BigEndian = false;
};

/// `value` stored at `offset` of `bytes`, byte-reversed when `swap` (the other byte order).
template <typename T>
void PutBytes(std::vector<unsigned char>& bytes, std::size_t offset, T value, bool swap)
{
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (swap)
  {
    std::reverse(raw, raw + sizeof(T));
  }
  std::copy(raw, raw + sizeof(T), bytes.begin() + static_cast<std::ptrdiff_t>(offset));
}

/// The header of `f` and its 4 extension bytes (none), as a single file (.nii) begins.
inline std::vector<unsigned char> NIfTIHeader(const NIfTIFields& f)
{
  const bool two = f.Version == 2;
  const std::size_t size = two ? 540 : 348;
  std::vector<unsigned char> b(size + 4, 0);
  const bool s = f.BigEndian;
  const double voxOffset = f.VoxOffset < 0 ? static_cast<double>(size + 4) : f.VoxOffset;
  PutBytes<std::int32_t>(
    b, 0, f.SizeOfHeader ? f.SizeOfHeader : static_cast<std::int32_t>(size), s);
  if (two)
  {
    std::memcpy(b.data() + 4, "n+2\0\r\n\032\n", 8);
    PutBytes<std::int16_t>(b, 12, static_cast<std::int16_t>(f.DataType), s);
    PutBytes<std::int16_t>(b, 14, static_cast<std::int16_t>(f.BitPix), s);
    for (int i = 0; i < 8; ++i)
    {
      PutBytes<std::int64_t>(b, 16 + 8 * i, f.Dim[i], s);
      PutBytes<double>(b, 104 + 8 * i, f.PixDim[i], s);
    }
    PutBytes<std::int64_t>(b, 168, static_cast<std::int64_t>(voxOffset), s);
    PutBytes<double>(b, 176, f.Slope, s);
    PutBytes<double>(b, 184, f.Intercept, s);
    PutBytes<double>(b, 216, f.TOffset, s);
    PutBytes<std::int32_t>(b, 344, f.QFormCode, s);
    PutBytes<std::int32_t>(b, 348, f.SFormCode, s);
    for (int i = 0; i < 3; ++i)
    {
      PutBytes<double>(b, 352 + 8 * i, f.Quatern[i], s);
      PutBytes<double>(b, 376 + 8 * i, f.QOffset[i], s);
      for (int c = 0; c < 4; ++c)
      {
        PutBytes<double>(b, 400 + 32 * i + 8 * c, f.SRow[i][c], s);
      }
    }
  }
  else
  {
    for (int i = 0; i < 8; ++i)
    {
      PutBytes<std::int16_t>(b, 40 + 2 * i, static_cast<std::int16_t>(f.Dim[i]), s);
      PutBytes<float>(b, 76 + 4 * i, static_cast<float>(f.PixDim[i]), s);
    }
    PutBytes<std::int16_t>(b, 70, static_cast<std::int16_t>(f.DataType), s);
    PutBytes<std::int16_t>(b, 72, static_cast<std::int16_t>(f.BitPix), s);
    PutBytes<float>(b, 108, static_cast<float>(voxOffset), s);
    PutBytes<float>(b, 112, static_cast<float>(f.Slope), s);
    PutBytes<float>(b, 116, static_cast<float>(f.Intercept), s);
    PutBytes<float>(b, 136, static_cast<float>(f.TOffset), s);
    PutBytes<std::int16_t>(b, 252, static_cast<std::int16_t>(f.QFormCode), s);
    PutBytes<std::int16_t>(b, 254, static_cast<std::int16_t>(f.SFormCode), s);
    for (int i = 0; i < 3; ++i)
    {
      PutBytes<float>(b, 256 + 4 * i, static_cast<float>(f.Quatern[i]), s);
      PutBytes<float>(b, 268 + 4 * i, static_cast<float>(f.QOffset[i]), s);
      for (int c = 0; c < 4; ++c)
      {
        PutBytes<float>(b, 280 + 16 * i + 4 * c, static_cast<float>(f.SRow[i][c]), s);
      }
    }
    std::memcpy(b.data() + 344, "n+1", 4);
  }
  return b;
}
} // namespace medical_test

#endif
