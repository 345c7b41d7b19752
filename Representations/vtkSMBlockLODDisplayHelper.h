// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkSMBlockLODDisplayHelper
 * @brief   Shows Block LOD Contour's output with its own display where the
 *          client can create it, and with ParaView's where it cannot.
 *
 * A render view shows a source's output with the representation proxy its
 * hints name (`<Representation view="RenderView" type="..."/>`), else with
 * ParaView's GeometryRepresentation. Block LOD Contour's own display
 * (BlockLODContourRepresentation: the geometry display whose surface types
 * draw a coarser level while the camera moves, vtkBlockLODSurfaceRepresentation)
 * has classes of this plugin on every process of the view, the client
 * included; a client that has only the plugin's proxy definitions (the plugin
 * loaded on the server alone) cannot create them, and ParaView aborts when a
 * proxy's class is missing. So the filter does not name its display in its
 * static hints; this helper, named in them,
 * @code{.xml}
 *   <InitializationHelper class="vtkSMBlockLODDisplayHelper"
 *                         view="RenderView" type="BlockLODContourRepresentation" />
 * @endcode
 * adds that Representation hint to the new filter proxy when it runs, which is
 * only where its own class, and so the display's, can be created (ParaView
 * skips a helper class the client does not know). A client without the
 * library keeps ParaView's geometry display and its decimated LOD, as before.
 */
#ifndef vtkSMBlockLODDisplayHelper_h
#define vtkSMBlockLODDisplayHelper_h

#include "MedicalIsosurfacesRepresentationsModule.h" // for export macro
#include "vtkSMProxyInitializationHelper.h"

class MEDICALISOSURFACESREPRESENTATIONS_EXPORT vtkSMBlockLODDisplayHelper
  : public vtkSMProxyInitializationHelper
{
public:
  static vtkSMBlockLODDisplayHelper* New();
  vtkTypeMacro(vtkSMBlockLODDisplayHelper, vtkSMProxyInitializationHelper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Adds `<Representation view="..." type="..."/>` (the helper element's
   * attributes) to the proxy's hints, unless they already name a
   * representation for that view.
   */
  void PostInitializeProxy(vtkSMProxy* proxy,
    vtkPVXMLElement* xml,
    vtkMTimeType initializationTimeStamp) override;

protected:
  vtkSMBlockLODDisplayHelper();
  ~vtkSMBlockLODDisplayHelper() override;

private:
  vtkSMBlockLODDisplayHelper(const vtkSMBlockLODDisplayHelper&) = delete;
  void operator=(const vtkSMBlockLODDisplayHelper&) = delete;
};

#endif
