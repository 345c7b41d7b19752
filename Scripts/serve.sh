#!/usr/bin/env bash
# The web client, from a bare Debian 12 machine to a URL to open:
#
#   Scripts/serve.sh [--data FILE_OR_DICOM_DIR ...] [--port N] [--host ADDR] [--token=TOKEN]
#
# 1. bootstrap: install packages, configure, build the plugin (Scripts/bootstrap.sh);
# 2. build the page's WebAssembly module with Debian's emscripten (Scripts/build-web.sh);
# 3. without --data: fetch the real head CT into the data cache (Python/fetch_data.py); when it
#    cannot be fetched the server serves the plugin's MedicalPhantom, and says so;
# 4. run the server (Python/serve.py in pvpython), which prints the page's URL with its token.
#
# --data takes a MetaImage (.mha/.mhd), VTK XML image (.vti), NIfTI (.nii, .nii.gz) file, a DICOM
# series folder, or phantom:N; repeat it for several volumes. The server listens on 127.0.0.1
# (this machine only) unless --host is given, on port 8765 unless --port is given; every request
# needs the token of the printed URL (random unless --token=TOKEN is given; a token that begins
# with '-' must be given so). A volume that cannot be read stops the server at start with one line
# naming the file and why. Ctrl-C stops it.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)

has_data=0
for arg in "$@"; do
  case $arg in
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    --data|--data=*) has_data=1 ;;
  esac
done

plugin=$("$repo/Scripts/bootstrap.sh" | tee /dev/stderr | tail -n 1)
# The server's web framework (Python's wslink is not packaged; aiohttp is).
if ! dpkg-query -W -f='${Status}' python3-aiohttp 2>/dev/null | grep -q "install ok installed"; then
  echo "serve: installing python3-aiohttp" >&2
  sudo=()
  [ "$(id -u)" = 0 ] || sudo=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get install -y -q --no-install-recommends python3-aiohttp >&2 ||
    { "${sudo[@]}" apt-get update -q >&2 &&
      "${sudo[@]}" apt-get install -y -q --no-install-recommends python3-aiohttp >&2; }
fi
"$repo/Scripts/build-web.sh" >&2
if [ $has_data = 0 ]; then
  python3 "$repo/Python/fetch_data.py" --only ct >&2 ||
    echo "serve: the head CT could not be fetched; the server will serve the phantom" >&2
fi
# --no-mpi: one process, and OpenMPI's start-up fails on a machine without a network interface.
exec pvpython --no-mpi "$repo/Python/serve.py" --plugin "$plugin" \
  --wasm "${MEDISO_WEB_BUILD_DIR:-$repo/build-web}/bin" "$@"
