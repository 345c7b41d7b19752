// SPDX-License-Identifier: BSD-3-Clause
// Baseline image: the real head CT's bone (400 HU) from vtkBlockLODContour at
// levels 0, 1, 2, 3, side by side. Skipped (125) when the CT is not cached
// (Python/fetch_data.py; the folder of medical_test::DataDirectory()).
#include "MedicalTestUtilities.h"
#include "vtkBlockLODContour.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"

#include <cstdio>
#include <string>

int TestBlockLODContourRender(int argc, char* argv[])
{
  const std::string ct = medical_test::CachedDataFile("ct_head.mha", "the real CT");
  if (ct.empty())
  {
    return medical_test::SkipReturnCode;
  }
  vtkNew<vtkMetaImageReader> reader;
  reader->SetFileName(ct.c_str());

  vtkNew<vtkRenderWindow> renWin;
  renWin->SetSize(800, 240);
  renWin->SetMultiSamples(0);
  for (int level = 0; level < 4; ++level)
  {
    vtkNew<vtkBlockLODContour> lod;
    lod->SetInputConnection(reader->GetOutputPort());
    lod->SetValue(0, 400.0);
    lod->SetLOD(level);
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(lod->GetOutputPort());
    mapper->ScalarVisibilityOff();
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->SetColor(0.96, 0.94, 0.86);
    actor->GetProperty()->SetSpecular(0.2);
    vtkNew<vtkRenderer> renderer;
    renderer->SetViewport(0.25 * level, 0.0, 0.25 * (level + 1), 1.0);
    renderer->SetBackground(0.1, 0.12, 0.16);
    renderer->AddActor(actor);
    // Face towards +y; head up is +z.
    vtkCamera* camera = renderer->GetActiveCamera();
    camera->SetFocalPoint(0, 0, 0);
    camera->SetPosition(-0.35, 1.0, 0.15);
    camera->SetViewUp(0, 0, 1);
    renderer->ResetCamera();
    camera->Dolly(1.3);
    renderer->ResetCameraClippingRange();
    renWin->AddRenderer(renderer);
  }
  vtkNew<vtkRenderWindowInteractor> iren;
  iren->SetRenderWindow(renWin);
  renWin->Render();
  const int result = vtkRegressionTestImage(renWin);
  if (result == vtkRegressionTester::DO_INTERACTOR)
  {
    iren->Start();
  }
  return !result;
}
