// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file ProcessMemory.h
 * @brief What this process may still allocate (no VTK): the one memory check
 * behind every large allocation of the plugin and its hosts.
 *
 * A host's physical memory says little about what a process may use: a
 * container or a batch system caps a job with a cgroup (`memory.max`), and
 * a user or a scheduler with an address-space limit (`ulimit -v`,
 * `RLIMIT_AS`). An allocation past either fails (or the job is killed) while
 * the host still shows gigabytes free. ProcessMemoryAllowance() takes the
 * least of the three:
 *
 * 1. the host's available physical memory (`MemAvailable` of
 *    `/proc/meminfo`);
 * 2. the address-space limit less the address space the process already
 *    maps (`VmSize` of `/proc/self/status`);
 * 3. the memory cgroup's limit less its current use (cgroup v2
 *    `memory.max` - `memory.current`, or v1 `memory.limit_in_bytes` -
 *    `memory.usage_in_bytes`), for the cgroup `/proc/self/cgroup` names.
 *
 * Each that cannot be read (no /proc, as in a browser) is left out; with
 * none, the allowance is unbounded and says so. A check is a look at the
 * moment: callers still catch `std::bad_alloc` where they allocate.
 */
#ifndef MedicalIsosurfaces_ProcessMemory_h
#define MedicalIsosurfaces_ProcessMemory_h

#include <cstdint>
#include <limits>
#include <string>

namespace mediso
{

/// What the process may allocate now, and which limit binds.
struct MemoryAllowance
{
  /// Bytes; std::numeric_limits<std::uint64_t>::max() when no limit could be read.
  std::uint64_t Bytes = std::numeric_limits<std::uint64_t>::max();
  /// The binding limit in words, for messages: "the host's available physical
  /// memory", "the process's address-space limit (ulimit -v)", "the cgroup's
  /// memory limit", or "no known limit".
  std::string Limit = "no known limit";

  bool Bounded() const { return this->Bytes != std::numeric_limits<std::uint64_t>::max(); }
};

/// The least of the physical, address-space and cgroup allowances (see the file's comment).
MemoryAllowance ProcessMemoryAllowance();

/**
 * Whether `bytes` more fit in ProcessMemoryAllowance(). When they do not,
 * `message` says what was asked for and what binds, e.g. "the output (2147.5
 * MB) does not fit in the 1024.0 MB the process may still allocate (the
 * process's address-space limit (ulimit -v))"; `what` names the allocation.
 * Megabytes are 10^6 bytes, as in the plugin's properties.
 */
bool FitsInProcessMemory(std::uint64_t bytes, const char* what, std::string& message);

/// The same against an allowance read earlier (a host that checks several
/// allocations of one step reads the allowance once and counts them off it).
bool FitsInAllowance(
  const MemoryAllowance& allowance, std::uint64_t bytes, const char* what, std::string& message);

} // namespace mediso

#endif
