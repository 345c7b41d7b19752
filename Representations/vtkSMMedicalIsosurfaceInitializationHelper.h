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
 * - for an array in Hounsfield units: skin (-500 HU) and bone (400 HU);
 * - otherwise: one surface at Otsu's threshold of the array's histogram;
 *
 * (vtkSMMedicalIsovaluesDomain::StartValues chooses). Where neither applies
 * ParaView's default stays. Only the values: colours and opacities stay as
 * they were, so a script that sets IsosurfaceValues draws what it drew before.
 *
 * The HU start is marked with the display annotation StartAnnotation(). The
 * isosurface list in the GUI (pqMedicalIsosurfaceListWidget) finds it on a
 * display still at the start and gives skin and bone their look
 * (GetSkinAndBone(): skin colour at opacity 0.35 over opaque bone, Color
 * Each Surface on), so that opening a CT and choosing the representation
 * shows skin over bone.
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

  /// The display annotation that marks a display started at skin and bone.
  static const char* StartAnnotation() { return "MedicalIsosurfaceStart"; }

  /// Skin's and bone's values (HU), colours (r, g, b each) and opacities, as the start shows them.
  static void GetSkinAndBone(double values[2], double colors[6], double opacities[2]);

protected:
  vtkSMMedicalIsosurfaceInitializationHelper();
  ~vtkSMMedicalIsosurfaceInitializationHelper() override;

private:
  vtkSMMedicalIsosurfaceInitializationHelper(
    const vtkSMMedicalIsosurfaceInitializationHelper&) = delete;
  void operator=(const vtkSMMedicalIsosurfaceInitializationHelper&) = delete;
};

#endif
