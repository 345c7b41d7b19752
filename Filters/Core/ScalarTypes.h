// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file ScalarTypes.h
 * @brief The scalar types the VTK-free core algorithms are compiled for: the
 * point-data types of the images the filters and mappers accept.
 */
#ifndef MedicalIsosurfaces_ScalarTypes_h
#define MedicalIsosurfaces_ScalarTypes_h

#include <cstdint>

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

#endif
