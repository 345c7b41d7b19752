// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkSMMedicalIsovaluesDomain
 * @brief   The range of the contoured array, and first isovalues that show
 * something.
 *
 * An array-range domain (vtkSMArrayRangeDomain: Input and ArraySelection as
 * required properties, the range of the chosen point array) whose default is
 * not the middle of the range but surfaces a user expects to see first
 * (HistogramThreshold.h explains the choice):
 *
 * - an array whose range looks like Hounsfield units (a CT) starts at the
 *   values of the XML attribute `hounsfield_values` (default "-500 400": skin
 *   and bone);
 * - any other point array starts at Otsu's threshold of its histogram, counted
 *   on the data server (vtkPVMedicalHistogramInformation);
 * - where neither applies (no one-component point array, a constant array),
 *   the superclass's default: the middle of the range.
 *
 * In the XML, in place of an ArrayRangeDomain:
 * @code{.xml}
 *   <MedicalIsovaluesDomain name="scalar_range" hounsfield_values="400">
 *     <RequiredProperties>
 *       <Property name="Input" function="Input" />
 *       <Property name="SelectInputScalars" function="ArraySelection" />
 *     </RequiredProperties>
 *   </MedicalIsovaluesDomain>
 * @endcode
 * Like every domain default, it applies when ParaView initialises a new proxy
 * (and on "Reset to defaults"): values a user or a script sets stay as set.
 *
 * StartValues() is the same choice for code that sets a property itself
 * (vtkSMMedicalIsosurfaceInitializationHelper).
 */
#ifndef vtkSMMedicalIsovaluesDomain_h
#define vtkSMMedicalIsovaluesDomain_h

#include "MedicalIsosurfacesRepresentationsModule.h" // for export macro
#include "vtkSMArrayRangeDomain.h"

#include <vector> // for the values

class vtkSMSourceProxy;

class MEDICALISOSURFACESREPRESENTATIONS_EXPORT vtkSMMedicalIsovaluesDomain
  : public vtkSMArrayRangeDomain
{
public:
  static vtkSMMedicalIsovaluesDomain* New();
  vtkTypeMacro(vtkSMMedicalIsovaluesDomain, vtkSMArrayRangeDomain);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  int SetDefaultValues(vtkSMProperty* property, bool useUncheckedValues) override;

  /**
   * The first isovalues of a point array of `source`'s output `port` (the
   * active scalars when `arrayName` is empty or null): `hounsfield` for a CT,
   * else Otsu's threshold (one value). False, with `values` untouched, when
   * there is no one-component point array or its values cannot be split.
   * `isHounsfield` (may be null) says which applied.
   */
  static bool StartValues(vtkSMSourceProxy* source, unsigned int port, const char* arrayName,
    const std::vector<double>& hounsfield, std::vector<double>& values, bool* isHounsfield);

protected:
  vtkSMMedicalIsovaluesDomain();
  ~vtkSMMedicalIsovaluesDomain() override;

  int ReadXMLAttributes(vtkSMProperty* property, vtkPVXMLElement* element) override;

private:
  vtkSMMedicalIsovaluesDomain(const vtkSMMedicalIsovaluesDomain&) = delete;
  void operator=(const vtkSMMedicalIsovaluesDomain&) = delete;

  std::vector<double> HounsfieldValues;
};

#endif
