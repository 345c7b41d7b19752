// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file ThreadedFor.h
 * @brief A ParallelFor (BlockLOD.h) over std::thread (no VTK): the one the
 * hosts without vtkSMPTools use, mediso-render and the web page's threaded
 * module (the ParaView plugin passes vtkSMPTools instead; a browser without
 * threads runs SerialFor).
 *
 * Header-only, so that linking the core adds no thread library: a host that
 * includes it links its platform's threads (Threads::Threads, or Emscripten's
 * -pthread).
 */
#ifndef MedicalIsosurfaces_ThreadedFor_h
#define MedicalIsosurfaces_ThreadedFor_h

#include <algorithm>
#include <cstdint>
#include <functional>
#include <thread>
#include <vector>

namespace mediso
{
/// Runs body over [begin, end) cut into one contiguous range per hardware thread.
inline void ThreadedFor(std::int64_t begin, std::int64_t end,
  const std::function<void(std::int64_t, std::int64_t)>& body)
{
  const std::int64_t count = end - begin;
  if (count <= 0)
  {
    return;
  }
  const std::int64_t threads =
    std::min<std::int64_t>(std::max(1u, std::thread::hardware_concurrency()), count);
  if (threads == 1)
  {
    body(begin, end);
    return;
  }
  std::vector<std::thread> workers;
  for (std::int64_t t = 0; t < threads; ++t)
  {
    const std::int64_t a = begin + count * t / threads;
    const std::int64_t b = begin + count * (t + 1) / threads;
    workers.emplace_back([&body, a, b]() { body(a, b); });
  }
  for (std::thread& w : workers)
  {
    w.join();
  }
}
} // namespace mediso

#endif
