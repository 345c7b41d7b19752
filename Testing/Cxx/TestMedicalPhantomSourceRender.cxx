// SPDX-License-Identifier: BSD-3-Clause
// Baseline-image test of the phantom: skin (-500 HU) and bone (400 HU)
// isosurfaces side by side, extracted with VTK's own vtkFlyingEdges3D so that
// the image checks the phantom, not our filters.
#include "RenderTestUtilities.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkFlyingEdges3D.h"
#include "vtkNew.h"
#include "vtkRenderWindow.h"

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
  // Look at the face from the front-left, head up (+z).
  const double eye[3] = { -0.6, 1.0, 0.25 };
  for (int n = 0; n < 2; ++n)
  {
    vtkNew<vtkFlyingEdges3D> contour;
    contour->SetInputConnection(phantom->GetOutputPort());
    contour->SetValue(0, isovalues[n]);
    contour->ComputeNormalsOn();
    medical_test::AddSurfacePanel(renWin, contour->GetOutputPort(), colors[n], n, 2, eye);
  }
  renWin->Render();
  return !medical_test::CompareWithBaseline(argc, argv, renWin);
}
