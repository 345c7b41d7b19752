// SPDX-License-Identifier: BSD-3-Clause
// Probes the OpenGL context of an offscreen render window with
// vtkMedicalGLCapabilities and prints its report.
//  - exit 0 when the GPU HistoPyramid path is supported;
//  - exit 125 (skip) when the context is below OpenGL 3.2, lacks a feature, or
//    there is no usable context, printing "SKIP: <reason>";
//  - exit 1 when the functional probe fails (count mismatch, shader failure):
//    that is a bug to look at, not a machine to skip.
// Then checks that MEDISO_DISABLE_GPU_PATH=1 turns the GPU path off.
#include "vtkMedicalGLCapabilities.h"

#include "vtkNew.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"

#include <cstdlib>
#include <iostream>
#include <string>

namespace
{
void SetEnv(const char* name, const char* value)
{
#ifdef _WIN32
  _putenv_s(name, value ? value : "");
#else
  if (value)
  {
    setenv(name, value, 1);
  }
  else
  {
    unsetenv(name);
  }
#endif
}

// Restores an environment variable to its value at construction.
class ScopedEnv
{
public:
  explicit ScopedEnv(const char* name)
    : Name(name)
  {
    const char* value = std::getenv(name);
    this->WasSet = value != nullptr;
    if (value)
    {
      this->Value = value;
    }
  }
  ~ScopedEnv() { SetEnv(this->Name, this->WasSet ? this->Value.c_str() : nullptr); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
  const char* Name;
  bool WasSet = false;
  std::string Value;
};
}

int TestMedicalGLCapabilities(int, char*[])
{
  const char* envName = "MEDISO_DISABLE_GPU_PATH";
  ScopedEnv savedEnv(envName);

  vtkNew<vtkRenderWindow> renWin;
  renWin->SetOffScreenRendering(1);
  renWin->SetSize(64, 64);
  renWin->SetMultiSamples(0);
  vtkNew<vtkRenderer> renderer;
  renWin->AddRenderer(renderer);

  // 1. The real probe, whatever the environment asked for.
  SetEnv(envName, nullptr);
  vtkNew<vtkMedicalGLCapabilities> caps;
  const bool supported = caps->Probe(renWin);
  std::cout << caps->GetReport() << std::flush;

  int result = 0;
  switch (caps->GetStatus())
  {
    case vtkMedicalGLCapabilities::StatusSupported:
      if (!supported || !caps->GetReason().empty() || !caps->GetProbePassed())
      {
        std::cout << "Probe() result, reason and status disagree\n";
        return 1;
      }
      break;
    case vtkMedicalGLCapabilities::StatusNoContext:
    case vtkMedicalGLCapabilities::StatusMissingFeature:
      std::cout << "SKIP: " << caps->GetReason() << "\n";
      result = 125;
      break;
    default:
      std::cout << "GPU path probe did not pass: " << caps->GetReason() << "\n";
      return 1;
  }
  if (supported && (caps->GetMajorVersion() < 3 ||
                     (caps->GetMajorVersion() == 3 && caps->GetMinorVersion() < 2)))
  {
    std::cout << "supported with OpenGL " << caps->GetMajorVersion() << "."
              << caps->GetMinorVersion() << " < 3.2\n";
    return 1;
  }

  // 2. MEDISO_DISABLE_GPU_PATH=1 forces the CPU fallback (no OpenGL needed).
  SetEnv(envName, "1");
  vtkNew<vtkMedicalGLCapabilities> disabled;
  const bool disabledSupported = disabled->Probe(renWin);
  if (disabledSupported || disabled->GetSupported() ||
    disabled->GetStatus() != vtkMedicalGLCapabilities::StatusDisabled ||
    disabled->GetReason() != "disabled by MEDISO_DISABLE_GPU_PATH")
  {
    std::cout << "MEDISO_DISABLE_GPU_PATH=1 was not honoured: status "
              << disabled->GetStatusAsString() << ", reason '" << disabled->GetReason() << "'\n";
    return 1;
  }
  // "0" means not disabled.
  SetEnv(envName, "0");
  if (vtkMedicalGLCapabilities::IsGPUPathDisabledByEnvironment())
  {
    std::cout << "MEDISO_DISABLE_GPU_PATH=0 disabled the GPU path\n";
    return 1;
  }

  // 3. A second real probe on the same (now initialised) window gives the
  //    same answer: the first one left its context usable.
  if (result == 0)
  {
    SetEnv(envName, nullptr);
    vtkNew<vtkMedicalGLCapabilities> again;
    if (!again->Probe(renWin))
    {
      std::cout << "second probe on the same window did not pass: " << again->GetReason() << "\n";
      return 1;
    }
    renWin->Render(); // the window still renders after the probes
  }
  return result;
}
