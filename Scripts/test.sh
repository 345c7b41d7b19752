#!/usr/bin/env bash
# The whole test suite: bootstrap (install, configure, build), then ctest.
#
#   Scripts/test.sh [ctest args...]
#
# First the C++ tests run once more in an AddressSanitizer build (<build>-asan;
# MEDISO_ASAN=0 skips that pass), then the full suite runs in the normal build.
# Every rendering test runs under its own Xvfb; pvserver tests run inside a
# loopback-only network namespace. Tests that need what the machine lacks are
# reported by ctest as skipped (Not Run), with the reason in their output.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${MEDISO_BUILD_DIR:-$repo/build}
"$repo/Scripts/bootstrap.sh"

if [ "${MEDISO_ASAN:-1}" != 0 ]; then
  asan="$build-asan"
  echo "test: AddressSanitizer pass over the C++ tests ($asan)"
  if [ ! -f "$asan/CMakeCache.txt" ]; then
    generator=()
    command -v ninja >/dev/null && generator=(-G Ninja)
    cmake -S "$repo" -B "$asan" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DMEDISO_ENABLE_ASAN=ON -DMEDISO_WARNINGS_AS_ERRORS=ON >/dev/null
  fi
  cmake --build "$asan" --parallel "$(nproc)" --target MedicalIsosurfacesCxxTestTargets
  (cd "$asan" &&
    ASAN_OPTIONS=detect_leaks=1 ctest --output-on-failure -L '^cxx$' &&
    ASAN_OPTIONS=detect_leaks=0 ctest --output-on-failure -L '^cxx-(render|egl)$')
fi

# The web client's tests: its WebAssembly module and the node packages that drive Chromium.
"$repo/Scripts/build-web.sh"
(cd "$repo/Testing/Web" && npm ci --no-audit --no-fund --loglevel=error)

# Tests on the real CT and MRI need the data cache; without network they skip.
python3 "$repo/Python/fetch_data.py" ||
  echo "test: real data unavailable; the tests that need it will be reported as skipped"

echo "test: full suite ($build)"
cd "$build"
ctest --output-on-failure --parallel "$(nproc)" "$@"
