// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file NIfTIImage.h
 * @brief NIfTI-1/2 headers checked, placed and calibrated without VTK: the
 * rules that vtkMedicalNIfTIReader (ParaView, the server) and the web page's
 * WebAssembly module (a file dropped on the page) share, so that a file is read
 * the same way, or refused with the same words, on every host.
 *
 * The work is done in four steps:
 *
 * 1. **The header** (ParseNIfTIHeader): 348 bytes for NIfTI-1 and Analyze 7.5,
 * 540 for NIfTI-2, in either byte order (found from sizeof_hdr); the fields
 * this code needs, in native byte order and NIfTI-2's widths.
 * 2. **The checks** (CheckNIfTIHeader), before anything is allocated: dim[0] 1
 * to 7; every dimension at least 1 and within an int; dim[5..7] at most 1 (no
 * vectors); a NIfTI datatype code, of one real number per voxel (BINARY,
 * COMPLEX*, RGB24, RGBA32 and FLOAT128 are named and refused); bitpix the
 * datatype's size; pixdim[1..3] finite; vox_offset a byte offset, after the
 * header in a single file. The file's length is the host's to check (it may be
 * gzipped): NIfTIVoxelBytes gives what it must hold.
 * 3. **Calibration** (NIfTICalibration, NIfTICalibratedType): scl_slope finite
 * and not 0, and not slope 1 with intercept 0, scales the values by a fixed
 * rule on the header (so that the type said before reading is the type
 * produced): slope 1, an integral intercept and a stored 8- or 16-bit integer
 * give integers, int16 when the stored range shifted fits, else int32;
 * otherwise float32 for stored 8- and 16-bit integers and FLOAT32, float64 for
 *    the rest.
 * 4. **Placement** (NIfTIPlacement), in the convention of VTK's
 * vtkNIFTIImageReader, which the ParaView reader uses: the sform when
 * sform_code > 0 (its columns divided by pixdim), else the qform when
 * qform_code > 0 (the quaternion's rotation, qoffset), else origin 0 and no
 *    rotation; world space RAS. When qfac (pixdim[0]) is negative with a qform,
 * or the sform's determinant is negative without one, the slices are stored in
 * reverse (index k is slice n - 1 - k of the file), the third column negated
 * and the origin moved to the last slice, so that the grid is right-handed. A
 * spacing of 0 is read as 1; a negative one as its magnitude with its axis
 * reversed.
 *
 * ReadNIfTI does all four on a whole single-file image (`.nii`, already
 * decompressed) held in memory: the page's path. A 4D file gives its first
 * volume.
 *
 * @sa vtkMedicalNIfTIReader, MetaImage.h
 */
#ifndef MedicalIsosurfaces_NIfTIImage_h
#define MedicalIsosurfaces_NIfTIImage_h

#include "ScalarTypes.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mediso
{

constexpr int NIfTI1HeaderBytes = 348;
constexpr int NIfTI2HeaderBytes = 540;

/// The fields of a NIfTI-1, NIfTI-2 or Analyze 7.5 header this code uses.
struct NIfTIHeader
{
  int Version = 0;         ///< 0: Analyze 7.5
  bool SingleFile = false; ///< magic "n+1"/"n+2": the voxels follow the header
                           ///< in the same file
  bool Swap = false;       ///< stored in the other byte order than this machine's
  std::int64_t Dim[8] = {};
  double PixDim[8] = {};
  int DataType = 0;
  int BitPix = 0;
  double VoxOffset = 0.0;
  double Slope = 0.0;
  double Intercept = 0.0;
  double TOffset = 0.0;
  int QFormCode = 0;
  int SFormCode = 0;
  double Quatern[3] = {}; ///< b, c, d
  double QOffset[3] = {}; ///< x, y, z
  double SRow[3][4] = {}; ///< srow_x, srow_y, srow_z
};

/// A NIfTI datatype code: its name, bits per voxel, and the scalar type of one
/// real value (or Stored false where the page's cores have none: INT64, UINT64,
/// and the refused ones).
struct NIfTIDataType
{
  int Code;
  const char* Name;
  int Bits;
  bool Real;       ///< one real number per voxel (else refused)
  bool Stored;     ///< Type holds the stored values
  ScalarType Type; ///< when Stored
};

/// The datatype of a code, or nullptr when the code is not NIfTI's.
const NIfTIDataType* FindNIfTIDataType(int code);

/// Step 1: the header from its first `got` bytes (at least 540 where there
/// are); "" or the reason it is not one.
std::string ParseNIfTIHeader(const unsigned char* bytes, std::size_t got, NIfTIHeader& header);

/// Step 2: "" when the header may be read, else the reason. `dims` gets
/// dim[0..7] with the dimensions beyond dim[0] set to 1.
std::string CheckNIfTIHeader(const NIfTIHeader& header, std::int64_t dims[8]);

/// Bytes of one 3D volume (long double: a header may describe more than 2^64).
long double NIfTIVolumeBytes(const NIfTIHeader& header, const std::int64_t dims[8]);

/// Step 3: whether the values are scaled, and by what (a non-finite slope: not
/// scaled; a non-finite intercept: 0); `warnings` gets a sentence for each of
/// those.
bool NIfTICalibration(
  const NIfTIHeader& header, double& slope, double& intercept, std::vector<std::string>& warnings);

/// Step 3: the scalar type of the calibrated values of a stored datatype.
ScalarType NIfTICalibratedType(int dataTypeCode, double slope, double intercept);

/// Step 4's result.
struct NIfTIPlacementResult
{
  double Origin[3] = { 0.0, 0.0, 0.0 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 }; ///< row-major, columns = axes (RAS)
  const char* Placement = "none";                      ///< "sform", "qform" or "none"
  bool ReverseSlices = false;                          ///< index k is the file's slice n-1-k
};

/// Step 4; `warnings` gets a sentence for a spacing of 0 or below.
void NIfTIPlacement(
  const NIfTIHeader& header, NIfTIPlacementResult& placement, std::vector<std::string>& warnings);

/// A single-file NIfTI image read whole: its grid (RAS), its calibrated values
/// and what was said.
struct NIfTIImage
{
  int Dimensions[3] = { 0, 0, 0 };
  NIfTIPlacementResult Placement;
  ScalarType Type = ScalarType::UInt8;
  std::vector<unsigned char> Bytes; ///< the values, x fastest, in the machine's byte order
  std::vector<std::string> Warnings;
};

/// Steps 1-4 on the bytes of a whole `.nii` (decompressed); false with the
/// reason in @a error (in the words vtkMedicalNIfTIReader uses, without the
/// file's name).
bool ReadNIfTI(const unsigned char* bytes, std::size_t size, NIfTIImage& image, std::string& error);

} // namespace mediso

#endif
