// SPDX-License-Identifier: BSD-3-Clause
// vtkMedicalPhantomSource under an address-space limit (`ulimit -v`) the test
// sets on itself: a phantom larger than what the process may still allocate
// is refused with one error naming that limit and an empty output, whatever
// MemoryLimit says above it; a MemoryLimit below it still binds; a small
// phantom is still generated, value for value as without the limit.
#include "AddressSpaceLimit.h"
#include "MedicalTestUtilities.h"
#include "vtkMedicalPhantomSource.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkShortArray.h"

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;

struct Run
{
  std::vector<std::string> Errors;
  vtkSmartPointer<vtkImageData> Output;
};

// Generates a phantom of `n`^3 points, capturing its errors.
Run Generate(int n, double memoryLimitMB)
{
  Run run;
  vtkNew<vtkMedicalPhantomSource> source;
  vtkNew<vtkCallbackCommand> command;
  command->SetClientData(&run.Errors);
  command->SetCallback(
    [](vtkObject*, unsigned long, void* clientData, void* callData)
    {
      std::string text = callData ? static_cast<const char*>(callData) : "";
      const std::size_t at = text.find("Cannot generate");
      text = at == std::string::npos ? text : text.substr(at);
      while (!text.empty() && text.back() == '\n')
      {
        text.pop_back();
      }
      static_cast<std::vector<std::string>*>(clientData)->push_back(text);
    });
  source->AddObserver(vtkCommand::ErrorEvent, command);
  source->AddObserver(vtkCommand::WarningEvent, command);
  source->SetDimensions(n, n, n);
  source->SetMemoryLimit(memoryLimitMB);
  source->Update();
  run.Output = vtkSmartPointer<vtkImageData>::New();
  run.Output->DeepCopy(source->GetOutput());
  return run;
}

bool EndsWith(const std::string& text, const std::string& end)
{
  return text.size() >= end.size() && text.compare(text.size() - end.size(), end.size(), end) == 0;
}

void ExpectRefused(const char* label, const Run& run, const std::string& limit)
{
  const std::string start = "Cannot generate the phantom: dimensions 512 x 512 x 512 need 268.";
  const std::string end = " MB (" + limit + "). The output is empty.";
  Check(
    run.Errors.size() == 1 && run.Errors[0].rfind(start, 0) == 0 && EndsWith(run.Errors[0], end),
    std::string(label) + ": one error \"" + start + "...more than ..." + end + "\"; got " +
      std::to_string(run.Errors.size()) + ": " + (run.Errors.empty() ? "" : run.Errors[0]));
  Check(run.Output->GetNumberOfPoints() == 0, std::string(label) + ": the output is empty");
  std::printf("%s: %s\n", label, run.Errors.empty() ? "(no error)" : run.Errors[0].c_str());
}
} // namespace

int TestMedicalPhantomSourceMemory(int, char*[])
{
  const Run before = Generate(24, 0.0);
  Check(before.Errors.empty() && before.Output->GetNumberOfPoints() == 24 * 24 * 24,
    "without a limit, a 24^3 phantom is generated");

  // Limit the address space to what is mapped now plus 64 MiB.
  const medical_test::AddressSpaceLimit limit(64ULL << 20);
  Check(limit.IsSet(), "address-space limit set");

  // 512^3 int16 points are 268.4 MB: more than the process may allocate.
  const std::string addressSpace =
    "what the process may still allocate: the process's address-space limit (ulimit -v)";
  ExpectRefused("MemoryLimit 0", Generate(512, 0.0), addressSpace);
  ExpectRefused("MemoryLimit 100 GB, above the allowance", Generate(512, 1.0e5), addressSpace);
  ExpectRefused(
    "MemoryLimit 1 MB, below the allowance", Generate(512, 1.0), "the MemoryLimit property");

  const Run after = Generate(24, 0.0);
  auto* a = vtkShortArray::SafeDownCast(before.Output->GetPointData()->GetScalars());
  auto* b = vtkShortArray::SafeDownCast(after.Output->GetPointData()->GetScalars());
  Check(after.Errors.empty() && a && b && a->GetNumberOfValues() == b->GetNumberOfValues() &&
      std::memcmp(a->GetPointer(0), b->GetPointer(0), sizeof(short) * a->GetNumberOfValues()) == 0,
    "under the limit, a 24^3 phantom is generated as before");
  return medical_test::Finish("vtkMedicalPhantomSource: the address-space limit binds");
}
