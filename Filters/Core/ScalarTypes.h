// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file ScalarTypes.h
 * @brief The scalar types the VTK-free core algorithms are compiled for: the
 * point-data types of the images the filters and mappers accept.
 */
#ifndef MedicalIsosurfaces_ScalarTypes_h
#define MedicalIsosurfaces_ScalarTypes_h

#include <cstdint>
#include <type_traits>

/// Applies MACRO(T); to every supported scalar type (for explicit instantiation).
#define MEDISO_FOR_EACH_SCALAR_TYPE(MACRO)                                                         \
  MACRO(std::int8_t);                                                                              \
  MACRO(std::uint8_t);                                                                             \
  MACRO(std::int16_t);                                                                             \
  MACRO(std::uint16_t);                                                                            \
  MACRO(std::int32_t);                                                                             \
  MACRO(std::uint32_t);                                                                            \
  MACRO(float);                                                                                    \
  MACRO(double)

namespace mediso
{
/// The scalar types as a value, for hosts that describe their data at run time.
enum class ScalarType
{
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Float32,
  Float64
};

/// The ScalarType of T (T one of MEDISO_FOR_EACH_SCALAR_TYPE's types).
template <typename T>
constexpr ScalarType ScalarTypeOf()
{
  static_assert(std::is_arithmetic<T>::value, "not a scalar type");
  if (std::is_floating_point<T>::value)
  {
    return sizeof(T) == 4 ? ScalarType::Float32 : ScalarType::Float64;
  }
  switch (sizeof(T))
  {
    case 1:
      return std::is_signed<T>::value ? ScalarType::Int8 : ScalarType::UInt8;
    case 2:
      return std::is_signed<T>::value ? ScalarType::Int16 : ScalarType::UInt16;
    default:
      return std::is_signed<T>::value ? ScalarType::Int32 : ScalarType::UInt32;
  }
}

/// Calls f(T{}) with the C++ type of `type`; false (f not called) for an
/// unknown value.
template <typename F>
bool VisitScalarType(ScalarType type, F&& f)
{
  switch (type)
  {
    case ScalarType::Int8:
      f(std::int8_t{});
      return true;
    case ScalarType::UInt8:
      f(std::uint8_t{});
      return true;
    case ScalarType::Int16:
      f(std::int16_t{});
      return true;
    case ScalarType::UInt16:
      f(std::uint16_t{});
      return true;
    case ScalarType::Int32:
      f(std::int32_t{});
      return true;
    case ScalarType::UInt32:
      f(std::uint32_t{});
      return true;
    case ScalarType::Float32:
      f(float{});
      return true;
    case ScalarType::Float64:
      f(double{});
      return true;
  }
  return false;
}

/// The name of `type` as the hosts write it where their languages meet (the web
/// server's X-Mediso-Type header, the page's volume loading): "int8", "uint8",
/// "int16", "uint16", "int32", "uint32", "float32", "float64"; "" for an
/// unknown value.
inline const char* ScalarTypeName(ScalarType type)
{
  switch (type)
  {
    case ScalarType::Int8:
      return "int8";
    case ScalarType::UInt8:
      return "uint8";
    case ScalarType::Int16:
      return "int16";
    case ScalarType::UInt16:
      return "uint16";
    case ScalarType::Int32:
      return "int32";
    case ScalarType::UInt32:
      return "uint32";
    case ScalarType::Float32:
      return "float32";
    case ScalarType::Float64:
      return "float64";
  }
  return "";
}

/// Bytes of one value of `type` (0 for an unknown value).
inline int ScalarTypeSize(ScalarType type)
{
  int size = 0;
  VisitScalarType(type, [&](auto v) { size = static_cast<int>(sizeof(v)); });
  return size;
}
} // namespace mediso

#endif
