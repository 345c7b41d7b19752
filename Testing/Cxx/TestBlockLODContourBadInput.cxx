// SPDX-License-Identifier: BSD-3-Clause
// Bad input to vtkBlockLODContour, one case per ctest test (the case name is
// the argument): each must give the expected error or warning and an empty
// (or NaN-free) output, never a crash.
#include "vtkBlockLODContour.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkTestErrorObserver.h"
#include "vtkTypeInt64Array.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace
{
vtkSmartPointer<vtkImageData> Image(int nx, int ny, int nz, vtkDataArray* scalars)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(nx, ny, nz);
  if (scalars)
  {
    scalars->SetNumberOfTuples(static_cast<vtkIdType>(nx) * ny * nz);
    for (vtkIdType i = 0; i < scalars->GetNumberOfTuples(); ++i)
    {
      for (int c = 0; c < scalars->GetNumberOfComponents(); ++c)
      {
        scalars->SetComponent(i, c, static_cast<double>(i % 97));
      }
    }
    image->GetPointData()->SetScalars(scalars);
  }
  return image;
}

// Runs the filter on `image`; checks the message and the output.
int Expect(vtkImageData* image, double iso, const char* kind, const char* needle,
  bool allowOutput = false, double budget = -1)
{
  vtkNew<vtkBlockLODContour> lod;
  vtkNew<vtkTest::ErrorObserver> observer;
  lod->AddObserver(vtkCommand::ErrorEvent, observer);
  lod->AddObserver(vtkCommand::WarningEvent, observer);
  lod->SetInputData(image);
  lod->SetValue(0, iso);
  if (budget >= 0)
  {
    lod->AutoLODOn();
    lod->SetMemoryBudget(budget);
  }
  lod->Update();
  const bool isError = std::strcmp(kind, "error") == 0;
  const bool got = isError ? observer->GetError() : observer->GetWarning();
  const std::string message = isError ? observer->GetErrorMessage() : observer->GetWarningMessage();
  // Echo the message body only: its "ERROR: In file, line" header would read
  // as a failure to ctest.
  const std::size_t body = message.find(')');
  std::printf("%s reported: %s\n", kind,
    body == std::string::npos ? message.c_str() : message.c_str() + body + 1);
  int failures = 0;
  if (!got || message.find(needle) == std::string::npos)
  {
    std::printf("FAILED: expected a %s mentioning '%s'\n", kind, needle);
    ++failures;
  }
  vtkPolyData* out = lod->GetOutput();
  if (!allowOutput && out->GetNumberOfPoints() != 0)
  {
    std::printf("FAILED: output should be empty, has %lld points\n",
      static_cast<long long>(out->GetNumberOfPoints()));
    ++failures;
  }
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    double x[3];
    out->GetPoint(i, x);
    if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
    {
      std::printf("FAILED: non-finite output point %lld\n", static_cast<long long>(i));
      ++failures;
      break;
    }
  }
  return failures;
}
} // namespace

int TestBlockLODContourBadInput(int argc, char* argv[])
{
  const std::string which = argc > 1 ? argv[1] : "";
  if (which == "NoScalars")
  {
    return Expect(Image(20, 20, 20, nullptr), 10, "error", "No point scalars");
  }
  if (which == "TwoDimensional")
  {
    vtkNew<vtkFloatArray> s;
    return Expect(Image(20, 20, 1, s), 10, "error", "3D image data");
  }
  if (which == "ThreeComponents")
  {
    vtkNew<vtkFloatArray> s;
    s->SetNumberOfComponents(3);
    return Expect(Image(20, 20, 20, s), 10, "error", "3 components");
  }
  if (which == "UnsupportedType")
  {
    vtkNew<vtkTypeInt64Array> s;
    return Expect(Image(20, 20, 20, s), 10, "error", "not supported");
  }
  if (which == "ConstantVolume")
  {
    vtkNew<vtkFloatArray> s;
    auto image = Image(20, 20, 20, s);
    s->FillValue(7.0f);
    return Expect(image, 7.0, "warning", "constant");
  }
  if (which == "NaNValues")
  {
    vtkNew<vtkMedicalPhantomSource> phantom;
    phantom->SetDimensions(40, 40, 40);
    phantom->Update();
    vtkNew<vtkFloatArray> s;
    s->DeepCopy(phantom->GetOutput()->GetPointData()->GetScalars());
    for (vtkIdType i = 0; i < s->GetNumberOfTuples(); i += 37)
    {
      s->SetValue(i, std::nanf(""));
    }
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->CopyStructure(phantom->GetOutput());
    image->GetPointData()->SetScalars(s);
    // A partial surface is expected: holes around NaNs, no NaN points.
    return Expect(image, -500, "warning", "NaN", /*allowOutput=*/true);
  }
  if (which == "IsovalueOutsideRange")
  {
    vtkNew<vtkFloatArray> s;
    return Expect(Image(20, 20, 20, s), 1000, "warning", "outside the data range");
  }
  if (which == "BudgetTooSmall")
  {
    vtkNew<vtkMedicalPhantomSource> phantom;
    phantom->SetDimensions(64, 64, 64);
    phantom->Update();
    return Expect(phantom->GetOutput(), 400, "error", "too small", false, /*budget MB=*/0.0001);
  }
  if (which == "DirectionMatrix")
  {
    vtkNew<vtkFloatArray> s;
    auto image = Image(20, 20, 20, s);
    image->SetDirectionMatrix(0, -1, 0, 1, 0, 0, 0, 0, 1);
    return Expect(image, 10, "error", "direction matrix");
  }
  std::printf("FAILED: unknown case '%s'\n", which.c_str());
  return 1;
}
