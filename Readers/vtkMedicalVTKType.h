// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkMedicalVTKType.h
 * @brief The VTK array type of a VTK-free core's scalar type (mediso::ScalarType), for the
 * readers that fill VTK arrays with what the shared reader cores (Readers/Core) decide: the
 * DICOM series reader's rescaled type and the NIfTI reader's calibrated type. The other way,
 * VTK to core, is Filters/vtkMedicalCoreScalarType.h.
 */
#ifndef vtkMedicalVTKType_h
#define vtkMedicalVTKType_h

#include "ScalarTypes.h" // mediso::ScalarType
#include "vtkType.h"     // VTK_SHORT and the other type constants

/// The VTK type holding values of `type` (VTK_DOUBLE for Float64).
inline int vtkMedicalVTKType(mediso::ScalarType type)
{
  switch (type)
  {
    case mediso::ScalarType::Int8:
      return VTK_SIGNED_CHAR;
    case mediso::ScalarType::UInt8:
      return VTK_UNSIGNED_CHAR;
    case mediso::ScalarType::Int16:
      return VTK_SHORT;
    case mediso::ScalarType::UInt16:
      return VTK_UNSIGNED_SHORT;
    case mediso::ScalarType::Int32:
      return VTK_INT;
    case mediso::ScalarType::UInt32:
      return VTK_UNSIGNED_INT;
    case mediso::ScalarType::Float32:
      return VTK_FLOAT;
    default:
      return VTK_DOUBLE;
  }
}

#endif
