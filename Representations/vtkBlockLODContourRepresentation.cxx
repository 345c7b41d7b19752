// SPDX-License-Identifier: BSD-3-Clause
#include "vtkBlockLODContourRepresentation.h"

#include "vtkObjectFactory.h"

vtkStandardNewMacro(vtkBlockLODContourRepresentation);

//------------------------------------------------------------------------------
vtkBlockLODContourRepresentation::vtkBlockLODContourRepresentation() = default;
vtkBlockLODContourRepresentation::~vtkBlockLODContourRepresentation() = default;

//------------------------------------------------------------------------------
void vtkBlockLODContourRepresentation::AddRepresentation(const char* key,
  vtkPVDataRepresentation* repr)
{
  if (key && repr)
  {
    this->RemoveRepresentation(key); // nothing when the key is new
  }
  this->Superclass::AddRepresentation(key, repr);
}

//------------------------------------------------------------------------------
void vtkBlockLODContourRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
