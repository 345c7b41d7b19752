// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkSMMedicalIsosurfaceInitializationHelper
 * @brief   Gives a new image display isosurfaces worth seeing before anyone
 * types a value.
 *
 * ParaView starts a volume display's IsosurfaceValues (shared by the Volume
 * and "HistoPyramid Isosurface" types) at the middle of the data range, which
 * for a CT is about 1000 HU: a ragged cap of cortical bone. This helper,
 * named by the plugin's extension of UniformGridRepresentation
 * (`<InitializationHelper
 * class="vtkSMMedicalIsosurfaceInitializationHelper"/>`), runs when ParaView
 * initialises a new image display (Show in pvpython, Apply in the GUI) and,
 * unless IsosurfaceValues was set during that initialisation, sets:
 *
 * - for an array in Hounsfield units: skin (-500 HU, skin colour, opacity
 *   0.35) over bone (400 HU, bone colour, opaque), Color Each Surface on;
 * - otherwise: one surface at Otsu's threshold of the array's histogram;
 *
 * (vtkSMMedicalIsovaluesDomain::StartValues chooses). Where neither applies
 * ParaView's default stays.
 *
 * The skin's colour and translucency belong to the start, not to whatever
 * values come next: the first time a script sets IsosurfaceValues to other
 * values, the colours, opacities and Color Each Surface the start set (if
 * still as set) return to their defaults, so a script that sets its own
 * isovalues draws exactly what it drew before the start existed. The
 * isosurface list in the GUI edits values, colours and opacities together and
 * so takes the start over (it removes the display's "MedicalIsosurfaceStart"
 * annotation, which keeps the start's look attached).
 */
#ifndef vtkSMMedicalIsosurfaceInitializationHelper_h
#define vtkSMMedicalIsosurfaceInitializationHelper_h

#include "MedicalIsosurfacesRepresentationsModule.h" // for export macro
#include "vtkSMProxyInitializationHelper.h"

class MEDICALISOSURFACESREPRESENTATIONS_EXPORT vtkSMMedicalIsosurfaceInitializationHelper
  : public vtkSMProxyInitializationHelper
{
public:
  static vtkSMMedicalIsosurfaceInitializationHelper* New();
  vtkTypeMacro(vtkSMMedicalIsosurfaceInitializationHelper, vtkSMProxyInitializationHelper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  void PostInitializeProxy(
    vtkSMProxy* proxy, vtkPVXMLElement* xml, vtkMTimeType initializationTimeStamp) override;

  /// The display annotation that keeps the start's colours and opacities
  /// attached to the start's values (see the class comment).
  static const char* StartAnnotation() { return "MedicalIsosurfaceStart"; }

protected:
  vtkSMMedicalIsosurfaceInitializationHelper();
  ~vtkSMMedicalIsosurfaceInitializationHelper() override;

private:
  vtkSMMedicalIsosurfaceInitializationHelper(
    const vtkSMMedicalIsosurfaceInitializationHelper&) = delete;
  void operator=(const vtkSMMedicalIsosurfaceInitializationHelper&) = delete;
};

#endif
