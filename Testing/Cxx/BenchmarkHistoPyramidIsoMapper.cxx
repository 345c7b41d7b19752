// SPDX-License-Identifier: BSD-3-Clause
// Benchmark of vtkHistoPyramidIsoMapper (issue 4) against its peers, in one
// process and one input per run:
//   hp  vtkHistoPyramidIsoMapper (the GPU path is checked and reported),
//   rc  vtkGPUVolumeRayCastMapper in isosurface blend mode, shading on,
//       AutoAdjustSampleDistances off, SampleDistance = factor x min spacing,
//   fe  vtkFlyingEdges3D (normals on) drawn by vtkPolyDataMapper.
// Measures, for every window size: the paper's rotation (1-degree camera
// azimuth steps after two warm-up renders, per isovalue) and the isovalue
// sweep (equidistant isovalues strictly inside the data range, time per
// change + frame; the methods' scenes take each isovalue in turn, and each
// method's record gives the per-step ratios against FlyingEdges), plus the
// HistoPyramid mapper's GPU memory against the volume's bytes. Every frame is vtkRenderWindow::Render() followed by
// WaitForCompletion() (glFinish), so a time includes the drawing itself.
//
// Not a ctest test: Python/benchmark_isomapper.py runs it under Xvfb once per
// input and turns its "bench-result: {json}" lines into tables.
//
//   BenchmarkHistoPyramidIsoMapper --input ct|ct512|phantom256|phantomN
//     [--ct FILE.mha] [--windows 1920x1080,1024x768] [--frames 360] [--sweep 95]
//     [--isovalues -500,400] [--methods hp,rc,fe[,hpbox][,hp1]] [--rc-factors 0.5,1.0]
//     [--opacity 1] [--together 0|1] [--zoom 1] [--write-input FILE.mha]
//
// --together 1: one rotation scene per window and method with all the
// isovalues at once (the demo's skin over bone): the first at --opacity, the
// others opaque; FlyingEdges extracts them all. The sweep is unchanged.
//     [--images DIR] [--interactive-budget SECONDS]
// --interactive-budget S (> 0): after each "hp" rotation, the same number of
// frames again as interactive renders (the window's DesiredUpdateRate 1000:
// under a second allocated, as in ParaView's interactive renders) with the
// mapper's InteractiveFrameBudget S; an "interactive" record has their
// median, the sample distances chosen, and the frame-time model's predicted
// against measured seconds of each frame it chose (its first frames, before
// any interactive frame was observed, included).
#include "MedicalTestUtilities.h"
#include "vtkHistoPyramidIsoMapper.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkContourValues.h"
#include "vtkDataArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkImageData.h"
#include "vtkImageReslice.h"
#include "vtkMetaImageReader.h"
#include "vtkMetaImageWriter.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkVersion.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWindowToImageFilter.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace
{
// ---------------------------------------------------------------------------
// Options
struct Options
{
  std::string Input = "ct";
  std::string CTFile = medical_test::DataFile("ct_head.mha");
  std::vector<std::pair<int, int>> Windows = { { 1920, 1080 }, { 1024, 768 } };
  int Frames = 360;
  int Sweep = 95;
  std::string WriteInput; // write the input volume as an uncompressed MetaImage, then stop
  std::vector<double> Isovalues = { -500.0, 400.0 };
  std::vector<std::string> Methods = { "hp", "rc", "fe" };
  std::vector<double> RayCastFactors = { 0.5 };
  double Opacity = 1.0; // of every isovalue (< 1: the mapper's translucent mode)
  double Zoom = 1.0;    // camera zoom after the reset (close zooms: the quad footprints)
  bool Together = false; // rotation with all isovalues in one scene
  double InteractiveBudget = 0.0; // > 0: also interactive rotation frames of "hp" (issue 30)
  // The coarser levels interactive frames may take: "volume" (InteractiveVolumeLevels),
  // "triangles" (InteractiveTriangleLevels), both, or "none".
  std::string InteractiveLevels = "volume,triangles";
  std::string ImageDir;
};

std::vector<std::string> Split(const std::string& text, char sep)
{
  std::vector<std::string> parts;
  std::stringstream stream(text);
  std::string part;
  while (std::getline(stream, part, sep))
  {
    if (!part.empty())
    {
      parts.push_back(part);
    }
  }
  return parts;
}

std::vector<double> Numbers(const std::string& text)
{
  std::vector<double> values;
  for (const std::string& s : Split(text, ','))
  {
    values.push_back(std::stod(s));
  }
  return values;
}

bool Parse(int argc, char* argv[], Options& opt)
{
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    // Options take "--name value" or "--name=value" (the latter for lists
    // starting with a minus sign).
    std::string name = arg;
    std::string value;
    const auto eq = arg.find('=');
    if (eq != std::string::npos)
    {
      name = arg.substr(0, eq);
      value = arg.substr(eq + 1);
    }
    else if (i + 1 < argc)
    {
      value = argv[++i];
    }
    else
    {
      std::fprintf(stderr, "missing value for %s\n", arg.c_str());
      return false;
    }
    if (name == "--input")
      opt.Input = value;
    else if (name == "--ct")
      opt.CTFile = value;
    else if (name == "--frames")
      opt.Frames = std::max(1, std::stoi(value));
    else if (name == "--sweep")
      opt.Sweep = std::max(0, std::stoi(value));
    else if (name == "--isovalues")
      opt.Isovalues = Numbers(value);
    else if (name == "--methods")
      opt.Methods = Split(value, ',');
    else if (name == "--rc-factors")
      opt.RayCastFactors = Numbers(value);
    else if (name == "--opacity")
      opt.Opacity = std::min(1.0, std::max(0.01, std::stod(value)));
    else if (name == "--zoom")
      opt.Zoom = std::max(1e-3, std::stod(value));
    else if (name == "--interactive-budget")
      opt.InteractiveBudget = std::max(0.0, std::stod(value));
    else if (name == "--interactive-levels")
      opt.InteractiveLevels = value;
    else if (name == "--together")
      opt.Together = std::stoi(value) != 0;
    else if (name == "--images")
      opt.ImageDir = value;
    else if (name == "--write-input")
      opt.WriteInput = value;
    else if (name == "--windows")
    {
      opt.Windows.clear();
      for (const std::string& w : Split(value, ','))
      {
        int width = 0, height = 0;
        if (std::sscanf(w.c_str(), "%dx%d", &width, &height) != 2 || width < 1 || height < 1)
        {
          std::fprintf(stderr, "bad window size %s\n", w.c_str());
          return false;
        }
        opt.Windows.emplace_back(width, height);
      }
    }
    else
    {
      std::fprintf(stderr, "unknown option %s\n", name.c_str());
      return false;
    }
  }
  return true;
}

// ---------------------------------------------------------------------------
// One JSON object per line, prefixed so that the wrapper finds it.
class Record
{
public:
  explicit Record(const std::string& kind) { this->Add("kind", kind); }
  Record& Add(const std::string& key, const std::string& value)
  {
    std::string escaped;
    for (char c : value)
    {
      if (c == '"' || c == '\\')
        escaped += '\\';
      if (c == '\n')
      {
        escaped += "\\n";
        continue;
      }
      escaped += c;
    }
    this->Fields.push_back("\"" + key + "\": \"" + escaped + "\"");
    return *this;
  }
  Record& Add(const std::string& key, double value)
  {
    char text[64];
    std::snprintf(text, sizeof(text), "%.9g", value);
    this->Fields.push_back("\"" + key + "\": " + text);
    return *this;
  }
  Record& Add(const std::string& key, const std::vector<double>& values)
  {
    std::string text = "[";
    for (std::size_t i = 0; i < values.size(); ++i)
    {
      char number[64];
      std::snprintf(number, sizeof(number), "%s%.9g", i ? ", " : "", values[i]);
      text += number;
    }
    this->Fields.push_back("\"" + key + "\": " + text + "]");
    return *this;
  }
  void Print() const
  {
    std::string line = "bench-result: {";
    for (std::size_t i = 0; i < this->Fields.size(); ++i)
    {
      line += (i ? ", " : "") + this->Fields[i];
    }
    std::printf("%s}\n", line.c_str());
    std::fflush(stdout);
  }

private:
  std::vector<std::string> Fields;
};

double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
    .count();
}

double PeakRSSMB()
{
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
  {
    if (line.rfind("VmHWM:", 0) == 0)
    {
      return std::atof(line.c_str() + 6) / 1024.0;
    }
  }
  return 0.0;
}

// ---------------------------------------------------------------------------
// Inputs
vtkSmartPointer<vtkImageData> LoadInput(const Options& opt, std::string& label)
{
  if (opt.Input.rfind("phantom", 0) == 0)
  {
    const int n = std::atoi(opt.Input.c_str() + 7);
    if (n < 2)
    {
      return nullptr;
    }
    // As Python/benchmark_blocklod.py and the demo: 240 mm across, seed 1, no noise.
    vtkNew<vtkMedicalPhantomSource> source;
    source->SetDimensions(n, n, n);
    const double h = 240.0 / (n - 1);
    source->SetSpacing(h, h, h);
    source->Update();
    label = "MedicalPhantom " + std::to_string(n) + "^3 (int16 HU, seed 1, no noise)";
    return source->GetOutput();
  }
  if (opt.Input != "ct" && opt.Input != "ct512")
  {
    return nullptr;
  }
  vtkNew<vtkMetaImageReader> reader;
  reader->SetFileName(opt.CTFile.c_str());
  reader->Update();
  vtkImageData* ct = reader->GetOutput();
  if (!ct || !ct->GetPointData()->GetScalars())
  {
    return nullptr;
  }
  if (opt.Input == "ct")
  {
    label = "head CT (" + opt.CTFile.substr(opt.CTFile.find_last_of('/') + 1) + ")";
    return ct;
  }
  // Exactly 512x512x216 over the same bounds, linear, as the CPU benchmark
  // (vtkImageResample with magnification 2 would give 511x511x215).
  int dimsIn[3];
  double spacingIn[3];
  ct->GetDimensions(dimsIn);
  ct->GetSpacing(spacingIn);
  const int dimsOut[3] = { 512, 512, 216 };
  vtkNew<vtkImageReslice> reslice;
  reslice->SetInputData(ct);
  reslice->SetInterpolationModeToLinear();
  reslice->SetOutputOrigin(ct->GetOrigin());
  reslice->SetOutputSpacing(spacingIn[0] * (dimsIn[0] - 1) / (dimsOut[0] - 1),
    spacingIn[1] * (dimsIn[1] - 1) / (dimsOut[1] - 1),
    spacingIn[2] * (dimsIn[2] - 1) / (dimsOut[2] - 1));
  reslice->SetOutputExtent(0, dimsOut[0] - 1, 0, dimsOut[1] - 1, 0, dimsOut[2] - 1);
  reslice->Update();
  label = "head CT resampled (linear, vtkImageReslice) to 512x512x216";
  return reslice->GetOutput();
}

// ---------------------------------------------------------------------------
// Scenes: one window per method, the same camera, light and material.
// Camera zoom after the reset (--zoom).
double CameraZoom = 1.0;

struct Scene
{
  std::string Method; // hp, rc or fe
  std::string Label;  // as printed in tables
  double SampleFactor = 0.0;
  vtkSmartPointer<vtkRenderWindow> Window;
  vtkSmartPointer<vtkRenderer> Renderer;
  vtkSmartPointer<vtkVolumeProperty> VolumeProperty;
  vtkSmartPointer<vtkHistoPyramidIsoMapper> HistoPyramid;
  vtkSmartPointer<vtkFlyingEdges3D> FlyingEdges;
  vtkSmartPointer<vtkPolyDataMapper> PolyMapper;
  double Bounds[6];

  void SetIsovalue(double value)
  {
    if (this->FlyingEdges)
    {
      this->FlyingEdges->SetValue(0, value);
    }
    else
    {
      this->VolumeProperty->GetIsoSurfaceValues()->SetValue(0, value);
    }
  }

  /// Extraction time (FlyingEdges only; the others extract while drawing).
  double Extract()
  {
    if (!this->FlyingEdges)
    {
      return 0.0;
    }
    const double t0 = Now();
    this->FlyingEdges->Update();
    return Now() - t0;
  }

  double Frame()
  {
    const double t0 = Now();
    this->Window->Render();
    this->Window->WaitForCompletion(); // glFinish
    return Now() - t0;
  }

  void ResetView()
  {
    vtkCamera* camera = this->Renderer->GetActiveCamera();
    const double c[3] = { 0.5 * (this->Bounds[0] + this->Bounds[1]),
      0.5 * (this->Bounds[2] + this->Bounds[3]), 0.5 * (this->Bounds[4] + this->Bounds[5]) };
    camera->SetFocalPoint(c);
    camera->SetPosition(c[0], c[1] - 1.0, c[2]); // from the front (-y), head up (+z)
    camera->SetViewUp(0.0, 0.0, 1.0);
    camera->SetViewAngle(30.0);
    this->Renderer->ResetCamera(this->Bounds); // the image's bounds for every method
    camera->Zoom(CameraZoom);
    this->Renderer->ResetCameraClippingRange(this->Bounds);
  }

  void Rotate(double degrees)
  {
    this->Renderer->GetActiveCamera()->Azimuth(degrees);
    this->Renderer->ResetCameraClippingRange(this->Bounds);
  }

  /// Triangles (FlyingEdges) or primitives (HistoPyramid) of the last frame.
  double Elements() const
  {
    if (this->FlyingEdges)
    {
      return static_cast<double>(this->FlyingEdges->GetOutput()->GetNumberOfPolys());
    }
    if (this->HistoPyramid)
    {
      return static_cast<double>(this->HistoPyramid->GetNumberOfPrimitives());
    }
    return -1.0;
  }
};

double SurfaceOpacity = 1.0; // --opacity

// One isovalue: SurfaceOpacity. Several: the first at SurfaceOpacity, the
// others opaque (skin over bone).
void SetLook(vtkVolumeProperty* property, const std::vector<double>& isovalues)
{
  vtkNew<vtkColorTransferFunction> color;
  color->AddRGBPoint(0.0, 0.93, 0.85, 0.75);
  vtkNew<vtkPiecewiseFunction> opacity;
  opacity->AddPoint(isovalues.front(), SurfaceOpacity);
  for (size_t i = 1; i < isovalues.size(); ++i)
  {
    opacity->AddPoint(isovalues[i], 1.0);
  }
  property->SetColor(color);
  property->SetScalarOpacity(opacity);
  property->SetInterpolationTypeToLinear();
  property->SetAmbient(0.15);
  property->SetDiffuse(0.8);
  property->SetSpecular(0.25);
  property->SetSpecularPower(30.0);
  property->ShadeOn();
}

Scene MakeScene(const std::string& method, double factor, vtkImageData* image, int width,
  int height, const std::vector<double>& isovalues)
{
  Scene scene;
  scene.Method = method;
  scene.SampleFactor = factor;
  image->GetBounds(scene.Bounds);
  scene.Window = vtkSmartPointer<vtkRenderWindow>::New();
  scene.Window->SetSize(width, height);
  scene.Window->SetPosition(0, 0);
  scene.Window->SetMultiSamples(0);
  scene.Renderer = vtkSmartPointer<vtkRenderer>::New();
  scene.Renderer->SetBackground(0.1, 0.12, 0.16);
  scene.Window->AddRenderer(scene.Renderer);

  if (method == "fe")
  {
    scene.Label = "vtkFlyingEdges3D + vtkPolyDataMapper";
    scene.FlyingEdges = vtkSmartPointer<vtkFlyingEdges3D>::New();
    scene.FlyingEdges->SetInputData(image);
    scene.FlyingEdges->ComputeNormalsOn();
    scene.FlyingEdges->ComputeScalarsOff();
    scene.FlyingEdges->ComputeGradientsOff();
    for (size_t i = 0; i < isovalues.size(); ++i)
    {
      scene.FlyingEdges->SetValue(static_cast<int>(i), isovalues[i]);
    }
    scene.PolyMapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    scene.PolyMapper->SetInputConnection(scene.FlyingEdges->GetOutputPort());
    scene.PolyMapper->ScalarVisibilityOff();
    vtkNew<vtkActor> actor;
    actor->SetMapper(scene.PolyMapper);
    vtkProperty* p = actor->GetProperty();
    p->SetColor(0.93, 0.85, 0.75);
    p->SetAmbient(0.15);
    p->SetDiffuse(0.8);
    p->SetSpecular(0.25);
    p->SetSpecularPower(30.0);
    scene.Renderer->AddActor(actor);
  }
  else
  {
    scene.VolumeProperty = vtkSmartPointer<vtkVolumeProperty>::New();
    SetLook(scene.VolumeProperty, isovalues);
    for (size_t i = 0; i < isovalues.size(); ++i)
    {
      scene.VolumeProperty->GetIsoSurfaceValues()->SetValue(static_cast<int>(i), isovalues[i]);
    }
    vtkNew<vtkVolume> volume;
    volume->SetProperty(scene.VolumeProperty);
    if (method == "hp" || method == "hpbox" || method == "hp1")
    {
      // hpbox: the cell boxes of the geometry stage on every frame (no point
      // sprites), to compare the two footprints in one run; hp1: one pass
      // always (no first-hit pass), to compare the two drawings.
      scene.Label = method == "hp" ? "vtkHistoPyramidIsoMapper"
        : method == "hpbox"        ? "vtkHistoPyramidIsoMapper, boxes only"
                                   : "vtkHistoPyramidIsoMapper, one pass";
      scene.HistoPyramid = vtkSmartPointer<vtkHistoPyramidIsoMapper>::New();
      scene.HistoPyramid->SetAllowPointFootprint(method != "hpbox");
      scene.HistoPyramid->SetFirstHitPass(method != "hp1");
      scene.HistoPyramid->SetInputData(image);
      volume->SetMapper(scene.HistoPyramid);
    }
    else
    {
      double spacing[3];
      image->GetSpacing(spacing);
      const double minSpacing = std::min({ spacing[0], spacing[1], spacing[2] });
      char label[128];
      std::snprintf(label, sizeof(label),
        "vtkGPUVolumeRayCastMapper iso, sample %.2g x min spacing", factor);
      scene.Label = label;
      vtkNew<vtkGPUVolumeRayCastMapper> mapper;
      mapper->SetInputData(image);
      mapper->SetBlendModeToIsoSurface();
      mapper->SetAutoAdjustSampleDistances(0);
      mapper->SetSampleDistance(static_cast<float>(factor * minSpacing));
      mapper->SetImageSampleDistance(1.0f);
      volume->SetMapper(mapper);
    }
    scene.Renderer->AddVolume(volume);
  }
  scene.ResetView();
  return scene;
}

void SaveImage(Scene& scene, const std::string& file)
{
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(scene.Window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(file.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
}

std::string Field(const std::string& report, const std::string& key)
{
  const auto at = report.find(key);
  if (at == std::string::npos)
  {
    return "unknown";
  }
  const auto start = at + key.size();
  const auto end = report.find('\n', start);
  std::string value = report.substr(start, end == std::string::npos ? end : end - start);
  value.erase(0, value.find_first_not_of(" :"));
  return value;
}

struct Stats
{
  double Min, Median, Mean, Total;
};

Stats Summarise(std::vector<double> t)
{
  Stats s{ 0, 0, 0, 0 };
  if (t.empty())
  {
    return s;
  }
  std::sort(t.begin(), t.end());
  s.Min = t.front();
  const std::size_t n = t.size();
  s.Median = n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
  for (double v : t)
  {
    s.Total += v;
  }
  s.Mean = s.Total / n;
  return s;
}

std::string WindowText(int w, int h)
{
  return std::to_string(w) + "x" + std::to_string(h);
}

/// One method's part of the interleaved isovalue sweep.
struct SweepRun
{
  Scene View;
  double BuildsBefore = 0.0;
  double BytesBefore = 0.0;
  std::vector<double> Changes, Extracts, Elements, Builds, Tiles;
  int NotGPU = 0;

  /// Set-isovalue + extract (FlyingEdges) + frame, timed.
  void Step(double value)
  {
    const double t0 = Now();
    this->View.SetIsovalue(value);
    const double e = this->View.Extract();
    this->View.Frame();
    this->Changes.push_back(Now() - t0);
    this->Extracts.push_back(e);
    this->Elements.push_back(this->View.Elements());
    vtkHistoPyramidIsoMapper* hp = this->View.HistoPyramid;
    if (hp)
    {
      this->Builds.push_back(hp->GetLastBuildSeconds());
      this->Tiles.push_back(static_cast<double>(hp->GetLastBuildTilesDrawn()) /
        static_cast<double>(std::max<std::uint64_t>(1, hp->GetLastBuildTiles())));
      if (hp->GetLastRenderPath() != vtkHistoPyramidIsoMapper::GPUPath)
      {
        ++this->NotGPU;
      }
    }
  }
};

} // namespace

int main(int argc, char* argv[])
{
  Options opt;
  if (!Parse(argc, argv, opt))
  {
    return 2;
  }
  SurfaceOpacity = opt.Opacity;
  CameraZoom = opt.Zoom;
  // vtkFlyingEdges3D's threads: the STDThread backend, whatever the build's default.
  vtkSMPTools::SetBackend("STDThread");
  vtkSMPTools::Initialize(0);

  std::string label;
  const double loadStart = Now();
  vtkSmartPointer<vtkImageData> image = LoadInput(opt, label);
  if (!image)
  {
    std::fprintf(stderr, "could not load input %s\n", opt.Input.c_str());
    return 2;
  }
  const double loadSeconds = Now() - loadStart;
  if (!opt.WriteInput.empty())
  {
    // The same volume for other programs (mediso-render), then nothing else.
    vtkNew<vtkMetaImageWriter> writer;
    writer->SetInputData(image);
    writer->SetFileName(opt.WriteInput.c_str());
    writer->SetCompression(false);
    writer->Write();
    std::printf("wrote %s\n", opt.WriteInput.c_str());
    return 0;
  }
  vtkDataArray* scalars = image->GetPointData()->GetScalars();
  double range[2];
  scalars->GetRange(range);
  int dims[3];
  image->GetDimensions(dims);
  const double volumeBytes =
    static_cast<double>(scalars->GetNumberOfValues()) * scalars->GetDataTypeSize();
  const std::string dimsText =
    std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" + std::to_string(dims[2]);
  double spacing[3];
  image->GetSpacing(spacing);
  Record("input")
    .Add("input", opt.Input)
    .Add("label", label)
    .Add("dims", dimsText)
    .Add("type", scalars->GetDataTypeAsString())
    .Add("range", std::vector<double>{ range[0], range[1] })
    .Add("spacing", std::vector<double>{ spacing[0], spacing[1], spacing[2] })
    .Add("volume_bytes", volumeBytes)
    .Add("load_s", loadSeconds)
    .Add("smp_backend", vtkSMPTools::GetBackend())
    .Add("smp_threads", vtkSMPTools::GetEstimatedNumberOfThreads())
    .Add("vtk", vtkVersion::GetVTKVersion())
    .Add("frames", opt.Frames)
    .Add("sweep", opt.Sweep)
    .Print();
  std::printf("input %s: %s, %s %s, range %g..%g, loaded in %.2f s; SMP %s, %d threads\n",
    opt.Input.c_str(), label.c_str(), dimsText.c_str(), scalars->GetDataTypeAsString(), range[0],
    range[1], loadSeconds, vtkSMPTools::GetBackend(),
    vtkSMPTools::GetEstimatedNumberOfThreads());

  // The sweep: equidistant, the range's ends left out so that every isovalue crosses.
  std::vector<double> sweep;
  for (int i = 0; i < opt.Sweep; ++i)
  {
    sweep.push_back(range[0] + (range[1] - range[0]) * (i + 1) / (opt.Sweep + 1));
  }

  bool reportedGL = false;
  int failures = 0;
  for (const auto& window : opt.Windows)
  {
    const std::string windowText = WindowText(window.first, window.second);
    for (const std::string& method : opt.Methods)
    {
      const std::vector<double> factors =
        method == "rc" ? opt.RayCastFactors : std::vector<double>{ 0.0 };
      for (double factor : factors)
      {
        // --- rotation, per isovalue: a fresh scene each, so every one starts cold.
        std::vector<std::vector<double>> rotations;
        for (double iso : opt.Isovalues)
        {
          rotations.push_back({ iso });
        }
        if (opt.Together)
        {
          rotations = { opt.Isovalues };
        }
        for (const std::vector<double>& isos : rotations)
        {
          const double iso = isos.front();
          Scene scene = MakeScene(method, factor, image, window.first, window.second, isos);
          double extract = scene.Extract();
          const double first = scene.Frame();
          if (!reportedGL)
          {
            const std::string caps = scene.Window->ReportCapabilities();
            Record("machine")
              .Add("gl_vendor", Field(caps, "OpenGL vendor string"))
              .Add("gl_renderer", Field(caps, "OpenGL renderer string"))
              .Add("gl_version", Field(caps, "OpenGL version string"))
              .Print();
            std::printf("GL: %s | %s\n", Field(caps, "OpenGL renderer string").c_str(),
              Field(caps, "OpenGL version string").c_str());
            reportedGL = true;
          }
          scene.Frame(); // warm-up
          std::string path = "-";
          std::string reason;
          double buildsBefore = 0.0;
          if (scene.HistoPyramid)
          {
            path = scene.HistoPyramid->GetLastRenderPathAsString();
            if (scene.HistoPyramid->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath)
            {
              path = path + "/" + scene.HistoPyramid->GetLastFootprintAsString();
              if (scene.HistoPyramid->GetLastFirstHitPass())
              {
                path += "/first-hit";
              }
            }
            reason = scene.HistoPyramid->GetFallbackReason();
            buildsBefore = static_cast<double>(scene.HistoPyramid->GetNumberOfPyramidBuilds());
            if (scene.HistoPyramid->GetLastRenderPath() != vtkHistoPyramidIsoMapper::GPUPath)
            {
              std::printf("WARNING: vtkHistoPyramidIsoMapper drew with path %s (%s)\n",
                path.c_str(), reason.c_str());
              ++failures;
            }
          }
          if (!opt.ImageDir.empty())
          {
            char name[256];
            std::snprintf(name, sizeof(name), "%s/%s_%s_%s%s_iso%g.png", opt.ImageDir.c_str(),
              opt.Input.c_str(), windowText.c_str(), method.c_str(),
              method == "rc" ? ("_" + std::to_string(factor)).substr(0, 5).c_str() : "", iso);
            SaveImage(scene, name);
          }
          std::vector<double> times;
          times.reserve(opt.Frames);
          // The first-hit buffers follow the volume's projection, which
          // changes as it turns: the largest they were.
          double peakBuffers =
            scene.HistoPyramid ? static_cast<double>(scene.HistoPyramid->GetFrameBufferBytes()) : 0.0;
          const double rotationStart = Now();
          for (int f = 0; f < opt.Frames; ++f)
          {
            scene.Rotate(1.0);
            times.push_back(scene.Frame());
            if (scene.HistoPyramid)
            {
              peakBuffers = std::max(
                peakBuffers, static_cast<double>(scene.HistoPyramid->GetFrameBufferBytes()));
            }
          }
          const double wall = Now() - rotationStart;
          const Stats s = Summarise(times);
          Record r("rotation");
          r.Add("input", opt.Input)
            .Add("window", windowText)
            .Add("method", method)
            .Add("label", scene.Label)
            .Add("factor", factor)
            .Add("iso", iso)
            .Add("isovalues", static_cast<double>(isos.size()))
            .Add("frames", opt.Frames)
            .Add("min_s", s.Min)
            .Add("median_s", s.Median)
            .Add("mean_s", s.Mean)
            .Add("total_s", wall)
            .Add("first_frame_s", first + extract)
            .Add("elements", scene.Elements())
            .Add("path", path);
          if (scene.HistoPyramid)
          {
            r.Add("reason", reason)
              .Add("gpu_bytes", static_cast<double>(scene.HistoPyramid->GetGPUMemoryBytes()))
              .Add("framebuffer_bytes", peakBuffers)
              .Add("volume_bytes", volumeBytes)
              .Add("builds_during_rotation",
                static_cast<double>(scene.HistoPyramid->GetNumberOfPyramidBuilds()) - buildsBefore)
              .Add("uploads", static_cast<double>(scene.HistoPyramid->GetNumberOfVolumeUploads()));
          }
          if (scene.FlyingEdges)
          {
            r.Add("output_mb",
              scene.FlyingEdges->GetOutput()->GetActualMemorySize() / 1024.0);
          }
          r.Print();
          if (scene.HistoPyramid && opt.InteractiveBudget > 0.0)
          {
            vtkHistoPyramidIsoMapper* hp = scene.HistoPyramid;
            hp->SetInteractiveFrameBudget(opt.InteractiveBudget);
            hp->SetInteractiveVolumeLevels(opt.InteractiveLevels.find("volume") != std::string::npos);
            hp->SetInteractiveTriangleLevels(
              opt.InteractiveLevels.find("triangles") != std::string::npos);
            scene.Window->SetDesiredUpdateRate(1000.0);
            std::vector<double> frameTimes, distances, predicted, measured, errors, levels, paths,
              oneOff, fixedCost, budgetLeft, margins;
            int within = 0;
            // Frames that made something before drawing (a level's build or
            // extraction, a program), and how many of them were within 25%.
            int oneOffFrames = 0, oneOffWithin = 0;
            int triangleFrames = 0;
            int volumeLevelFrames = 0;
            for (int f = 0; f < opt.Frames; ++f)
            {
              scene.Rotate(1.0);
              // The margin this frame's choice divides its budget by (the
              // last frames' measured overrun, GetPredictionMargin()).
              margins.push_back(hp->GetPredictionMargin());
              frameTimes.push_back(scene.Frame());
              distances.push_back(hp->GetLastSampleDistance());
              levels.push_back(hp->GetLastLevel());
              paths.push_back(static_cast<double>(hp->GetLastRenderPath()));
              triangleFrames +=
                hp->GetLastRenderPath() == vtkHistoPyramidIsoMapper::FallbackPath ? 1 : 0;
              volumeLevelFrames +=
                hp->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath && hp->GetLastLevel() < 3
                ? 1
                : 0;
              // The whole frame's prediction: its drawing and its one-off work.
              predicted.push_back(
                hp->GetLastPredictedSeconds() + hp->GetLastPredictedOneOffSeconds());
              oneOff.push_back(hp->GetLastPredictedOneOffSeconds());
              measured.push_back(hp->GetLastMeasuredSeconds());
              // The window's cost outside the mapper that this frame took off
              // the budget, and the budget its drawing was chosen for.
              budgetLeft.push_back(hp->GetLastBudgetSeconds());
              fixedCost.push_back(
                std::max(0.0, opt.InteractiveBudget - budgetLeft.back() * (1.0 + margins.back())));
              const double error =
                std::abs(predicted.back() - measured.back()) / std::max(measured.back(), 1e-9);
              errors.push_back(error);
              within += error <= 0.25 ? 1 : 0;
              if (oneOff.back() > 0.0)
              {
                ++oneOffFrames;
                oneOffWithin += error <= 0.25 ? 1 : 0;
              }
            }
            scene.Window->SetDesiredUpdateRate(0.0001);
            const double stillAfter = scene.Frame();
            const Stats is = Summarise(frameTimes);
            Record("interactive")
              .Add("input", opt.Input)
              .Add("window", windowText)
              .Add("iso", iso)
              .Add("isovalues", static_cast<double>(isos.size()))
              .Add("opacity", SurfaceOpacity)
              .Add("budget_s", opt.InteractiveBudget)
              .Add("frames", opt.Frames)
              .Add("still_median_s", s.Median)
              .Add("median_s", is.Median)
              .Add("min_s", is.Min)
              .Add("distance_median", Summarise(distances).Median)
              .Add("distance_min", Summarise(distances).Min)
              .Add("distance_max", *std::max_element(distances.begin(), distances.end()))
              .Add("level_min", *std::min_element(levels.begin(), levels.end()))
              .Add("level_median", Summarise(levels).Median)
              .Add("triangle_frames", static_cast<double>(triangleFrames))
              .Add("volume_level_frames", static_cast<double>(volumeLevelFrames))
              .Add("predicted_median_s", Summarise(predicted).Median)
              .Add("measured_median_s", Summarise(measured).Median)
              .Add("error_median", Summarise(errors).Median)
              .Add("within_25", static_cast<double>(within) / std::max(1, opt.Frames))
              .Add("still_after_s", stillAfter)
              // Per frame, for classifying the model's misses (issue 30): the
              // frame's wall time, the mapper's prediction and its own timing,
              // level, sample distance and path (GetLastRenderPath()).
              .Add("frame_s", frameTimes)
              .Add("frame_predicted_s", predicted)
              .Add("frame_measured_s", measured)
              .Add("frame_level", levels)
              .Add("frame_distance", distances)
              .Add("frame_path", paths)
              .Add("frame_predicted_one_off_s", oneOff)
              .Add("frame_window_fixed_s", fixedCost)
              .Add("window_fixed_median_s", Summarise(fixedCost).Median)
              .Add("frame_margin", margins)
              .Add("margin_median", Summarise(margins).Median)
              .Add("one_off_frames", static_cast<double>(oneOffFrames))
              .Add("one_off_within_25", static_cast<double>(oneOffWithin))
              .Add("still_after_distance", hp->GetLastSampleDistance())
              .Print();
            std::printf("%s %s interactive (budget %g s): median %.4f s against still %.4f s, "
                        "sample distance median %g, predicted/measured median %.4f/%.4f s, "
                        "%.0f%% of frames predicted within 25%%\n",
              opt.Input.c_str(), windowText.c_str(), opt.InteractiveBudget, is.Median, s.Median,
              Summarise(distances).Median, Summarise(predicted).Median, Summarise(measured).Median,
              100.0 * within / std::max(1, opt.Frames));
            std::printf("%s %s interactive: the window's cost outside the mapper, taken off the "
                        "budget, median %.4f s\n",
              opt.Input.c_str(),
              windowText.c_str(),
              Summarise(fixedCost).Median);
          }
          std::printf("%s %s %s iso %g: %d frames, median %.4f s (%.1f fps), min %.4f s, "
                      "total %.1f s, %.0f elements, path %s\n",
            opt.Input.c_str(), windowText.c_str(), scene.Label.c_str(), iso, opt.Frames,
            s.Median, 1.0 / s.Median, s.Min, wall, scene.Elements(), path.c_str());
          std::fflush(stdout);
          scene.Window->Finalize();
        }
      }
    }

    // --- isovalue sweep: change + frame (FlyingEdges: extract + frame). The
    // methods' scenes live side by side and take the isovalues in turn, the
    // order rotating at every step (each method goes first equally often),
    // so a load that drifts on a shared machine falls on all of them alike,
    // and each step gives a ratio of two times taken moments apart.
    if (sweep.empty())
    {
      continue;
    }
    std::vector<SweepRun> runs;
    for (const std::string& method : opt.Methods)
    {
      const std::vector<double> factors =
        method == "rc" ? opt.RayCastFactors : std::vector<double>{ 0.0 };
      for (double factor : factors)
      {
        SweepRun run;
        run.View =
          MakeScene(method, factor, image, window.first, window.second, { opt.Isovalues.front() });
        run.View.Extract();
        run.View.Frame();
        run.View.Frame();
        if (run.View.HistoPyramid)
        {
          run.BuildsBefore = static_cast<double>(run.View.HistoPyramid->GetNumberOfPyramidBuilds());
          run.BytesBefore = static_cast<double>(run.View.HistoPyramid->GetGPUMemoryBytes());
        }
        runs.push_back(std::move(run));
      }
    }
    for (std::size_t i = 0; i < sweep.size(); ++i)
    {
      for (std::size_t k = 0; k < runs.size(); ++k)
      {
        runs[(i + k) % runs.size()].Step(sweep[i]);
      }
    }
    const SweepRun* fe = nullptr;
    for (const SweepRun& run : runs)
    {
      if (run.View.Method == "fe")
      {
        fe = &run;
      }
    }
    for (SweepRun& run : runs)
    {
      Scene& scene = run.View;
      const Stats s = Summarise(run.Changes);
      const Stats se = Summarise(run.Extracts);
      Record r("sweep");
      r.Add("input", opt.Input)
        .Add("window", windowText)
        .Add("method", scene.Method)
        .Add("label", scene.Label)
        .Add("factor", scene.SampleFactor)
        .Add("n", static_cast<double>(sweep.size()))
        .Add("first_iso", sweep.front())
        .Add("last_iso", sweep.back())
        .Add("min_s", s.Min)
        .Add("median_s", s.Median)
        .Add("mean_s", s.Mean)
        .Add("total_s", s.Total)
        .Add("max_s", *std::max_element(run.Changes.begin(), run.Changes.end()))
        .Add("extract_median_s", se.Median)
        .Add("min_elements", *std::min_element(run.Elements.begin(), run.Elements.end()))
        .Add("max_elements", *std::max_element(run.Elements.begin(), run.Elements.end()))
        .Add("interleaved_with", static_cast<double>(runs.size() - 1));
      if (scene.HistoPyramid)
      {
        r.Add("builds",
            static_cast<double>(scene.HistoPyramid->GetNumberOfPyramidBuilds()) - run.BuildsBefore)
          .Add("build_median_s", Summarise(run.Builds).Median)
          .Add("build_tiles_median", Summarise(run.Tiles).Median)
          .Add("gpu_bytes_before", run.BytesBefore)
          .Add("gpu_bytes_after", static_cast<double>(scene.HistoPyramid->GetGPUMemoryBytes()))
          .Add("volume_bytes", volumeBytes)
          .Add("frames_not_gpu", run.NotGPU);
        if (run.NotGPU)
        {
          ++failures;
        }
      }
      // Against FlyingEdges + PolyDataMapper step by step: the ratio of each
      // isovalue's two times, summarised over the sweep.
      if (fe && &run != fe)
      {
        std::vector<double> ratios;
        for (std::size_t i = 0; i < run.Changes.size(); ++i)
        {
          ratios.push_back(run.Changes[i] / fe->Changes[i]);
        }
        const Stats sr = Summarise(ratios);
        r.Add("paired_fe_median", sr.Median)
          .Add("paired_fe_min", sr.Min)
          .Add("paired_fe_max", *std::max_element(ratios.begin(), ratios.end()))
          .Add("paired_fe_at_most_half",
            static_cast<double>(
              std::count_if(ratios.begin(), ratios.end(), [](double x) { return x <= 0.5; })));
      }
      r.Print();
      std::printf("%s %s %s sweep of %zu: median %.4f s per change+frame (min %.4f, total "
                  "%.1f s), elements %.0f..%.0f\n",
        opt.Input.c_str(), windowText.c_str(), scene.Label.c_str(), sweep.size(), s.Median, s.Min,
        s.Total, *std::min_element(run.Elements.begin(), run.Elements.end()),
        *std::max_element(run.Elements.begin(), run.Elements.end()));
      std::fflush(stdout);
    }
    for (SweepRun& run : runs)
    {
      run.View.Window->Finalize();
    }
  }
  Record("end").Add("peak_rss_mb", PeakRSSMB()).Add("failures", failures).Print();
  return failures ? 1 : 0;
}
