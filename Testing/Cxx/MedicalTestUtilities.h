// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file MedicalTestUtilities.h
 * @brief Small helpers shared by the project's C++ tests (standard C++ only,
 * so the VTK-free core tests can use them too): checks that count failures
 * instead of stopping at the first, and the location of the cached real data
 * (a test skips when it is not there).
 */
#ifndef MedicalTestUtilities_h
#define MedicalTestUtilities_h

#include <cstdio>
#include <cstdlib>
#include <string>

namespace medical_test
{
/// Failed checks so far in this test.
inline int Failures = 0;

/// Records a failed check with a line that makes ctest fail the test.
inline void Check(bool ok, const std::string& what)
{
  if (!ok)
  {
    std::printf("FAILED: %s\n", what.c_str());
    ++Failures;
  }
}

/// The test's exit code: 1 and a summary when a check failed, else 0 and `passed`.
inline int Finish(const char* passed)
{
  if (Failures)
  {
    std::printf("%d check(s) failed\n", Failures);
    return 1;
  }
  std::printf("%s\n", passed);
  return 0;
}

/// The real-data folder that Python/fetch_data.py fills: $MEDISO_DATA_DIR, else
/// ${XDG_CACHE_HOME:-$HOME/.cache}/medical-isosurfaces. The same rule as the Python side's one
/// function (fetch_data.resolve_cache_dir); change both together.
inline std::string DataDirectory()
{
  const char* dir = std::getenv("MEDISO_DATA_DIR");
  if (dir && *dir)
  {
    return dir;
  }
  const char* cache = std::getenv("XDG_CACHE_HOME");
  if (cache && *cache)
  {
    return std::string(cache) + "/medical-isosurfaces";
  }
  const char* home = std::getenv("HOME");
  return std::string(home ? home : ".") + "/.cache/medical-isosurfaces";
}

/// Path of a file in the real-data folder (DataDirectory()).
inline std::string DataFile(const std::string& name)
{
  return DataDirectory() + "/" + name;
}

/// The exit code ctest reads as "skipped" (the tests' SKIP_RETURN_CODE).
inline constexpr int SkipReturnCode = 125;

/// Path of a file in the real-data folder when it is there; otherwise prints
/// the SKIP line that says how to fetch it (naming it as `what`) and returns "",
/// and the test returns SkipReturnCode: a test of real data cannot pass without it.
inline std::string CachedDataFile(const std::string& name, const char* what)
{
  const std::string path = DataFile(name);
  if (std::FILE* file = std::fopen(path.c_str(), "rb"))
  {
    std::fclose(file);
    return path;
  }
  std::printf(
    "SKIP: %s is not cached (%s); run python3 Python/fetch_data.py\n", what, path.c_str());
  return std::string();
}
} // namespace medical_test

#endif
