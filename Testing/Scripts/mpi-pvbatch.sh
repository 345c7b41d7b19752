#!/usr/bin/env bash
# Run a pvbatch script once in one process (--out reference.json) and then
# under mpiexec with each given number of ranks (--reference reference.json),
# inside a loopback-only network namespace under its own Xvfb (netns.sh).
#
# Usage: mpi-pvbatch.sh PVBATCH SCRIPT RANKS... [-- SCRIPT_ARGS...]
# Environment: MEDISO_PLUGIN (passed to every rank). Exits 125 (skip) without
# mpiexec, network namespaces or Xvfb.
set -u
pvbatch=$1 script=$2
shift 2
ranks=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do ranks+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
here=$(cd "$(dirname "$0")" && pwd)
if [ "${MEDISO_IN_NETNS:-}" != 1 ]; then
  for tool in "$pvbatch" mpiexec; do
    command -v "$tool" >/dev/null 2>&1 || { echo "SKIP: $tool not found"; exit 125; }
  done
  exec "$here/netns.sh" "$0" "$pvbatch" "$script" "${ranks[@]}" -- "$@"
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "=== one process (pvbatch --no-mpi): the reference"
"$pvbatch" --no-mpi "$script" --out "$work/reference.json" "$@" </dev/null || exit 1
for n in "${ranks[@]}"; do
  echo "=== mpiexec -n $n pvbatch"
  # mpiexec reads stdin: always </dev/null. -x passes the variables to every rank.
  mpiexec --allow-run-as-root --oversubscribe -n "$n" -x DISPLAY -x MEDISO_PLUGIN \
    "$pvbatch" "$script" --reference "$work/reference.json" "$@" </dev/null || exit 1
done
