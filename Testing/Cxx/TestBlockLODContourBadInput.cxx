// SPDX-License-Identifier: BSD-3-Clause
// Bad input to vtkBlockLODContour, one case per ctest test (the case name is
// the argument): each must give exactly the expected error or warning and an
// empty (or finite) output, never a crash. The DefaultArray cases check what
// is contoured when ContourBy is unset (no message then).
#include "vtkBlockLODContour.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkCellData.h"
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
#include <limits>
#include <string>

namespace
{
int CheckFinite(vtkPolyData* out)
{
  vtkDataArray* normals = out->GetPointData()->GetNormals();
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    double x[3], n[3] = { 0, 0, 0 };
    out->GetPoint(i, x);
    if (normals)
    {
      normals->GetTuple(i, n);
    }
    for (int c = 0; c < 3; ++c)
    {
      if (!std::isfinite(x[c]) || !std::isfinite(n[c]))
      {
        std::printf("FAILED: non-finite output point or normal %lld\n", static_cast<long long>(i));
        return 1;
      }
    }
  }
  return 0;
}

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

int Count(const std::string& text, const std::string& word)
{
  int n = 0;
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1))
  {
    ++n;
  }
  return n;
}

// The phantom as float (to hold NaN and infinities), named "HU", active.
vtkSmartPointer<vtkImageData> FloatPhantom(int n)
{
  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(n, n, n);
  phantom->Update();
  vtkNew<vtkFloatArray> s;
  s->DeepCopy(phantom->GetOutput()->GetPointData()->GetScalars());
  s->SetName("HU");
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->CopyStructure(phantom->GetOutput());
  image->GetPointData()->SetScalars(s);
  return image;
}

// Runs the filter on `image`; checks the message and the output. `arrayName`
// (when not null) is what ContourBy sets: "" is ParaView's unset property.
int Expect(vtkImageData* image, double iso, const char* kind, const char* needle,
  bool allowOutput = false, double budget = -1, const char* arrayName = nullptr)
{
  vtkNew<vtkBlockLODContour> lod;
  vtkNew<vtkTest::ErrorObserver> observer;
  lod->AddObserver(vtkCommand::ErrorEvent, observer);
  lod->AddObserver(vtkCommand::WarningEvent, observer);
  lod->SetInputData(image);
  lod->SetValue(0, iso);
  if (arrayName)
  {
    lod->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, arrayName);
  }
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
  // One message, saying the one thing that is wrong.
  if (Count(message, isError ? "ERROR: In" : "Warning: In") != 1 ||
    (isError ? observer->GetWarning() : observer->GetError()))
  {
    std::printf("FAILED: expected exactly one %s and nothing else\n", kind);
    ++failures;
  }
  vtkPolyData* out = lod->GetOutput();
  if (!allowOutput && out->GetNumberOfPoints() != 0)
  {
    std::printf("FAILED: output should be empty, has %lld points\n",
      static_cast<long long>(out->GetNumberOfPoints()));
    ++failures;
  }
  return failures + CheckFinite(out);
}

// Runs the filter with ContourBy unset as ParaView leaves it (an empty name)
// and as a C++ caller leaves it (the active scalars attribute); both must
// contour `expected` without a message, as naming it would.
int ExpectDefaultArray(vtkImageData* image, double iso, const char* expected)
{
  int failures = 0;
  vtkNew<vtkBlockLODContour> named;
  named->SetInputData(image);
  named->SetValue(0, iso);
  named->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, expected);
  named->Update();
  const vtkIdType triangles = named->GetOutput()->GetNumberOfPolys();
  for (bool paraview : { true, false })
  {
    vtkNew<vtkBlockLODContour> lod;
    vtkNew<vtkTest::ErrorObserver> observer;
    lod->AddObserver(vtkCommand::ErrorEvent, observer);
    lod->AddObserver(vtkCommand::WarningEvent, observer);
    lod->SetInputData(image);
    lod->SetValue(0, iso);
    if (paraview)
    {
      lod->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "");
    }
    lod->Update();
    const vtkIdType got = lod->GetOutput()->GetNumberOfPolys();
    std::printf("ContourBy unset (%s): %lld triangles; naming '%s': %lld\n",
      paraview ? "ParaView's empty name" : "C++ default", static_cast<long long>(got), expected,
      static_cast<long long>(triangles));
    if (observer->GetError() || observer->GetWarning() || got == 0 || got != triangles)
    {
      std::printf("FAILED: with ContourBy unset the filter should contour '%s' silently\n",
        expected);
      ++failures;
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
    auto image = FloatPhantom(40);
    vtkFloatArray* s = vtkFloatArray::SafeDownCast(image->GetPointData()->GetScalars());
    for (vtkIdType i = 0; i < s->GetNumberOfTuples(); i += 37)
    {
      s->SetValue(i, std::nanf(""));
    }
    // A partial surface is expected: holes around NaNs, no NaN points.
    return Expect(image, -500, "warning", "NaN values", /*allowOutput=*/true);
  }
  if (which == "InfiniteValues")
  {
    // +inf and -inf voxels: treated like NaN, one warning for several
    // updates, only finite points and normals, and the same surface as NaN there.
    auto image = FloatPhantom(40);
    auto nans = FloatPhantom(40);
    vtkFloatArray* s = vtkFloatArray::SafeDownCast(image->GetPointData()->GetScalars());
    vtkFloatArray* n = vtkFloatArray::SafeDownCast(nans->GetPointData()->GetScalars());
    const float inf = std::numeric_limits<float>::infinity();
    for (vtkIdType i = 0; i < s->GetNumberOfTuples(); i += 37)
    {
      s->SetValue(i, (i / 37) % 2 ? inf : -inf);
      n->SetValue(i, std::nanf(""));
    }
    vtkNew<vtkBlockLODContour> lod;
    vtkNew<vtkTest::ErrorObserver> observer;
    lod->AddObserver(vtkCommand::ErrorEvent, observer);
    lod->AddObserver(vtkCommand::WarningEvent, observer);
    lod->SetInputData(image);
    vtkNew<vtkBlockLODContour> reference;
    reference->AddObserver(vtkCommand::WarningEvent, vtkNew<vtkTest::ErrorObserver>());
    reference->SetInputData(nans);
    int failures = 0;
    for (double iso : { -500.0, 400.0 })
    {
      for (int level : { 0, 3 })
      {
        lod->SetValue(0, iso);
        lod->SetLOD(level);
        lod->Update();
        reference->SetValue(0, iso);
        reference->SetLOD(level);
        reference->Update();
        failures += CheckFinite(lod->GetOutput());
        const vtkIdType got = lod->GetOutput()->GetNumberOfPolys();
        std::printf("iso %g level %d: %lld triangles with infinities, %lld with NaN there\n", iso,
          level, static_cast<long long>(got),
          static_cast<long long>(reference->GetOutput()->GetNumberOfPolys()));
        if (got == 0 || got != reference->GetOutput()->GetNumberOfPolys())
        {
          std::printf("FAILED: infinite voxels should cut the surface as NaN voxels do\n");
          ++failures;
        }
      }
    }
    const std::string message = observer->GetWarningMessage();
    std::printf("warning reported: %s\n", message.substr(message.find(')') + 1).c_str());
    if (Count(message, "Warning: In") != 1 || message.find("infinite values") == std::string::npos ||
      observer->GetError())
    {
      std::printf("FAILED: expected one warning about infinite values over four updates\n");
      ++failures;
    }
    return failures;
  }
  if (which == "AllNaN")
  {
    vtkNew<vtkFloatArray> s;
    auto image = Image(20, 20, 20, s);
    s->FillValue(std::nanf(""));
    return Expect(image, 10, "warning", "no finite values");
  }
  if (which == "DefaultArrayActive")
  {
    // ParaView leaves ContourBy empty: the active scalars are contoured, not
    // the other one-component array.
    auto image = FloatPhantom(40);
    vtkNew<vtkFloatArray> other;
    other->SetName("Other");
    other->SetNumberOfTuples(image->GetNumberOfPoints());
    other->FillValue(1.0f);
    image->GetPointData()->AddArray(other);
    return ExpectDefaultArray(image, 400, "HU");
  }
  if (which == "DefaultArrayOnly")
  {
    // No active scalars; one one-component array among others: that one.
    auto phantom = FloatPhantom(40);
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->CopyStructure(phantom);
    vtkNew<vtkFloatArray> velocity;
    velocity->SetName("Velocity");
    velocity->SetNumberOfComponents(3);
    velocity->SetNumberOfTuples(image->GetNumberOfPoints());
    velocity->FillValue(0.0f);
    image->GetPointData()->AddArray(velocity);
    vtkDataArray* hu = phantom->GetPointData()->GetScalars();
    hu->SetName("Density");
    image->GetPointData()->AddArray(hu);
    return ExpectDefaultArray(image, 400, "Density");
  }
  if (which == "OnlyArrayThreeComponents")
  {
    vtkNew<vtkFloatArray> s;
    s->SetName("Velocity");
    s->SetNumberOfComponents(3);
    auto image = Image(20, 20, 20, nullptr);
    s->SetNumberOfTuples(image->GetNumberOfPoints());
    s->FillValue(1.0f);
    image->GetPointData()->AddArray(s);
    return Expect(image, 10, "error", "the input's only point array, 'Velocity', has 3 components", false, -1, "");
  }
  if (which == "SeveralArraysNoneActive")
  {
    auto image = Image(20, 20, 20, nullptr);
    for (const char* name : { "T1", "T2" })
    {
      vtkNew<vtkFloatArray> s;
      s->SetName(name);
      s->SetNumberOfTuples(image->GetNumberOfPoints());
      s->FillValue(1.0f);
      image->GetPointData()->AddArray(s);
    }
    return Expect(image, 10, "error", "several one-component point arrays and no active scalars "
                                      "(its point arrays: 'T1' (1 component), 'T2' (1 component))",
      false, -1, "");
  }
  if (which == "MissingArray")
  {
    auto image = FloatPhantom(20);
    return Expect(image, 10, "error",
      "names the point array 'Density', which the input does not have (its point array: 'HU' "
      "(1 component))",
      false, -1, "Density");
  }
  if (which == "CellArray")
  {
    auto image = FloatPhantom(20);
    vtkNew<vtkFloatArray> cells;
    cells->SetName("Label");
    cells->SetNumberOfTuples(image->GetNumberOfCells());
    cells->FillValue(1.0f);
    image->GetCellData()->AddArray(cells);
    return Expect(image, 10, "error", "'Label' is a cell array", false, -1, "Label");
  }
  if (which == "ZeroSpacing" || which == "NonFiniteSpacing")
  {
    auto image = FloatPhantom(20);
    image->SetSpacing(1.0, which == "ZeroSpacing" ? 0.0 : std::nan(""), 1.0);
    return Expect(image, 400, "error", "zero or non-finite component");
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
    // A turned or mirrored direction is placed (TestBlockLODContourOriented);
    // a sheared one is not a rotation and is refused.
    image->SetDirectionMatrix(1, 0.5, 0, 0, 1, 0, 0, 0, 1);
    return Expect(image, 10, "error", "is not orthonormal");
  }
  std::printf("FAILED: unknown case '%s'\n", which.c_str());
  return 1;
}
