#!/usr/bin/env bash
# Take a Debian 12 machine from bare to a built MedicalIsosurfaces plugin.
#
#   Scripts/bootstrap.sh            install what is missing, configure, build
#
# Idempotent: packages already present are not reinstalled, an existing build
# directory is reused, and an up-to-date build takes seconds.
# Environment:
#   MEDISO_BUILD_DIR   build directory (default: <repo>/build)
#   MEDISO_CMAKE_ARGS  extra arguments for the first configure
# Prints the plugin library path as its last line.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${MEDISO_BUILD_DIR:-$repo/build}

# Everything the build, the tests and the demo use, named here so that a fresh
# machine needs nothing else (CI machines may hold leftovers; never rely on them).
packages=(
  # ParaView 5.11 with its VTK, pvpython, pvbatch, pvserver, OpenMPI; numpy for the benchmark
  paraview paraview-dev python3-paraview python3-numpy
  # packages the ParaView CMake components we request look for at configure time
  libopenmpi-dev libdouble-conversion-dev libutfcpp-dev liblz4-dev
  qtbase5-dev qttools5-dev libqt5svg5-dev libqt5opengl5-dev qtxmlpatterns5-dev-tools
  libavformat-dev libavcodec-dev libavutil-dev libswscale-dev
  libhdf5-dev libgdal-dev libnetcdf-dev libgl2ps-dev libglew-dev libtheora-dev libtiff-dev
  # the GUI panel widgets (pqComponents) and the plugin's documentation (Qt help)
  libxml2-dev libboost-dev qhelpgenerator-qt5
  # DCMTK: the DICOM reader's library (libdcmtk-dev), and its tools (dcmtk) and
  # pydicom (for /usr/bin/python3), which write the DICOM series the tests open
  libdcmtk-dev dcmtk python3-pydicom
  # toolchain (python3 runs the data script and the offline format test)
  cmake ninja-build g++ make python3
  # rendering without a display (Mesa llvmpipe), and tests' network namespaces
  xvfb libgl1-mesa-dri iproute2 util-linux
  # the GPU core's headless host (mediso-render, EGL tests): EGL, the Khronos
  # GLES3 headers, Mesa's EGL (surfaceless llvmpipe), zlib for PNG
  libegl-dev libgles-dev libegl-mesa0 zlib1g-dev
  # the web client: its server (aiohttp in pvpython), its browser tests (Chromium, node)
  python3-aiohttp chromium
  # the GUI test's screen captures (xwd) and window queries (xwininfo)
  x11-apps x11-utils
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "bootstrap: installing ${#missing[@]} Debian package(s): ${missing[*]}"
  sudo=()
  if [ "$(id -u)" != 0 ]; then
    command -v sudo >/dev/null || { echo "bootstrap: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
    sudo=(sudo)
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -q
  "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "bootstrap: all ${#packages[@]} Debian packages present"
fi

# node and npm (a machine may have them from elsewhere; else Debian's)
if ! command -v npm >/dev/null; then
  echo "bootstrap: installing Debian's nodejs and npm"
  if [ "$(id -u)" = 0 ]; then
    apt-get install -y -q --no-install-recommends nodejs npm
  else
    sudo apt-get install -y -q --no-install-recommends nodejs npm
  fi
fi

if [ ! -f "$build/CMakeCache.txt" ]; then
  generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  # Debian 12's toolchain builds the project without a warning: keep it so.
  # shellcheck disable=SC2086
  cmake -S "$repo" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DMEDISO_WARNINGS_AS_ERRORS=ON ${MEDISO_CMAKE_ARGS:-}
fi
cmake --build "$build" --parallel "$(nproc)"
echo "bootstrap: plugin built; load it with LoadPlugin('$(cat "$build/plugin-path.txt")', ns=globals())"
cat "$build/plugin-path.txt"
