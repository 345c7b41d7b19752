// SPDX-License-Identifier: BSD-3-Clause
#include "vtkSMMedicalIsosurfaceInitializationHelper.h"

#include "vtkObjectFactory.h"
#include "vtkSMMedicalIsovaluesDomain.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"
#include "vtkSMSourceProxy.h"

#include "HistogramThreshold.h"

#include <algorithm>
#include <vector>

namespace
{
const double SkinAndBoneColors[] = { 0.93, 0.75, 0.62, 0.96, 0.94, 0.86 };
const double SkinAndBoneOpacities[] = { 0.35, 1.0 };
}

vtkStandardNewMacro(vtkSMMedicalIsosurfaceInitializationHelper);

//------------------------------------------------------------------------------
vtkSMMedicalIsosurfaceInitializationHelper::vtkSMMedicalIsosurfaceInitializationHelper() = default;

//------------------------------------------------------------------------------
vtkSMMedicalIsosurfaceInitializationHelper::~vtkSMMedicalIsosurfaceInitializationHelper() = default;

//------------------------------------------------------------------------------
void vtkSMMedicalIsosurfaceInitializationHelper::PostInitializeProxy(
  vtkSMProxy* display, vtkPVXMLElement*, vtkMTimeType initializationTimeStamp)
{
  vtkSMProperty* isovalues = display ? display->GetProperty("IsosurfaceValues") : nullptr;
  if (!isovalues || isovalues->GetMTime() > initializationTimeStamp)
  {
    return;
  }
  vtkSMPropertyHelper input(display, "Input", /*quiet=*/true);
  auto* source = vtkSMSourceProxy::SafeDownCast(input.GetAsProxy());
  // ColorArrayName is not chosen yet: the array is the active point scalars,
  // the one the representation contours while coloured by Solid Color.
  const std::vector<double> hounsfield = { mediso::SkinHounsfield, mediso::BoneHounsfield };
  std::vector<double> values;
  bool isHounsfield = false;
  if (!source ||
    !vtkSMMedicalIsovaluesDomain::StartValues(
      source, input.GetOutputPort(), nullptr, hounsfield, values, &isHounsfield))
  {
    return;
  }
  vtkSMPropertyHelper(isovalues).Set(values.data(), static_cast<unsigned int>(values.size()));
  if (isHounsfield)
  {
    display->SetAnnotation(StartAnnotation(), "skin and bone");
  }
  display->UpdateVTKObjects();
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
