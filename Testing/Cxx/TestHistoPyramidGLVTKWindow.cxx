// SPDX-License-Identifier: BSD-3-Clause
// The GPU core's HistoPyramid against the CPU model, node for node (every
// check of HistoPyramidGLChecks.h), inside a VTK render window's context:
// the context the ParaView mapper draws in, with the functions VTK's GLEW
// loaded (vtkMedicalGLCapabilities::LoadCoreApi()).
//  - exit 0 when everything matches;
//  - exit 125 (skip), printing "SKIP: <reason>", where the context cannot run
//    the GPU path;
//  - exit 1 on any mismatch.
#include "vtkMedicalGLCapabilities.h"

#include "vtkNew.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"

#include "HistoPyramidGLChecks.h"

#include <iostream>

int TestHistoPyramidGLVTKWindow(int, char*[])
{
  vtkNew<vtkRenderWindow> renWin;
  renWin->SetOffScreenRendering(1);
  renWin->SetSize(64, 64);
  renWin->SetMultiSamples(0);
  vtkNew<vtkRenderer> renderer;
  renWin->AddRenderer(renderer);

  vtkNew<vtkMedicalGLCapabilities> caps;
  if (!caps->Probe(renWin))
  {
    if (caps->GetStatus() == vtkMedicalGLCapabilities::StatusProbeFailed)
    {
      std::cout << "GPU path probe failed: " << caps->GetReason() << "\n";
      return 1;
    }
    std::cout << "SKIP: " << caps->GetReason() << "\n";
    return 125;
  }
  renWin->Render();
  renWin->MakeCurrent();
  std::string error;
  const auto gl = vtkMedicalGLCapabilities::LoadCoreApi(renWin, error);
  if (!gl)
  {
    std::cout << "the core cannot use the window's context: " << error << "\n";
    return 1;
  }
  const int result = pyramid_checks::RunAll(gl, "TestHistoPyramidGLVTKWindow passed");
  renWin->Render(); // the window still renders
  return result;
}
