#!/usr/bin/env bash
# Runs one browser test of Testing/Web with node:
#
#   Testing/Scripts/web-test.sh Testing/Web/TestSomething.mjs [args...]
#
# Installs Testing/Web/node_modules from its lock file first when it is missing or older than
# the lock (npm ci, under a lock so that tests running in parallel install once). Nothing
# downloads a browser: playwright-core only drives Debian's /usr/bin/chromium. Exit 125
# (skipped) with the reason when node, npm or chromium is missing or the install fails.
set -uo pipefail
web=$(cd "$(dirname "$0")/../Web" && pwd)
command -v node >/dev/null || { echo "SKIP: node is not installed"; exit 125; }
[ -x /usr/bin/chromium ] || { echo "SKIP: /usr/bin/chromium is not installed (apt-get install chromium)"; exit 125; }
(
  flock 9
  if [ ! -f "$web/node_modules/.package-lock.json" ] ||
     [ "$web/package-lock.json" -nt "$web/node_modules/.package-lock.json" ]; then
    command -v npm >/dev/null || { echo "SKIP: npm is not installed"; exit 125; }
    (cd "$web" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error) ||
      { echo "SKIP: npm ci failed in $web (no registry?)"; exit 125; }
  fi
) 9>"${TMPDIR:-/tmp}/medical-isosurfaces-npm-ci.lock" || exit $?
exec node "$@"
