// SPDX-License-Identifier: BSD-3-Clause
// Numeric test of vtkMedicalPhantomSource: requested extent, type, spacing and
// origin; identical output for any SMP backend and for any piece split; clear
// errors and empty output for bad parameters.
#include "MedicalTestUtilities.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSMPTools.h"
#include "vtkShortArray.h"
#include "vtkTestErrorObserver.h"

#include <cstdio>
#include <cstring>
#include <string>

#include <unistd.h>

namespace
{
using medical_test::Check;
// Copy of the source's output after a full update with the given backend.
vtkSmartPointer<vtkImageData> Generate(const char* backend, double noise)
{
  vtkSMPTools::SetBackend(backend);
  vtkNew<vtkMedicalPhantomSource> source;
  source->SetDimensions(45, 38, 33);
  source->SetNoiseStandardDeviation(noise);
  source->SetSeed(1234);
  source->Update();
  auto copy = vtkSmartPointer<vtkImageData>::New();
  copy->DeepCopy(source->GetOutput());
  return copy;
}

bool SameScalars(vtkImageData* a, vtkImageData* b)
{
  auto* sa = vtkShortArray::SafeDownCast(a->GetPointData()->GetScalars());
  auto* sb = vtkShortArray::SafeDownCast(b->GetPointData()->GetScalars());
  return sa && sb && sa->GetNumberOfValues() == sb->GetNumberOfValues() &&
    std::memcmp(sa->GetPointer(0), sb->GetPointer(0), sizeof(short) * sa->GetNumberOfValues()) == 0;
}

void TestGeometryAndType()
{
  vtkNew<vtkMedicalPhantomSource> source;
  source->SetDimensions(33, 47, 21);
  source->SetSpacing(0.5, 0.75, 2.0);
  source->SetOrigin(-10.0, 5.0, 100.0);
  source->Update();
  vtkImageData* out = source->GetOutput();
  int ext[6];
  out->GetExtent(ext);
  Check(ext[0] == 0 && ext[1] == 32 && ext[2] == 0 && ext[3] == 46 && ext[4] == 0 && ext[5] == 20,
    "extent matches the requested dimensions");
  double bounds[6];
  out->GetBounds(bounds);
  Check(bounds[0] == -10.0 && bounds[1] == -10.0 + 32 * 0.5 && bounds[2] == 5.0 &&
      bounds[3] == 5.0 + 46 * 0.75 && bounds[4] == 100.0 && bounds[5] == 140.0,
    "bounds follow spacing and origin");
  vtkDataArray* scalars = out->GetPointData()->GetScalars();
  Check(scalars && scalars->GetDataType() == VTK_SHORT && scalars->GetNumberOfComponents() == 1,
    "scalars are one-component int16");
  Check(scalars && std::string(scalars->GetName()) == "HU", "scalars are named HU");
  double range[2] = { 0, 0 };
  if (scalars)
  {
    scalars->GetRange(range);
  }
  Check(range[0] == -1000.0 && range[1] > 400.0, "range spans air to bone");
  vtkDataArray* pid = out->GetFieldData()->GetArray("ProducerProcessId");
  Check(pid && pid->GetTuple1(0) == static_cast<double>(getpid()), "producer process id recorded");
}

void TestBackendsAgree()
{
  auto sequential = Generate("Sequential", 20.0);
  auto threaded = Generate("STDThread", 20.0);
  Check(SameScalars(sequential, threaded), "Sequential and STDThread backends give the same volume");
  Check(!SameScalars(threaded, Generate("STDThread", 0.0)), "noise changes the volume");
}

void TestPiecesJoin()
{
  vtkNew<vtkMedicalPhantomSource> source;
  source->SetDimensions(45, 38, 33);
  source->SetNoiseStandardDeviation(20.0);
  source->SetSeed(1234);
  source->Update();
  vtkImageData* whole = source->GetOutput();
  vtkNew<vtkImageData> wholeCopy;
  wholeCopy->DeepCopy(whole);

  // Three pieces, as an MPI run would request them: each is generated alone
  // and must equal the whole volume on its extent.
  const int pieces = 3;
  for (int piece = 0; piece < pieces; ++piece)
  {
    source->UpdatePiece(piece, pieces, 0);
    vtkImageData* part = source->GetOutput();
    int ext[6];
    part->GetExtent(ext);
    int mismatches = 0;
    for (int k = ext[4]; k <= ext[5]; ++k)
      for (int j = ext[2]; j <= ext[3]; ++j)
        for (int i = ext[0]; i <= ext[1]; ++i)
          mismatches += part->GetScalarComponentAsDouble(i, j, k, 0) !=
            wholeCopy->GetScalarComponentAsDouble(i, j, k, 0);
    Check(part->GetNumberOfPoints() < wholeCopy->GetNumberOfPoints(), "a piece is a part of the volume");
    Check(mismatches == 0, "piece " + std::to_string(piece) + " equals the whole volume on its extent");
  }
}

// Each bad parameter set must raise exactly a clear error and give an empty output.
void TestBadInput(const char* label, int nx, int ny, int nz, double spacing, const char* expected,
  double memoryLimitMB = 0.0)
{
  vtkNew<vtkMedicalPhantomSource> source;
  source->SetMemoryLimit(memoryLimitMB);
  vtkNew<vtkTest::ErrorObserver> errors;
  source->AddObserver(vtkCommand::ErrorEvent, errors);
  source->SetDimensions(nx, ny, nz);
  source->SetSpacing(spacing, spacing, spacing);
  source->Update();
  Check(errors->GetError(), std::string(label) + ": an error is reported");
  const std::string message = errors->GetErrorMessage();
  Check(message.find(expected) != std::string::npos,
    std::string(label) + ": message mentions '" + expected + "' (got: " + message + ")");
  Check(source->GetOutput()->GetNumberOfPoints() == 0, std::string(label) + ": output is empty");
}
} // namespace

int TestMedicalPhantomSource(int, char*[])
{
  TestGeometryAndType();
  TestBackendsAgree();
  TestPiecesJoin();
  TestBadInput("zero dimension", 0, 64, 64, 1.0, "at least 2 points");
  TestBadInput("negative dimension", 64, -3, 64, 1.0, "at least 2 points");
  TestBadInput("2D request", 64, 64, 1, 1.0, "3D volume");
  TestBadInput("absurd size", 100000, 100000, 100000, 1.0, "MB");
  // The output (17.2 GB) fits a 20 GB limit; a row of 2^31 doubles per
  // thread (17.2 GB each) does not: the check must count it.
  TestBadInput("row scratch", 2147483647, 2, 2, 1.0, "a row of 2147483647 doubles", 20000.0);
  TestBadInput("negative spacing", 16, 16, 16, -1.0, "spacing");
  return medical_test::Finish("vtkMedicalPhantomSource: all checks passed");
}
