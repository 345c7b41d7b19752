// SPDX-License-Identifier: BSD-3-Clause
// Baseline image: the real head CT through vtkHistoPyramidIsoMapper's GPU
// path: bone (400 HU) opaque on the left; translucent skin (-500 HU, opacity
// 0.3) over the bone on the right. Skipped (125) when the CT is not cached
// (Python/fetch_data.py) or the GL lacks what the GPU path needs.
#include "IsoMapperTestScenes.h"
#include "MedicalTestUtilities.h"
#include "RenderTestUtilities.h"

#include "vtkCamera.h"
#include "vtkMetaImageReader.h"
#include "vtkRenderer.h"

#include <cstdio>
#include <string>

int TestHistoPyramidIsoMapperCT(int argc, char* argv[])
{
  const std::string ct = medical_test::CachedDataFile("ct_head.mha", "the real CT");
  if (ct.empty())
  {
    return medical_test::SkipReturnCode;
  }
  vtkNew<vtkRenderWindow> renWin;
  renWin->SetSize(800, 400);
  renWin->SetMultiSamples(0);
  if (const int skip = iso_test::ProbeOrSkip(renWin))
  {
    return skip;
  }
  vtkNew<vtkMetaImageReader> reader;
  reader->SetFileName(ct.c_str());
  reader->Update();

  const iso_test::Look bone{ 400.0, { 0.97, 0.95, 0.88 }, 1.0 };
  const iso_test::Look skin{ -500.0, { 0.93, 0.75, 0.62 }, 0.3 };
  vtkNew<vtkHistoPyramidIsoMapper> boneMapper, bothMapper;
  auto boneVolume = iso_test::MakeVolume(reader->GetOutput(), { bone }, boneMapper);
  auto bothVolume = iso_test::MakeVolume(reader->GetOutput(), { skin, bone }, bothMapper);
  vtkVolume* volumes[2] = { boneVolume, bothVolume };
  for (int v = 0; v < 2; ++v)
  {
    vtkNew<vtkRenderer> renderer;
    renderer->SetViewport(0.5 * v, 0.0, 0.5 * (v + 1), 1.0);
    renderer->SetBackground(0.1, 0.12, 0.16);
    renderer->AddVolume(volumes[v]);
    // Face towards +y; head up is +z (as TestBlockLODContourRender).
    vtkCamera* camera = renderer->GetActiveCamera();
    camera->SetFocalPoint(0, 0, 0);
    camera->SetPosition(-0.35, 1.0, 0.15);
    camera->SetViewUp(0, 0, 1);
    renderer->ResetCamera();
    camera->Zoom(1.3);
    renWin->AddRenderer(renderer);
  }
  renWin->Render();
  for (vtkHistoPyramidIsoMapper* mapper : { boneMapper.Get(), bothMapper.Get() })
  {
    std::printf("path %s, %llu primitives, %.1f MB of GPU memory\n",
      mapper->GetLastRenderPathAsString(),
      static_cast<unsigned long long>(mapper->GetNumberOfPrimitives()),
      mapper->GetGPUMemoryBytes() / 1e6);
    medical_test::Check(
      mapper->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath, "drawn by the GPU path");
  }
  const int result = medical_test::CompareWithBaseline(argc, argv, renWin);
  medical_test::Check(result != vtkRegressionTester::FAILED, "image matches the baseline");
  return medical_test::Finish("TestHistoPyramidIsoMapperCT");
}
