// SPDX-License-Identifier: BSD-3-Clause
// The memory estimator and AutoLOD of vtkBlockLODContour:
// - predicted vs actual triangles and bytes per level are printed (estimates
//   of a new isovalue after only level 0 was extracted), and at least 95% of
//   the pairs with 1000 or more triangles are within 10%, none under by more
//   (issue 24), on the phantom with noise, the real CT, the CT with noise, the
//   MRI, and a sparse high isovalue of each real scan;
// - the byte estimate of an extracted pair equals the output's real arrays;
// - across the paper's 95-isovalue sweep with AutoLOD, the output never
//   exceeds MemoryBudget, and the level is the highest that fits.
// Inputs: the phantom with noise (256x240x200); the real CT and MRI when cached.
#include "MedicalTestUtilities.h"
#include "vtkBlockLODContour.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkTestErrorObserver.h"
#include "vtkTrivialProducer.h"
#include <vtksys/SystemTools.hxx>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;
int Occurrences(const std::string& text, const std::string& word)
{
  int n = 0;
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1))
  {
    ++n;
  }
  return n;
}

// Bytes held by the output's arrays (what the estimate predicts).
double OutputBytes(vtkPolyData* pd)
{
  double bytes = 0;
  auto add = [&bytes](vtkDataArray* a) {
    if (a)
    {
      bytes += static_cast<double>(a->GetNumberOfValues()) * a->GetDataTypeSize();
    }
  };
  add(pd->GetPoints() ? pd->GetPoints()->GetData() : nullptr);
  add(pd->GetPointData()->GetNormals());
  add(pd->GetPolys()->GetConnectivityArray());
  add(pd->GetPolys()->GetOffsetsArray());
  return bytes;
}

// Adds seeded Gaussian noise (Box-Muller on std::mt19937, identical on every
// platform) to the image's scalars, rounded and clamped to the array's type.
void AddNoise(vtkImageData* image, double sigma, unsigned seed)
{
  vtkDataArray* a = image->GetPointData()->GetScalars();
  std::mt19937 rng(seed);
  const double lo = a->GetDataTypeMin(), hi = a->GetDataTypeMax();
  const double twoPi = 6.283185307179586;
  for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i)
  {
    const double u1 = (rng() + 1.0) / 4294967297.0, u2 = rng() / 4294967296.0;
    const double n = std::sqrt(-2.0 * std::log(u1)) * std::cos(twoPi * u2);
    a->SetTuple1(i, std::round(std::min(hi, std::max(lo, a->GetTuple1(i) + sigma * n))));
  }
  a->Modified();
}

// `extra`: isovalues beyond the five spread over the range (a sparse, high
// one); `autoLOD`: also run the 95-isovalue AutoLOD sweep.
void Sweep(const std::string& label, vtkImageData* image, const std::vector<double>& extra = {},
  bool autoLOD = true)
{
  vtkNew<vtkTrivialProducer> producer;
  producer->SetOutput(image);
  double range[2];
  image->GetPointData()->GetScalars()->GetRange(range);

  // Estimates against actual counts for a few isovalues at every level.
  std::printf("%s: estimate (read before the level is extracted; level 0 was) vs actual\n",
    label.c_str());
  std::printf("  %8s %5s %12s %12s %8s %10s %10s\n", "iso", "level", "estimated", "actual",
    "error %", "est. MB", "actual MB");
  std::vector<double> isovalues;
  for (int n = 1; n <= 5; ++n)
  {
    isovalues.push_back(range[0] + (range[1] - range[0]) * n / 6.0 + 0.5);
  }
  isovalues.insert(isovalues.end(), extra.begin(), extra.end());
  int within = 0, counted = 0, under = 0;
  for (double iso : isovalues)
  {
    vtkNew<vtkBlockLODContour> lod;
    lod->SetInputConnection(producer->GetOutputPort());
    lod->SetValue(0, iso);
    lod->SetLOD(0);
    lod->Update(); // block ranges; estimates for every level of this isovalue
    double estimated[4], estimatedMB[4];
    lod->GetEstimatedTriangles(estimated);
    lod->GetEstimatedMegabytes(estimatedMB);
    for (int level = 0; level < 4; ++level)
    {
      lod->SetLOD(level);
      lod->Update();
      const double actual = static_cast<double>(lod->GetOutput()->GetNumberOfPolys());
      const double actualMB = OutputBytes(lod->GetOutput()) / 1e6;
      const double error = actual > 0 ? 100.0 * (estimated[level] - actual) / actual : 0.0;
      std::printf("  %8.1f %5d %12.0f %12.0f %8.2f %10.3f %10.3f\n", iso, level, estimated[level],
        actual, error, estimatedMB[level], actualMB);
      if (actual >= 1000)
      {
        ++counted;
        within += std::fabs(error) <= 10.0;
        under += error < -10.0;
      }
      // Once extracted, the estimate of the pair is exact, bytes included.
      Check(std::fabs(lod->EstimateTriangles(iso, level) - actual) < 0.5,
        label + ": estimate of an extracted pair is exact");
      Check(std::fabs(lod->EstimateMegabytes(iso, level) - actualMB) <= 1e-6 + 1e-9 * actualMB,
        label + ": byte estimate of an extracted pair equals the output's arrays");
    }
  }
  std::printf("  %d of %d pairs with >= 1000 triangles within +-10%%, %d under by more\n", within,
    counted, under);
  // Issue 24: within 10% for at least 95% of the pairs, never under by more.
  Check(counted > 0 && within >= 0.95 * counted, label + ": 95% of the estimates within 10%");
  Check(under == 0, label + ": no estimate under the real count by more than 10%");
  if (!autoLOD)
  {
    return;
  }

  // The 95-isovalue sweep with AutoLOD: never over the budget.
  vtkNew<vtkBlockLODContour> lod;
  lod->SetInputConnection(producer->GetOutputPort());
  // A low estimate makes the filter drop a level with a warning: count them.
  vtkNew<vtkTest::ErrorObserver> warnings;
  lod->AddObserver(vtkCommand::WarningEvent, warnings);
  lod->AutoLODOn();
  const double budget = 8.0; // MB
  lod->SetMemoryBudget(budget);
  int levels[4] = { 0, 0, 0, 0 };
  double worst = 0;
  for (int n = 1; n <= 95; ++n)
  {
    const double iso = range[0] + (range[1] - range[0]) * n / 96.0;
    lod->SetValue(0, iso);
    lod->Update();
    const int level = lod->GetChosenLevel();
    const double mb = OutputBytes(lod->GetOutput()) / 1e6;
    worst = std::max(worst, mb);
    Check(mb <= budget, label + ": output within the budget at iso " + std::to_string(iso));
    if (level >= 0)
    {
      ++levels[level];
      // The level is the highest that fits: the next one up would not.
      if (level < 3)
      {
        Check(lod->EstimateMegabytes(iso, level + 1) > budget * 0.9,
          label + ": a higher level would not have fitted at iso " + std::to_string(iso));
      }
    }
  }
  std::printf("%s: 95-isovalue AutoLOD sweep, budget %.1f MB: largest output %.3f MB; levels "
              "chosen 0:%d 1:%d 2:%d 3:%d; fallbacks after a low estimate: %d\n",
    label.c_str(), budget, worst, levels[0], levels[1], levels[2], levels[3],
    Occurrences(warnings->GetWarningMessage(), "over the MemoryBudget"));
}
} // namespace

int TestBlockLODContourEstimator(int, char*[])
{
  vtkSMPTools::SetBackend("STDThread");
  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(256, 240, 200);
  phantom->SetNoiseStandardDeviation(20);
  phantom->Update();
  Sweep("phantom 256x240x200 noise 20", phantom->GetOutput());

  // The real scans when cached, and noisy and sparse stand-ins for scans the
  // project does not ship: the CT with 40 HU of noise (a low-dose scan), the
  // CT at 1500 HU (a thin, sparse surface of dense bone), the MRI (noisy
  // background) and its isovalue 200 (sparse bright structures).
  const std::string ct = medical_test::DataFile("ct_head.mha");
  const std::string mri = medical_test::DataFile("mri_head.mha");
  if (vtksys::SystemTools::FileExists(ct))
  {
    vtkNew<vtkMetaImageReader> reader;
    reader->SetFileName(ct.c_str());
    reader->Update();
    Sweep("real CT", reader->GetOutput(), { 1500.0 });
    vtkNew<vtkImageData> noisy;
    noisy->DeepCopy(reader->GetOutput());
    AddNoise(noisy, 40.0, 1);
    Sweep("real CT + noise 40 HU", noisy, { 1500.0 }, /*autoLOD=*/false);
  }
  else
  {
    std::printf("real CT not cached (%s)\n", ct.c_str());
  }
  if (vtksys::SystemTools::FileExists(mri))
  {
    vtkNew<vtkMetaImageReader> reader;
    reader->SetFileName(mri.c_str());
    reader->Update();
    Sweep("real MRI", reader->GetOutput(), { 200.0 }, /*autoLOD=*/false);
  }
  else
  {
    std::printf("real MRI not cached (%s)\n", mri.c_str());
  }
  return medical_test::Finish("vtkBlockLODContour estimator: all checks passed");
}
