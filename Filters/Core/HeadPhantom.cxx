// SPDX-License-Identifier: BSD-3-Clause
#include "HeadPhantom.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace mediso
{
namespace
{
// The default head. Coordinates: x left-right, y posterior-anterior,
// z inferior-superior, all in [-1, 1]. Order matters: later regions are
// painted over earlier ones (the brain inside the skull, the orbits carved
// into the skull by the eyes).
std::vector<PhantomEllipsoid> MakeDefaultHead()
{
  using HU = PhantomHU;
  return {
    { "scalp", { 0.0, 0.0, -0.05 }, { 0.74, 0.90, 0.94 }, HU::Scalp },
    { "lower face", { 0.0, 0.22, -0.50 }, { 0.52, 0.60, 0.32 }, HU::Scalp },
    { "nose", { 0.0, 0.84, -0.22 }, { 0.07, 0.11, 0.15 }, HU::Scalp },
    { "neck", { 0.0, -0.05, -1.05 }, { 0.42, 0.46, 0.50 }, HU::Scalp },
    { "vertebra", { 0.0, -0.22, -1.02 }, { 0.11, 0.11, 0.42 }, HU::Vertebra },
    // The mandible: a bone slab hollowed from behind by soft tissue, leaving
    // a U open towards the neck.
    { "mandible", { 0.0, 0.34, -0.60 }, { 0.42, 0.40, 0.08 }, HU::Bone },
    { "floor of mouth", { 0.0, 0.25, -0.60 }, { 0.35, 0.40, 0.20 }, HU::Scalp },
    { "skull", { 0.0, 0.0, -0.02 }, { 0.68, 0.84, 0.84 }, HU::Bone },
    { "csf", { 0.0, 0.0, -0.02 }, { 0.61, 0.77, 0.77 }, HU::CSF },
    { "brain", { 0.0, 0.0, -0.02 }, { 0.59, 0.75, 0.75 }, HU::Brain },
    { "left ventricle", { -0.10, 0.0, 0.10 }, { 0.06, 0.28, 0.12 }, HU::CSF },
    { "right ventricle", { 0.10, 0.0, 0.10 }, { 0.06, 0.28, 0.12 }, HU::CSF },
    { "left eye", { -0.26, 0.70, -0.28 }, { 0.10, 0.10, 0.10 }, HU::Eye },
    { "right eye", { 0.26, 0.70, -0.28 }, { 0.10, 0.10, 0.10 }, HU::Eye },
    { "lesion", { 0.25, -0.30, 0.35 }, { 0.09, 0.08, 0.10 }, HU::Lesion },
    { "calcification", { -0.20, -0.35, 0.25 }, { 0.035, 0.035, 0.035 }, HU::Calcification },
  };
}

// Smallest blend half-width, in normalised units (about 1.4 mm on a 240 mm head).
constexpr double MinimumHalfWidth = 0.012;
// Blend half-width in grid steps on coarse grids, against aliasing.
constexpr double HalfWidthInSteps = 1.5;
// Guard band around the closed-form spans so that a voxel assigned directly
// (coverage exactly 0 or 1) is one for which the exact formula agrees.
constexpr double SpanGuard = 1e-9;

double MinAxis(const PhantomEllipsoid& e)
{
  return std::min(e.Axes[0], std::min(e.Axes[1], e.Axes[2]));
}

// Coverage in [0, 1] of ellipsoid `e` at normalised point p, blended over a
// band of half-width w around its surface. The signed distance is estimated to
// first order as (r - 1) / |grad r|, with r the ellipsoidal radius.
double Coverage(const PhantomEllipsoid& e, const double p[3], double w)
{
  double q[3];
  double r2 = 0.0;
  double g2 = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    q[a] = (p[a] - e.Center[a]) / e.Axes[a];
    r2 += q[a] * q[a];
    const double ga = q[a] / e.Axes[a];
    g2 += ga * ga;
  }
  const double r = std::sqrt(r2);
  // At the centre the gradient vanishes; the point is as deep inside as it gets.
  const double d = g2 > 0.0 ? (r - 1.0) * r / std::sqrt(g2) : -MinAxis(e);
  double t = 0.5 - d / (2.0 * w);
  t = std::min(1.0, std::max(0.0, t));
  return t * t * (3.0 - 2.0 * t);
}

// Paint value e over v with coverage s. Full coverage assigns exactly, so the
// row evaluation (which assigns inside the span) and the point evaluation agree
// bit for bit.
inline void Paint(double& v, double s, double e)
{
  v = s >= 1.0 ? e : v + s * (e - v);
}

// splitmix64 finaliser: a cheap, well-mixed 64-bit hash.
std::uint64_t Mix(std::uint64_t x)
{
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
} // namespace

HeadPhantom::HeadPhantom(const int dimensions[3], double noiseStdDev, std::uint32_t seed)
  : NoiseStdDev(noiseStdDev)
  , Seed(seed)
  , Regions(MakeDefaultHead())
{
  std::copy(dimensions, dimensions + 3, this->Dimensions);
  this->HalfWidth = this->BlendWidth();
}

std::string HeadPhantom::Validate() const
{
  std::ostringstream msg;
  const int* d = this->Dimensions;
  if (d[0] < 2 || d[1] < 2 || d[2] < 2)
  {
    msg << "dimensions " << d[0] << " x " << d[1] << " x " << d[2]
        << " are invalid: the phantom is a 3D volume and needs at least 2 points along each axis";
    return msg.str();
  }
  const double points = static_cast<double>(d[0]) * d[1] * d[2];
  if (points > static_cast<double>(std::numeric_limits<std::int64_t>::max() / 4))
  {
    msg << "dimensions " << d[0] << " x " << d[1] << " x " << d[2]
        << " give more points than a 64-bit index can address";
    return msg.str();
  }
  if (!(this->NoiseStdDev >= 0.0) || !std::isfinite(this->NoiseStdDev))
  {
    msg << "noise standard deviation " << this->NoiseStdDev
        << " is invalid: it must be a finite number >= 0";
    return msg.str();
  }
  return std::string();
}

std::int64_t HeadPhantom::GetNumberOfPoints() const
{
  return static_cast<std::int64_t>(this->Dimensions[0]) * this->Dimensions[1] *
    this->Dimensions[2];
}

double HeadPhantom::BlendWidth() const
{
  const int minDim = std::max(2, std::min(this->Dimensions[0],
                                   std::min(this->Dimensions[1], this->Dimensions[2])));
  const double step = 2.0 / (minDim - 1);
  return std::max(MinimumHalfWidth, HalfWidthInSteps * step);
}

double HeadPhantom::ToNormalized(int index, int axis) const
{
  return -1.0 + 2.0 * index / (this->Dimensions[axis] - 1);
}

double HeadPhantom::Noise(int i, int j, int k) const
{
  if (this->NoiseStdDev <= 0.0)
  {
    return 0.0;
  }
  // Four 16-bit uniforms from one hash; their centred sum (Irwin-Hall, n = 4)
  // is close to Gaussian with variance 4/12, rescaled to unit variance.
  std::uint64_t h = Mix(static_cast<std::uint64_t>(this->Seed) * 0x100000001B3ull ^
    Mix((static_cast<std::uint64_t>(static_cast<std::uint32_t>(k)) << 42) ^
      (static_cast<std::uint64_t>(static_cast<std::uint32_t>(j)) << 21) ^
      static_cast<std::uint32_t>(i)));
  double sum = 0.0;
  for (int n = 0; n < 4; ++n, h >>= 16)
  {
    sum += static_cast<double>(h & 0xFFFFu) / 65536.0;
  }
  return (sum - 2.0) * std::sqrt(3.0) * this->NoiseStdDev;
}

std::int16_t HeadPhantom::Quantize(double value, int i, int j, int k) const
{
  const double v = std::nearbyint(value + this->Noise(i, j, k));
  return static_cast<std::int16_t>(std::min(32767.0, std::max(-32768.0, v)));
}

double HeadPhantom::EvaluateContinuous(double x, double y, double z) const
{
  const double p[3] = { x, y, z };
  double value = PhantomHU::Air;
  for (const auto& e : this->Regions)
  {
    Paint(value, Coverage(e, p, this->HalfWidth), e.Value);
  }
  return value;
}

std::int16_t HeadPhantom::EvaluatePoint(int i, int j, int k) const
{
  const double v =
    this->EvaluateContinuous(this->ToNormalized(i, 0), this->ToNormalized(j, 1), this->ToNormalized(k, 2));
  return this->Quantize(v, i, j, k);
}

void HeadPhantom::FillSlices(
  const int extent[6], int kBegin, int kEnd, std::int16_t* out, double* row) const
{
  const int i0 = extent[0];
  const int i1 = extent[1];
  const int nx = i1 - i0 + 1;
  const std::int64_t ny = extent[3] - extent[2] + 1;
  const double w = this->HalfWidth;
  // x = -1 + 2 i / (nx - 1)  <=>  i = (x + 1) (n - 1) / 2
  const double toIndex = 0.5 * (this->Dimensions[0] - 1);

  for (int k = kBegin; k < kEnd; ++k)
  {
    const double z = this->ToNormalized(k, 2);
    for (int j = extent[2]; j <= extent[3]; ++j)
    {
      const double y = this->ToNormalized(j, 1);
      std::fill(row, row + nx, PhantomHU::Air);
      for (const auto& e : this->Regions)
      {
        const double qy = (y - e.Center[1]) / e.Axes[1];
        const double qz = (z - e.Center[2]) / e.Axes[2];
        const double t = qy * qy + qz * qz;
        // Outside radius rOut the coverage is exactly 0, inside rIn exactly 1
        // (|d| >= |r - 1| * minAxis, see Coverage()).
        const double band = w / MinAxis(e);
        const double rOut = 1.0 + band + SpanGuard;
        const double rIn = 1.0 - band - SpanGuard;
        if (rOut * rOut <= t)
        {
          continue;
        }
        const double halfOut = e.Axes[0] * std::sqrt(rOut * rOut - t);
        const int lo = std::max(i0, static_cast<int>(std::ceil((e.Center[0] - halfOut + 1.0) * toIndex)));
        const int hi = std::min(i1, static_cast<int>(std::floor((e.Center[0] + halfOut + 1.0) * toIndex)));
        int inLo = hi + 1;
        int inHi = hi;
        if (rIn > 0.0 && rIn * rIn > t)
        {
          const double halfIn = e.Axes[0] * std::sqrt(rIn * rIn - t);
          inLo = std::max(lo, static_cast<int>(std::ceil((e.Center[0] - halfIn + 1.0) * toIndex)));
          inHi = std::min(hi, static_cast<int>(std::floor((e.Center[0] + halfIn + 1.0) * toIndex)));
          if (inLo > inHi)
          {
            inLo = hi + 1;
            inHi = hi;
          }
        }
        const double p0[2] = { y, z };
        auto blend = [&](int from, int to) {
          for (int i = from; i <= to; ++i)
          {
            const double p[3] = { this->ToNormalized(i, 0), p0[0], p0[1] };
            Paint(row[i - i0], Coverage(e, p, w), e.Value);
          }
        };
        blend(lo, inLo - 1);
        std::fill(row + (inLo - i0), row + (inHi + 1 - i0), e.Value);
        blend(inHi + 1, hi);
      }
      std::int16_t* dst = out + ((k - extent[4]) * ny + (j - extent[2])) * nx;
      for (int i = i0; i <= i1; ++i)
      {
        dst[i - i0] = this->Quantize(row[i - i0], i, j, k);
      }
    }
  }
}

} // namespace mediso
