// SPDX-License-Identifier: BSD-3-Clause
// Baseline image: the real head CT's bone (400 HU) from vtkBlockLODContour at
// levels 0, 1, 2, 3, side by side. Skipped (125) when the CT is not cached
// (Python/fetch_data.py; the folder of medical_test::DataDirectory()).
#include "MedicalTestUtilities.h"
#include "RenderTestUtilities.h"
#include "vtkBlockLODContour.h"

#include "vtkCamera.h"
#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkRenderWindow.h"
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
  const double bone[3] = { 0.96, 0.94, 0.86 };
  // Face towards +y; head up is +z.
  const double eye[3] = { -0.35, 1.0, 0.15 };
  for (int level = 0; level < 4; ++level)
  {
    vtkNew<vtkBlockLODContour> lod;
    lod->SetInputConnection(reader->GetOutputPort());
    lod->SetValue(0, 400.0);
    lod->SetLOD(level);
    vtkRenderer* renderer =
      medical_test::AddSurfacePanel(renWin, lod->GetOutputPort(), bone, level, 4, eye);
    renderer->GetActiveCamera()->Dolly(1.3);
    renderer->ResetCameraClippingRange();
  }
  renWin->Render();
  return !medical_test::CompareWithBaseline(argc, argv, renWin);
}
