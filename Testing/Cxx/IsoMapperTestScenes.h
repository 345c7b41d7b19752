// SPDX-License-Identifier: BSD-3-Clause
// Shared scenes of the vtkHistoPyramidIsoMapper tests: analytic fields, the
// phantom, and a volume set up with the mapper and given isovalues.
#ifndef IsoMapperTestScenes_h
#define IsoMapperTestScenes_h

#include "vtkHistoPyramidIsoMapper.h"
#include "vtkMedicalGLCapabilities.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkColorTransferFunction.h"
#include "vtkContourValues.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkSmartPointer.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include <cmath>
#include <cstdio>
#include <functional>
#include <utility>
#include <vector>

namespace iso_test
{
// Probes the GPU path in `window` (a small one of its own when null): 0 when
// it can run; else prints why and returns the test's exit code, 125 (skip)
// for a machine without the features, 1 for a failed probe (a bug).
inline int ProbeOrSkip(vtkRenderWindow* window = nullptr)
{
  vtkNew<vtkRenderWindow> own;
  own->SetSize(64, 64);
  vtkNew<vtkMedicalGLCapabilities> caps;
  if (caps->Probe(window ? window : own.Get()))
  {
    return 0;
  }
  std::printf("SKIP: %s (%s)\n", caps->GetReason().c_str(), caps->GetStatusAsString());
  return caps->GetStatus() == vtkMedicalGLCapabilities::StatusProbeFailed ? 1 : 125;
}

// A float image sampling f(x, y, z) at its points (world coordinates).
inline vtkSmartPointer<vtkImageData> SampleField(const int dims[3], const double spacing[3],
  const double origin[3], const std::function<double(double, double, double)>& f)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(dims[0], dims[1], dims[2]);
  image->SetSpacing(spacing[0], spacing[1], spacing[2]);
  image->SetOrigin(origin[0], origin[1], origin[2]);
  vtkNew<vtkFloatArray> values;
  values->SetName("field");
  values->SetNumberOfTuples(static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2]);
  vtkIdType id = 0;
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i, ++id)
        values->SetValue(id,
          static_cast<float>(f(origin[0] + i * spacing[0], origin[1] + j * spacing[1],
            origin[2] + k * spacing[2])));
  image->GetPointData()->SetScalars(values);
  return image;
}

// Distance to a centre: the isosurface r is a sphere of radius r.
inline vtkSmartPointer<vtkImageData> Sphere(int n, double spacing = 1.0)
{
  const int dims[3] = { n, n, n };
  const double h[3] = { spacing, spacing, spacing };
  const double c = 0.5 * (n - 1) * spacing;
  const double origin[3] = { -c, -c, -c };
  return SampleField(dims, h, origin,
    [](double x, double y, double z) { return std::sqrt(x * x + y * y + z * z); });
}

// Distance to a circle of radius R in the xy plane: isosurface r is a torus.
inline vtkSmartPointer<vtkImageData> Torus(int n, double R)
{
  const int dims[3] = { n, n, n / 2 };
  const double h[3] = { 1.0, 1.0, 1.0 };
  const double origin[3] = { -0.5 * (n - 1), -0.5 * (n - 1), -0.5 * (n / 2 - 1) };
  return SampleField(dims, h, origin,
    [R](double x, double y, double z)
    {
      const double q = std::sqrt(x * x + y * y) - R;
      return std::sqrt(q * q + z * z);
    });
}

inline vtkSmartPointer<vtkImageData> Phantom(int n)
{
  vtkNew<vtkMedicalPhantomSource> source;
  source->SetDimensions(n, n, n);
  source->SetSpacing(200.0 / n, 200.0 / n, 200.0 / n);
  source->Update();
  return source->GetOutput();
}

struct Look
{
  double Value;
  double Color[3];
  double Opacity;
};

// A volume drawn by a vtkHistoPyramidIsoMapper with the given isosurfaces
// (colour and opacity transfer functions made to give each its look).
inline vtkSmartPointer<vtkVolume> MakeVolume(
  vtkImageData* image, const std::vector<Look>& looks, vtkHistoPyramidIsoMapper* mapper)
{
  mapper->SetInputData(image);
  vtkNew<vtkColorTransferFunction> color;
  vtkNew<vtkPiecewiseFunction> opacity;
  vtkNew<vtkVolumeProperty> property;
  for (std::size_t i = 0; i < looks.size(); ++i)
  {
    color->AddRGBPoint(looks[i].Value, looks[i].Color[0], looks[i].Color[1], looks[i].Color[2]);
    opacity->AddPoint(looks[i].Value, looks[i].Opacity);
    property->GetIsoSurfaceValues()->SetValue(static_cast<int>(i), looks[i].Value);
  }
  property->SetColor(color);
  property->SetScalarOpacity(opacity);
  property->SetAmbient(0.15);
  property->SetDiffuse(0.8);
  property->SetSpecular(0.25);
  property->SetSpecularPower(30.0);
  property->ShadeOn();
  auto volume = vtkSmartPointer<vtkVolume>::New();
  volume->SetMapper(mapper);
  volume->SetProperty(property);
  return volume;
}
} // namespace iso_test

#endif
