// SPDX-License-Identifier: BSD-3-Clause
// vtkHistoPyramidIsoMapper checks, one ctest test per case (the argument):
//  Counts    - the pyramid's total (the primitives drawn) equals the CPU count
//              of active cell-isovalue pairs, for 40 single isovalues and 6
//              isovalue sets, in int16, uint8, float and double data; camera
//              moves reuse the pyramid (no rebuild, no re-upload).
//  Memory    - GPU memory against volume bytes (<= 1.5x for a 256x256x108
//              int16 volume, the head CT's size); it stays the same across
//              1000 isovalue changes (24^3 phantom); ReleaseGraphicsResources()
//              frees it all.
//  Reference - the GPU image matches the full-resolution CPU marching-cubes
//              image (the mapper's fallback: vtkBlockLODContour level 3 and a
//              vtkPolyDataMapper) of the same isovalues: covered-pixel masks
//              agree on >= 98.5% of the pixels covered by either, and the
//              mean colour difference over pixels covered by both is <= 12
//              (of 255) per channel, shaded and opaque (phantom skin and
//              bone, a torus, and an ellipsoid in volumes thin in x and in
//              y, whose pyramid axis reaches one node early). Translucent: two
//              nested half-transparent spheres 0.35 cell apart, flat colours
//              (mean difference <= 2, and the centre pixel within 2 of the
//              exact composite of its four hits), which checks the order of
//              the hits inside one cell (GPU) and the back-to-front sort of
//              the triangles (CPU).
//  Shading   - the normals the surface is lit with: a linear field's
//              isosurface (a plane, int16 and float, anisotropic spacing)
//              has its one analytic Lambert colour at every pixel (within 2
//              of 255), in both projections and both paths.
//  FirstHit  - the first-hit pass (opaque, points) against one pass: it is
//              taken exactly where it applies, and the window's colours and
//              depth buffer are the same (at most 1 in 2000 covered pixels
//              differ), also with an opaque plane through the surface, in a
//              renderer that does not start at the window's origin, and
//              with two or three opaque isovalues that share cells (the
//              nearest hit of a cell's isovalues). Its buffers (10 bytes per
//              pixel) cover the volume's projection, not the viewport: at
//              least the box's projected rectangle, at most that rounded up
//              to 64 pixels (and the viewport); they grow after a frame of a
//              smaller projection and shrink after one of a much larger one
//              (same images); they exist only where used and are freed with
//              the rest.
//  Footprint - point sprites and cell boxes give the same image (masks agree
//              on >= 99.8% of the covered pixels, mean colour difference
//              <= 1 of 255) for opaque and translucent surfaces in
//              perspective and parallel projection, and for random values
//              (every kind of cell); the mapper picks points
//              for a whole-volume view and boxes for a close zoom and for an
//              eye inside the volume, and says which it used.
//  Fallback  - MEDISO_DISABLE_GPU_PATH=1 makes the mapper render through the
//              fallback, report it (path, reason) and warn exactly once.
//  BadInput  - no scalars, cell scalars, 3 components, 64-bit integers, 2D
//              data, no isovalues, more than 8 isovalues, NaN values, an
//              isovalue outside the range: one clear message each (said once
//              over several renders) and nothing drawn, never a crash; a
//              volume over GL_MAX_3D_TEXTURE_SIZE is drawn as bricks on the
//              GPU path with no message.
//  Budget    - SetGPUMemoryBudget: 0.45 MB keeps the 64^3 phantom as bricks
//              on the GPU path (dense bone, 1000 HU) with the primitives of
//              one texture and no message; 0.001 MB, which its bricks
//              exceed, falls back with that reason in one warning.
#include "HistoPyramid.h"
#include "IsoMapperTestScenes.h"
#include "MedicalTestUtilities.h"
#include "RenderTestUtilities.h"
#include "vtkMedicalGLCapabilities.h"

#include "vtkActor.h"
#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkMath.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkShortArray.h"
#include "vtkTypeInt64Array.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;

// Counts the error and warning events of an object and keeps their texts.
class MessageCounter
{
public:
  explicit MessageCounter(vtkObject* object)
  {
    this->Callback->SetClientData(this);
    this->Callback->SetCallback(
      [](vtkObject*, unsigned long event, void* clientData, void* callData)
      {
        auto* self = static_cast<MessageCounter*>(clientData);
        const std::string text = callData ? static_cast<const char*>(callData) : "";
        if (event == vtkCommand::ErrorEvent)
        {
          ++self->Errors;
        }
        else
        {
          ++self->Warnings;
        }
        // Keep the message, not the "ERROR: In file, line" header line.
        std::string message = text;
        const std::size_t newline = message.find('\n');
        if (newline != std::string::npos)
        {
          message = message.substr(newline + 1);
        }
        while (!message.empty() && message.back() == '\n')
        {
          message.pop_back();
        }
        self->Text += message + "\n";
      });
    object->AddObserver(vtkCommand::ErrorEvent, this->Callback);
    object->AddObserver(vtkCommand::WarningEvent, this->Callback);
  }
  int Errors = 0;
  int Warnings = 0;
  std::string Text;

private:
  vtkNew<vtkCallbackCommand> Callback;
};

struct Scene
{
  vtkNew<vtkRenderWindow> Window;
  vtkNew<vtkRenderer> Renderer;
  explicit Scene(int width = 300, int height = 300)
  {
    this->Window->SetSize(width, height);
    this->Window->SetMultiSamples(0);
    this->Window->AddRenderer(this->Renderer);
    this->Renderer->SetBackground(0, 0, 0);
  }
  void Show(vtkVolume* volume)
  {
    this->Renderer->AddVolume(volume);
    vtkCamera* camera = this->Renderer->GetActiveCamera();
    camera->SetPosition(-0.4, 1.0, 0.3);
    camera->SetFocalPoint(0, 0, 0);
    camera->SetViewUp(0, 0, 1);
    this->Renderer->ResetCamera();
  }
};

template <typename T>
std::uint64_t CPUCount(vtkImageData* image, const std::vector<double>& isovalues)
{
  int dims[3];
  image->GetDimensions(dims);
  const T* data = static_cast<const T*>(image->GetPointData()->GetScalars()->GetVoidPointer(0));
  std::uint64_t total = 0;
  for (std::uint32_t c : mediso::HistoPyramid::CountCrossings(data, dims, isovalues))
  {
    total += c;
  }
  return total;
}

template <typename T, typename ArrayT>
vtkSmartPointer<vtkImageData> Convert(vtkImageData* source, double scale, double shift)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->CopyStructure(source);
  vtkDataArray* in = source->GetPointData()->GetScalars();
  vtkNew<ArrayT> out;
  out->SetNumberOfTuples(in->GetNumberOfTuples());
  for (vtkIdType i = 0; i < in->GetNumberOfTuples(); ++i)
  {
    out->SetValue(i, static_cast<T>(in->GetTuple1(i) * scale + shift));
  }
  image->GetPointData()->SetScalars(out);
  return image;
}

template <typename T>
void CountCase(const std::string& name, vtkImageData* image)
{
  double range[2];
  image->GetPointData()->GetScalars()->GetRange(range);
  vtkNew<vtkHistoPyramidIsoMapper> mapper;
  auto volume = iso_test::MakeVolume(image, { { 0.5 * (range[0] + range[1]), { 1, 1, 1 }, 1 } }, mapper);
  Scene scene(200, 200);
  scene.Show(volume);
  std::vector<std::vector<double>> sets;
  for (int i = 0; i < 40; ++i)
  {
    sets.push_back({ range[0] + (range[1] - range[0]) * (i + 0.5) / 40.0 });
  }
  sets.push_back({ range[0] + 0.2 * (range[1] - range[0]), range[0] + 0.7 * (range[1] - range[0]) });
  sets.push_back({ range[0], range[1] });                 // the ends: nothing crosses at the minimum
  sets.push_back({ range[0] - 10.0, range[1] + 10.0 });   // outside the range
  std::vector<double> eight;
  for (int i = 0; i < 8; ++i)
  {
    eight.push_back(range[0] + (range[1] - range[0]) * (i + 1) / 9.0);
  }
  sets.push_back(eight);
  sets.push_back({ std::floor(range[0] + 0.3 * (range[1] - range[0])) }); // an integer value
  sets.push_back({ std::floor(range[0] + 0.3 * (range[1] - range[0])) + 0.5 });
  int mismatches = 0;
  for (const auto& isovalues : sets)
  {
    vtkContourValues* values = volume->GetProperty()->GetIsoSurfaceValues();
    values->SetNumberOfContours(0);
    for (std::size_t i = 0; i < isovalues.size(); ++i)
    {
      values->SetValue(static_cast<int>(i), isovalues[i]);
    }
    // Opacity 1 everywhere so that no isovalue is left out as invisible.
    volume->GetProperty()->GetScalarOpacity()->RemoveAllPoints();
    volume->GetProperty()->GetScalarOpacity()->AddPoint(range[0] - 100, 1.0);
    volume->GetProperty()->GetScalarOpacity()->AddPoint(range[1] + 100, 1.0);
    scene.Window->Render();
    const std::uint64_t cpu = CPUCount<T>(image, isovalues);
    const std::uint64_t gpu = mapper->GetNumberOfPrimitives();
    if (gpu != cpu || mapper->GetLastRenderPath() != vtkHistoPyramidIsoMapper::GPUPath)
    {
      ++mismatches;
      std::printf("  %s: isovalue %g (+%zu more): GPU %llu, CPU %llu, path %s\n", name.c_str(),
        isovalues[0], isovalues.size() - 1, static_cast<unsigned long long>(gpu),
        static_cast<unsigned long long>(cpu), mapper->GetLastRenderPathAsString());
    }
  }
  std::printf("%s: %zu isovalue sets, %d mismatches\n", name.c_str(), sets.size(), mismatches);
  Check(mismatches == 0, name + ": primitives equal the CPU count of active cells");

  // Camera moves reuse the pyramid and the uploaded volume.
  const auto builds = mapper->GetNumberOfPyramidBuilds();
  const auto uploads = mapper->GetNumberOfVolumeUploads();
  for (int i = 0; i < 10; ++i)
  {
    scene.Renderer->GetActiveCamera()->Azimuth(10.0);
    scene.Window->Render();
  }
  Check(mapper->GetNumberOfPyramidBuilds() == builds && mapper->GetNumberOfVolumeUploads() == uploads,
    name + ": camera moves neither rebuild the pyramid nor upload the volume");
  Check(uploads == 1, name + ": one volume upload for all isovalue changes");
}

void Counts()
{
  auto phantom = iso_test::Phantom(45);
  CountCase<short>("int16 phantom", phantom);
  CountCase<unsigned char>(
    "uint8", Convert<unsigned char, vtkUnsignedCharArray>(phantom, 0.08, 90.0));
  auto torus = iso_test::Torus(33, 9.0);
  CountCase<float>("float torus", torus);
  CountCase<double>("double", Convert<double, vtkDoubleArray>(phantom, 1.0, 0.25));
}

void Memory()
{
  // The ratio on a 256x256x108 int16 volume, as the head CT.
  {
    vtkNew<vtkMedicalPhantomSource> source;
    source->SetDimensions(256, 256, 108);
    source->SetSpacing(0.957, 0.957, 1.5);
    source->Update();
    vtkNew<vtkHistoPyramidIsoMapper> mapper;
    auto volume =
      iso_test::MakeVolume(source->GetOutput(), { { -500.0, { 1, 1, 1 }, 1.0 } }, mapper);
    Scene scene(64, 64);
    scene.Show(volume);
    scene.Window->Render();
    const double volumeBytes = 256.0 * 256.0 * 108.0 * 2.0;
    const std::uint64_t bytes = mapper->GetGPUMemoryBytes();
    std::printf("256x256x108 int16: GPU memory %.2f MB for a %.2f MB volume: %.3fx\n", bytes / 1e6,
      volumeBytes / 1e6, bytes / volumeBytes);
    Check(bytes > volumeBytes && bytes <= 1.5 * volumeBytes, "GPU memory <= 1.5x the volume bytes");
  }

  // Flat across 1000 isovalue changes (a small volume keeps this quick).
  auto phantom = iso_test::Phantom(24);
  vtkNew<vtkHistoPyramidIsoMapper> mapper;
  auto volume = iso_test::MakeVolume(phantom, { { -900.0, { 1, 1, 1 }, 1.0 } }, mapper);
  volume->GetProperty()->GetScalarOpacity()->AddPoint(2000.0, 1.0);
  volume->GetProperty()->GetScalarOpacity()->AddPoint(-1100.0, 1.0);
  Scene scene(64, 64);
  scene.Show(volume);
  scene.Window->Render();
  const std::uint64_t first = mapper->GetGPUMemoryBytes();
  std::uint64_t low = first, high = first;
  for (int i = 0; i < 1000; ++i)
  {
    volume->GetProperty()->GetIsoSurfaceValues()->SetValue(0, -899.0 + 2.0 * i);
    scene.Window->Render();
    low = std::min(low, mapper->GetGPUMemoryBytes());
    high = std::max(high, mapper->GetGPUMemoryBytes());
  }
  std::printf("1000 isovalue changes: GPU memory %llu..%llu bytes, %llu builds, %llu uploads\n",
    static_cast<unsigned long long>(low), static_cast<unsigned long long>(high),
    static_cast<unsigned long long>(mapper->GetNumberOfPyramidBuilds()),
    static_cast<unsigned long long>(mapper->GetNumberOfVolumeUploads()));
  Check(first > 0 && low == first && high == first, "GPU memory flat across 1000 isovalue changes");
  Check(mapper->GetNumberOfPyramidBuilds() == 1001 && mapper->GetNumberOfVolumeUploads() == 1,
    "one pyramid build per isovalue change, one upload");
  mapper->ReleaseGraphicsResources(scene.Window);
  Check(mapper->GetGPUMemoryBytes() == 0, "ReleaseGraphicsResources frees all GPU memory");
  scene.Window->Render(); // everything is made again
  Check(mapper->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath &&
      mapper->GetGPUMemoryBytes() == first,
    "renders again after a release");
}

using medical_test::ImageAgreement;
using medical_test::CompareImages;

// How RenderPixels() lights: shaded, or flat (ambient 1, diffuse and
// specular 0: each surface in its own colour, so that a pixel's colour
// tells which surfaces were composited in which order).
enum class Lighting
{
  Shaded,
  Flat,
  Diffuse // ambient 0, diffuse 1, specular 0: the colour is the Lambert term
};

// Renders `image` with `looks` through `mapper` in a 300x300 window from the
// standard view (changed by `place`, if given); returns the RGB pixels.
std::vector<unsigned char> RenderPixels(vtkHistoPyramidIsoMapper* mapper, vtkImageData* image,
  const std::vector<iso_test::Look>& looks,
  const std::function<void(vtkCamera*)>& place = nullptr, Lighting lighting = Lighting::Shaded)
{
  const int size = 300;
  auto volume = iso_test::MakeVolume(image, looks, mapper);
  Scene scene(size, size);
  if (lighting != Lighting::Shaded)
  {
    const bool flat = lighting == Lighting::Flat;
    volume->GetProperty()->SetAmbient(flat ? 1.0 : 0.0);
    volume->GetProperty()->SetDiffuse(flat ? 0.0 : 1.0);
    volume->GetProperty()->SetSpecular(0.0);
  }
  scene.Show(volume);
  if (place)
  {
    place(scene.Renderer->GetActiveCamera());
    scene.Renderer->ResetCameraClippingRange();
  }
  scene.Window->Render();
  vtkNew<vtkUnsignedCharArray> rgb;
  scene.Window->GetPixelData(0, 0, size - 1, size - 1, 1, rgb);
  return std::vector<unsigned char>(rgb->GetPointer(0), rgb->GetPointer(0) + 3 * size * size);
}

// Renders a scene with the GPU path and with the fallback; compares.
// Returns the GPU path's pixels.
std::vector<unsigned char> CompareWithCPU(const std::string& name, vtkImageData* image,
  const std::vector<iso_test::Look>& looks, Lighting lighting = Lighting::Shaded)
{
  std::vector<unsigned char> pixels[2];
  for (int pass = 0; pass < 2; ++pass)
  {
    vtkNew<vtkHistoPyramidIsoMapper> mapper;
    mapper->SetForceCPUFallback(pass == 1);
    pixels[pass] = RenderPixels(mapper, image, looks, nullptr, lighting);
    Check(mapper->GetLastRenderPath() ==
        (pass == 0 ? vtkHistoPyramidIsoMapper::GPUPath : vtkHistoPyramidIsoMapper::FallbackPath),
      name + ": path " + mapper->GetLastRenderPathAsString());
  }
  const ImageAgreement a = CompareImages(pixels[0], pixels[1]);
  std::printf("%s: %d pixels covered by either, masks agree on %.2f%%, mean colour difference "
              "%.2f\n",
    name.c_str(), a.Either, 100.0 * a.Agreement, a.MeanDifference);
  Check(a.Either > 5000, name + ": the surface covers a good part of the image");
  Check(a.Agreement >= 0.985, name + ": covered pixels agree with the CPU marching-cubes image");
  // Shaded, the triangles' interpolated normals differ from the exact
  // surface's gradients; flat, only the coverage and the order of the layers
  // can differ.
  const double maxDifference = lighting == Lighting::Flat ? 2.0 : 12.0;
  Check(a.MeanDifference <= maxDifference,
    name + ": colours agree with the CPU marching-cubes image");
  return pixels[0];
}

void Reference()
{
  auto phantom = iso_test::Phantom(96);
  const iso_test::Look skin{ -500.0, { 0.93, 0.75, 0.62 }, 1.0 };
  const iso_test::Look bone{ 400.0, { 0.97, 0.95, 0.88 }, 1.0 };
  CompareWithCPU("phantom skin", phantom, { skin });
  CompareWithCPU("phantom bone", phantom, { bone });
  CompareWithCPU("torus", iso_test::Torus(40, 11.0), { { 4.2, { 0.5, 0.85, 0.45 }, 1.0 } });
  // Volumes thin in x, then in y (12 points against 40): padded to 16 against
  // 64, that axis of the pyramid reaches one node two levels before the
  // others, so the walk reads packed texels (2x2 nodes in x and y) whose odd
  // components along it are nodes beyond the level. An ellipsoid flat along
  // the thin axis.
  for (int thinAxis = 0; thinAxis < 2; ++thinAxis)
  {
    int dims[3] = { 40, 40, 40 };
    dims[thinAxis] = 12;
    const double h[3] = { 1.0, 1.0, 1.0 };
    const double origin[3] = { -0.5 * (dims[0] - 1), -0.5 * (dims[1] - 1), -0.5 * (dims[2] - 1) };
    double squash[3] = { 1.0, 1.0, 1.0 };
    squash[thinAxis] = 1.0 / 0.09; // radius 0.3 x 15 = 4.5 along the thin axis
    auto field = iso_test::SampleField(dims, h, origin,
      [squash](double x, double y, double z)
      { return std::sqrt(squash[0] * x * x + squash[1] * y * y + squash[2] * z * z); });
    CompareWithCPU(std::string("ellipsoid in a volume thin in ") + (thinAxis == 0 ? "x" : "y"),
      field, { { 15.0, { 0.8, 0.8, 0.55 }, 1.0 } });
  }
  // Translucent compositing order: two half-transparent spheres 0.35 cell
  // apart, so that most cells the surfaces cross hold both and the order of
  // the hits inside one cell decides the colour. Flat colours, against the
  // CPU path's triangles (sorted back to front), and at the centre of the
  // image against the exact answer: the ray meets the outer (blue) sphere,
  // the inner (red) one, red again and blue again, so it sees
  // 0.5 blue + 0.25 red + 0.125 red + 0.0625 blue over black.
  const iso_test::Look inner{ 12.0, { 1.0, 0.1, 0.1 }, 0.5 };
  const iso_test::Look outer{ 12.35, { 0.1, 0.2, 1.0 }, 0.5 };
  const std::vector<unsigned char> spheres = CompareWithCPU(
    "nested translucent spheres", iso_test::Sphere(40), { inner, outer }, Lighting::Flat);
  const std::size_t centre = 3 * (150 * 300 + 150);
  int worst = 0;
  for (int c = 0; c < 3; ++c)
  {
    const double expected =
      255.0 * (0.5625 * outer.Color[c] + 0.375 * inner.Color[c]);
    worst = std::max(worst, static_cast<int>(std::lround(std::abs(spheres[centre + c] - expected))));
  }
  std::printf("nested translucent spheres: centre pixel %d %d %d, at most %d from the exact "
              "composite\n",
    spheres[centre], spheres[centre + 1], spheres[centre + 2], worst);
  Check(worst <= 2, "nested translucent spheres: the centre pixel composites the four hits in order");
}

// Renders `image` with points allowed and with boxes only, from a camera set
// by `place`; checks the footprint the mapper chose and that both agree.
void CompareFootprints(const std::string& name, vtkImageData* image,
  const std::vector<iso_test::Look>& looks, const std::function<void(vtkCamera*)>& place,
  int expected)
{
  std::vector<unsigned char> pixels[2];
  for (int pass = 0; pass < 2; ++pass)
  {
    vtkNew<vtkHistoPyramidIsoMapper> mapper;
    mapper->SetAllowPointFootprint(pass == 0);
    MessageCounter messages(mapper);
    pixels[pass] = RenderPixels(mapper, image, looks, place);
    const int footprint = pass == 0 ? expected : vtkHistoPyramidIsoMapper::BoxFootprint;
    Check(mapper->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath &&
        mapper->GetLastFootprint() == footprint && messages.Errors + messages.Warnings == 0,
      name + ": drawn on the GPU with " + (footprint ? "points" : "boxes") + " (got " +
        mapper->GetLastRenderPathAsString() + ", " + mapper->GetLastFootprintAsString() + ")");
  }
  const ImageAgreement a = CompareImages(pixels[0], pixels[1]);
  std::printf("%s: %d pixels covered by either, masks agree on %.3f%%, mean colour difference "
              "%.3f\n",
    name.c_str(), a.Either, 100.0 * a.Agreement, a.MeanDifference);
  Check(a.Either > 3000, name + ": the surface covers a good part of the image");
  Check(a.Agreement >= 0.998, name + ": covered pixels agree between the footprints");
  Check(a.MeanDifference <= 1.0, name + ": colours agree between the footprints");
}

void Footprint()
{
  auto phantom = iso_test::Phantom(64);
  const iso_test::Look skin{ -500.0, { 0.93, 0.75, 0.62 }, 1.0 };
  const iso_test::Look glass{ -500.0, { 0.93, 0.75, 0.62 }, 0.35 };
  const iso_test::Look bone{ 400.0, { 0.97, 0.95, 0.88 }, 1.0 };
  const auto whole = [](vtkCamera*) {};
  const auto parallel = [](vtkCamera* camera) { camera->ParallelProjectionOn(); };
  // Cells of the 64^3 phantom about 400 pixels wide: beyond any point size
  // llvmpipe (255) or common GPUs (256..2047, with the bound's margin) allow.
  const auto close = [](vtkCamera* camera) { camera->Zoom(150.0); };
  double centre[3];
  phantom->GetCenter(centre);
  const auto inside = [&centre](vtkCamera* camera)
  {
    // The eye at the centre of the phantom's head, looking at the skull.
    camera->SetFocalPoint(centre[0], centre[1] - 10.0, centre[2]);
    camera->SetPosition(centre);
    camera->SetViewUp(0.0, 0.0, 1.0);
    camera->SetViewAngle(60.0);
  };
  const int points = vtkHistoPyramidIsoMapper::PointFootprint;
  const int boxes = vtkHistoPyramidIsoMapper::BoxFootprint;
  CompareFootprints("skin, perspective", phantom, { skin }, whole, points);
  CompareFootprints("bone, parallel", phantom, { bone }, parallel, points);
  CompareFootprints("translucent skin over bone", phantom, { glass, bone }, whole, points);
  CompareFootprints(
    "torus, parallel", iso_test::Torus(40, 11.0), { { 4.2, { 0.5, 0.85, 0.45 }, 1.0 } }, parallel,
    points);
  // Random values: every kind of cell (saddles, tunnels, corners cut off,
  // several sheets) with cells about 30 pixels wide, so the point footprint's
  // box around the surface in each cell must be right to the pixel.
  const int n = 10;
  std::vector<double> noise(n * n * n);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (double& v : noise)
  {
    v = uniform(random);
  }
  const int noiseDims[3] = { n, n, n };
  const double unit[3] = { 1.0, 1.0, 1.0 };
  const double zero[3] = { 0.0, 0.0, 0.0 };
  auto field = iso_test::SampleField(noiseDims, unit, zero,
    [&noise, n](double x, double y, double z)
    {
      return noise[static_cast<int>(std::lround(x)) + n * static_cast<int>(std::lround(y)) +
        n * n * static_cast<int>(std::lround(z))];
    });
  CompareFootprints("random values", field, { { 0.5, { 0.5, 0.7, 0.9 }, 1.0 } }, whole, points);
  CompareFootprints("random values, two translucent", field,
    { { 0.3, { 0.9, 0.6, 0.4 }, 0.5 }, { 0.7, { 0.5, 0.7, 0.9 }, 1.0 } }, parallel, points);
  // Ties: looking down z in parallel projection with 20 pixels per cell and
  // the grid's points on pixel centres, so the projected cell edges run
  // through pixel centres (the case a point's margin is there for).
  const auto aligned = [](vtkCamera* camera)
  {
    const double half = 0.5 / 20.0; // half a pixel, in cells
    camera->ParallelProjectionOn();
    camera->SetFocalPoint(4.5 - half, 4.5 - half, 4.5);
    camera->SetPosition(4.5 - half, 4.5 - half, 40.0);
    camera->SetViewUp(0.0, 1.0, 0.0);
    camera->SetParallelScale(150.0 / 20.0);
  };
  CompareFootprints("random values, cell edges on pixel centres", field,
    { { 0.5, { 0.5, 0.7, 0.9 }, 1.0 } }, aligned, points);
  CompareFootprints("skin, close zoom", phantom, { skin }, close, boxes);
  CompareFootprints("bone, eye inside the volume", phantom, { bone }, inside, boxes);
}

// The shading normal: a linear field f = g . (i, j, k) (index space) has the
// same gradient everywhere, and central differences (one-sided at the
// border) of it are exact, so its isosurface is a plane whose every pixel
// has the one Lambert colour of that gradient: with the renderer's
// headlight and diffuse light only, 255 c |n . d|, n the world gradient
// (g divided by the spacing), d the direction of projection, in either
// projection. A difference that reads a wrong point (every point has its
// own value), the wrong side or the wrong span changes the normal at some
// corners, and the colour varies across the plane. int16 and float data,
// anisotropic spacing, both paths (the fallback's triangles of a plane are
// flat too). Two widths: the volume is stored 4 points to a texel along x,
// and at the +x border the vertex stage reads a point past the row's end,
// which must read as the last point: from the next texel (past the last
// one) with 20 points, from the last texel's padding with 22.
void ShadingPlane(int width)
{
  const int dims[3] = { width, 24, 28 };
  const double spacing[3] = { 1.0, 0.8, 1.3 };
  const double g[3] = { 3.0, 5.0, 8.0 }; // integer: exact in int16
  const double color[3] = { 0.9, 0.7, 0.5 };
  double n[3] = { g[0] / spacing[0], g[1] / spacing[1], g[2] / spacing[2] };
  vtkMath::Normalize(n);
  for (int type = 0; type < 2; ++type)
  {
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(dims[0], dims[1], dims[2]);
    image->SetSpacing(spacing[0], spacing[1], spacing[2]);
    image->SetOrigin(-4.0, 2.0, 1.0);
    vtkSmartPointer<vtkDataArray> values = type == 0
      ? vtkSmartPointer<vtkDataArray>(vtkSmartPointer<vtkShortArray>::New())
      : vtkSmartPointer<vtkDataArray>(vtkSmartPointer<vtkFloatArray>::New());
    values->SetNumberOfTuples(image->GetNumberOfPoints());
    vtkIdType id = 0;
    for (int k = 0; k < dims[2]; ++k)
      for (int j = 0; j < dims[1]; ++j)
        for (int i = 0; i < dims[0]; ++i, ++id)
          values->SetTuple1(id, g[0] * i + g[1] * j + g[2] * k - 100.0);
    image->GetPointData()->SetScalars(values);
    for (int parallel = 0; parallel < 2; ++parallel)
    {
      for (int pass = 0; pass < 2; ++pass)
      {
        const std::string name = "plane " + std::to_string(width) + " wide, " +
          (type == 0 ? "int16" : "float") +
          (parallel ? ", parallel" : ", perspective") + (pass == 0 ? ", gpu" : ", fallback");
        vtkNew<vtkHistoPyramidIsoMapper> mapper;
        mapper->SetForceCPUFallback(pass == 1);
        double d[3] = { 0.0, 0.0, 0.0 };
        const std::vector<unsigned char> pixels = RenderPixels(mapper, image,
          { { 140.5, { color[0], color[1], color[2] }, 1.0 } },
          [&](vtkCamera* camera)
          {
            camera->SetParallelProjection(parallel);
            camera->GetDirectionOfProjection(d);
          },
          Lighting::Diffuse);
        Check(mapper->GetLastRenderPath() ==
            (pass == 0 ? vtkHistoPyramidIsoMapper::GPUPath : vtkHistoPyramidIsoMapper::FallbackPath),
          name + ": path " + mapper->GetLastRenderPathAsString());
        const double lambert = std::abs(vtkMath::Dot(n, d));
        int covered = 0, worst = 0;
        for (std::size_t p = 0; p + 2 < pixels.size(); p += 3)
        {
          if (pixels[p] == 0 && pixels[p + 1] == 0 && pixels[p + 2] == 0)
          {
            continue;
          }
          ++covered;
          for (int c = 0; c < 3; ++c)
          {
            const double expected = 255.0 * color[c] * lambert;
            worst = std::max(
              worst, static_cast<int>(std::lround(std::abs(pixels[p + c] - expected))));
          }
        }
        std::printf("%s: %d pixels, |n . d| = %.4f, at most %d from the Lambert colour\n",
          name.c_str(), covered, lambert, worst);
        Check(covered > 5000, name + ": the plane covers a good part of the image");
        Check(worst <= 2, name + ": every pixel has the plane's Lambert colour");
      }
    }
  }
}

void Shading()
{
  for (const int width : { 20, 22 })
  {
    ShadingPlane(width);
  }
}

// One frame of the first-hit comparison: `looks` of `image` through a
// mapper with the first-hit pass on or off, in a renderer covering
// `viewport` of a 300x300 window, with an opaque plane through the volume's
// centre (normal `normal`) when given; returns the window's RGB and depth.
struct Frame
{
  std::vector<unsigned char> Pixels;
  std::vector<float> Depth;
  bool FirstHit = false;
  int Path = vtkHistoPyramidIsoMapper::NoPath;
  std::uint64_t BufferBytes = 0;        // the first-hit buffers after the frame
  std::uint64_t ViewportPixels = 0;     // the renderer's
  int Projected[2] = { 0, 0 };          // the volume box's projection, in pixels (cut to the viewport)
  std::uint64_t BytesAfterRelease = 0;  // everything, after ReleaseGraphicsResources()
};

Frame RenderFrame(vtkImageData* image, const std::vector<iso_test::Look>& looks, bool firstHit,
  const double viewport[4], const double* normal, const std::function<void(vtkCamera*)>& place,
  const std::function<void(vtkCamera*)>& before)
{
  const int size = 300;
  vtkNew<vtkHistoPyramidIsoMapper> mapper;
  mapper->SetFirstHitPass(firstHit);
  auto volume = iso_test::MakeVolume(image, looks, mapper);
  Scene scene(size, size);
  scene.Renderer->SetViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  vtkNew<vtkPlaneSource> plane;
  vtkNew<vtkPolyDataMapper> planeMapper;
  vtkNew<vtkActor> planeActor;
  if (normal)
  {
    double centre[3], bounds[6];
    image->GetCenter(centre);
    image->GetBounds(bounds);
    const double extent = 2.0 * std::max({ bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4] });
    plane->SetOrigin(-extent, -extent, 0.0);
    plane->SetPoint1(extent, -extent, 0.0);
    plane->SetPoint2(-extent, extent, 0.0);
    plane->SetCenter(centre);
    plane->SetNormal(normal[0], normal[1], normal[2]);
    planeMapper->SetInputConnection(plane->GetOutputPort());
    planeActor->SetMapper(planeMapper);
    planeActor->GetProperty()->SetColor(0.9, 0.1, 0.1);
    scene.Renderer->AddActor(planeActor);
  }
  scene.Show(volume);
  if (before)
  {
    // A frame from another camera first (the first-hit buffers are kept
    // between frames while the volume's projection fits them).
    vtkNew<vtkCamera> saved;
    saved->DeepCopy(scene.Renderer->GetActiveCamera());
    before(scene.Renderer->GetActiveCamera());
    scene.Renderer->ResetCameraClippingRange();
    scene.Window->Render();
    scene.Renderer->GetActiveCamera()->DeepCopy(saved);
    scene.Renderer->ResetCameraClippingRange();
  }
  if (place)
  {
    place(scene.Renderer->GetActiveCamera());
    scene.Renderer->ResetCameraClippingRange();
  }
  scene.Window->Render();
  Frame frame;
  {
    // The window pixels the volume's box covers: its 8 corners' bounding
    // rectangle, cut to the renderer's viewport.
    const double* bounds = volume->GetBounds();
    double lo[2] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MAX }, hi[2] = { -VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX };
    for (int i = 0; i < 8; ++i)
    {
      scene.Renderer->SetWorldPoint(
        bounds[i & 1], bounds[2 + ((i >> 1) & 1)], bounds[4 + ((i >> 2) & 1)], 1.0);
      scene.Renderer->WorldToDisplay();
      const double* display = scene.Renderer->GetDisplayPoint();
      for (int a = 0; a < 2; ++a)
      {
        lo[a] = std::min(lo[a], display[a]);
        hi[a] = std::max(hi[a], display[a]);
      }
    }
    const int* origin = scene.Renderer->GetOrigin();
    const int* extent = scene.Renderer->GetSize();
    for (int a = 0; a < 2; ++a)
    {
      const double first = std::max(lo[a], double(origin[a]));
      const double last = std::min(hi[a], double(origin[a] + extent[a]));
      frame.Projected[a] = last > first ? static_cast<int>(std::floor(last - first)) : 0;
    }
  }
  frame.FirstHit = mapper->GetLastFirstHitPass();
  frame.Path = mapper->GetLastRenderPath();
  vtkNew<vtkUnsignedCharArray> rgb;
  scene.Window->GetPixelData(0, 0, size - 1, size - 1, 1, rgb);
  frame.Pixels.assign(rgb->GetPointer(0), rgb->GetPointer(0) + 3 * size * size);
  vtkNew<vtkFloatArray> z;
  scene.Window->GetZbufferData(0, 0, size - 1, size - 1, z);
  frame.Depth.assign(z->GetPointer(0), z->GetPointer(0) + size * size);
  frame.BufferBytes = mapper->GetFrameBufferBytes();
  const int* pixels = scene.Renderer->GetSize();
  frame.ViewportPixels = static_cast<std::uint64_t>(pixels[0]) * pixels[1];
  mapper->ReleaseGraphicsResources(scene.Window);
  frame.BytesAfterRelease = mapper->GetFrameBufferBytes() + mapper->GetGPUMemoryBytes();
  return frame;
}

// Draws a scene with the first-hit pass and in one pass; checks which ran
// (the first-hit pass only where it applies) and that the colours and the
// depth buffer are the same.
void CompareFirstHit(const std::string& name, vtkImageData* image,
  const std::vector<iso_test::Look>& looks, bool applies, const double viewport[4],
  const double* normal = nullptr, const std::function<void(vtkCamera*)>& place = nullptr,
  const std::function<void(vtkCamera*)>& before = nullptr, int minCovered = 3000,
  double depthTolerance = 0.0)
{
  const Frame on = RenderFrame(image, looks, true, viewport, normal, place, before);
  const Frame off = RenderFrame(image, looks, false, viewport, normal, place, before);
  Check(on.Path == vtkHistoPyramidIsoMapper::GPUPath && off.Path == vtkHistoPyramidIsoMapper::GPUPath,
    name + ": GPU path");
  Check(on.FirstHit == applies && !off.FirstHit,
    name + (applies ? ": drawn through the first-hit pass" : ": drawn in one pass (no first hit here)"));
  // 10 bytes per pixel over the volume's projection: at least its rectangle,
  // at most that widened by 2 pixels and rounded up to 64 (and the viewport).
  const std::uint64_t least = 10u * static_cast<std::uint64_t>(on.Projected[0]) * on.Projected[1];
  const std::uint64_t most = 10u *
    std::min<std::uint64_t>(on.ViewportPixels,
      static_cast<std::uint64_t>(on.Projected[0] + 67) * (on.Projected[1] + 67));
  std::printf("%s: first-hit buffers %llu bytes (projection %dx%d, viewport %llu pixels)\n",
    name.c_str(), static_cast<unsigned long long>(on.BufferBytes), on.Projected[0], on.Projected[1],
    static_cast<unsigned long long>(on.ViewportPixels));
  Check((applies ? on.BufferBytes >= least && on.BufferBytes <= most : on.BufferBytes == 0) &&
      off.BufferBytes == 0,
    name + ": the first-hit buffers are 10 bytes per pixel of the volume's projection, and only "
           "where used");
  Check(on.BytesAfterRelease == 0 && off.BytesAfterRelease == 0,
    name + ": ReleaseGraphicsResources() frees them");
  int colourDiffers = 0, depthDiffers = 0, covered = 0;
  double worstDepth = 0.0;
  for (std::size_t p = 0; p < on.Depth.size(); ++p)
  {
    const unsigned char* a = &on.Pixels[3 * p];
    const unsigned char* b = &off.Pixels[3 * p];
    covered += (a[0] || a[1] || a[2]) ? 1 : 0;
    colourDiffers += (a[0] != b[0] || a[1] != b[1] || a[2] != b[2]) ? 1 : 0;
    const double dz = std::abs(static_cast<double>(on.Depth[p]) - off.Depth[p]);
    depthDiffers += dz > depthTolerance ? 1 : 0;
    worstDepth = std::max(worstDepth, dz);
  }
  std::printf("%s: first hit %s, %d pixels covered, %d differ in colour, %d in depth (at most "
              "%.3g)\n",
    name.c_str(), on.FirstHit ? "yes" : "no", covered, colourDiffers, depthDiffers, worstDepth);
  Check(covered > minCovered, name + ": the scene covers a good part of the image");
  // The same hits, shaded by the same code, give the same 8-bit colours and
  // the same depths, except where a pixel's ray meets two cells at their
  // shared face (the first in drawing order against the nearer by depth):
  // a handful of pixels, never a surface behind another.
  Check(colourDiffers <= covered / 2000, name + ": the same colours as in one pass");
  Check(depthDiffers <= covered / 2000 && worstDepth < 1e-3, name + ": the same depth buffer as in one pass");
}

// The first-hit pass against one pass.
void FirstHit()
{
  auto phantom = iso_test::Phantom(64);
  const iso_test::Look skin{ -500.0, { 0.93, 0.75, 0.62 }, 1.0 };
  const iso_test::Look glass{ -500.0, { 0.93, 0.75, 0.62 }, 0.35 };
  const iso_test::Look bone{ 400.0, { 0.97, 0.95, 0.88 }, 1.0 };
  const double whole[4] = { 0.0, 0.0, 1.0, 1.0 };
  const double part[4] = { 0.3, 0.2, 0.95, 0.9 }; // not at the window's origin
  const double tilted[3] = { 0.3, 1.0, 0.2 };
  const auto parallel = [](vtkCamera* camera) { camera->ParallelProjectionOn(); };
  CompareFirstHit("skin, perspective", phantom, { skin }, true, whole);
  CompareFirstHit("bone, parallel", phantom, { bone }, true, whole, nullptr, parallel);
  CompareFirstHit("bone cut by a plane, in part of the window", phantom, { bone }, true, part, tilted);
  CompareFirstHit("skin cut by a plane, parallel, in part of the window", phantom, { skin }, true,
    part, tilted, parallel);
  CompareFirstHit("torus", iso_test::Torus(40, 11.0), { { 4.2, { 0.5, 0.85, 0.45 }, 1.0 } }, true,
    whole);
  // The buffers follow the projection: a small one, one that grows after a
  // frame of a smaller one, and one that shrinks after a frame of a larger
  // one (each checked against its last frame's projection above).
  const auto far = [](vtkCamera* camera) { camera->Zoom(0.3); };
  CompareFirstHit("bone, zoomed out", phantom, { bone }, true, whole, nullptr,
    [](vtkCamera* camera) { camera->Zoom(0.4); }, nullptr, 1000);
  CompareFirstHit("skin, after a zoomed-out frame", phantom, { skin }, true, whole, nullptr, nullptr,
    far);
  CompareFirstHit("skin, zoomed out after a whole-view frame", phantom, { skin }, true, whole,
    nullptr, far, [](vtkCamera*) {}, 500);
  // Several opaque isovalues: one primitive per cell, which takes the
  // nearest hit of its isovalues. Two spheres 0.4 cells apart share most of
  // their cells, where the outer one (the higher isovalue, the second in
  // each cell's isovalue order) is hit first. The depths may differ by
  // rounding: one pass casts each isovalue's ray from the near depth of
  // that isovalue's box in the cell, this pass from that of the union of
  // the boxes, so the same root comes out rounded differently (by at most
  // 1.5e-6 of the depth range here); 1e-5 is far below a cell's depth.
  const double rounding = 1e-5;
  CompareFirstHit("skin and bone", phantom, { skin, bone }, true, whole, nullptr, nullptr, nullptr,
    3000, rounding);
  CompareFirstHit("two spheres in the same cells", iso_test::Sphere(40),
    { { 12.0, { 0.9, 0.2, 0.2 }, 1.0 }, { 12.4, { 0.2, 0.9, 0.2 }, 1.0 } }, true, whole, nullptr,
    nullptr, nullptr, 3000, rounding);
  CompareFirstHit("three spheres, parallel", iso_test::Sphere(40),
    { { 6.0, { 0.9, 0.2, 0.2 }, 1.0 }, { 12.2, { 0.2, 0.9, 0.2 }, 1.0 },
      { 12.5, { 0.2, 0.2, 0.9 }, 1.0 } },
    true, whole, tilted, parallel, nullptr, 3000, rounding);
  // Where it does not apply: translucency and cell boxes (a close zoom).
  CompareFirstHit("translucent skin over bone", phantom, { glass, bone }, false, whole);
  CompareFirstHit("bone, close zoom (boxes)", phantom, { bone }, false, whole, nullptr,
    [](vtkCamera* camera) { camera->Zoom(150.0); });
}

void Fallback()
{
  auto phantom = iso_test::Phantom(48);
  vtkNew<vtkHistoPyramidIsoMapper> mapper;
  MessageCounter messages(mapper);
  auto volume = iso_test::MakeVolume(phantom, { { -500.0, { 1, 1, 1 }, 1.0 } }, mapper);
  Scene scene;
  scene.Show(volume);
  for (int i = 0; i < 3; ++i)
  {
    scene.Window->Render();
    scene.Renderer->GetActiveCamera()->Azimuth(20);
  }
  volume->GetProperty()->GetIsoSurfaceValues()->SetValue(0, 400.0);
  scene.Window->Render();
  std::printf("path %s, reason '%s', %llu triangles, %d warnings:\n%s",
    mapper->GetLastRenderPathAsString(), mapper->GetFallbackReason().c_str(),
    static_cast<unsigned long long>(mapper->GetNumberOfFallbackTriangles()), messages.Warnings,
    messages.Text.c_str());
  Check(mapper->GetLastRenderPath() == vtkHistoPyramidIsoMapper::FallbackPath, "fallback path taken");
  Check(mapper->GetFallbackReason().find("MEDISO_DISABLE_GPU_PATH") != std::string::npos,
    "the reason names the switch");
  Check(messages.Warnings == 1 && messages.Errors == 0 &&
      messages.Text.find("GPU isosurface path unavailable") != std::string::npos,
    "one warning says so, once over several renders");
  Check(mapper->GetNumberOfFallbackTriangles() > 1000 && mapper->GetNumberOfPrimitives() == 0,
    "the fallback drew triangles, the GPU path nothing");
  Check(mapper->GetGPUMemoryBytes() == 0, "no GPU volume held by the fallback");
}

vtkSmartPointer<vtkImageData> SmallImage(int nx, int ny, int nz, vtkDataArray* scalars, bool cells = false)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(nx, ny, nz);
  if (scalars)
  {
    const vtkIdType n = cells ? image->GetNumberOfCells() : image->GetNumberOfPoints();
    scalars->SetNumberOfTuples(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      for (int c = 0; c < scalars->GetNumberOfComponents(); ++c)
      {
        scalars->SetComponent(i, c, static_cast<double>(i % 97));
      }
    }
    if (cells)
    {
      image->GetCellData()->SetScalars(scalars);
    }
    else
    {
      image->GetPointData()->SetScalars(scalars);
    }
  }
  return image;
}

void ExpectMessage(const std::string& name, vtkImageData* image, std::vector<double> isovalues,
  bool error, const std::string& needle, vtkHistoPyramidIsoMapper::RenderPathType path)
{
  vtkNew<vtkHistoPyramidIsoMapper> mapper;
  MessageCounter messages(mapper);
  std::vector<iso_test::Look> looks;
  for (double v : isovalues)
  {
    looks.push_back({ v, { 1, 1, 1 }, 1.0 });
  }
  auto volume = iso_test::MakeVolume(image, looks.empty() ? std::vector<iso_test::Look>{ { 10.0, { 1, 1, 1 }, 1.0 } } : looks, mapper);
  if (looks.empty())
  {
    volume->GetProperty()->GetIsoSurfaceValues()->SetNumberOfContours(0);
  }
  Scene scene(100, 100);
  scene.Show(volume);
  scene.Window->Render();
  scene.Window->Render();
  scene.Renderer->GetActiveCamera()->Azimuth(30);
  scene.Window->Render();
  const int count = error ? messages.Errors : messages.Warnings;
  const int other = error ? messages.Warnings : messages.Errors;
  std::printf("%s: path %s, %d errors, %d warnings: %s", name.c_str(),
    mapper->GetLastRenderPathAsString(), messages.Errors, messages.Warnings,
    messages.Text.empty() ? "(none)\n" : messages.Text.c_str());
  Check(path == vtkHistoPyramidIsoMapper::NoPath ? mapper->GetLastRenderPath() == path
                                                 : mapper->GetLastRenderPath() == path,
    name + ": path " + mapper->GetLastRenderPathAsString());
  if (needle.empty())
  {
    Check(messages.Errors == 0 && messages.Warnings == 0, name + ": no message");
  }
  else
  {
    Check(count == 1 && other == 0 && messages.Text.find(needle) != std::string::npos,
      name + ": one message containing '" + needle + "'");
  }
}

void BadInput()
{
  ExpectMessage("no scalars", SmallImage(8, 8, 8, nullptr), { 10.0 }, true, "no point scalars",
    vtkHistoPyramidIsoMapper::NoPath);
  vtkNew<vtkFloatArray> cellValues;
  cellValues->SetName("cells");
  ExpectMessage("cell scalars", SmallImage(8, 8, 8, cellValues, true), { 10.0 }, true,
    "is cell data", vtkHistoPyramidIsoMapper::NoPath);
  vtkNew<vtkFloatArray> three;
  three->SetNumberOfComponents(3);
  ExpectMessage("3 components", SmallImage(8, 8, 8, three), { 10.0 }, true, "3 components",
    vtkHistoPyramidIsoMapper::NoPath);
  vtkNew<vtkTypeInt64Array> wide;
  ExpectMessage("int64", SmallImage(8, 8, 8, wide), { 10.0 }, true, "one component of an 8, 16 or 32-bit",
    vtkHistoPyramidIsoMapper::NoPath);
  vtkNew<vtkFloatArray> flat;
  ExpectMessage("2D", SmallImage(8, 8, 1, flat), { 10.0 }, true, "needs 3D image data",
    vtkHistoPyramidIsoMapper::NoPath);
  vtkNew<vtkFloatArray> plain;
  auto image = SmallImage(8, 8, 8, plain);
  ExpectMessage("no isovalues", image, {}, false, "no isovalues", vtkHistoPyramidIsoMapper::NoPath);
  ExpectMessage("nine isovalues", image, { 1, 2, 3, 4, 5, 6, 7, 8, 9 }, false,
    "only the lowest 8 are drawn", vtkHistoPyramidIsoMapper::GPUPath);
  ExpectMessage("isovalue outside the range", image, { 1000.0 }, false, "",
    vtkHistoPyramidIsoMapper::GPUPath);
  // NaN values: their cells are never active; no NaN reaches the picture.
  vtkNew<vtkFloatArray> withNaN;
  auto nanImage = SmallImage(8, 8, 8, withNaN);
  for (vtkIdType i = 0; i < withNaN->GetNumberOfTuples(); i += 5)
  {
    withNaN->SetValue(i, std::numeric_limits<float>::quiet_NaN());
  }
  ExpectMessage("NaN values", nanImage, { 40.0 }, false, "", vtkHistoPyramidIsoMapper::GPUPath);
  // Over GL_MAX_3D_TEXTURE_SIZE (2048 here) along z: kept as bricks, still the GPU path (issue 31).
  vtkNew<vtkFloatArray> tall;
  ExpectMessage("2100 slices (bricks)", SmallImage(4, 4, 2100, tall), { 40.0 }, false, "",
    vtkHistoPyramidIsoMapper::GPUPath);
}

// The GPU memory budget (issue 31): a budget below the 64^3 phantom's one texture (0.57 MB) keeps
// it as bricks with the primitives of one texture, on the GPU path with no message, where the
// bricks the isovalue crosses fit (1000 HU: the densest bone, a few bricks); one that they cannot
// fit falls back with that reason, said once. (Bone at 400 HU crosses most bricks, whose aprons
// and pyramids take more than the one texture: no budget bricks it.)
void Budget()
{
  auto phantom = iso_test::Phantom(64);
  const auto render = [&](double megabytes, vtkHistoPyramidIsoMapper* mapper)
  {
    mapper->SetGPUMemoryBudget(megabytes);
    auto volume = iso_test::MakeVolume(phantom, { { 1000.0, { 1, 1, 1 }, 1.0 } }, mapper);
    Scene scene(100, 100);
    scene.Show(volume);
    scene.Window->Render();
    scene.Renderer->GetActiveCamera()->Azimuth(30);
    scene.Window->Render();
  };
  vtkNew<vtkHistoPyramidIsoMapper> whole;
  render(0.0, whole);
  vtkNew<vtkHistoPyramidIsoMapper> bricked;
  MessageCounter messages(bricked);
  render(0.45, bricked);
  std::printf("default budget: %s, %llu primitives, %llu bricks; 0.45 MB: %s, %llu primitives, "
              "%llu bricks (%llu active, %llu resident), %d messages\n",
    whole->GetLastRenderPathAsString(),
    static_cast<unsigned long long>(whole->GetNumberOfPrimitives()),
    static_cast<unsigned long long>(whole->GetLastBricks()), bricked->GetLastRenderPathAsString(),
    static_cast<unsigned long long>(bricked->GetNumberOfPrimitives()),
    static_cast<unsigned long long>(bricked->GetLastBricks()),
    static_cast<unsigned long long>(bricked->GetLastActiveBricks()),
    static_cast<unsigned long long>(bricked->GetLastResidentBricks()),
    messages.Errors + messages.Warnings);
  Check(whole->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath &&
      whole->GetLastBricks() == 0 && whole->GetNumberOfPrimitives() > 0,
    "the default budget: one texture");
  Check(bricked->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath &&
      bricked->GetLastBricks() > 1 && bricked->GetLastActiveBricks() > 0 &&
      bricked->GetLastActiveBricks() <= bricked->GetLastResidentBricks() &&
      messages.Errors + messages.Warnings == 0,
    "a 0.45 MB budget: the GPU path over bricks, no message");
  Check(bricked->GetNumberOfPrimitives() == whole->GetNumberOfPrimitives(),
    "as bricks, the primitives of one texture");

  vtkNew<vtkHistoPyramidIsoMapper> over;
  MessageCounter overMessages(over);
  render(0.001, over);
  std::printf("0.001 MB: %s, reason '%s', %llu triangles, %d warnings\n",
    over->GetLastRenderPathAsString(), over->GetFallbackReason().c_str(),
    static_cast<unsigned long long>(over->GetNumberOfFallbackTriangles()), overMessages.Warnings);
  Check(over->GetLastRenderPath() == vtkHistoPyramidIsoMapper::FallbackPath &&
      over->GetNumberOfFallbackTriangles() > 0,
    "a budget the active bricks exceed: the fallback draws");
  Check(over->GetFallbackReason().find("over the budget") != std::string::npos &&
      overMessages.Warnings == 1 && overMessages.Errors == 0 &&
      overMessages.Text.find("GPU isosurface path unavailable") != std::string::npos,
    "one warning gives the reason");
}
} // namespace

int TestHistoPyramidIsoMapperChecks(int argc, char* argv[])
{
  const std::string which = argc > 1 ? argv[1] : "";
  if (which == "Fallback")
  {
    // Before any window exists: the capability probe reads it.
    setenv("MEDISO_DISABLE_GPU_PATH", "1", 1);
    Fallback();
    return medical_test::Finish("TestHistoPyramidIsoMapperChecks Fallback");
  }
  if (const int skip = iso_test::ProbeOrSkip())
  {
    return skip;
  }
  if (which == "Counts")
  {
    Counts();
  }
  else if (which == "Memory")
  {
    Memory();
  }
  else if (which == "Reference")
  {
    Reference();
  }
  else if (which == "FirstHit")
  {
    FirstHit();
  }
  else if (which == "Shading")
  {
    Shading();
  }
  else if (which == "Footprint")
  {
    Footprint();
  }
  else if (which == "BadInput")
  {
    BadInput();
  }
  else if (which == "Budget")
  {
    Budget();
  }
  else
  {
    std::printf("unknown case '%s'\n", which.c_str());
    return 1;
  }
  return medical_test::Finish(("TestHistoPyramidIsoMapperChecks " + which).c_str());
}
