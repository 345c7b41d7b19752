// SPDX-License-Identifier: BSD-3-Clause
#include "vtkSMMedicalIsovaluesDomain.h"

#include "vtkDataSetAttributes.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPVArrayInformation.h"
#include "vtkPVDataInformation.h"
#include "vtkPVDataSetAttributesInformation.h"
#include "vtkPVMedicalHistogramInformation.h"
#include "vtkPVXMLElement.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMSourceProxy.h"
#include "vtkSMUncheckedPropertyHelper.h"
#include "vtkType.h"

#include "HistogramThreshold.h"

#include <sstream>

vtkStandardNewMacro(vtkSMMedicalIsovaluesDomain);

//------------------------------------------------------------------------------
vtkSMMedicalIsovaluesDomain::vtkSMMedicalIsovaluesDomain()
  : HounsfieldValues{ mediso::SkinHounsfield, mediso::BoneHounsfield }
{
}

//------------------------------------------------------------------------------
vtkSMMedicalIsovaluesDomain::~vtkSMMedicalIsovaluesDomain() = default;

//------------------------------------------------------------------------------
int vtkSMMedicalIsovaluesDomain::ReadXMLAttributes(
  vtkSMProperty* property, vtkPVXMLElement* element)
{
  if (!this->Superclass::ReadXMLAttributes(property, element))
  {
    return 0;
  }
  if (const char* text = element->GetAttribute("hounsfield_values"))
  {
    std::istringstream values(text);
    std::vector<double> parsed;
    double value = 0.0;
    while (values >> value)
    {
      parsed.push_back(value);
    }
    if (parsed.empty())
    {
      vtkErrorMacro("hounsfield_values=\"" << text << "\" holds no number.");
      return 0;
    }
    this->HounsfieldValues = parsed;
  }
  return 1;
}

//------------------------------------------------------------------------------
bool vtkSMMedicalIsovaluesDomain::StartValues(vtkSMSourceProxy* source, unsigned int port,
  const char* arrayName, const std::vector<double>& hounsfield, std::vector<double>& values,
  bool* isHounsfield)
{
  if (!source || port >= source->GetNumberOfOutputPorts())
  {
    return false;
  }
  vtkPVDataSetAttributesInformation* points =
    source->GetDataInformation(port)->GetPointDataInformation();
  const bool named = arrayName && arrayName[0];
  vtkPVArrayInformation* array = named
    ? points->GetArrayInformation(arrayName)
    : points->GetAttributeInformation(vtkDataSetAttributes::SCALARS);
  if (!array || array->GetNumberOfComponents() != 1)
  {
    return false;
  }
  double range[2];
  array->GetComponentRange(0, range);
  if (!(range[0] <= range[1]))
  {
    return false;
  }
  if (mediso::LooksLikeHounsfieldUnits(range[0], range[1]))
  {
    values = hounsfield;
    if (isHounsfield)
    {
      *isHounsfield = true;
    }
    return true;
  }
  const int type = array->GetDataType();
  const bool integral = type != VTK_FLOAT && type != VTK_DOUBLE;
  const mediso::HistogramBins bins = mediso::HistogramBins::For(range[0], range[1], integral);
  if (bins.Count == 0)
  {
    return false;
  }
  vtkNew<vtkPVMedicalHistogramInformation> histogram;
  histogram->SetPortNumber(static_cast<int>(port));
  histogram->SetArrayName(named ? arrayName : "");
  histogram->SetBins(bins.Low, bins.Width, static_cast<int>(bins.Count));
  source->GatherInformation(histogram);
  if (histogram->GetNumberOfBins() != static_cast<int>(bins.Count))
  {
    return false;
  }
  std::vector<std::uint64_t> counts(bins.Count);
  for (std::size_t i = 0; i < bins.Count; ++i)
  {
    counts[i] = static_cast<std::uint64_t>(histogram->GetCount(static_cast<int>(i)));
  }
  double threshold = 0.0;
  if (!mediso::OtsuThreshold(counts, bins, threshold))
  {
    return false;
  }
  values.assign(1, threshold);
  if (isHounsfield)
  {
    *isHounsfield = false;
  }
  return true;
}

//------------------------------------------------------------------------------
int vtkSMMedicalIsovaluesDomain::SetDefaultValues(vtkSMProperty* property, bool useUncheckedValues)
{
  vtkSMProperty* input = this->GetRequiredProperty("Input");
  vtkSMProperty* selection = this->GetRequiredProperty("ArraySelection");
  if (input && property)
  {
    vtkSMUncheckedPropertyHelper inputHelper(input);
    auto* source = vtkSMSourceProxy::SafeDownCast(inputHelper.GetAsProxy());
    const unsigned int port = inputHelper.GetOutputPort();
    // The array selection is (port, connection, field, association, name)
    // for a filter and (association, name) for a representation; point
    // arrays only, as the superclass's range.
    const char* name = nullptr;
    int association = vtkDataObject::FIELD_ASSOCIATION_POINTS;
    if (selection)
    {
      vtkSMUncheckedPropertyHelper selected(selection);
      const unsigned int n = selected.GetNumberOfElements();
      if (n >= 2)
      {
        name = selected.GetAsString(n - 1);
        association = selected.GetAsInt(n - 2);
      }
      else if (n == 1)
      {
        name = selected.GetAsString(0);
      }
    }
    std::vector<double> values;
    if (source && association == vtkDataObject::FIELD_ASSOCIATION_POINTS &&
      StartValues(source, port, name, this->HounsfieldValues, values, nullptr))
    {
      vtkSMPropertyHelper helper(property);
      helper.SetUseUnchecked(useUncheckedValues);
      helper.Set(values.data(), static_cast<unsigned int>(values.size()));
      return 1;
    }
  }
  return this->Superclass::SetDefaultValues(property, useUncheckedValues);
}

//------------------------------------------------------------------------------
void vtkSMMedicalIsovaluesDomain::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "HounsfieldValues:";
  for (double value : this->HounsfieldValues)
  {
    os << " " << value;
  }
  os << "\n";
}
