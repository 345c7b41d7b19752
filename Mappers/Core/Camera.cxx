// SPDX-License-Identifier: BSD-3-Clause
#include "Camera.h"

#include <algorithm>
#include <cmath>

namespace mediso
{
namespace
{
constexpr double Pi = 3.14159265358979323846;

double Dot(const double a[3], const double b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void Cross(const double a[3], const double b[3], double out[3])
{
  const double c[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
    a[0] * b[1] - a[1] * b[0] };
  std::copy(c, c + 3, out);
}

double Normalize(double v[3])
{
  const double length = std::sqrt(Dot(v, v));
  if (length > 0.0)
  {
    for (int a = 0; a < 3; ++a)
    {
      v[a] /= length;
    }
  }
  return length;
}

// Rotates v by `degrees` about the unit axis (right-handed), in place.
void Rotate(double v[3], const double axisIn[3], double degrees)
{
  double axis[3] = { axisIn[0], axisIn[1], axisIn[2] };
  if (Normalize(axis) == 0.0)
  {
    return;
  }
  const double t = degrees * Pi / 180.0;
  const double c = std::cos(t), s = std::sin(t);
  double kxv[3];
  Cross(axis, v, kxv);
  const double kdv = Dot(axis, v);
  for (int a = 0; a < 3; ++a)
  {
    v[a] = v[a] * c + kxv[a] * s + axis[a] * kdv * (1.0 - c);
  }
}

// Rotates point p by `degrees` about the axis through `center`.
void RotateAbout(double p[3], const double center[3], const double axis[3], double degrees)
{
  double v[3] = { p[0] - center[0], p[1] - center[1], p[2] - center[2] };
  Rotate(v, axis, degrees);
  for (int a = 0; a < 3; ++a)
  {
    p[a] = center[a] + v[a];
  }
}

// gluLookAt: rows are the view's x (right), y (up), z (towards the eye).
matrix4::Matrix LookAt(const double eye[3], const double focal[3], const double up[3])
{
  double z[3] = { eye[0] - focal[0], eye[1] - focal[1], eye[2] - focal[2] };
  Normalize(z);
  double x[3];
  Cross(up, z, x);
  Normalize(x);
  double y[3];
  Cross(z, x, y);
  matrix4::Matrix m = matrix4::Identity();
  for (int c = 0; c < 3; ++c)
  {
    m[c] = x[c];
    m[4 + c] = y[c];
    m[8 + c] = z[c];
  }
  m[3] = -Dot(x, eye);
  m[7] = -Dot(y, eye);
  m[11] = -Dot(z, eye);
  return m;
}
} // namespace

void Camera::SetPosition(const double position[3])
{
  std::copy(position, position + 3, this->Position);
  this->View = LookAt(this->Position, this->FocalPoint, this->ViewUp);
}

void Camera::Reset(const double bounds[6], double aspect)
{
  double normal[3] = { this->Position[0] - this->FocalPoint[0],
    this->Position[1] - this->FocalPoint[1], this->Position[2] - this->FocalPoint[2] };
  if (Normalize(normal) == 0.0)
  {
    normal[2] = 1.0;
  }
  this->ViewAngle = 30.0;
  const double center[3] = { 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
    0.5 * (bounds[4] + bounds[5]) };
  double radius = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    const double w = bounds[2 * a + 1] - bounds[2 * a];
    radius += w * w;
  }
  radius = std::sqrt(radius == 0.0 ? 1.0 : radius) * 0.5;
  double angle = this->ViewAngle * Pi / 180.0;
  double parallelScale = radius;
  if (aspect < 1.0)
  {
    // A portrait viewport: fit the sphere in the narrower horizontal angle.
    angle = 2.0 * std::atan(std::tan(angle * 0.5) * aspect);
    parallelScale /= aspect;
  }
  const double distance = radius / std::sin(angle * 0.5);
  if (std::fabs(Dot(this->ViewUp, normal)) > 0.999)
  {
    const double up[3] = { -this->ViewUp[2], this->ViewUp[0], this->ViewUp[1] };
    std::copy(up, up + 3, this->ViewUp);
  }
  std::copy(center, center + 3, this->FocalPoint);
  const double position[3] = { center[0] + distance * normal[0], center[1] + distance * normal[1],
    center[2] + distance * normal[2] };
  this->SetPosition(position);
  this->ResetClippingRange(bounds);
  this->ParallelScale = parallelScale;
}

void Camera::ResetClippingRange(const double bounds[6])
{
  double normal[3] = { this->Position[0] - this->FocalPoint[0],
    this->Position[1] - this->FocalPoint[1], this->Position[2] - this->FocalPoint[2] };
  Normalize(normal);
  const double a = -normal[0], b = -normal[1], c = -normal[2];
  const double d = -(a * this->Position[0] + b * this->Position[1] + c * this->Position[2]);
  double range[2] = { a * bounds[0] + b * bounds[2] + c * bounds[4] + d, 1e-18 };
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
      {
        const double dist = a * bounds[i] + b * bounds[2 + j] + c * bounds[4 + k] + d;
        range[0] = std::min(range[0], dist);
        range[1] = std::max(range[1], dist);
      }
  double minGap = this->Parallel ? 0.1 * this->ParallelScale
                                 : 0.2 * std::tan(this->ViewAngle * Pi / 360.0) * range[1];
  if (range[1] - range[0] < minGap)
  {
    minGap = minGap - range[1] + range[0];
    range[1] += minGap / 2.0;
    range[0] -= minGap / 2.0;
  }
  range[0] = std::max(range[0], 0.0);
  const double expansion = 0.5;
  range[0] = 0.99 * range[0] - (range[1] - range[0]) * expansion;
  range[1] = 1.01 * range[1] + (range[1] - range[0]) * expansion;
  range[0] = range[0] >= range[1] ? 0.01 * range[1] : range[0];
  range[0] = std::max(range[0], 0.001 * range[1]);
  this->ClippingRange[0] = range[0];
  this->ClippingRange[1] = range[1];
}

void Camera::Azimuth(double degrees)
{
  double position[3] = { this->Position[0], this->Position[1], this->Position[2] };
  RotateAbout(position, this->FocalPoint, this->ViewUp, degrees);
  this->SetPosition(position);
}

void Camera::Elevation(double degrees)
{
  this->View = LookAt(this->Position, this->FocalPoint, this->ViewUp);
  const double axis[3] = { -this->View[0], -this->View[1], -this->View[2] };
  // As vtkCamera: the view transform is made with the rotated view up, the
  // view up itself stays (OrthogonalizeViewUp() then takes the rotated one).
  const double savedUp[3] = { this->ViewUp[0], this->ViewUp[1], this->ViewUp[2] };
  Rotate(this->ViewUp, axis, degrees);
  double position[3] = { this->Position[0], this->Position[1], this->Position[2] };
  RotateAbout(position, this->FocalPoint, axis, degrees);
  this->SetPosition(position);
  std::copy(savedUp, savedUp + 3, this->ViewUp);
}

void Camera::OrthogonalizeViewUp()
{
  this->ViewUp[0] = this->View[4];
  this->ViewUp[1] = this->View[5];
  this->ViewUp[2] = this->View[6];
}

void Camera::Zoom(double factor)
{
  if (factor <= 0.0)
  {
    return;
  }
  if (this->Parallel)
  {
    this->ParallelScale /= factor;
  }
  else
  {
    this->ViewAngle /= factor;
  }
}

void Camera::Dolly(double factor)
{
  if (factor <= 0.0)
  {
    return;
  }
  double position[3];
  for (int a = 0; a < 3; ++a)
  {
    position[a] = this->FocalPoint[a] + (this->Position[a] - this->FocalPoint[a]) / factor;
  }
  this->SetPosition(position);
}

void Camera::SetView(const double position[3], const double focalPoint[3], const double viewUp[3])
{
  std::copy(focalPoint, focalPoint + 3, this->FocalPoint);
  std::copy(viewUp, viewUp + 3, this->ViewUp);
  this->SetPosition(position);
}

matrix4::Matrix Camera::ViewMatrix() const
{
  return LookAt(this->Position, this->FocalPoint, this->ViewUp);
}

matrix4::Matrix Camera::ProjectionMatrix(double aspect) const
{
  const double n = this->ClippingRange[0], f = this->ClippingRange[1];
  matrix4::Matrix p{};
  if (this->Parallel)
  {
    const double w = this->ParallelScale * aspect, h = this->ParallelScale;
    p[0] = 1.0 / w;
    p[5] = 1.0 / h;
    p[10] = -2.0 / (f - n);
    p[11] = -(f + n) / (f - n);
    p[15] = 1.0;
  }
  else
  {
    const double t = std::tan(this->ViewAngle * Pi / 360.0);
    p[0] = 1.0 / (t * aspect);
    p[5] = 1.0 / t;
    p[10] = -(f + n) / (f - n);
    p[11] = -2.0 * f * n / (f - n);
    p[14] = -1.0;
  }
  return p;
}

} // namespace mediso
