// SPDX-License-Identifier: BSD-3-Clause
// Unit test of the VTK-free phantom core (Filters/Core/HeadPhantom). Builds
// and runs without VTK or ParaView.
#include "MedicalTestUtilities.h"
#include "HeadPhantom.h"

#include <cmath>
#include <cstdio>
#include <vector>

namespace
{
using medical_test::Check;
std::vector<std::int16_t> Fill(const mediso::HeadPhantom& p, const int ext[6])
{
  const int nx = ext[1] - ext[0] + 1;
  const std::size_t n = static_cast<std::size_t>(nx) * (ext[3] - ext[2] + 1) * (ext[5] - ext[4] + 1);
  std::vector<std::int16_t> out(n);
  std::vector<double> row(nx);
  p.FillSlices(ext, ext[4], ext[5] + 1, out.data(), row.data());
  return out;
}

void TestValidation()
{
  const int good[3] = { 32, 32, 32 };
  Check(mediso::HeadPhantom(good, 0.0, 1).Validate().empty(), "32^3 is valid");
  const int bad[][3] = { { 0, 32, 32 }, { 32, -4, 32 }, { 32, 32, 1 }, { -1, -1, -1 } };
  for (const auto& d : bad)
  {
    Check(!mediso::HeadPhantom(d, 0.0, 1).Validate().empty(), "degenerate dimensions rejected");
  }
  const int huge[3] = { 2000000000, 2000000000, 2000000000 };
  Check(!mediso::HeadPhantom(huge, 0.0, 1).Validate().empty(), "overflowing dimensions rejected");
  Check(!mediso::HeadPhantom(good, -1.0, 1).Validate().empty(), "negative noise rejected");
  Check(!mediso::HeadPhantom(good, std::nan(""), 1).Validate().empty(), "NaN noise rejected");
}

void TestRowsMatchPoints()
{
  // Odd, unequal sizes so that no axis is special; with noise.
  const int dims[3] = { 37, 44, 29 };
  const mediso::HeadPhantom p(dims, 12.5, 7);
  const int ext[6] = { 0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1 };
  const auto whole = Fill(p, ext);
  int mismatches = 0;
  std::size_t idx = 0;
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i, ++idx)
        mismatches += whole[idx] != p.EvaluatePoint(i, j, k);
  Check(mismatches == 0, "row evaluation equals point evaluation everywhere");

  // A sub-extent holds exactly the whole grid's values (pieces join seamlessly).
  const int sub[6] = { 5, 30, 11, 40, 3, 20 };
  const auto part = Fill(p, sub);
  mismatches = 0;
  idx = 0;
  for (int k = sub[4]; k <= sub[5]; ++k)
    for (int j = sub[2]; j <= sub[3]; ++j)
      for (int i = sub[0]; i <= sub[1]; ++i, ++idx)
        mismatches += part[idx] != whole[(static_cast<std::size_t>(k) * dims[1] + j) * dims[0] + i];
  Check(mismatches == 0, "sub-extent equals the whole grid there");
}

void TestTissues()
{
  const int dims[3] = { 128, 128, 128 };
  const mediso::HeadPhantom p(dims, 0.0, 1);
  using HU = mediso::PhantomHU;
  Check(p.EvaluateContinuous(-0.99, -0.99, 0.99) == HU::Air, "corner is air");
  Check(p.EvaluateContinuous(0.0, 0.3, -0.3) == HU::Brain, "deep brain is brain");
  Check(p.EvaluateContinuous(0.0, 0.0, 0.78) > 0.9 * HU::Bone, "top of the skull is bone");
  Check(p.EvaluateContinuous(0.0, 0.0, 0.86) == HU::Scalp, "above the skull is scalp");
  Check(std::fabs(p.EvaluateContinuous(-0.1, 0.0, 0.1) - HU::CSF) < 1e-9, "ventricle is CSF");
  // Smoothness: a step of 1e-4 never changes the field by more than the
  // largest tissue contrast times the slope bound of the blend.
  double worst = 0.0;
  for (double z = -1.0; z <= 1.0; z += 0.001)
  {
    worst = std::max(worst, std::fabs(p.EvaluateContinuous(0.0, 0.1, z + 1e-4) - p.EvaluateContinuous(0.0, 0.1, z)));
  }
  Check(worst < 20.0, "field is continuous along a line through the head");
}

void TestNoise()
{
  const int dims[3] = { 64, 64, 64 };
  const double sigma = 25.0;
  const mediso::HeadPhantom a(dims, sigma, 42);
  const mediso::HeadPhantom b(dims, sigma, 42);
  const mediso::HeadPhantom c(dims, sigma, 43);
  int same = 0;
  int differ = 0;
  double sum = 0.0;
  double sum2 = 0.0;
  int n = 0;
  // Air in the corner block: the noise-free value there is exactly -1000.
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 64; ++i)
      {
        const int va = a.EvaluatePoint(i, j, k);
        same += va == b.EvaluatePoint(i, j, k);
        differ += va != c.EvaluatePoint(i, j, k);
        const double e = va - mediso::PhantomHU::Air;
        sum += e;
        sum2 += e * e;
        ++n;
      }
  Check(same == n, "same seed, same noise");
  Check(differ > n / 2, "another seed, other noise");
  const double mean = sum / n;
  const double sd = std::sqrt(sum2 / n - mean * mean);
  std::printf("noise: requested sigma %.2f, measured mean %.3f sigma %.3f over %d samples\n", sigma, mean, sd, n);
  Check(std::fabs(mean) < 0.1 * sigma, "noise has zero mean");
  Check(std::fabs(sd - sigma) < 0.05 * sigma, "noise has the requested standard deviation");
}
} // namespace

int main()
{
  TestValidation();
  TestRowsMatchPoints();
  TestTissues();
  TestNoise();
  return medical_test::Finish("all phantom core checks passed");
}
