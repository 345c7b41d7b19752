#!/usr/bin/env bash
# Run a command inside a private, loopback-only network namespace, under its
# own Xvfb. Everything that starts pvserver or MPI runs through this: pvserver
# 5.11 listens on every interface (no bind-address option) and OpenMPI opens
# ports of its own; in a new namespace only 127.0.0.1 exists, so nothing is
# reachable from outside, and ports cannot collide with other jobs.
#
# Usage: netns.sh COMMAND [ARGS...]
# Exits 125 (skip) when network namespaces, loopback set-up or Xvfb are
# unavailable; otherwise with the command's status.
set -u
here=$(cd "$(dirname "$0")" && pwd)
if [ "${MEDISO_IN_NETNS:-}" != 1 ]; then
  # Root (CI) gets a plain network namespace; a plain user may get one inside
  # a user namespace (-r) where the kernel allows it.
  if [ "$(id -u)" = 0 ] && unshare -n true 2>/dev/null; then
    netns=(unshare -n)
  elif unshare -rn true 2>/dev/null; then
    netns=(unshare -rn)
  else
    echo "SKIP: cannot create a private network namespace (unshare -n needs root or user namespaces)"
    exit 125
  fi
  export MEDISO_IN_NETNS=1
  exec "${netns[@]}" "$0" "$@"
fi
# Inside: only loopback exists, and it starts down.
if ! ip link set lo up 2>/dev/null; then
  echo "SKIP: cannot bring up loopback in the namespace (iproute2 missing?)"
  exit 125
fi
if [ -z "${MEDISO_NETNS_XVFB:-}" ]; then
  export MEDISO_NETNS_XVFB=1
  exec "$here/with-xvfb.sh" "$0" "$@"
fi
"$@"
