// SPDX-License-Identifier: BSD-3-Clause
#include "PageCamera.h"

#include "BlockLOD.h"
#include "HistoPyramid.h"
#include "IsosurfaceScene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace mediso
{
namespace web
{
namespace
{
using emscripten::val;

void Triple(const val& array, double out[3])
{
  for (int a = 0; a < 3; ++a)
  {
    out[a] = array[a].as<double>();
  }
}

val TripleVal(const double v[3])
{
  val out = val::array();
  for (int a = 0; a < 3; ++a)
  {
    out.call<void>("push", v[a]);
  }
  return out;
}
} // namespace

void PageCamera::SetPlacement(const val& dims, const val& spacing, const val& origin)
{
  for (int a = 0; a < 3; ++a)
  {
    this->Placement.Dimensions[a] = dims[a].as<int>();
    this->Placement.Spacing[a] = spacing[a].as<double>();
    this->Placement.Origin[a] = origin[a].as<double>();
  }
}

bool PageCamera::SetDirection(const val& direction)
{
  if (direction["length"].as<int>() != 9)
  {
    return false;
  }
  double d[9];
  for (int k = 0; k < 9; ++k)
  {
    d[k] = direction[k].as<double>();
    if (!std::isfinite(d[k]))
    {
      return false;
    }
  }
  // Columns of unit length and orthogonal: a rotation or a reflection, which
  // keeps the spacing's lengths and the normals' angles.
  for (int a = 0; a < 3; ++a)
  {
    for (int b = 0; b < 3; ++b)
    {
      const double dot = d[a] * d[b] + d[3 + a] * d[3 + b] + d[6 + a] * d[6 + b];
      if (std::abs(dot - (a == b ? 1.0 : 0.0)) > 1e-6)
      {
        return false;
      }
    }
  }
  std::copy(d, d + 9, this->Placement.Direction);
  return true;
}

void PageCamera::Resize(int width, int height)
{
  this->Width = std::max(1, width);
  this->Height = std::max(1, height);
}

void PageCamera::ResetCamera()
{
  double bounds[6];
  this->Placement.Bounds(bounds);
  this->View = Camera();
  this->View.Parallel = this->Parallel;
  this->View.Reset(bounds, static_cast<double>(this->Width) / this->Height);
}

void PageCamera::Elevation(double degrees)
{
  this->View.Elevation(degrees);
  this->View.OrthogonalizeViewUp();
}

void PageCamera::SetParallel(bool parallel)
{
  this->Parallel = parallel;
  this->View.Parallel = parallel;
}

void PageCamera::SetView(const val& view)
{
  double position[3], focal[3], up[3];
  Triple(view["position"], position);
  Triple(view["focalPoint"], focal);
  Triple(view["viewUp"], up);
  if (!view["viewAngle"].isUndefined())
  {
    this->View.ViewAngle = view["viewAngle"].as<double>();
  }
  if (!view["parallelScale"].isUndefined())
  {
    this->View.ParallelScale = view["parallelScale"].as<double>();
  }
  this->View.SetView(position, focal, up);
}

val PageCamera::GetView() const
{
  val view = val::object();
  view.set("position", TripleVal(this->View.Position));
  view.set("focalPoint", TripleVal(this->View.FocalPoint));
  view.set("viewUp", TripleVal(this->View.ViewUp));
  view.set("viewAngle", this->View.ViewAngle);
  view.set("parallelScale", this->View.ParallelScale);
  return view;
}

double CountActivePairs(
  ScalarType type, const void* data, const int dims[3], const val& isovalues, int level)
{
  if (!data || ScalarTypeSize(type) == 0 || level < IsosurfaceScene::CoarsestLevel ||
    level >= NumberOfLevels)
  {
    return 0.0;
  }
  std::vector<double> values;
  const int n = isovalues["length"].as<int>();
  for (int i = 0; i < n; ++i)
  {
    values.push_back(isovalues[i].as<double>());
  }
  std::uint64_t total = 0;
  VisitScalarType(type,
    [&](auto tag)
    {
      using T = decltype(tag);
      Volume<T> volume;
      volume.Data = static_cast<const T*>(data);
      std::copy(dims, dims + 3, volume.Dims);
      std::vector<T> samples;
      if (level < NumberOfLevels - 1)
      {
        volume =
          MakeStrideCopy(volume, IsosurfaceScene::VolumeLevelStride(level), samples, SerialFor);
      }
      for (std::uint32_t count : HistoPyramid::CountCrossings(volume.Data, volume.Dims, values))
      {
        total += count;
      }
    });
  return static_cast<double>(total);
}

} // namespace web
} // namespace mediso
