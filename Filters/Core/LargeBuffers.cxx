// SPDX-License-Identifier: BSD-3-Clause
#include "LargeBuffers.h"

#if defined(__linux__) && !defined(__EMSCRIPTEN__)
#define MEDISO_LARGE_BUFFERS_MAPPED 1
#include <sys/mman.h>
#include <unistd.h>
#else
#define MEDISO_LARGE_BUFFERS_MAPPED 0
#endif

#include <algorithm>

namespace mediso
{
namespace
{
#if MEDISO_LARGE_BUFFERS_MAPPED
std::size_t PageRounded(std::size_t bytes)
{
  const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  return (std::max<std::size_t>(bytes, 1) + page - 1) / page * page;
}

void* MapFresh(std::size_t length)
{
  void* memory = mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  return memory == MAP_FAILED ? nullptr : memory;
}

// The mapping `memory` of `old` bytes made `length` bytes long, its pages
// kept; null when that failed, the mapping then unchanged.
void* Remap(void* memory, std::size_t old, std::size_t length)
{
  if (length < old)
  {
    munmap(static_cast<char*>(memory) + length, old - length);
    return memory;
  }
  if (length == old)
  {
    return memory;
  }
  void* moved = mremap(memory, old, length, MREMAP_MAYMOVE);
  return moved == MAP_FAILED ? nullptr : moved;
}
#endif
} // namespace

LargeBuffers::LargeBuffers(const Limits& limits)
  : Limit(limits)
{
}

LargeBuffers::~LargeBuffers()
{
#if MEDISO_LARGE_BUFFERS_MAPPED
  for (const Spare& s : this->Spares)
  {
    munmap(s.Memory, s.Length);
  }
#endif
}

LargeBuffers& LargeBuffers::Process()
{
  static LargeBuffers* const process = new LargeBuffers(Limits());
  return *process;
}

void LargeBuffers::ReleaseToProcess(void* memory)
{
  Process().Release(memory);
}

bool LargeBuffers::Supported()
{
  return MEDISO_LARGE_BUFFERS_MAPPED != 0;
}

void* LargeBuffers::Allocate(std::size_t bytes)
{
#if MEDISO_LARGE_BUFFERS_MAPPED
  if (bytes < this->Limit.MinimumBytes)
  {
    return nullptr;
  }
  const std::size_t length = PageRounded(bytes);
  void* memory = nullptr;
  const Spare spare = this->TakeSpare(length);
  if (spare.Memory)
  {
    memory = Remap(spare.Memory, spare.Length, length);
    if (!memory)
    {
      munmap(spare.Memory, spare.Length);
    }
  }
  if (!memory)
  {
    memory = MapFresh(length);
  }
  if (memory)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Lengths[memory] = length;
  }
  return memory;
#else
  (void)bytes;
  return nullptr;
#endif
}

std::size_t LargeBuffers::Capacity(void* memory) const
{
  std::lock_guard<std::mutex> lock(this->Mutex);
  auto found = this->Lengths.find(memory);
  return found == this->Lengths.end() ? 0 : found->second;
}

void* LargeBuffers::Resize(void* memory, std::size_t bytes)
{
#if MEDISO_LARGE_BUFFERS_MAPPED
  const std::size_t old = this->Capacity(memory);
  if (old == 0)
  {
    return nullptr;
  }
  const std::size_t length = PageRounded(bytes);
  void* moved = Remap(memory, old, length);
  if (moved)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Lengths.erase(memory);
    this->Lengths[moved] = length;
  }
  return moved;
#else
  (void)memory;
  (void)bytes;
  return nullptr;
#endif
}

void LargeBuffers::Release(void* memory)
{
  std::size_t length = 0;
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    auto found = this->Lengths.find(memory);
    if (found == this->Lengths.end())
    {
      return;
    }
    length = found->second;
    this->Lengths.erase(found);
  }
#if MEDISO_LARGE_BUFFERS_MAPPED
  if (length > this->Limit.SpareBytes || madvise(memory, length, MADV_FREE) != 0)
  {
    munmap(memory, length);
    return;
  }
  std::vector<Spare> expired;
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Spares.push_back(Spare{ memory, length, Clock::now() });
    this->SpareTotal += length;
    this->Expire(expired);
  }
  for (const Spare& s : expired)
  {
    munmap(s.Memory, s.Length);
  }
#else
  (void)length;
#endif
}

std::size_t LargeBuffers::GetNumberOfSpares() const
{
  std::lock_guard<std::mutex> lock(this->Mutex);
  return this->Spares.size();
}

std::size_t LargeBuffers::GetSpareBytes() const
{
  std::lock_guard<std::mutex> lock(this->Mutex);
  return this->SpareTotal;
}

LargeBuffers::Spare LargeBuffers::TakeSpare(std::size_t length)
{
  std::vector<Spare> expired;
  Spare taken;
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Expire(expired);
    const std::size_t none = this->Spares.size();
    std::size_t fitting = none, largest = none;
    for (std::size_t s = 0; s < this->Spares.size(); ++s)
    {
      const std::size_t has = this->Spares[s].Length;
      if (has >= length)
      {
        fitting = fitting == none || has < this->Spares[fitting].Length ? s : fitting;
      }
      else if (2 * has >= length)
      {
        largest = largest == none || has > this->Spares[largest].Length ? s : largest;
      }
    }
    const std::size_t best = fitting != none ? fitting : largest;
    if (best != none)
    {
      taken = this->Spares[best];
      this->SpareTotal -= taken.Length;
      this->Spares.erase(this->Spares.begin() + static_cast<std::ptrdiff_t>(best));
    }
  }
#if MEDISO_LARGE_BUFFERS_MAPPED
  for (const Spare& s : expired)
  {
    munmap(s.Memory, s.Length);
  }
#endif
  return taken;
}

// Moves the oldest kept mappings to `expired` (unmapped by the caller, outside
// the lock) while more than SpareBytes are kept or they are older than
// SpareSeconds. Holds Mutex.
void LargeBuffers::Expire(std::vector<Spare>& expired)
{
  const Clock::time_point now = Clock::now();
  const auto limit = std::chrono::duration<double>(this->Limit.SpareSeconds);
  while (!this->Spares.empty() &&
    (this->SpareTotal > this->Limit.SpareBytes || now - this->Spares.front().Released > limit))
  {
    expired.push_back(this->Spares.front());
    this->SpareTotal -= this->Spares.front().Length;
    this->Spares.erase(this->Spares.begin());
  }
}

} // namespace mediso
