#!/usr/bin/env bash
# Run a pvpython client script against a pvserver with the plugin, both inside
# a private, loopback-only network namespace (pvserver 5.11 listens on every
# interface and has no bind-address option: it must never be reachable).
#
# Usage: client-server.sh PVSERVER PVPYTHON CLIENT_SCRIPT [pvserver args...]
# Environment: MEDISO_PLUGIN (plugin library path) is passed to the client.
# The client gets --port, --server-pid and --plugin arguments.
#
# The namespace is new and private, so its port cannot be held by anyone else.
# Exits 125 (skip) when network namespaces or Xvfb are unavailable.
set -u
pvserver=$1 pvpython=$2 client=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)

if [ "${MEDISO_IN_NETNS:-}" != 1 ]; then
  for tool in "$pvserver" "$pvpython"; do
    if ! command -v "$tool" >/dev/null 2>&1; then
      echo "SKIP: $tool not found"
      exit 125
    fi
  done
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
  exec "${netns[@]}" "$here/with-xvfb.sh" "$0" "$pvserver" "$pvpython" "$client" "$@"
fi

# Inside the namespace, under Xvfb: only loopback exists, and it starts down.
ip link set lo up 2>/dev/null || { echo "SKIP: cannot bring up loopback (iproute2 missing?)"; exit 125; }
port=11111
log=$(mktemp)
cleanup() {
  [ -n "${server_pid:-}" ] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null
  rm -f "$log"
}
trap cleanup EXIT

"$pvserver" --no-mpi --force-offscreen-rendering --server-port=$port "$@" </dev/null >"$log" 2>&1 &
server_pid=$!
for _ in $(seq 1 300); do
  grep -q "Accepting connection" "$log" && break
  if ! kill -0 "$server_pid" 2>/dev/null; then
    echo "pvserver exited before accepting connections:" >&2
    cat "$log" >&2
    exit 1
  fi
  sleep 0.1
done
grep -q "Accepting connection" "$log" || { echo "pvserver did not start:" >&2; cat "$log" >&2; exit 1; }

"$pvpython" --force-offscreen-rendering "$client" --port "$port" \
  --server-pid "$server_pid" --plugin "${MEDISO_PLUGIN:-}"
status=$?
if [ $status -ne 0 ]; then
  echo "--- pvserver output ---"
  cat "$log"
fi
exit $status
