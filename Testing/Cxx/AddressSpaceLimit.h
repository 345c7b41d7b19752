// SPDX-License-Identifier: BSD-3-Clause
// A test's own address-space limit (RLIMIT_AS, as `ulimit -v` sets it), for the
// tests that check what a filter, reader or core does when the process may
// allocate less than it needs. VTK-free, so the core tests use it too.
//
//   medical_test::AddressSpaceLimit limit(64ULL << 20);
//   Check(limit.IsSet(), "address-space limit set");
//   ... run what must be refused ...
//   // the limit is given back when `limit` goes out of scope
//
// The limit is what the process maps when the object is made plus a headroom:
// a fixed number would depend on how much the sanitizers, the libraries and the
// test itself have mapped. It is given back on scope exit (or by Restore())
// because a limit left in place starves whatever runs after the checks:
// AddressSanitizer's leak check at exit, for one, cannot map its own memory and
// hangs.
#ifndef AddressSpaceLimit_h
#define AddressSpaceLimit_h

#include <cstdio>

#include <sys/resource.h>

namespace medical_test
{
class AddressSpaceLimit
{
public:
  // Limits the address space to what the process maps now plus `headroom`
  // bytes; IsSet() says whether that worked.
  explicit AddressSpaceLimit(unsigned long long headroom)
  {
    this->MappedKB = ReadMappedKB();
    rlimit limit{};
    if (this->MappedKB == 0 || getrlimit(RLIMIT_AS, &limit) != 0)
    {
      return;
    }
    this->Original = limit;
    limit.rlim_cur = static_cast<rlim_t>(this->MappedKB * 1024 + headroom);
    this->Set = setrlimit(RLIMIT_AS, &limit) == 0;
  }

  ~AddressSpaceLimit() { this->Restore(); }

  AddressSpaceLimit(const AddressSpaceLimit&) = delete;
  AddressSpaceLimit& operator=(const AddressSpaceLimit&) = delete;

  // Gives the limit the process had before back; true when it is back (or
  // was never changed).
  bool Restore()
  {
    if (!this->Set)
    {
      return true;
    }
    this->Set = setrlimit(RLIMIT_AS, &this->Original) != 0;
    return !this->Set;
  }

  bool IsSet() const { return this->Set; }

  // The process's VmSize when the limit was made, in KiB (0 where
  // /proc/self/status could not be read).
  unsigned long long GetMappedKB() const { return this->MappedKB; }

  // The process's VmSize now, in KiB (0 where /proc/self/status could not be read).
  static unsigned long long ReadMappedKB()
  {
    unsigned long long vmKB = 0;
    if (std::FILE* status = std::fopen("/proc/self/status", "r"))
    {
      char line[256];
      while (std::fgets(line, sizeof(line), status))
      {
        std::sscanf(line, "VmSize: %llu kB", &vmKB);
      }
      std::fclose(status);
    }
    return vmKB;
  }

private:
  rlimit Original{};
  unsigned long long MappedKB = 0;
  bool Set = false;
};
} // namespace medical_test

#endif
