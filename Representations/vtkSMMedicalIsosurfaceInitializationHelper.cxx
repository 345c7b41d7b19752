// SPDX-License-Identifier: BSD-3-Clause
#include "vtkSMMedicalIsosurfaceInitializationHelper.h"

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
#include "vtkSMProxy.h"
#include "vtkSMSourceProxy.h"
#include "vtkType.h"

#include "HistogramThreshold.h"

#include <algorithm>
#include <sstream>
#include <vector>

namespace
{
const double SkinAndBoneColors[] = { 0.93, 0.75, 0.62, 0.96, 0.94, 0.86 };
const double SkinAndBoneOpacities[] = { 0.35, 1.0 };

// The range and kind of a one-component point array of a source's output (the
// active scalars for an empty or null name), from the client's data
// information; false when there is no such array or its range is not finite.
bool ArrayRange(vtkSMSourceProxy* source, unsigned int port, const char* arrayName,
  double range[2], bool& integral)
{
  if (!source || port >= source->GetNumberOfOutputPorts())
  {
    return false;
  }
  vtkPVDataSetAttributesInformation* points =
    source->GetDataInformation(port)->GetPointDataInformation();
  vtkPVArrayInformation* array = arrayName && arrayName[0]
    ? points->GetArrayInformation(arrayName)
    : points->GetAttributeInformation(vtkDataSetAttributes::SCALARS);
  if (!array || array->GetNumberOfComponents() != 1)
  {
    return false;
  }
  array->GetComponentRange(0, range);
  const int type = array->GetDataType();
  integral = type != VTK_FLOAT && type != VTK_DOUBLE;
  return range[0] <= range[1];
}
}

vtkStandardNewMacro(vtkSMMedicalIsosurfaceInitializationHelper);

//------------------------------------------------------------------------------
vtkSMMedicalIsosurfaceInitializationHelper::vtkSMMedicalIsosurfaceInitializationHelper() = default;

//------------------------------------------------------------------------------
vtkSMMedicalIsosurfaceInitializationHelper::~vtkSMMedicalIsosurfaceInitializationHelper() = default;

//------------------------------------------------------------------------------
void vtkSMMedicalIsosurfaceInitializationHelper::PostInitializeProxy(
  vtkSMProxy* proxy, vtkPVXMLElement* xml, vtkMTimeType initializationTimeStamp)
{
  const char* name = xml ? xml->GetAttribute("property") : nullptr;
  vtkSMProperty* isovalues = proxy && name ? proxy->GetProperty(name) : nullptr;
  if (!isovalues || isovalues->GetMTime() > initializationTimeStamp)
  {
    return;
  }
  std::vector<double> hounsfield = { mediso::SkinHounsfield, mediso::BoneHounsfield };
  if (const char* text = xml->GetAttribute("hounsfield_values"))
  {
    std::istringstream numbers(text);
    std::vector<double> parsed;
    double value = 0.0;
    while (numbers >> value)
    {
      parsed.push_back(value);
    }
    if (!parsed.empty())
    {
      hounsfield = parsed;
    }
  }
  int markStart = 0;
  xml->GetScalarAttribute("mark_start", &markStart);

  vtkSMPropertyHelper input(proxy, "Input", /*quiet=*/true);
  auto* source = vtkSMSourceProxy::SafeDownCast(input.GetAsProxy());
  // No array is chosen yet (a display's ColorArrayName, a filter's
  // SelectInputScalars): the active point scalars, which both then use.
  std::vector<double> values;
  bool isHounsfield = false;
  if (!source ||
    !StartValues(source, input.GetOutputPort(), nullptr, hounsfield, values, &isHounsfield))
  {
    return;
  }
  vtkSMPropertyHelper(isovalues).Set(values.data(), static_cast<unsigned int>(values.size()));
  if (isHounsfield && markStart)
  {
    proxy->SetAnnotation(StartAnnotation(), "skin and bone");
  }
  proxy->UpdateVTKObjects();
}

//------------------------------------------------------------------------------
bool vtkSMMedicalIsosurfaceInitializationHelper::StartValues(vtkSMSourceProxy* source,
  unsigned int port, const char* arrayName, const std::vector<double>& hounsfield,
  std::vector<double>& values, bool* isHounsfield)
{
  double range[2];
  bool integral = false;
  if (!ArrayRange(source, port, arrayName, range, integral))
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
  double low = 0.0;
  double width = 1.0;
  std::vector<double> gathered;
  if (!GatherHistogram(source, port, arrayName, range, integral, low, width, gathered))
  {
    return false;
  }
  mediso::HistogramBins bins;
  bins.Low = low;
  bins.Width = width;
  bins.Count = gathered.size();
  std::vector<std::uint64_t> counts(gathered.begin(), gathered.end());
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
bool vtkSMMedicalIsosurfaceInitializationHelper::GatherHistogram(vtkSMSourceProxy* source,
  unsigned int port, const char* arrayName, double range[2], bool& integral, double& low,
  double& width, std::vector<double>& counts)
{
  double arrayRange[2];
  if (!ArrayRange(source, port, arrayName, arrayRange, integral))
  {
    return false;
  }
  const mediso::HistogramBins bins =
    mediso::HistogramBins::For(arrayRange[0], arrayRange[1], integral);
  if (bins.Count == 0)
  {
    return false;
  }
  vtkNew<vtkPVMedicalHistogramInformation> histogram;
  histogram->SetPortNumber(static_cast<int>(port));
  histogram->SetArrayName(arrayName && arrayName[0] ? arrayName : "");
  histogram->SetBins(bins.Low, bins.Width, static_cast<int>(bins.Count));
  source->GatherInformation(histogram);
  if (histogram->GetNumberOfBins() != static_cast<int>(bins.Count))
  {
    return false;
  }
  counts.resize(bins.Count);
  for (std::size_t i = 0; i < bins.Count; ++i)
  {
    counts[i] = histogram->GetCount(static_cast<int>(i));
  }
  range[0] = arrayRange[0];
  range[1] = arrayRange[1];
  low = bins.Low;
  width = bins.Width;
  return true;
}

//------------------------------------------------------------------------------
void vtkSMMedicalIsosurfaceInitializationHelper::GetSkinAndBone(
  double values[2], double colors[6], double opacities[2])
{
  values[0] = mediso::SkinHounsfield;
  values[1] = mediso::BoneHounsfield;
  std::copy(SkinAndBoneColors, SkinAndBoneColors + 6, colors);
  std::copy(SkinAndBoneOpacities, SkinAndBoneOpacities + 2, opacities);
}

//------------------------------------------------------------------------------
void vtkSMMedicalIsosurfaceInitializationHelper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
