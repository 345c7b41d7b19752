// SPDX-License-Identifier: BSD-3-Clause
#include "VolumeSources.h"

#include "HeadPhantom.h"
#include "ThreadedFor.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <type_traits>
#include <vector>

namespace mediso
{
namespace headless
{
namespace
{
bool Allocate(MetaImage& image, std::string& error)
{
  const std::int64_t bytes = image.GetNumberOfPoints() * ScalarTypeSize(image.Type);
  try
  {
    image.Bytes.assign(static_cast<std::size_t>(bytes), 0);
  }
  catch (const std::bad_alloc&)
  {
    error = "cannot allocate " + std::to_string(bytes / 1000000) + " MB for the volume";
    return false;
  }
  return true;
}

template <typename T>
T Store(double v)
{
  if (std::is_floating_point<T>::value)
  {
    return static_cast<T>(v);
  }
  // Rounded half up and clamped, as vtkImageReslice's linear interpolation stores integers.
  const double r = std::floor(v + 0.5);
  const double lo = static_cast<double>(std::numeric_limits<T>::lowest());
  const double hi = static_cast<double>(std::numeric_limits<T>::max());
  return static_cast<T>(std::min(std::max(r, lo), hi));
}

/// Per output index along one axis: the lower input index and the weight of the upper one.
void AxisSamples(int in, int out, std::vector<int>& index, std::vector<double>& weight)
{
  index.resize(static_cast<std::size_t>(out));
  weight.resize(static_cast<std::size_t>(out));
  const double scale = static_cast<double>(in - 1) / static_cast<double>(out - 1);
  for (int i = 0; i < out; ++i)
  {
    const double x = std::min(static_cast<double>(i) * scale, static_cast<double>(in - 1));
    const int lo = std::min(static_cast<int>(std::floor(x)), in - 2);
    index[i] = lo;
    weight[i] = x - lo;
  }
}
} // namespace

bool ParsePhantomSpec(const std::string& spec, int& n, std::string& error)
{
  static const std::string prefix = "phantom:";
  if (spec.compare(0, prefix.size(), prefix) != 0)
  {
    return false;
  }
  const std::string digits = spec.substr(prefix.size());
  char* end = nullptr;
  const long value = std::strtol(digits.c_str(), &end, 10);
  if (digits.empty() || *end != '\0' || value < 2 || value > MaximumPhantomSize)
  {
    error = spec + ": the phantom's size N (phantom:N, N^3 points) must be a whole number from 2 to " +
      std::to_string(MaximumPhantomSize);
    return true;
  }
  n = static_cast<int>(value);
  return true;
}

bool MakePhantom(int n, MetaImage& image, std::string& error)
{
  const int dims[3] = { n, n, n };
  const HeadPhantom phantom(dims, 0.0, 1u);
  error = phantom.Validate();
  if (!error.empty())
  {
    return false;
  }
  image = MetaImage();
  std::copy(dims, dims + 3, image.Dimensions);
  const double h = 240.0 / (n - 1);
  std::fill(image.Spacing, image.Spacing + 3, h);
  image.Type = ScalarType::Int16;
  if (!Allocate(image, error))
  {
    return false;
  }
  std::int16_t* values = reinterpret_cast<std::int16_t*>(image.Bytes.data());
  const int extent[6] = { 0, n - 1, 0, n - 1, 0, n - 1 };
  ThreadedFor(0, n,
    [&](std::int64_t k0, std::int64_t k1)
    {
      std::vector<double> row(static_cast<std::size_t>(n));
      phantom.FillSlices(extent, static_cast<int>(k0), static_cast<int>(k1), values, row.data());
    });
  return true;
}

bool Resample(const MetaImage& input, const int dimensions[3], MetaImage& output, std::string& error)
{
  for (int a = 0; a < 3; ++a)
  {
    if (input.Dimensions[a] < 2 || dimensions[a] < 2)
    {
      error = "resampling needs at least 2 points per axis, in and out";
      return false;
    }
  }
  output = MetaImage();
  std::copy(dimensions, dimensions + 3, output.Dimensions);
  std::copy(input.Origin, input.Origin + 3, output.Origin);
  std::copy(input.Direction, input.Direction + 9, output.Direction);
  for (int a = 0; a < 3; ++a)
  {
    output.Spacing[a] =
      input.Spacing[a] * (input.Dimensions[a] - 1) / static_cast<double>(dimensions[a] - 1);
  }
  output.Type = input.Type;
  if (!Allocate(output, error))
  {
    return false;
  }
  std::vector<int> index[3];
  std::vector<double> weight[3];
  for (int a = 0; a < 3; ++a)
  {
    AxisSamples(input.Dimensions[a], dimensions[a], index[a], weight[a]);
  }
  VisitScalarType(input.Type,
    [&](auto tag)
    {
      using T = decltype(tag);
      const T* in = reinterpret_cast<const T*>(input.Bytes.data());
      T* out = reinterpret_cast<T*>(output.Bytes.data());
      const std::int64_t nx = input.Dimensions[0];
      const std::int64_t nxy = nx * input.Dimensions[1];
      const std::int64_t mx = dimensions[0], my = dimensions[1];
      ThreadedFor(0, dimensions[2],
        [&](std::int64_t k0, std::int64_t k1)
        {
          for (std::int64_t k = k0; k < k1; ++k)
          {
            const double wz = weight[2][k];
            for (std::int64_t j = 0; j < my; ++j)
            {
              const double wy = weight[1][j];
              const T* base = in + index[2][k] * nxy + index[1][j] * nx;
              T* row = out + (k * my + j) * mx;
              for (std::int64_t i = 0; i < mx; ++i)
              {
                const double wx = weight[0][i];
                const T* p = base + index[0][i];
                auto lerp = [wx](const T* q) {
                  return static_cast<double>(q[0]) + wx * (static_cast<double>(q[1]) - q[0]);
                };
                const double y0 = lerp(p) + wy * (lerp(p + nx) - lerp(p));
                const double y1 = lerp(p + nxy) + wy * (lerp(p + nxy + nx) - lerp(p + nxy));
                row[i] = Store<T>(y0 + wz * (y1 - y0));
              }
            }
          }
        });
    });
  return true;
}

} // namespace headless
} // namespace mediso
