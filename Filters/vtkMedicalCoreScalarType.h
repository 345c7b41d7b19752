// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkMedicalCoreScalarType.h
 * @brief The VTK-free cores' scalar type (mediso::ScalarType) of a VTK array type, for the
 * filters and mappers that hand VTK arrays to them.
 */
#ifndef vtkMedicalCoreScalarType_h
#define vtkMedicalCoreScalarType_h

#include "ScalarTypes.h" // mediso::ScalarType
#include "vtkType.h"     // VTK_SHORT and the other type constants

#include <limits>

/// The core's scalar type of VTK array type `vtkType`; false for a type the cores do not take
/// (64-bit integers, strings, bits...). VTK_CHAR follows the platform's char signedness.
inline bool vtkMedicalCoreScalarType(int vtkType, mediso::ScalarType& type)
{
  switch (vtkType)
  {
    case VTK_CHAR:
      type = std::numeric_limits<char>::is_signed ? mediso::ScalarType::Int8 : mediso::ScalarType::UInt8;
      return true;
    case VTK_SIGNED_CHAR:
      type = mediso::ScalarType::Int8;
      return true;
    case VTK_UNSIGNED_CHAR:
      type = mediso::ScalarType::UInt8;
      return true;
    case VTK_SHORT:
      type = mediso::ScalarType::Int16;
      return true;
    case VTK_UNSIGNED_SHORT:
      type = mediso::ScalarType::UInt16;
      return true;
    case VTK_INT:
      type = mediso::ScalarType::Int32;
      return true;
    case VTK_UNSIGNED_INT:
      type = mediso::ScalarType::UInt32;
      return true;
    case VTK_FLOAT:
      type = mediso::ScalarType::Float32;
      return true;
    case VTK_DOUBLE:
      type = mediso::ScalarType::Float64;
      return true;
    default:
      return false;
  }
}

#endif
