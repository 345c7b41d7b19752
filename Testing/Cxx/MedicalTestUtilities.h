// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file MedicalTestUtilities.h
 * @brief Small helpers shared by the project's C++ tests (standard C++ only,
 * so the VTK-free core tests can use them too): checks that count failures
 * instead of stopping at the first, and the location of the cached real data.
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

/// Path of a file in the real-data cache of Python/fetch_data.py:
/// $MEDISO_DATA_DIR, else ~/.cache/medical-isosurfaces.
inline std::string DataFile(const std::string& name)
{
  const char* dir = std::getenv("MEDISO_DATA_DIR");
  if (dir && *dir)
  {
    return std::string(dir) + "/" + name;
  }
  const char* home = std::getenv("HOME");
  return std::string(home ? home : ".") + "/.cache/medical-isosurfaces/" + name;
}
} // namespace medical_test

#endif
