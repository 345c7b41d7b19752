// SPDX-License-Identifier: BSD-3-Clause
// mediso::LargeBuffers with small limits the test sets: requests below the
// minimum are left to the caller; a released mapping is kept and serves the
// next request (the same pages, trimmed or grown with their values); the kept
// bytes and their age are bounded; memory it did not allocate is ignored.
#include "LargeBuffers.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>

namespace
{
int failures = 0;
void Check(bool ok, const std::string& what)
{
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  failures += ok ? 0 : 1;
}

constexpr std::size_t MB = std::size_t(1) << 20;

// Writes a pattern over `bytes` of `memory`; Holds() reads it back.
void Fill(void* memory, std::size_t bytes, unsigned char seed)
{
  auto* p = static_cast<unsigned char*>(memory);
  for (std::size_t i = 0; i < bytes; ++i)
  {
    p[i] = static_cast<unsigned char>(seed + i * 7);
  }
}
bool Holds(const void* memory, std::size_t bytes, unsigned char seed)
{
  const auto* p = static_cast<const unsigned char*>(memory);
  for (std::size_t i = 0; i < bytes; ++i)
  {
    if (p[i] != static_cast<unsigned char>(seed + i * 7))
    {
      return false;
    }
  }
  return true;
}
} // namespace

int main()
{
  mediso::LargeBuffers::Limits limits;
  limits.MinimumBytes = 1 * MB;
  limits.SpareBytes = 8 * MB;
  limits.SpareSeconds = 60.0;
  mediso::LargeBuffers buffers(limits);

  Check(buffers.Allocate(MB / 2) == nullptr, "below the minimum: left to the caller");
  if (!mediso::LargeBuffers::Supported())
  {
    Check(buffers.Allocate(4 * MB) == nullptr, "not supported here: every request left to malloc");
    std::printf("LargeBuffers maps nothing on this platform\n");
    return failures == 0 ? 0 : 1;
  }

  // A buffer, released and taken again: the same mapping, trimmed.
  void* a = buffers.Allocate(3 * MB + 100);
  Check(a != nullptr && buffers.Capacity(a) >= 3 * MB + 100, "a mapping that holds the request");
  Fill(a, 3 * MB + 100, 1);
  Check(Holds(a, 3 * MB + 100, 1), "its memory written and read back");
  buffers.Release(a);
  Check(buffers.Capacity(a) == 0 && buffers.GetNumberOfSpares() == 1 &&
      buffers.GetSpareBytes() >= 3 * MB + 100,
    "released: kept, no longer in use");
  void* b = buffers.Allocate(2 * MB + 5);
  Check(b == a && buffers.GetNumberOfSpares() == 0, "the next request reuses the kept mapping");
  Check(buffers.Capacity(b) >= 2 * MB + 5 && buffers.Capacity(b) < 3 * MB,
    "trimmed to the request (whole pages)");

  // Grown and shrunk with its values.
  Fill(b, 2 * MB + 5, 2);
  void* grown = buffers.Resize(b, 6 * MB);
  Check(grown != nullptr && buffers.Capacity(grown) >= 6 * MB, "grown");
  Check(grown && Holds(grown, 2 * MB + 5, 2), "growing keeps the values");
  if (grown)
  {
    Fill(grown, 6 * MB, 3);
    void* shrunk = buffers.Resize(grown, 1 * MB + 1);
    Check(shrunk == grown && Holds(shrunk, 1 * MB + 1, 3), "shrinking keeps the values in place");
    b = shrunk ? shrunk : grown;
  }
  buffers.Release(b);

  // A request with no kept mapping at least half its size is mapped afresh.
  void* c = buffers.Allocate(5 * MB);
  Check(
    c != nullptr && buffers.GetNumberOfSpares() == 1, "nothing half as big kept: a new mapping");
  buffers.Release(c);
  Check(buffers.GetNumberOfSpares() == 2, "two kept");

  // At most SpareBytes kept: the oldest go first.
  void* d = buffers.Allocate(4 * MB);
  void* e = buffers.Allocate(4 * MB);
  void* f = buffers.Allocate(4 * MB);
  buffers.Release(d);
  buffers.Release(e);
  buffers.Release(f);
  Check(buffers.GetSpareBytes() <= limits.SpareBytes, "kept bytes bounded");
  Check(buffers.GetNumberOfSpares() == 2, "the newest two 4 MB mappings kept");

  // Ignored: memory it did not allocate, a second release.
  int local = 0;
  buffers.Release(&local);
  buffers.Release(f);
  Check(buffers.GetNumberOfSpares() == 2 && buffers.Capacity(&local) == 0,
    "memory it did not allocate is ignored");

  // Kept for SpareSeconds at most.
  mediso::LargeBuffers::Limits brief = limits;
  brief.SpareSeconds = 0.05;
  mediso::LargeBuffers shortLived(brief);
  void* g = shortLived.Allocate(2 * MB);
  shortLived.Release(g);
  Check(shortLived.GetNumberOfSpares() == 1, "kept just after its release");
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  void* h = shortLived.Allocate(MB + 1);
  Check(h != nullptr && shortLived.GetNumberOfSpares() == 0 && shortLived.GetSpareBytes() == 0,
    "older than SpareSeconds: unmapped, not reused");
  shortLived.Release(h);

  // The process's instance: arrays of 32 MiB and more.
  Check(mediso::LargeBuffers::Process().Allocate(16 * MB) == nullptr,
    "the process's instance leaves arrays below 32 MiB to malloc");

  std::printf(
    "%s\n", failures == 0 ? "LargeBuffers: all checks passed" : "LargeBuffers: checks failed");
  return failures == 0 ? 0 : 1;
}
