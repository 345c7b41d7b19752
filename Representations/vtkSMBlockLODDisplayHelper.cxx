// SPDX-License-Identifier: BSD-3-Clause
#include "vtkSMBlockLODDisplayHelper.h"

#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPVXMLElement.h"
#include "vtkSMProxy.h"

#include <cstring>

vtkStandardNewMacro(vtkSMBlockLODDisplayHelper);

//------------------------------------------------------------------------------
vtkSMBlockLODDisplayHelper::vtkSMBlockLODDisplayHelper() = default;
vtkSMBlockLODDisplayHelper::~vtkSMBlockLODDisplayHelper() = default;

//------------------------------------------------------------------------------
void vtkSMBlockLODDisplayHelper::PostInitializeProxy(vtkSMProxy* proxy,
  vtkPVXMLElement* xml,
  vtkMTimeType)
{
  const char* view = xml ? xml->GetAttribute("view") : nullptr;
  const char* type = xml ? xml->GetAttribute("type") : nullptr;
  vtkPVXMLElement* hints = proxy ? proxy->GetHints() : nullptr;
  if (!view || !type || !hints)
  {
    return;
  }
  for (unsigned int i = 0; i < hints->GetNumberOfNestedElements(); ++i)
  {
    vtkPVXMLElement* hint = hints->GetNestedElement(i);
    const char* hintView = hint->GetAttribute("view");
    if (hint->GetName() && std::strcmp(hint->GetName(), "Representation") == 0 && hintView &&
      std::strcmp(hintView, view) == 0)
    {
      return; // named already (an earlier proxy of the same definition)
    }
  }
  vtkNew<vtkPVXMLElement> representation;
  representation->SetName("Representation");
  representation->AddAttribute("view", view);
  representation->AddAttribute("type", type);
  hints->AddNestedElement(representation);
}

//------------------------------------------------------------------------------
void vtkSMBlockLODDisplayHelper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
