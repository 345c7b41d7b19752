#!/usr/bin/env bash
# The demo, from a bare Debian 12 machine to pictures and a frame-rate report:
#
#   Scripts/demo.sh [OUTPUT_DIR]       (default: <repo>/demo-output)
#
# 1. bootstrap: install packages, configure, build the plugin;
# 2. fetch the real head CT (Debian invesalius-examples) into the data cache
#    (Python/fetch_data.py; $MEDISO_DATA_DIR overrides the cache location);
# 3. render its skin (-500 HU) and bone (400 HU) through the plugin in pvpython
#    under a private Xvfb, and write PNGs and report.txt into OUTPUT_DIR.
# Without network access for the data it falls back to the plugin's
# MedicalPhantom, and says so.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
out=$(mkdir -p "${1:-$repo/demo-output}" && cd "${1:-$repo/demo-output}" && pwd)

plugin=$("$repo/Scripts/bootstrap.sh" | tail -n 1)

source_args=()
set +e
fetch_log=$(python3 "$repo/Python/fetch_data.py" --only ct 2>&1)
fetch_status=$?
set -e
echo "$fetch_log"
if [ $fetch_status -eq 0 ]; then
  ct=$(echo "$fetch_log" | sed -n 's/^fetch_data: ready: \([^,]*\.mha\).*/\1/p' | head -n 1)
  source_args=(--ct "$ct")
else
  reason=$(echo "$fetch_log" | grep -m1 -E "unavailable|check failed" || echo "data fetch failed")
  echo "demo: the real CT is not available ($reason); falling back to the synthetic MedicalPhantom"
  reason=${reason#fetch_data: }
  reason=${reason#unavailable: }
  source_args=(--phantom --fallback-reason "real CT unavailable: ${reason:0:120}")
fi

# ParaView 5.11's VTK defaults to the Sequential SMP backend; use the threads we have.
export VTK_SMP_BACKEND_IN_USE=${VTK_SMP_BACKEND_IN_USE:-STDThread}
# --no-mpi: the demo is one process, and OpenMPI's start-up fails on a machine
# with no network interface at all (where the phantom fallback matters most).
"$repo/Testing/Scripts/with-xvfb.sh" pvpython --no-mpi --force-offscreen-rendering \
  "$repo/Python/demo.py" --plugin "$plugin" --out "$out" "${source_args[@]}"
echo "demo: images and report in $out"
