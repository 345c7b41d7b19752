// SPDX-License-Identifier: BSD-3-Clause
#include "vtkSMMedicalIsosurfaceInitializationHelper.h"

#include "vtkCommand.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkSMMedicalIsovaluesDomain.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"
#include "vtkSMSourceProxy.h"
#include "vtkWeakPointer.h"

#include "HistogramThreshold.h"

#include <vector>

namespace
{
const char* const ColorsName = "HistoPyramidSurfaceColors";
const char* const OpacitiesName = "HistoPyramidSurfaceOpacities";
const char* const ColorEachName = "HistoPyramidColorEachSurface";

// Skin and bone, as the isosurface list's palette starts.
const double SkinAndBoneColors[] = { 0.93, 0.75, 0.62, 0.96, 0.94, 0.86 };
const double SkinAndBoneOpacities[] = { 0.35, 1.0 };

bool Equals(vtkSMProxy* display, const char* name, const std::vector<double>& expected)
{
  vtkSMPropertyHelper helper(display, name, /*quiet=*/true);
  return helper.GetArray<double>() == expected;
}

/**
 * Watches the display's IsosurfaceValues once the start is set: the first
 * change to other values (by a script) takes the start's colours and
 * opacities away, if nobody changed them, and stops watching.
 */
class StartObserver : public vtkCommand
{
public:
  static StartObserver* New() { return new StartObserver; }

  vtkWeakPointer<vtkSMProxy> Display;
  std::vector<double> Values;
  std::vector<double> Colors;
  std::vector<double> Opacities;

  void Execute(vtkObject* caller, unsigned long, void*) override
  {
    vtkSMProxy* display = this->Display;
    auto* property = vtkSMProperty::SafeDownCast(caller);
    if (!display || !property)
    {
      return;
    }
    if (!display->HasAnnotation(vtkSMMedicalIsosurfaceInitializationHelper::StartAnnotation()))
    {
      property->RemoveObserver(this);
      return;
    }
    if (Equals(display, "IsosurfaceValues", this->Values))
    {
      return;
    }
    if (Equals(display, ColorsName, this->Colors) &&
      Equals(display, OpacitiesName, this->Opacities) &&
      vtkSMPropertyHelper(display, ColorEachName, true).GetAsInt() == 1)
    {
      for (const char* name : { ColorsName, OpacitiesName, ColorEachName })
      {
        if (vtkSMProperty* owned = display->GetProperty(name))
        {
          owned->ResetToXMLDefaults();
        }
      }
      display->UpdateVTKObjects();
    }
    display->RemoveAnnotation(vtkSMMedicalIsosurfaceInitializationHelper::StartAnnotation());
    property->RemoveObserver(this);
  }
};
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
  if (isHounsfield && display->GetProperty(ColorsName) && display->GetProperty(OpacitiesName) &&
    display->GetProperty(ColorEachName))
  {
    vtkSMPropertyHelper(display, ColorsName).Set(SkinAndBoneColors, 6);
    vtkSMPropertyHelper(display, OpacitiesName).Set(SkinAndBoneOpacities, 2);
    vtkSMPropertyHelper(display, ColorEachName).Set(1);
    display->SetAnnotation(StartAnnotation(), "skin and bone");
    vtkNew<StartObserver> observer;
    observer->Display = display;
    observer->Values = values;
    observer->Colors.assign(SkinAndBoneColors, SkinAndBoneColors + 6);
    observer->Opacities.assign(SkinAndBoneOpacities, SkinAndBoneOpacities + 2);
    isovalues->AddObserver(vtkCommand::ModifiedEvent, observer);
  }
  display->UpdateVTKObjects();
}

//------------------------------------------------------------------------------
void vtkSMMedicalIsosurfaceInitializationHelper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
