// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkBlockLODContourRepresentation
 * @brief   The display of a vtkBlockLODContour output in ParaView's render
 *          view: ParaView's geometry display with its surface types drawn by
 *          vtkBlockLODSurfaceRepresentation.
 *
 * The ServerManager XML defines this display (BlockLODContourRepresentation)
 * as ParaView's GeometryRepresentation with four more RepresentationType
 * entries, "Points", "Wireframe", "Surface" and "Surface With Edges", that
 * name vtkBlockLODSurfaceRepresentation instead of the base's surface
 * representation. ParaView adds the entries in order, so the derived ones
 * replace the base's; vtkCompositeRepresentation warns on every such
 * replacement, which here is the design, not a mistake: this class replaces
 * without the warning. Nothing else differs from vtkPVCompositeRepresentation.
 *
 * @sa vtkBlockLODSurfaceRepresentation vtkPVCompositeRepresentation
 */
#ifndef vtkBlockLODContourRepresentation_h
#define vtkBlockLODContourRepresentation_h

#include "MedicalIsosurfacesRepresentationsModule.h" // For export macro
#include "vtkPVCompositeRepresentation.h"

class MEDICALISOSURFACESREPRESENTATIONS_EXPORT vtkBlockLODContourRepresentation
  : public vtkPVCompositeRepresentation
{
public:
  static vtkBlockLODContourRepresentation* New();
  vtkTypeMacro(vtkBlockLODContourRepresentation, vtkPVCompositeRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * As vtkCompositeRepresentation's, except that a key already present is
   * replaced silently (the derived proxy's types replace the base's).
   */
  void AddRepresentation(const char* key, vtkPVDataRepresentation* repr) override;

protected:
  vtkBlockLODContourRepresentation();
  ~vtkBlockLODContourRepresentation() override;

private:
  vtkBlockLODContourRepresentation(const vtkBlockLODContourRepresentation&) = delete;
  void operator=(const vtkBlockLODContourRepresentation&) = delete;
};

#endif
