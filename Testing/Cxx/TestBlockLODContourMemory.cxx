// SPDX-License-Identifier: BSD-3-Clause
// vtkBlockLODContour when the process may allocate less than the output needs,
// one case per ctest test (the case is the argument). The input is made and
// the exact output sizes measured first; then the test limits its own address
// space (RLIMIT_AS, as `ulimit -v` does) to what it maps plus a headroom, and
// runs the filter again:
// - Surface: the level-3 surface does not fit: one error naming it, its size
//   and the limit, an empty output, no abort;
// - Assembly: each of two surfaces fits, their merged output does not: one
//   error naming the output, an empty output;
// - AutoLOD: level 3 fits the MemoryBudget but not the process: level 2 is
//   made, with one warning saying what limited it.
// Only the allowance's megabytes vary from run to run: every other word and
// number of the message is checked.
#include "AddressSpaceLimit.h"
#include "vtkBlockLODContour.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPolyData.h"
#include "vtkTestErrorObserver.h"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace
{
int Failures = 0;
void Check(bool ok, const std::string& what)
{
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  Failures += ok ? 0 : 1;
}

std::string MB(double bytes)
{
  char text[64];
  std::snprintf(text, sizeof(text), "%.1f", bytes / 1.0e6);
  return text;
}

// The exact bytes of the filter's output for one isovalue at a level
// (EstimatedMB of the planned level is exact).
double OutputBytes(vtkImageData* image, double isovalue, int level)
{
  vtkNew<vtkBlockLODContour> lod;
  lod->SetInputData(image);
  lod->SetValue(0, isovalue);
  lod->SetLOD(level);
  lod->Update();
  return lod->GetEstimatedMegabytes()[level] * 1.0e6;
}

// The text of a message after VTK's "ERROR: In file, line N\nclass (address): ".
std::string Body(const std::string& message)
{
  const std::size_t at = message.find("): ");
  std::string body = at == std::string::npos ? message : message.substr(at + 3);
  while (!body.empty() && (body.back() == '\n' || body.back() == ' '))
  {
    body.pop_back();
  }
  return body;
}

// Checks that `body` is `before` + some megabytes + `after`, the megabytes
// below `most` (the headroom given, and a megabyte for what the process
// unmapped after the limit was set).
void CheckMessage(
  const std::string& body, const std::string& before, const std::string& after, double most)
{
  std::printf("message: %s\n", body.c_str());
  const bool framed = body.compare(0, before.size(), before) == 0 && body.size() > after.size() &&
    body.compare(body.size() - after.size(), after.size(), after) == 0 &&
    body.size() > before.size() + after.size();
  Check(framed, "the message reads '" + before + "<MB>" + after + "'");
  if (framed)
  {
    const std::string number =
      body.substr(before.size(), body.size() - before.size() - after.size());
    char* end = nullptr;
    const double allowed = std::strtod(number.c_str(), &end);
    Check(end && *end == '\0' && allowed >= 0 && allowed * 1.0e6 < most,
      "the allowance (" + number + " MB) is a number below " + MB(most) + " MB");
  }
}
} // namespace

int TestBlockLODContourMemory(int argc, char* argv[])
{
  const std::string which = argc > 1 ? argv[1] : "";
  vtkNew<vtkMedicalPhantomSource> phantom;
  phantom->SetDimensions(160, 160, 160);
  phantom->Update();
  vtkImageData* image = phantom->GetOutput();
  const char* limit = "the process's address-space limit (ulimit -v)";

  vtkNew<vtkBlockLODContour> lod;
  vtkNew<vtkTest::ErrorObserver> observer;
  lod->AddObserver(vtkCommand::ErrorEvent, observer);
  lod->AddObserver(vtkCommand::WarningEvent, observer);
  lod->SetInputData(image);
  lod->SetValue(0, 400.0);

  if (which == "Surface")
  {
    const double surface = OutputBytes(image, 400.0, 3);
    std::printf("level 3's surface: %s MB\n", MB(surface).c_str());
    medical_test::AddressSpaceLimit space(static_cast<unsigned long long>(0.5 * surface));
    Check(space.IsSet(), "address-space limit set");
    lod->SetLOD(3);
    lod->Update();
    // Given back once the filter has run: the checks need room of their own.
    Check(space.Restore(), "address-space limit restored");
    Check(observer->GetError() && !observer->GetWarning(), "one error, no warning");
    CheckMessage(Body(observer->GetErrorMessage()),
      "Level 3's surface of isovalue 400 (" + MB(surface) + " MB) does not fit in the ",
      std::string(" MB the process may still allocate (") + limit + "). The output is empty.",
      0.5 * surface + 1.0e6);
    Check(lod->GetChosenLevel() == -1, "no level was made");
  }
  else if (which == "Assembly")
  {
    const double first = OutputBytes(image, 400.0, 2);
    const double second = OutputBytes(image, -500.0, 2);
    const double both = first + second;
    std::printf("level 2's surfaces: %s + %s MB\n", MB(first).c_str(), MB(second).c_str());
    // The two surfaces fit, a second copy of both (the merged output) does not.
    medical_test::AddressSpaceLimit space(static_cast<unsigned long long>(1.8 * both));
    Check(space.IsSet(), "address-space limit set");
    lod->SetLOD(2);
    lod->SetValue(1, -500.0);
    lod->Update();
    // Given back once the filter has run: the checks need room of their own.
    Check(space.Restore(), "address-space limit restored");
    Check(observer->GetError() && !observer->GetWarning(), "one error, no warning");
    CheckMessage(Body(observer->GetErrorMessage()),
      "The output (" + MB(both) + " MB) does not fit in the ",
      std::string(" MB the process may still allocate (") + limit + "). The output is empty.",
      both + 1.0e6);
    Check(lod->GetChosenLevel() == -1, "no level was made");
  }
  else if (which == "AutoLOD")
  {
    const double level3 = OutputBytes(image, 400.0, 3);
    const double level2 = OutputBytes(image, 400.0, 2);
    std::printf("levels 3 and 2: %s and %s MB\n", MB(level3).c_str(), MB(level2).c_str());
    Check(4 * level2 < 3 * level3, "level 2 needs well under level 3's bytes");
    // Level 3 fits the budget, not the process; level 2 fits both.
    medical_test::AddressSpaceLimit space(static_cast<unsigned long long>(0.75 * level3));
    Check(space.IsSet(), "address-space limit set");
    lod->AutoLODOn();
    lod->SetMemoryBudget(256.0);
    lod->Update();
    // Given back once the filter has run: the checks need room of their own.
    Check(space.Restore(), "address-space limit restored");
    Check(observer->GetWarning() && !observer->GetError(), "one warning, no error");
    CheckMessage(Body(observer->GetWarningMessage()),
      "Level 3 fits the MemoryBudget of 256 MB but not the ",
      std::string(" MB the process may still allocate (") + limit + "): using level 2.",
      0.75 * level3 + 1.0e6);
    Check(lod->GetChosenLevel() == 2, "level 2 was made");
    vtkDataArray* levelField = lod->GetOutput()->GetFieldData()->GetArray("BlockLODLevel");
    Check(levelField && levelField->GetTuple1(0) == 2 && lod->GetOutput()->GetNumberOfPolys() > 0,
      "the output is level 2's surface");
    return Failures == 0 ? 0 : 1;
  }
  else
  {
    std::printf("FAILED: unknown case '%s'\n", which.c_str());
    return 1;
  }
  vtkPolyData* out = lod->GetOutput();
  Check(out->GetNumberOfPoints() == 0 && out->GetNumberOfCells() == 0, "the output is empty");
  return Failures == 0 ? 0 : 1;
}
