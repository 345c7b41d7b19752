// SPDX-License-Identifier: BSD-3-Clause
// Baseline image of vtkHistoPyramidIsoMapper's GPU path, six views in one
// window: the phantom's skin (-500 HU) and bone (400 HU) opaque; the same
// with translucent skin over opaque bone; an analytic sphere in parallel
// projection; an analytic torus in perspective; a close zoom on the sphere
// where one cell covers more pixels than GL_POINT_SIZE_RANGE allows a
// point sprite (a radius-6 sphere sampled every 5 units); the phantom's bone in parallel projection, rotated volume.
// Every view must have been drawn by the GPU path (a machine without the GL
// features skips, 125).
#include "IsoMapperTestScenes.h"
#include "MedicalTestUtilities.h"
#include "RenderTestUtilities.h"
#include "vtkMedicalGLCapabilities.h"

#include "vtkCamera.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"

#include "vtkMath.h"

#include <cmath>
#include <cstdio>

int TestHistoPyramidIsoMapperRender(int argc, char* argv[])
{
  using namespace iso_test;
  vtkNew<vtkRenderWindow> renWin;
  renWin->SetSize(900, 600);
  renWin->SetMultiSamples(0);
  vtkNew<vtkMedicalGLCapabilities> caps;
  if (!caps->Probe(renWin))
  {
    std::printf("SKIP: %s (%s)\n", caps->GetReason().c_str(), caps->GetStatusAsString());
    return caps->GetStatus() == vtkMedicalGLCapabilities::StatusProbeFailed ? 1 : 125;
  }

  auto phantom = Phantom(96);
  auto sphere = Sphere(24);
  auto coarseSphere = Sphere(8, 5.0); // 7 cells of 5 units
  auto torus = Torus(40, 11.0);
  const Look skin{ -500.0, { 0.93, 0.75, 0.62 }, 1.0 };
  const Look skinGlass{ -500.0, { 0.93, 0.75, 0.62 }, 0.3 };
  const Look bone{ 400.0, { 0.97, 0.95, 0.88 }, 1.0 };
  const Look blue{ 8.3, { 0.4, 0.6, 0.95 }, 1.0 };
  const Look green{ 4.2, { 0.5, 0.85, 0.45 }, 1.0 };

  std::vector<vtkSmartPointer<vtkHistoPyramidIsoMapper>> mappers;
  auto addView = [&](int index, vtkImageData* image, const std::vector<Look>& looks,
                   bool parallel, const double direction[3], double zoom)
  {
    auto mapper = vtkSmartPointer<vtkHistoPyramidIsoMapper>::New();
    mappers.push_back(mapper);
    auto volume = MakeVolume(image, looks, mapper);
    if (index == 5)
    {
      volume->RotateZ(30.0);
      volume->RotateX(-20.0);
    }
    vtkNew<vtkRenderer> renderer;
    renderer->SetViewport((index % 3) / 3.0, (index / 3) / 2.0, (index % 3 + 1) / 3.0,
      (index / 3 + 1) / 2.0);
    renderer->SetBackground(0.1, 0.12, 0.16);
    renderer->AddVolume(volume);
    vtkCamera* camera = renderer->GetActiveCamera();
    camera->SetFocalPoint(0, 0, 0);
    camera->SetPosition(direction);
    camera->SetViewUp(0, 0, 1);
    camera->SetParallelProjection(parallel);
    if (zoom > 0.0)
    {
      renderer->ResetCamera();
      camera->Zoom(zoom);
    }
    else
    {
      // Close-up of the top of a radius-6 sphere, side on: 5.6 units of
      // view height in a 300-pixel viewport, so one 5-unit cell spans about
      // 270 pixels.
      camera->SetFocalPoint(0.0, 0.0, 6.0);
      camera->SetPosition(0.0, -40.0, 6.0);
      camera->SetViewAngle(8.0);
    }
    renWin->AddRenderer(renderer);
  };
  const double front[3] = { -0.4, 1.0, 0.2 };
  const double oblique[3] = { 1.0, -0.6, 0.8 };
  addView(0, phantom, { skin, bone }, false, front, 1.2);
  addView(1, phantom, { skinGlass, bone }, false, front, 1.2);
  addView(2, sphere, { blue }, true, oblique, 1.0);
  addView(3, torus, { green }, false, oblique, 1.3);
  addView(4, coarseSphere, { Look{ 6.0, { 0.4, 0.6, 0.95 }, 1.0 } }, false, front, 0.0);
  const double cellPixels = 300.0 * 5.0 / (2.0 * 40.0 * std::tan(vtkMath::RadiansFromDegrees(4.0)));
  std::printf("close-up: a cell spans %.0f pixels; GL_POINT_SIZE_RANGE max %.0f\n", cellPixels,
    caps->GetPointSizeRange()[1]);
  medical_test::Check(cellPixels > caps->GetPointSizeRange()[1],
    "the close-up's cells are larger than the largest point sprite");
  addView(5, phantom, { bone }, true, front, 1.1);

  renWin->Render();
  for (std::size_t i = 0; i < mappers.size(); ++i)
  {
    std::printf("view %zu: path %s, footprint %s, %llu primitives, %llu GPU bytes\n", i,
      mappers[i]->GetLastRenderPathAsString(), mappers[i]->GetLastFootprintAsString(),
      static_cast<unsigned long long>(mappers[i]->GetNumberOfPrimitives()),
      static_cast<unsigned long long>(mappers[i]->GetGPUMemoryBytes()));
    medical_test::Check(mappers[i]->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath,
      "view " + std::to_string(i) + " drawn by the GPU path");
    // The close-up's cells exceed the largest point: boxes; the other views'
    // cells are a few pixels: points.
    const int footprint =
      i == 4 ? vtkHistoPyramidIsoMapper::BoxFootprint : vtkHistoPyramidIsoMapper::PointFootprint;
    medical_test::Check(mappers[i]->GetLastFootprint() == footprint,
      "view " + std::to_string(i) + " drawn with the expected footprint");
  }

  const int result = medical_test::CompareWithBaseline(argc, argv, renWin);
  medical_test::Check(result != vtkRegressionTester::FAILED, "image matches the baseline");
  return medical_test::Finish("TestHistoPyramidIsoMapperRender");
}
