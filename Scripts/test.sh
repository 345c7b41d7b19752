#!/usr/bin/env bash
# The whole test suite: bootstrap (install, configure, build), then ctest.
#
#   Scripts/test.sh [ctest args...]
#
# Every rendering test runs under its own Xvfb; pvserver tests run inside a
# loopback-only network namespace. Tests that need what the machine lacks are
# reported by ctest as skipped (Not Run), with the reason in their output.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${MEDISO_BUILD_DIR:-$repo/build}
"$repo/Scripts/bootstrap.sh"
cd "$build"
ctest --output-on-failure --parallel "$(nproc)" "$@"
