// SPDX-License-Identifier: BSD-3-Clause
// vtkHistoPyramidIsoMapper's clipping planes and cropping, on the phantom's
// skin (-500 HU) and bone (400 HU):
//  - an oblique clipping plane that removes the front of the head: the GPU
//    path and the fallback, each against vtkBlockLODContour (level 3) +
//    vtkClipPolyData of the same surfaces drawn by a vtkPolyDataMapper, with
//    the thresholds of TestHistoPyramidIsoMapperChecks_Reference (covered
//    pixels agree on >= 98.5% of those covered by either, mean colour
//    difference <= 12 of 255 where both cover), and a cut at the plane, not
//    along whole cells (masks agree on >= 99.7%); the clipped image must differ
//    from the unclipped one (the bone shows through the cut);
//  - the same plane with translucent skin: the GPU path against the fallback
//    (mean difference <= 12);
//  - cropping to a box on voxel faces (subvolume flags): both paths against
//    vtkBlockLODContour of the vtkExtractVOI of that box;
//  - a plane that removes the whole volume draws nothing; unsupported
//    cropping region flags give one warning and the uncropped image.
// Then the baseline: the GPU plane (opaque, translucent), the GPU crop and
// the fallback plane in one window.
#include "IsoMapperTestScenes.h"
#include "MedicalTestUtilities.h"
#include "RenderTestUtilities.h"

#include "vtkActor.h"
#include "vtkBlockLODContour.h"
#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkClipPolyData.h"
#include "vtkCommand.h"
#include "vtkExtractVOI.h"
#include "vtkPlane.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkUnsignedCharArray.h"

#include <cstdio>
#include <string>
#include <vector>

namespace
{
using iso_test::Look;
using medical_test::Check;

const int Size = 300;

// The view every image shares: from (-0.4, 1, 0.3) towards the image's centre,
// fitted to the whole image (not to what is left of it), a little closer.
void PlaceCamera(vtkRenderer* renderer, vtkImageData* image)
{
  double bounds[6], centre[3];
  image->GetBounds(bounds);
  image->GetCenter(centre);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetFocalPoint(centre);
  camera->SetPosition(centre[0] - 0.4, centre[1] + 1.0, centre[2] + 0.3);
  camera->SetViewUp(0, 0, 1);
  renderer->ResetCamera(bounds);
  camera->Zoom(1.4);
}

void SetMaterial(vtkProperty* p, const Look& look)
{
  p->SetColor(look.Color[0], look.Color[1], look.Color[2]);
  p->SetOpacity(look.Opacity);
  p->SetAmbient(0.15);
  p->SetDiffuse(0.8);
  p->SetSpecular(0.25);
  p->SetSpecularPower(30.0);
}

std::vector<unsigned char> Pixels(vtkRenderWindow* window)
{
  vtkNew<vtkUnsignedCharArray> rgb;
  window->GetPixelData(0, 0, Size - 1, Size - 1, 1, rgb);
  return std::vector<unsigned char>(rgb->GetPointer(0), rgb->GetPointer(0) + 3 * Size * Size);
}

// What the mapper is asked to do besides its isosurfaces.
struct Cut
{
  std::vector<vtkSmartPointer<vtkPlane>> Planes; // clipping planes (world)
  bool Crop = false;
  double CropPlanes[6] = { 0, 0, 0, 0, 0, 0 };
  int CropFlags = VTK_CROP_SUBVOLUME;
};

// Renders `image` through a vtkHistoPyramidIsoMapper (GPU path or forced
// fallback) with `cut`; the path and warnings are reported.
std::vector<unsigned char> RenderMapper(vtkImageData* image, const std::vector<Look>& looks,
  const Cut& cut, bool fallback, const std::string& name, int* warnings = nullptr,
  std::uint64_t* primitives = nullptr)
{
  vtkNew<vtkHistoPyramidIsoMapper> mapper;
  mapper->SetForceCPUFallback(fallback);
  int said = 0;
  vtkNew<vtkCallbackCommand> counter;
  counter->SetClientData(&said);
  counter->SetCallback(
    [](vtkObject*, unsigned long, void* data, void*) { ++*static_cast<int*>(data); });
  mapper->AddObserver(vtkCommand::WarningEvent, counter);
  mapper->AddObserver(vtkCommand::ErrorEvent, counter);
  for (const auto& plane : cut.Planes)
  {
    mapper->AddClippingPlane(plane);
  }
  mapper->SetCropping(cut.Crop);
  mapper->SetCroppingRegionPlanes(const_cast<double*>(cut.CropPlanes));
  mapper->SetCroppingRegionFlags(cut.CropFlags);
  auto volume = iso_test::MakeVolume(image, looks, mapper);
  vtkNew<vtkRenderWindow> window;
  window->SetSize(Size, Size);
  window->SetMultiSamples(0);
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(0, 0, 0);
  window->AddRenderer(renderer);
  renderer->AddVolume(volume);
  PlaceCamera(renderer, image);
  window->Render();
  window->Render(); // a second frame: warnings are said once
  Check(mapper->GetLastRenderPath() ==
        (fallback ? vtkHistoPyramidIsoMapper::FallbackPath : vtkHistoPyramidIsoMapper::GPUPath) ||
      (primitives && mapper->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath),
    name + ": path " + mapper->GetLastRenderPathAsString());
  if (warnings)
  {
    *warnings = said;
  }
  else
  {
    Check(said == 0, name + ": no warning or error");
  }
  if (primitives)
  {
    *primitives = mapper->GetNumberOfPrimitives();
  }
  return Pixels(window);
}

// The reference: each surface by vtkBlockLODContour (level 3) of `image`,
// cut by vtkClipPolyData with each plane, drawn by a vtkPolyDataMapper with
// the volume's material; translucent surfaces are not supported here.
std::vector<unsigned char> RenderReference(vtkImageData* image, vtkImageData* contoured,
  const std::vector<Look>& looks, const std::vector<vtkSmartPointer<vtkPlane>>& planes)
{
  vtkNew<vtkRenderWindow> window;
  window->SetSize(Size, Size);
  window->SetMultiSamples(0);
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(0, 0, 0);
  window->AddRenderer(renderer);
  for (const Look& look : looks)
  {
    vtkNew<vtkBlockLODContour> contour;
    contour->SetInputData(contoured);
    contour->SetLOD(3);
    contour->SetComputeNormals(true);
    contour->SetValue(0, look.Value);
    vtkAlgorithmOutput* port = contour->GetOutputPort();
    std::vector<vtkSmartPointer<vtkClipPolyData>> clips;
    for (const auto& plane : planes)
    {
      auto clip = vtkSmartPointer<vtkClipPolyData>::New();
      clip->SetInputConnection(port);
      clip->SetClipFunction(plane);
      port = clip->GetOutputPort();
      clips.push_back(clip);
    }
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(port);
    mapper->ScalarVisibilityOff();
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    SetMaterial(actor->GetProperty(), look);
    renderer->AddActor(actor);
  }
  PlaceCamera(renderer, image);
  window->Render();
  return Pixels(window);
}

using medical_test::ImageAgreement;
using medical_test::CompareImages;

void ExpectAgree(
  const std::string& name, const std::vector<unsigned char>& a, const std::vector<unsigned char>& b)
{
  const ImageAgreement r = CompareImages(a, b);
  std::printf("%s: %d pixels covered by either, masks agree on %.2f%%, mean colour difference "
              "%.2f, %d pixels differ by more than 24\n",
    name.c_str(), r.Either, 100.0 * r.Agreement, r.MeanDifference, r.Differing);
  Check(r.Either > 5000, name + ": the surfaces cover a good part of the image");
  Check(r.Agreement >= 0.985, name + ": covered pixels agree");
  // Both images hold the same surfaces, so the outline of the cut is what
  // the masks can differ by: exact cuts differ on ~0.04% of the pixels, a cut
  // along whole cells (the plane's cells skipped, no cut inside them) on ~1.1%.
  Check(r.Agreement >= 0.997, name + ": the cut lies where the plane is");
  Check(r.MeanDifference <= 12.0, name + ": colours agree");
}

vtkSmartPointer<vtkPlane> MakePlane(const double origin[3], const double normal[3])
{
  auto plane = vtkSmartPointer<vtkPlane>::New();
  plane->SetOrigin(origin[0], origin[1], origin[2]);
  plane->SetNormal(normal[0], normal[1], normal[2]);
  return plane;
}
} // anonymous namespace

int TestHistoPyramidIsoMapperClipping(int argc, char* argv[])
{
  if (const int skip = iso_test::ProbeOrSkip())
  {
    return skip;
  }
  auto phantom = iso_test::Phantom(96);
  const Look skin{ -500.0, { 0.93, 0.75, 0.62 }, 1.0 };
  const Look skinGlass{ -500.0, { 0.93, 0.75, 0.62 }, 0.35 };
  const Look bone{ 400.0, { 0.97, 0.95, 0.88 }, 1.0 };
  const std::vector<Look> opaque = { skin, bone };
  const std::vector<Look> glass = { skinGlass, bone };

  // The plane: through the centre, oblique to the view, keeping the half
  // its normal points to (the camera sees the cut and the skin beside it).
  double centre[3];
  phantom->GetCenter(centre);
  const double normal[3] = { 1.0, -0.35, 0.15 };
  Cut plane;
  plane.Planes.push_back(MakePlane(centre, normal));

  // 1. The plane, both paths, against BlockLODContour + vtkClipPolyData.
  const auto reference = RenderReference(phantom, phantom, opaque, plane.Planes);
  const auto gpuPlane = RenderMapper(phantom, opaque, plane, false, "GPU plane");
  const auto cpuPlane = RenderMapper(phantom, opaque, plane, true, "fallback plane");
  ExpectAgree("GPU plane vs BlockLODContour + vtkClipPolyData", gpuPlane, reference);
  ExpectAgree("fallback plane vs BlockLODContour + vtkClipPolyData", cpuPlane, reference);
  const auto gpuWhole = RenderMapper(phantom, opaque, Cut(), false, "GPU unclipped");
  const ImageAgreement change = CompareImages(gpuWhole, gpuPlane);
  std::printf("the plane changes %d pixels of the unclipped image\n", change.Differing);
  Check(change.Differing > 5000, "the plane changes the image (the bone shows through the cut)");

  // 2. Translucent skin: the GPU path's compositing against the fallback's sorted triangles.
  const auto gpuGlass = RenderMapper(phantom, glass, plane, false, "GPU translucent plane");
  const auto cpuGlass = RenderMapper(phantom, glass, plane, true, "fallback translucent plane");
  ExpectAgree("GPU translucent plane vs fallback", gpuGlass, cpuGlass);

  // 3. Cropping to a box on voxel faces against the contour of that VOI.
  const int voi[6] = { 10, 70, 20, 85, 30, 95 };
  Cut crop;
  crop.Crop = true;
  for (int i = 0; i < 6; ++i)
  {
    crop.CropPlanes[i] = phantom->GetOrigin()[i / 2] + voi[i] * phantom->GetSpacing()[i / 2];
  }
  vtkNew<vtkExtractVOI> extract;
  extract->SetInputData(phantom);
  extract->SetVOI(voi[0], voi[1], voi[2], voi[3], voi[4], voi[5]);
  extract->Update();
  const auto cropReference = RenderReference(phantom, extract->GetOutput(), opaque, {});
  const auto gpuCrop = RenderMapper(phantom, opaque, crop, false, "GPU crop");
  const auto cpuCrop = RenderMapper(phantom, opaque, crop, true, "fallback crop");
  ExpectAgree("GPU crop vs BlockLODContour of the VOI", gpuCrop, cropReference);
  ExpectAgree("fallback crop vs BlockLODContour of the VOI", cpuCrop, cropReference);

  // 4. A plane that removes everything; unsupported cropping flags.
  Cut all;
  const double away[3] = { 0.0, 0.0, 1.0 };
  double below[3] = { centre[0], centre[1], centre[2] + 1000.0 };
  all.Planes.push_back(MakePlane(below, away));
  std::uint64_t primitives = 1;
  const auto nothing =
    RenderMapper(phantom, opaque, all, false, "everything clipped", nullptr, &primitives);
  Check(CompareImages(nothing, nothing).Either == 0 && primitives == 0,
    "a plane that removes the whole volume draws nothing");
  Cut fence = crop;
  fence.CropFlags = VTK_CROP_FENCE;
  int warnings = 0;
  const auto uncropped = RenderMapper(phantom, opaque, fence, false, "fence flags", &warnings);
  Check(warnings == 1,
    "unsupported cropping flags: one warning (got " + std::to_string(warnings) + ")");
  Check(CompareImages(uncropped, gpuWhole).Differing == 0, "unsupported cropping flags: drawn uncropped");

  // 5. The baseline: four panels.
  vtkNew<vtkRenderWindow> window;
  window->SetSize(600, 600);
  window->SetMultiSamples(0);
  struct Panel
  {
    const std::vector<Look>* Looks;
    const Cut* With;
    bool Fallback;
  };
  const Panel panels[4] = { { &opaque, &plane, false }, { &glass, &plane, false },
    { &opaque, &crop, false }, { &opaque, &plane, true } };
  std::vector<vtkSmartPointer<vtkHistoPyramidIsoMapper>> mappers;
  for (int i = 0; i < 4; ++i)
  {
    auto mapper = vtkSmartPointer<vtkHistoPyramidIsoMapper>::New();
    mappers.push_back(mapper);
    mapper->SetForceCPUFallback(panels[i].Fallback);
    for (const auto& p : panels[i].With->Planes)
    {
      mapper->AddClippingPlane(p);
    }
    mapper->SetCropping(panels[i].With->Crop);
    mapper->SetCroppingRegionPlanes(const_cast<double*>(panels[i].With->CropPlanes));
    auto volume = iso_test::MakeVolume(phantom, *panels[i].Looks, mapper);
    vtkNew<vtkRenderer> renderer;
    renderer->SetViewport((i % 2) * 0.5, (i / 2) * 0.5, (i % 2) * 0.5 + 0.5, (i / 2) * 0.5 + 0.5);
    renderer->SetBackground(0.1, 0.12, 0.16);
    renderer->AddVolume(volume);
    PlaceCamera(renderer, phantom);
    window->AddRenderer(renderer);
  }
  window->Render();
  const int result = medical_test::CompareWithBaseline(argc, argv, window);
  Check(result != vtkRegressionTester::FAILED, "the window matches the baseline");
  return medical_test::Finish("TestHistoPyramidIsoMapperClipping");
}
