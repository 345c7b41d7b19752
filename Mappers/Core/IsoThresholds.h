// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file IsoThresholds.h
 * @brief Isovalues as exact thresholds of a volume's own value type (no VTK, no GL).
 *
 * The GPU compares a volume's values in their own type (int, uint or float
 * in GLSL), while the CPU model and the filters compare in double. For every
 * value v of the type, a threshold t is chosen with (v < t) == (v < iso) and
 * (t <= v) == (iso <= v): ceil(iso) for integer data, the smallest float not
 * below iso for float data. The crossing test min < t <= max on the GPU is
 * then exactly min < iso <= max in double precision. Isovalues that cannot
 * cross any cell of the type's range, and NaN ones, are left out; Indices
 * says which isovalue each threshold stands for.
 */
#ifndef MedicalIsosurfaces_IsoThresholds_h
#define MedicalIsosurfaces_IsoThresholds_h

#include "ScalarTypes.h"

#include <cstdint>
#include <string>
#include <vector>

namespace mediso
{

/// How the GPU compares a type's values: as int, uint or float.
enum class ValueKind
{
  Signed,
  Unsigned,
  Float
};

/// The GLSL value kind of a scalar type (double data goes to the GPU as float).
ValueKind ValueKindOf(ScalarType type);

/// The GLSL #defines of a value kind (VALUE_SAMPLER, VALUE_TYPE, VALUE_VEC4, VALUE_IS_FLOAT).
std::string ValueKindDefines(ValueKind kind);

struct IsoThresholds
{
  ValueKind Kind = ValueKind::Float;
  std::vector<std::int32_t> Ints;   // Kind == Signed
  std::vector<std::uint32_t> UInts; // Kind == Unsigned
  std::vector<float> Floats;        // Kind == Float
  std::vector<int> Indices;         // isovalue index of each threshold, increasing
  int Count = 0;

  /// Whether a value range [lo, hi] (in the kind's type, as double) holds a threshold t with lo < t <= hi.
  bool Crosses(double lo, double hi) const;
};

/// The thresholds of `isovalues` for data of `type`.
IsoThresholds MakeIsoThresholds(ScalarType type, const std::vector<double>& isovalues);

} // namespace mediso

#endif
