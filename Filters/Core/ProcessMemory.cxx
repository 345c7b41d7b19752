// SPDX-License-Identifier: BSD-3-Clause
#include "ProcessMemory.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

#if defined(__linux__)
#include <sys/resource.h>
#endif

namespace mediso
{
namespace
{

/// The number after `key` in a "key: value kB" file such as /proc/meminfo, in bytes.
bool ReadKilobytes(const char* path, const std::string& key, std::uint64_t& bytes)
{
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
  {
    if (line.compare(0, key.size(), key) == 0)
    {
      std::istringstream fields(line.substr(key.size()));
      std::uint64_t kilobytes = 0;
      if (fields >> kilobytes)
      {
        bytes = kilobytes * 1024;
        return true;
      }
    }
  }
  return false;
}

/// One unsigned number from a file ("max" or anything else unreadable gives false).
bool ReadNumber(const std::string& path, std::uint64_t& value)
{
  std::ifstream in(path);
  std::string word;
  if (!(in >> word) || word.empty() || word.find_first_not_of("0123456789") != std::string::npos)
  {
    return false;
  }
  std::istringstream(word) >> value;
  return true;
}

/// The memory cgroup's limit less its use, for the cgroup this process is in.
bool CgroupAllowance(std::uint64_t& bytes)
{
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line))
  {
    // v2: "0::/path"; v1: "N:memory:/path" (or a list with memory in it).
    const auto first = line.find(':');
    const auto second = first == std::string::npos ? first : line.find(':', first + 1);
    if (second == std::string::npos)
    {
      continue;
    }
    const std::string controllers = line.substr(first + 1, second - first - 1);
    const std::string path = line.substr(second + 1);
    std::uint64_t limit = 0, used = 0;
    if (controllers.empty())
    {
      const std::string dir = "/sys/fs/cgroup" + (path == "/" ? std::string() : path);
      if (ReadNumber(dir + "/memory.max", limit) && ReadNumber(dir + "/memory.current", used))
      {
        bytes = limit > used ? limit - used : 0;
        return true;
      }
    }
    else if (("," + controllers + ",").find(",memory,") != std::string::npos)
    {
      for (const std::string& dir :
        { "/sys/fs/cgroup/memory" + path, std::string("/sys/fs/cgroup/memory") })
      {
        // v1 says "no limit" with a huge number near 2^63.
        if (ReadNumber(dir + "/memory.limit_in_bytes", limit) && limit < (1ULL << 62) &&
          ReadNumber(dir + "/memory.usage_in_bytes", used))
        {
          bytes = limit > used ? limit - used : 0;
          return true;
        }
      }
    }
  }
  return false;
}

} // namespace

//------------------------------------------------------------------------------
MemoryAllowance ProcessMemoryAllowance()
{
  MemoryAllowance allowance;
  auto consider = [&allowance](std::uint64_t bytes, const char* limit)
  {
    if (bytes < allowance.Bytes)
    {
      allowance.Bytes = bytes;
      allowance.Limit = limit;
    }
  };
  std::uint64_t bytes = 0;
  if (ReadKilobytes("/proc/meminfo", "MemAvailable:", bytes))
  {
    consider(bytes, "the host's available physical memory");
  }
#if defined(__linux__)
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
  {
    std::uint64_t mapped = 0;
    ReadKilobytes("/proc/self/status", "VmSize:", mapped);
    const std::uint64_t cap = static_cast<std::uint64_t>(limit.rlim_cur);
    consider(cap > mapped ? cap - mapped : 0, "the process's address-space limit (ulimit -v)");
  }
#endif
  if (CgroupAllowance(bytes))
  {
    consider(bytes, "the cgroup's memory limit");
  }
  return allowance;
}

//------------------------------------------------------------------------------
bool FitsInProcessMemory(std::uint64_t bytes, const char* what, std::string& message)
{
  return FitsInAllowance(ProcessMemoryAllowance(), bytes, what, message);
}

bool FitsInAllowance(
  const MemoryAllowance& allowance, std::uint64_t bytes, const char* what, std::string& message)
{
  if (bytes <= allowance.Bytes)
  {
    return true;
  }
  char text[512];
  std::snprintf(text, sizeof(text),
    "%s (%.1f MB) does not fit in the %.1f MB the process may still allocate (%s)", what,
    static_cast<double>(bytes) / 1.0e6, static_cast<double>(allowance.Bytes) / 1.0e6,
    allowance.Limit.c_str());
  message = text;
  return false;
}

} // namespace mediso
