// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file MetaImage.h
 * @brief Reads an uncompressed 3D MetaImage (.mha, or .mhd + raw data) without VTK or ITK.
 *
 * The header is `Key = Value` lines; the ones read are ObjectType (Image),
 * NDims (3), DimSize, ElementType (MET_CHAR, MET_UCHAR, MET_SHORT,
 * MET_USHORT, MET_INT, MET_UINT, MET_FLOAT, MET_DOUBLE; MET_LONG/ULONG when
 * 4 bytes), ElementNumberOfChannels (1), ElementSpacing (or ElementSize),
 * Offset (or Origin, Position), TransformMatrix (or Rotation, Orientation;
 * the columns are the image axes), BinaryDataByteOrderMSB (or
 * ElementByteOrderMSB), CompressedData (must be False), HeaderSize and
 * ElementDataFile (LOCAL: the data follows the header; else a file beside
 * the header). Everything is checked against the file before any large
 * allocation, and every problem is reported with the file's name.
 */
#ifndef MedicalIsosurfaces_MetaImage_h
#define MedicalIsosurfaces_MetaImage_h

#include "ScalarTypes.h"

#include <cstdint>
#include <string>
#include <vector>

namespace mediso
{
namespace headless
{

struct MetaImage
{
  int Dimensions[3] = { 0, 0, 0 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  double Origin[3] = { 0.0, 0.0, 0.0 };
  /// Row-major 3x3: column a is the direction of image axis a.
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  ScalarType Type = ScalarType::UInt8;
  std::vector<unsigned char> Bytes; ///< the values, x fastest, in the machine's byte order

  std::int64_t GetNumberOfPoints() const
  {
    return static_cast<std::int64_t>(this->Dimensions[0]) * this->Dimensions[1] * this->Dimensions[2];
  }
  /// Least and greatest value, NaN left out (lo > hi when there is none).
  void GetRange(double range[2]) const;
};

/// Reads `path` into `image`; false with the reason in @a error.
bool ReadMetaImage(const std::string& path, MetaImage& image, std::string& error);

/// Writes `image` to `path` as an uncompressed .mha (data LOCAL, in the machine's byte order).
bool WriteMetaImage(const std::string& path, const MetaImage& image, std::string& error);

/// The type's MetaImage name ("MET_SHORT").
const char* MetaElementType(ScalarType type);

} // namespace headless
} // namespace mediso

#endif
