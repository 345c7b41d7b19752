// SPDX-License-Identifier: BSD-3-Clause
// mediso-render (the GPU core on its own EGL context, no X, no VTK) against
// vtkHistoPyramidIsoMapper (the same core inside a VTK render window) on
// the same scene: the volume written as a MetaImage, the same isosurfaces,
// colours, material, background, image size and camera (VTK's ResetCamera,
// then Azimuth, Elevation, OrthogonalizeViewUp, Zoom), and VTK's headlight.
//   TestHistoPyramidIsoMapperHeadless MEDISO_RENDER TEMP_DIR Sphere|Torus|Clip|CT
// Passes when the two images differ by more than 24 levels (of 255, in any
// channel) in at most 0.5% of the pixels, and both drew the same number of
// primitives. Skipped (125) where either path cannot run, or without the CT
// for the CT case.
#include "IsoMapperTestScenes.h"
#include "MedicalTestUtilities.h"

#include "vtkCamera.h"
#include "vtkImageData.h"
#include "vtkMetaImageReader.h"
#include "vtkMetaImageWriter.h"
#include "vtkPNGReader.h"
#include "vtkPNGWriter.h"
#include "vtkPlane.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkPointData.h"
#include "vtkWindowToImageFilter.h"
#include <vtksys/SystemTools.hxx>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>

namespace
{
using medical_test::Check;

// A MetaImage header's TransformMatrix (row-major, the axes as columns, as
// Headless/MetaImage.cxx reads it); the identity without one.
std::vector<double> MetaImageDirection(const std::string& path)
{
  std::vector<double> m = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int i = 0; i < 64 && std::getline(in, line); ++i)
  {
    const auto equals = line.find('=');
    std::string key;
    std::istringstream(line.substr(0, equals)) >> key;
    if (key == "ElementDataFile" || equals == std::string::npos)
    {
      break;
    }
    if (key == "TransformMatrix")
    {
      std::istringstream values(line.substr(equals + 1));
      std::vector<double> read(9);
      for (double& v : read)
      {
        values >> v;
      }
      if (values)
      {
        m = read;
      }
    }
  }
  return m;
}

struct Scene
{
  vtkSmartPointer<vtkImageData> Image;
  std::string Volume; // the MetaImage mediso-render reads
  std::vector<iso_test::Look> Looks;
  int Size[2] = { 400, 300 };
  double Azimuth = 0.0, Elevation = 0.0, Zoom = 1.0;
  bool Parallel = false;
  // Clipping planes (world: a x + b y + c z + d >= 0 kept) and a cropping box
  // of point indices (none when Crop[0] > Crop[1]).
  std::vector<std::array<double, 4>> ClipPlanes;
  int Crop[6] = { 1, 0, 0, 0, 0, 0 };
};

// The scene's image drawn by vtkHistoPyramidIsoMapper, and its primitives.
vtkSmartPointer<vtkImageData> RenderWithVTK(const Scene& s, std::uint64_t& primitives, bool& gpu)
{
  vtkNew<vtkRenderWindow> window;
  window->SetSize(s.Size[0], s.Size[1]);
  window->SetMultiSamples(0);
  window->SetOffScreenRendering(1);
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(0.1, 0.12, 0.16);
  window->AddRenderer(renderer);
  vtkNew<vtkHistoPyramidIsoMapper> mapper;
  auto volume = iso_test::MakeVolume(s.Image, s.Looks, mapper);
  for (const auto& p : s.ClipPlanes)
  {
    // The plane's point nearest the origin: -d n / |n|^2.
    const double norm2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    vtkNew<vtkPlane> plane;
    plane->SetNormal(p[0], p[1], p[2]);
    plane->SetOrigin(-p[3] * p[0] / norm2, -p[3] * p[1] / norm2, -p[3] * p[2] / norm2);
    mapper->AddClippingPlane(plane);
  }
  if (s.Crop[0] <= s.Crop[1])
  {
    double planes[6];
    for (int i = 0; i < 6; ++i)
    {
      planes[i] = s.Image->GetOrigin()[i / 2] + s.Crop[i] * s.Image->GetSpacing()[i / 2];
    }
    mapper->SetCropping(true);
    mapper->SetCroppingRegionPlanes(planes);
  }
  renderer->AddVolume(volume);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetParallelProjection(s.Parallel);
  renderer->ResetCamera();
  camera->Azimuth(s.Azimuth);
  camera->Elevation(s.Elevation);
  camera->OrthogonalizeViewUp();
  camera->Zoom(s.Zoom);
  renderer->ResetCameraClippingRange();
  window->Render();
  gpu = mapper->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath;
  primitives = mapper->GetNumberOfPrimitives();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(grab->GetOutput());
  return image;
}

std::string Quote(const std::string& s)
{
  return "'" + s + "'";
}

// Runs mediso-render on the scene; its image (or null) and primitives.
vtkSmartPointer<vtkImageData> RenderHeadless(const Scene& s, const std::string& program,
  const std::string& png, std::uint64_t& primitives, int& status, std::string& output)
{
  std::ostringstream command;
  command.precision(17);
  command << Quote(program) << " " << Quote(s.Volume) << " --size " << s.Size[0] << "x" << s.Size[1]
          << " --azimuth " << s.Azimuth << " --elevation " << s.Elevation << " --zoom " << s.Zoom
          << (s.Parallel ? " --parallel" : "") << " --output " << Quote(png) << " --stats";
  for (const auto& p : s.ClipPlanes)
  {
    command << " --clip " << p[0] << "," << p[1] << "," << p[2] << "," << p[3];
  }
  if (s.Crop[0] <= s.Crop[1])
  {
    command << " --crop " << s.Crop[0] << "," << s.Crop[1] << "," << s.Crop[2] << "," << s.Crop[3]
            << "," << s.Crop[4] << "," << s.Crop[5];
  }
  for (const iso_test::Look& look : s.Looks)
  {
    command << " --iso " << look.Value << ":" << look.Color[0] << "," << look.Color[1] << ","
            << look.Color[2] << "," << look.Opacity;
  }
  command << " 2>&1";
  std::printf("running %s\n", command.str().c_str());
  output.clear();
  std::FILE* pipe = popen(command.str().c_str(), "r");
  if (!pipe)
  {
    status = -1;
    return nullptr;
  }
  char buffer[4096];
  while (std::fgets(buffer, sizeof(buffer), pipe))
  {
    output += buffer;
  }
  const int raw = pclose(pipe);
  status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::printf("%s", output.c_str());
  const std::size_t at = output.find("\"primitives\": ");
  primitives = at == std::string::npos ? 0 : std::strtoull(output.c_str() + at + 14, nullptr, 10);
  if (status != 0)
  {
    return nullptr;
  }
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(png.c_str());
  reader->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(reader->GetOutput());
  return image;
}

// Fraction of pixels whose largest channel difference exceeds `levels`.
double DifferingFraction(vtkImageData* a, vtkImageData* b, int levels, int& largest)
{
  largest = 0;
  auto* pa = vtkUnsignedCharArray::SafeDownCast(a->GetPointData()->GetScalars());
  auto* pb = vtkUnsignedCharArray::SafeDownCast(b->GetPointData()->GetScalars());
  int da[3], db[3];
  a->GetDimensions(da);
  b->GetDimensions(db);
  if (!pa || !pb || da[0] != db[0] || da[1] != db[1] || pa->GetNumberOfComponents() < 3 ||
    pb->GetNumberOfComponents() < 3)
  {
    return 1.0;
  }
  const vtkIdType n = pa->GetNumberOfTuples();
  vtkIdType differing = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    int d = 0;
    for (int c = 0; c < 3; ++c)
    {
      d = std::max(d, std::abs(int(pa->GetTypedComponent(i, c)) - int(pb->GetTypedComponent(i, c))));
    }
    largest = std::max(largest, d);
    differing += d > levels ? 1 : 0;
  }
  return static_cast<double>(differing) / static_cast<double>(n);
}
} // namespace

int TestHistoPyramidIsoMapperHeadless(int argc, char* argv[])
{
  if (argc < 4)
  {
    std::printf("usage: TestHistoPyramidIsoMapperHeadless MEDISO_RENDER TEMP_DIR Sphere|Torus|Clip|CT\n");
    return 1;
  }
  const std::string program = argv[1], temp = argv[2], which = argv[3];
  vtksys::SystemTools::MakeDirectory(temp);
  if (const int skip = iso_test::ProbeOrSkip())
  {
    return skip;
  }
  std::vector<Scene> scenes;
  auto writeVolume = [&](vtkImageData* image, const std::string& name) -> std::string
  {
    const std::string path = temp + "/" + name;
    vtkNew<vtkMetaImageWriter> writer;
    writer->SetInputData(image);
    writer->SetFileName(path.c_str());
    writer->SetCompression(false);
    writer->Write();
    return path;
  };
  if (which == "Sphere")
  {
    Scene s;
    s.Image = iso_test::Sphere(40, 0.5);
    s.Volume = writeVolume(s.Image, "sphere.mhd"); // header and raw data apart
    s.Looks = { { 6.0, { 0.9, 0.5, 0.3 }, 1.0 } };
    s.Azimuth = 25.0;
    s.Elevation = 15.0;
    scenes.push_back(s);
    s.Parallel = true;
    s.Zoom = 1.4;
    s.Looks = { { 4.0, { 0.3, 0.6, 0.9 }, 1.0 }, { 8.0, { 0.9, 0.9, 0.7 }, 0.4 } };
    scenes.push_back(s);
  }
  else if (which == "Torus")
  {
    Scene s;
    s.Image = iso_test::Torus(48, 12.0);
    s.Volume = writeVolume(s.Image, "torus.mha");
    s.Looks = { { 4.5, { 0.8, 0.8, 0.4 }, 1.0 } };
    s.Azimuth = -35.0;
    s.Elevation = 50.0;
    s.Zoom = 1.2;
    scenes.push_back(s);
    // A close zoom on the tube seen from the side: cells wider than the
    // largest point, so quads, not points, cover them.
    s.Elevation = 90.0;
    s.Zoom = 30.0;
    scenes.push_back(s);
  }
  else if (which == "Clip")
  {
    // The torus cut by an oblique plane and cropped to a box (--clip, --crop).
    Scene s;
    s.Image = iso_test::Torus(48, 12.0);
    s.Volume = writeVolume(s.Image, "torus_clip.mha");
    s.Looks = { { 4.5, { 0.8, 0.8, 0.4 }, 1.0 }, { 7.0, { 0.4, 0.6, 0.9 }, 0.4 } };
    s.Azimuth = -35.0;
    s.Elevation = 50.0;
    s.Zoom = 1.2;
    s.ClipPlanes = { { 1.0, 0.5, 0.3, -2.0 } };
    const int crop[6] = { 4, 40, 0, 47, 2, 23 };
    std::copy(crop, crop + 6, s.Crop);
    scenes.push_back(s);
  }
  else if (which == "CT")
  {
    const std::string ct = medical_test::CachedDataFile("ct_head.mha", "the real CT");
    if (ct.empty())
    {
      return medical_test::SkipReturnCode;
    }
    vtkNew<vtkMetaImageReader> reader;
    reader->SetFileName(ct.c_str());
    reader->Update();
    Scene s;
    s.Image = reader->GetOutput();
    // mediso-render places the file by its TransformMatrix (Python/fetch_data.py writes the
    // CT's direction in patient space), which VTK's reader leaves out: the same direction on
    // VTK's image, so that both draw the same scene.
    s.Image->SetDirectionMatrix(MetaImageDirection(ct).data());
    s.Volume = ct;
    s.Size[0] = 480;
    s.Size[1] = 360;
    s.Looks = { { -500.0, { 0.93, 0.75, 0.62 }, 0.35 }, { 400.0, { 0.97, 0.95, 0.88 }, 1.0 } };
    s.Elevation = -80.0;
    s.Azimuth = 20.0;
    scenes.push_back(s);
  }
  else
  {
    std::printf("unknown case %s\n", which.c_str());
    return 1;
  }

  for (std::size_t i = 0; i < scenes.size(); ++i)
  {
    const Scene& s = scenes[i];
    const std::string name = which + std::to_string(i);
    std::uint64_t vtkPrimitives = 0, headlessPrimitives = 0;
    bool gpu = false;
    auto vtkImage = RenderWithVTK(s, vtkPrimitives, gpu);
    if (!gpu)
    {
      std::printf("SKIP: vtkHistoPyramidIsoMapper did not draw on the GPU\n");
      return 125;
    }
    int status = 0;
    std::string output;
    auto headless = RenderHeadless(s, program, temp + "/" + name + ".png", headlessPrimitives,
      status, output);
    if (status == 4)
    {
      std::printf("SKIP: mediso-render has no usable OpenGL context here\n");
      return 125;
    }
    Check(headless != nullptr, name + ": mediso-render failed with status " + std::to_string(status));
    if (!headless)
    {
      continue;
    }
    vtkNew<vtkPNGWriter> writer;
    writer->SetInputData(vtkImage);
    writer->SetFileName((temp + "/" + name + "-vtk.png").c_str());
    writer->Write();
    int largest = 0;
    const double fraction = DifferingFraction(vtkImage, headless, 24, largest);
    std::printf("%s: %llu primitives (VTK) / %llu (mediso-render); %.3f%% of pixels differ by "
                "more than 24 levels, largest difference %d\n",
      name.c_str(), static_cast<unsigned long long>(vtkPrimitives),
      static_cast<unsigned long long>(headlessPrimitives), 100.0 * fraction, largest);
    Check(vtkPrimitives == headlessPrimitives && vtkPrimitives > 0,
      name + ": the primitives differ");
    Check(fraction <= 0.005, name + ": the images differ in more than 0.5% of the pixels");
  }
  return medical_test::Finish("TestHistoPyramidIsoMapperHeadless passed");
}
