// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file LargeBuffers.h
 * @brief Memory for large output arrays that is kept a while after it is
 * released, so that the next surface reuses its pages (no VTK).
 *
 * A fresh block of memory costs a page fault and a page the kernel zeroes per
 * 4 KB the first time it is written: for a warm isovalue change on a noisy
 * MRI (a 54 MB surface) that is a third of the change. glibc keeps freed
 * blocks in its heap for reuse, but not those at or above its largest mmap
 * threshold (32 MiB on 64-bit): it maps each of them afresh and unmaps it when
 * freed, so a surface's 36 MB connectivity is faulted in by every change even
 * when another surface just released one of that size.
 *
 * LargeBuffers maps such arrays itself and, when one is released, keeps the
 * mapping for the next: Allocate() takes the smallest kept mapping that holds
 * the request (else the largest at least half as big, grown in place or moved
 * by `mremap`, which keeps its pages) and trims it to the request. At most
 * `SpareBytes` are kept, for at most `SpareSeconds` (older ones are unmapped
 * at the next call), and a kept mapping is given to the kernel as free to take
 * (`MADV_FREE`): under memory pressure it reclaims those pages instead of
 * swapping, the host counts them as available, and a reclaimed page reads as
 * a fresh zero page. So the contents of Allocate()'s memory are unspecified,
 * as malloc's are.
 *
 * Linux only; elsewhere (and below `MinimumBytes`) Allocate() returns null and
 * the caller allocates as usual. Thread-safe.
 *
 * @sa vtkBlockLODContour (its output arrays), ProcessMemory.h
 */
#ifndef MedicalIsosurfaces_LargeBuffers_h
#define MedicalIsosurfaces_LargeBuffers_h

#include <chrono>
#include <cstddef>
#include <map>
#include <mutex>
#include <vector>

namespace mediso
{

class LargeBuffers
{
public:
  struct Limits
  {
    /// Requests below this many bytes are left to the caller (malloc).
    std::size_t MinimumBytes = std::size_t(32) << 20;
    /// Released mappings kept for reuse: bytes at most.
    std::size_t SpareBytes = std::size_t(256) << 20;
    /// Released mappings kept for reuse: seconds at most.
    double SpareSeconds = 10.0;
  };

  explicit LargeBuffers(const Limits& limits);
  /// Unmaps the kept mappings (buffers still in use stay the caller's).
  ~LargeBuffers();
  LargeBuffers(const LargeBuffers&) = delete;
  LargeBuffers& operator=(const LargeBuffers&) = delete;

  /// The process's instance, with the default Limits; never destroyed, so
  /// that arrays released during static destruction still find it.
  static LargeBuffers& Process();
  /// Process().Release(memory): a free function for arrays (vtkBuffer's).
  static void ReleaseToProcess(void* memory);
  /// Whether this platform maps buffers at all.
  static bool Supported();

  /// Memory for `bytes` (a kept mapping, else a fresh one), or null when
  /// `bytes` is below MinimumBytes, the platform is not supported or mapping
  /// failed. Its contents are unspecified.
  void* Allocate(std::size_t bytes);
  /// The bytes `memory` can hold; 0 when it is not one of this instance's
  /// buffers in use.
  std::size_t Capacity(void* memory) const;
  /// `memory` made to hold `bytes`, its first min(old, new) bytes kept (the
  /// pages moved, not copied); null when that failed, `memory` then unchanged.
  void* Resize(void* memory, std::size_t bytes);
  /// Gives `memory` back: kept for reuse, or unmapped. Memory this instance
  /// did not allocate is ignored.
  void Release(void* memory);

  /// Kept mappings now, and their bytes.
  std::size_t GetNumberOfSpares() const;
  std::size_t GetSpareBytes() const;

private:
  using Clock = std::chrono::steady_clock;
  struct Spare
  {
    void* Memory = nullptr;
    std::size_t Length = 0;
    Clock::time_point Released;
  };

  Spare TakeSpare(std::size_t length);
  void Expire(std::vector<Spare>& expired);

  const Limits Limit;
  mutable std::mutex Mutex;
  std::map<void*, std::size_t> Lengths; // buffers in use
  std::vector<Spare> Spares;            // oldest first
  std::size_t SpareTotal = 0;
};

} // namespace mediso

#endif
