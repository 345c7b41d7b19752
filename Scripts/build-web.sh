#!/usr/bin/env bash
# Build the web page's WebAssembly module (build-web/bin/mediso.js, mediso.wasm)
# with Debian's emscripten, installing it when missing. Idempotent.
#
#   Scripts/build-web.sh
#
# Environment: MEDISO_WEB_BUILD_DIR (default <repo>/build-web).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${MEDISO_WEB_BUILD_DIR:-$repo/build-web}

packages=(emscripten nodejs)
missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -gt 0 ] && ! command -v emcc >/dev/null; then
  echo "build-web: installing ${missing[*]}"
  sudo=()
  [ "$(id -u)" = 0 ] || sudo=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -q
  "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# VTK's marching-cubes case table comes from the native build (the web build has no VTK).
table="${MEDISO_BUILD_DIR:-$repo/build}/generated/MarchingCubesCases.cxx"
if [ ! -f "$table" ]; then
  "$repo/Scripts/bootstrap.sh" >/dev/null
fi

# Debian's emscripten runs node for the link step; a node that is not Debian's
# does not search Debian's module folder on its own.
export NODE_PATH=${NODE_PATH:-/usr/share/nodejs}
# Two modules: mediso (one thread) and mediso-mt (threads, for cross-origin
# isolated pages); the threaded one compiles every object with -pthread.
for threads in OFF ON; do
  dir=$build
  [ "$threads" = ON ] && dir=$build/threads
  if [ ! -f "$dir/CMakeCache.txt" ]; then
    generator=()
    command -v ninja >/dev/null && generator=(-G Ninja)
    emcmake cmake -S "$repo" -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
      -DMEDISO_WARNINGS_AS_ERRORS=ON "-DMEDISO_CASE_TABLE=$table" \
      "-DMEDISO_WEB_THREADS=$threads" >/dev/null
  fi
  cmake --build "$dir" --parallel "$(nproc)"
done
cp -p "$build"/threads/bin/mediso-mt.* "$build/bin/"
echo "build-web: $build/bin: mediso.js, mediso.wasm, mediso-mt.js, mediso-mt.wasm, mediso-mt.worker.js"
