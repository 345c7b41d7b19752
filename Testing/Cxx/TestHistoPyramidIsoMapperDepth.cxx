// SPDX-License-Identifier: BSD-3-Clause
// vtkHistoPyramidIsoMapper's hit depth against the true surface, and its
// depth compositing with polygonal geometry (GPU path; 125 without it).
//
// 1. Analytic depth. The distance-to-centre field of a 40^3 grid (float) has
//    the sphere |x| = r as its isosurface r. Every covered pixel's depth-buffer
//    value is unprojected to a world point, whose distance to the centre must
//    be r within 0.05 voxel (the trilinear interpolant of the distance field
//    departs from the sphere by at most ~3h^2/(8r) = 0.03 voxel at r = 12.7,
//    plus depth-buffer quantisation); in perspective and parallel projection.
//    The covered pixels must be those whose pixel-centre ray meets the
//    sphere, except along the outline (at most 1.5% of them differ).
// 2. Occlusion both ways. An opaque red plane through the sphere's centre,
//    tilted 35 degrees out of the view plane, is drawn with the (blue)
//    isosurface: at every pixel the colour must be the one of the nearer of
//    the two analytic surfaces (ray-sphere against ray-plane), except along
//    the outlines and the intersection curve (at most 1.5% of the pixels
//    covered by either).
#include "IsoMapperTestScenes.h"
#include "MedicalTestUtilities.h"
#include "vtkMedicalGLCapabilities.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkFloatArray.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkUnsignedCharArray.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace
{
using medical_test::Check;
constexpr int Size = 400;

// World-space ray through the centre of pixel (i, j), and the unprojection of
// a depth-buffer value there.
struct Unprojector
{
  vtkNew<vtkMatrix4x4> Inverse;
  explicit Unprojector(vtkRenderer* ren)
  {
    vtkMatrix4x4* m = ren->GetActiveCamera()->GetCompositeProjectionTransformMatrix(
      ren->GetTiledAspectRatio(), -1, 1);
    vtkMatrix4x4::Invert(m, this->Inverse);
  }
  void Point(int i, int j, double ndcZ, double out[3]) const
  {
    double p[4] = { 2.0 * (i + 0.5) / Size - 1.0, 2.0 * (j + 0.5) / Size - 1.0, ndcZ, 1.0 };
    this->Inverse->MultiplyPoint(p, p);
    for (int a = 0; a < 3; ++a)
    {
      out[a] = p[a] / p[3];
    }
  }
  void Ray(int i, int j, double origin[3], double dir[3]) const
  {
    double far[3];
    this->Point(i, j, -1.0, origin);
    this->Point(i, j, 1.0, far);
    for (int a = 0; a < 3; ++a)
    {
      dir[a] = far[a] - origin[a];
    }
  }
};

// First t >= 0 of origin + t dir on the sphere |x| = r (or -1).
double RaySphere(const double o[3], const double d[3], double r)
{
  const double a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  const double b = 2.0 * (o[0] * d[0] + o[1] * d[1] + o[2] * d[2]);
  const double c = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - r * r;
  const double disc = b * b - 4 * a * c;
  if (disc < 0)
  {
    return -1.0;
  }
  const double t = (-b - std::sqrt(disc)) / (2 * a);
  return t >= 0 ? t : -1.0;
}

void AnalyticDepth(bool parallel)
{
  const std::string what = parallel ? "parallel" : "perspective";
  const double radius = 12.7;
  auto image = iso_test::Sphere(40);
  vtkNew<vtkHistoPyramidIsoMapper> mapper;
  auto volume = iso_test::MakeVolume(image, { { radius, { 1, 1, 1 }, 1.0 } }, mapper);
  vtkNew<vtkRenderWindow> renWin;
  renWin->SetSize(Size, Size);
  renWin->SetMultiSamples(0);
  vtkNew<vtkRenderer> ren;
  renWin->AddRenderer(ren);
  ren->AddVolume(volume);
  vtkCamera* camera = ren->GetActiveCamera();
  camera->SetPosition(0.3, -1.0, 0.45);
  camera->SetFocalPoint(0, 0, 0);
  camera->SetParallelProjection(parallel);
  ren->ResetCamera();
  camera->Zoom(1.4);
  renWin->Render();
  Check(mapper->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath, what + ": GPU path");

  vtkNew<vtkFloatArray> depth;
  renWin->GetZbufferData(0, 0, Size - 1, Size - 1, depth);
  Unprojector un(ren);
  int covered = 0, expected = 0, mismatched = 0;
  double maxError = 0.0, sumError = 0.0;
  for (int j = 0; j < Size; ++j)
  {
    for (int i = 0; i < Size; ++i)
    {
      const float z = depth->GetValue(j * Size + i);
      double o[3], d[3];
      un.Ray(i, j, o, d);
      const bool hitExpected = RaySphere(o, d, radius) >= 0.0;
      const bool hit = z < 1.0f;
      expected += hitExpected;
      mismatched += hit != hitExpected;
      if (hit)
      {
        ++covered;
        double p[3];
        un.Point(i, j, 2.0 * z - 1.0, p);
        const double error = std::abs(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - radius);
        maxError = std::max(maxError, error);
        sumError += error;
      }
    }
  }
  std::printf("%s: %d covered pixels (%d expected, %d differ), depth error max %.4f mean %.5f "
              "voxel\n",
    what.c_str(), covered, expected, mismatched, maxError, covered ? sumError / covered : 0.0);
  Check(expected > 20000, what + ": the sphere covers a good part of the image");
  Check(mismatched <= 0.015 * expected, what + ": covered pixels are those whose ray meets the sphere");
  Check(covered > 0 && maxError <= 0.05, what + ": every hit within 0.05 voxel of the true sphere");
}

void PlaneOcclusion(bool parallel)
{
  const std::string what = std::string("plane, ") + (parallel ? "parallel" : "perspective");
  const double radius = 12.7;
  auto image = iso_test::Sphere(40);
  vtkNew<vtkHistoPyramidIsoMapper> mapper;
  auto volume = iso_test::MakeVolume(image, { { radius, { 0, 0, 1 }, 1.0 } }, mapper);
  vtkVolumeProperty* property = volume->GetProperty();
  property->SetAmbient(1.0); // flat colours: the test reads which surface is seen
  property->SetDiffuse(0.0);
  property->SetSpecular(0.0);

  // Plane through the centre, normal n (tilted 35 degrees from the view axis -y).
  const double tilt = vtkMath::RadiansFromDegrees(35.0);
  const double n[3] = { 0.0, -std::cos(tilt), std::sin(tilt) };
  vtkNew<vtkPlaneSource> plane;
  plane->SetOrigin(-30, 0, -30);
  plane->SetPoint1(30, 0, -30);
  plane->SetPoint2(-30, 0, 30);
  plane->SetCenter(0, 0, 0);
  plane->SetNormal(n[0], n[1], n[2]);
  vtkNew<vtkPolyDataMapper> planeMapper;
  planeMapper->SetInputConnection(plane->GetOutputPort());
  vtkNew<vtkActor> planeActor;
  planeActor->SetMapper(planeMapper);
  planeActor->GetProperty()->SetColor(1, 0, 0);
  planeActor->GetProperty()->SetAmbient(1.0);
  planeActor->GetProperty()->SetDiffuse(0.0);
  planeActor->GetProperty()->SetSpecular(0.0);
  planeActor->GetProperty()->LightingOff();

  vtkNew<vtkRenderWindow> renWin;
  renWin->SetSize(Size, Size);
  renWin->SetMultiSamples(0);
  vtkNew<vtkRenderer> ren;
  renWin->AddRenderer(ren);
  ren->AddVolume(volume);
  ren->AddActor(planeActor);
  vtkCamera* camera = ren->GetActiveCamera();
  camera->SetPosition(0.0, -60.0, 0.0);
  camera->SetFocalPoint(0, 0, 0);
  camera->SetViewUp(0, 0, 1);
  camera->SetParallelProjection(parallel);
  camera->SetParallelScale(20.0);
  camera->SetViewAngle(36.0);
  renWin->Render();
  Check(mapper->GetLastRenderPath() == vtkHistoPyramidIsoMapper::GPUPath, what + ": GPU path");

  vtkNew<vtkUnsignedCharArray> rgb;
  renWin->GetPixelData(0, 0, Size - 1, Size - 1, 1, rgb);
  Unprojector un(ren);
  int considered = 0, wrong = 0, sphereSeen = 0, planeSeen = 0;
  for (int j = 0; j < Size; ++j)
  {
    for (int i = 0; i < Size; ++i)
    {
      double o[3], d[3];
      un.Ray(i, j, o, d);
      const double ts = RaySphere(o, d, radius);
      const double dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
      double tp = -1.0;
      if (std::abs(dn) > 1e-12)
      {
        tp = -(o[0] * n[0] + o[1] * n[1] + o[2] * n[2]) / dn;
        double p[3];
        for (int a = 0; a < 3; ++a)
        {
          p[a] = o[a] + tp * d[a];
        }
        if (tp < 0 || std::abs(p[0]) > 29.0 || std::abs(p[2]) > 23.0)
        {
          tp = -1.0; // off the plane's extent (kept clear of its edges)
        }
      }
      if (ts < 0 && tp < 0)
      {
        continue;
      }
      ++considered;
      const bool expectSphere = ts >= 0 && (tp < 0 || ts < tp);
      const unsigned char* c = rgb->GetPointer(3 * (j * Size + i));
      const bool isBlue = c[2] > 128 && c[0] < 100;
      const bool isRed = c[0] > 128 && c[2] < 100;
      sphereSeen += isBlue;
      planeSeen += isRed;
      wrong += expectSphere ? !isBlue : !isRed;
    }
  }
  std::printf("%s: %d pixels on the sphere or plane, %d blue, %d red, %d wrong\n", what.c_str(),
    considered, sphereSeen, planeSeen, wrong);
  Check(sphereSeen > 5000 && planeSeen > 5000, what + ": both surfaces visible");
  Check(wrong <= 0.015 * considered, what + ": the nearer surface is seen at (almost) every pixel");
}
} // namespace

int TestHistoPyramidIsoMapperDepth(int, char*[])
{
  if (const int skip = iso_test::ProbeOrSkip())
  {
    return skip;
  }
  AnalyticDepth(false);
  AnalyticDepth(true);
  PlaneOcclusion(false);
  PlaneOcclusion(true);
  return medical_test::Finish("TestHistoPyramidIsoMapperDepth");
}
