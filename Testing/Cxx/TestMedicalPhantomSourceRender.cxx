// SPDX-License-Identifier: BSD-3-Clause
// Baseline-image test of the phantom: skin (-500 HU) and bone (400 HU)
// isosurfaces side by side, extracted with VTK's own vtkFlyingEdges3D so that
// the image checks the phantom, not our filters.
#include "vtkMedicalPhantomSource.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkFlyingEdges3D.h"
#include "vtkNew.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"

int TestMedicalPhantomSourceRender(int argc, char* argv[])
{
  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(96, 96, 96);
  phantom->SetSpacing(2.5, 2.5, 2.5);

  vtkNew<vtkRenderWindow> renWin;
  renWin->SetSize(600, 300);
  renWin->SetMultiSamples(0);

  const double isovalues[2] = { -500.0, 400.0 };
  const double colors[2][3] = { { 0.95, 0.75, 0.62 }, { 0.95, 0.93, 0.85 } };
  for (int n = 0; n < 2; ++n)
  {
    vtkNew<vtkFlyingEdges3D> contour;
    contour->SetInputConnection(phantom->GetOutputPort());
    contour->SetValue(0, isovalues[n]);
    contour->ComputeNormalsOn();
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(contour->GetOutputPort());
    mapper->ScalarVisibilityOff();
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->SetColor(colors[n][0], colors[n][1], colors[n][2]);
    actor->GetProperty()->SetSpecular(0.2);
    vtkNew<vtkRenderer> renderer;
    renderer->SetViewport(0.5 * n, 0.0, 0.5 * (n + 1), 1.0);
    renderer->SetBackground(0.1, 0.12, 0.16);
    renderer->AddActor(actor);
    // Look at the face from the front-left, head up (+z).
    vtkCamera* camera = renderer->GetActiveCamera();
    camera->SetFocalPoint(0, 0, 0);
    camera->SetPosition(-0.6, 1.0, 0.25);
    camera->SetViewUp(0, 0, 1);
    renderer->ResetCamera();
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
