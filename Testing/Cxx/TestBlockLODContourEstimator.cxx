// SPDX-License-Identifier: BSD-3-Clause
// The memory estimator and AutoLOD of vtkBlockLODContour:
// - predicted vs actual triangles and bytes per level are printed (sampled
//   estimate of a new isovalue, and scaled from another level);
// - the byte estimate of an extracted pair equals the output's real arrays;
// - across the paper's 95-isovalue sweep with AutoLOD, the output never
//   exceeds MemoryBudget, and the level is the highest that fits.
// Inputs: the phantom with noise (256x240x200) and the real CT when cached.
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

void Sweep(const std::string& label, vtkImageData* image)
{
  vtkNew<vtkTrivialProducer> producer;
  producer->SetOutput(image);
  double range[2];
  image->GetPointData()->GetScalars()->GetRange(range);

  // Estimates against actual counts for a few isovalues at every level.
  std::printf("%s: sampled estimate (read before any level is extracted) vs actual\n",
    label.c_str());
  std::printf("  %8s %5s %12s %12s %8s %10s %10s\n", "iso", "level", "estimated", "actual",
    "error %", "est. MB", "actual MB");
  int within = 0, counted = 0;
  for (int n = 1; n <= 5; ++n)
  {
    const double iso = range[0] + (range[1] - range[0]) * n / 6.0 + 0.5;
    vtkNew<vtkBlockLODContour> lod;
    lod->SetInputConnection(producer->GetOutputPort());
    lod->SetValue(0, iso);
    lod->SetLOD(0);
    lod->Update(); // block ranges; sampled estimates for every level of this isovalue
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
      }
      // Once extracted, the estimate of the pair is exact, bytes included.
      Check(std::fabs(lod->EstimateTriangles(iso, level) - actual) < 0.5,
        label + ": estimate of an extracted pair is exact");
      Check(std::fabs(lod->EstimateMegabytes(iso, level) - actualMB) <= 1e-6 + 1e-9 * actualMB,
        label + ": byte estimate of an extracted pair equals the output's arrays");
    }
  }
  std::printf("  %d of %d pairs with >= 1000 triangles within +-10%%\n", within, counted);

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

  const std::string ct = medical_test::DataFile("ct_head.mha");
  if (vtksys::SystemTools::FileExists(ct))
  {
    vtkNew<vtkMetaImageReader> reader;
    reader->SetFileName(ct.c_str());
    reader->Update();
    Sweep("real CT", reader->GetOutput());
  }
  else
  {
    std::printf("real CT not cached (%s): phantom only\n", ct.c_str());
  }
  return medical_test::Finish("vtkBlockLODContour estimator: all checks passed");
}
