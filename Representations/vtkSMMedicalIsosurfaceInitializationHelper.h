// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkSMMedicalIsosurfaceInitializationHelper
 * @brief   Gives a new image display, or a new Block LOD Contour, isosurfaces
 * worth seeing before anyone types a value.
 *
 * ParaView starts isovalues at the middle of the array's range (the
 * ArrayRangeDomain's default), which for a CT is about 1000 HU: a ragged cap
 * of cortical bone. This helper, named in a proxy's hints,
 * @code{.xml}
 *   <InitializationHelper class="vtkSMMedicalIsosurfaceInitializationHelper"
 *                         property="ContourValues" hounsfield_values="400" />
 * @endcode
 * runs when ParaView initialises the new proxy (Show or a filter's creation in
 * pvpython, Apply in the GUI) and, unless the property was set during that
 * initialisation, sets it from the input's active point scalars
 * (HistogramThreshold.h explains the choice):
 *
 * - an array whose range looks like Hounsfield units (a CT): the values of
 *   `hounsfield_values` (default "-500 400": skin and bone);
 * - any other: one value, Otsu's threshold of the array's histogram, counted
 *   where the data lives (vtkPVMedicalHistogramInformation);
 * - where neither applies (no one-component point array, a constant array),
 *   nothing: the domain's default stays.
 *
 * Only the values: colours and opacities stay as they were, so a script that
 * sets the isovalues itself draws what it drew before. With `mark_start="1"`
 * a Hounsfield start is marked with the proxy annotation StartAnnotation():
 * the isosurface list in the GUI (pqMedicalIsosurfaceListWidget) finds it on
 * a display still at the start and gives skin and bone their look
 * (GetSkinAndBone(): skin colour at opacity 0.35 over opaque bone, Color Each
 * Surface on), so that opening a CT and choosing the representation shows
 * skin over bone.
 *
 * A helper (rather than a domain) because a client that has only the proxy
 * definitions (the plugin loaded on the server alone) skips a helper class it
 * does not know, and keeps ParaView's default, where an unknown domain is an
 * error.
 */
#ifndef vtkSMMedicalIsosurfaceInitializationHelper_h
#define vtkSMMedicalIsosurfaceInitializationHelper_h

#include "MedicalIsosurfacesRepresentationsModule.h" // for export macro
#include "vtkSMProxyInitializationHelper.h"

#include <vector> // for the values

class vtkSMSourceProxy;

class MEDICALISOSURFACESREPRESENTATIONS_EXPORT vtkSMMedicalIsosurfaceInitializationHelper
  : public vtkSMProxyInitializationHelper
{
public:
  static vtkSMMedicalIsosurfaceInitializationHelper* New();
  vtkTypeMacro(vtkSMMedicalIsosurfaceInitializationHelper, vtkSMProxyInitializationHelper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  void PostInitializeProxy(
    vtkSMProxy* proxy, vtkPVXMLElement* xml, vtkMTimeType initializationTimeStamp) override;

  /// The proxy annotation that marks a display started at skin and bone.
  static const char* StartAnnotation() { return "MedicalIsosurfaceStart"; }

  /// Skin's and bone's values (HU), colours (r, g, b each) and opacities, as the start shows them.
  static void GetSkinAndBone(double values[2], double colors[6], double opacities[2]);

  /**
   * The first isovalues of a point array of `source`'s output `port` (the
   * active scalars when `arrayName` is empty or null): `hounsfield` for a CT,
   * else Otsu's threshold (one value). False, with `values` untouched, when
   * there is no one-component point array or its values cannot be split.
   * `isHounsfield` (may be null) says which applied.
   */
  static bool StartValues(vtkSMSourceProxy* source, unsigned int port, const char* arrayName,
    const std::vector<double>& hounsfield, std::vector<double>& values, bool* isHounsfield);

  /**
   * The histogram of the same point array, counted where the data lives
   * (vtkPVMedicalHistogramInformation, summed over the server's processes):
   * the array's `range`, whether it holds integers (`integral`), the bins (the
   * first at [low, low + width)) and one count per bin: one bin per integer for integer data of at most 256 values,
   * else 256 equal bins over the range (mediso::HistogramBins). False, with
   * nothing set, when there is no one-component point array with a finite
   * range. The Otsu start above and the panels' histograms
   * (pqMedicalHistogramWidget) both count with it.
   */
  static bool GatherHistogram(vtkSMSourceProxy* source, unsigned int port, const char* arrayName,
    double range[2], bool& integral, double& low, double& width, std::vector<double>& counts);

protected:
  vtkSMMedicalIsosurfaceInitializationHelper();
  ~vtkSMMedicalIsosurfaceInitializationHelper() override;

private:
  vtkSMMedicalIsosurfaceInitializationHelper(
    const vtkSMMedicalIsosurfaceInitializationHelper&) = delete;
  void operator=(const vtkSMMedicalIsosurfaceInitializationHelper&) = delete;
};

#endif
