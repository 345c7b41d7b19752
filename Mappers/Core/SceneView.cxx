// SPDX-License-Identifier: BSD-3-Clause
#include "SceneView.h"

#include <algorithm>
#include <cmath>

namespace mediso
{

matrix4::Matrix VolumePlacement::IndexToWorld() const
{
  matrix4::Matrix m = matrix4::Identity();
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      m[4 * r + c] = this->Direction[3 * r + c] * this->Spacing[c];
    }
    m[4 * r + 3] = this->Origin[r];
  }
  return m;
}

void VolumePlacement::Bounds(double bounds[6]) const
{
  const matrix4::Matrix m = this->IndexToWorld();
  for (int a = 0; a < 3; ++a)
  {
    bounds[2 * a] = HUGE_VAL;
    bounds[2 * a + 1] = -HUGE_VAL;
  }
  for (int i = 0; i < 8; ++i)
  {
    const double p[4] = { (i & 1) ? this->Dimensions[0] - 1.0 : 0.0,
      (i & 2) ? this->Dimensions[1] - 1.0 : 0.0, (i & 4) ? this->Dimensions[2] - 1.0 : 0.0, 1.0 };
    const auto w = matrix4::Transform(m, p);
    for (int a = 0; a < 3; ++a)
    {
      bounds[2 * a] = std::min(bounds[2 * a], w[a]);
      bounds[2 * a + 1] = std::max(bounds[2 * a + 1], w[a]);
    }
  }
}

void SetFrameView(IsosurfaceFrame& frame, const Camera& camera, const VolumePlacement& placement,
  int width, int height)
{
  const double aspect = static_cast<double>(width) / std::max(1, height);
  const matrix4::Matrix indexToView =
    matrix4::Multiply(camera.ViewMatrix(), placement.IndexToWorld());
  const matrix4::Matrix projection = camera.ProjectionMatrix(aspect);
  std::copy(indexToView.begin(), indexToView.end(), frame.IndexToView);
  std::copy(projection.begin(), projection.end(), frame.Projection);
  frame.Parallel = camera.Parallel;
  frame.NearPlane = camera.ClippingRange[0];
  frame.Viewport[0] = 0;
  frame.Viewport[1] = 0;
  frame.Viewport[2] = width;
  frame.Viewport[3] = height;
  frame.NumberOfLights = 1;
  const float toLight[3] = { 0.0f, 0.0f, 1.0f }; // a headlight, in view space
  for (int a = 0; a < 3; ++a)
  {
    frame.LightDirections[0][a] = toLight[a];
    frame.LightColors[0][a] = 1.0f;
  }
}

} // namespace mediso
