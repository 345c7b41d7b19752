// SPDX-License-Identifier: BSD-3-Clause
// ProcessMemoryAllowance() against limits the test sets on itself: an
// address-space limit (as `ulimit -v` sets it) binds below physical memory,
// and FitsInProcessMemory() refuses what exceeds it with a message naming it.
#include "AddressSpaceLimit.h"
#include "ProcessMemory.h"

#include <cstdio>
#include <string>

namespace
{
int failures = 0;
void Check(bool ok, const std::string& what)
{
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  failures += ok ? 0 : 1;
}
}

int main()
{
  const mediso::MemoryAllowance before = mediso::ProcessMemoryAllowance();
  Check(before.Bounded(), "a Linux host bounds the allowance (" + before.Limit + ")");
  Check(before.Bytes > 0, "some memory is allowed before any limit is set");

  std::string message;
  Check(mediso::FitsInProcessMemory(1 << 20, "one megabyte", message), "one megabyte fits");

  // Limit the address space to what is mapped now plus 64 MiB.
  const unsigned long long headroom = 64ULL << 20;
  const medical_test::AddressSpaceLimit limit(headroom);
  Check(limit.GetMappedKB() > 0, "VmSize read");
  Check(limit.IsSet(), "address-space limit set");

  const mediso::MemoryAllowance after = mediso::ProcessMemoryAllowance();
  Check(after.Limit == "the process's address-space limit (ulimit -v)",
    "the address-space limit binds: " + after.Limit);
  Check(after.Bytes <= headroom && after.Bytes + (8ULL << 20) >= headroom,
    "the allowance is the headroom left (" + std::to_string(after.Bytes) + " bytes)");

  message.clear();
  Check(!mediso::FitsInProcessMemory(1ULL << 30, "the output", message), "a gigabyte is refused");
  Check(message.find("the output (1073.7 MB) does not fit in the ") == 0 &&
      message.find("(the process's address-space limit (ulimit -v))") != std::string::npos,
    "the message names the allocation and the limit: " + message);

  std::printf("%d failure(s)\n", failures);
  return failures == 0 ? 0 : 1;
}
