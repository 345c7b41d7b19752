#!/usr/bin/env bash
# Run a pvpython client script against a pvserver, both inside a private,
# loopback-only network namespace (netns.sh: pvserver 5.11 listens on every
# interface and has no bind-address option: it must never be reachable), with
# a byte-counting relay (byte_relay.py) between them.
#
# Usage: client-server.sh PVSERVER PVPYTHON CLIENT_SCRIPT [CLIENT_ARGS...]
# Environment:
#   MEDISO_PLUGIN              plugin library path (passed to the client)
#   MEDISO_SERVER_RANKS=N      run pvserver under mpiexec with N ranks (default:
#                              one process, --no-mpi)
#   MEDISO_SERVER_PLUGIN_PATH=1  start pvserver with PV_PLUGIN_PATH set to the
#                              plugin's folder (else the client loads it remotely)
#   MEDISO_SERVER_ARGS         extra pvserver arguments (word-split)
# The client gets --port (the relay's), --server-port, --server-pid,
# --server-log, --plugin, --relay-control and then CLIENT_ARGS.
# Exits 125 (skip) when a tool, network namespaces or Xvfb are unavailable.
set -u
pvserver=$1 pvpython=$2 client=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)

if [ "${MEDISO_IN_NETNS:-}" != 1 ]; then
  for tool in "$pvserver" "$pvpython" python3; do
    if ! command -v "$tool" >/dev/null 2>&1; then
      echo "SKIP: $tool not found"
      exit 125
    fi
  done
  ranks=${MEDISO_SERVER_RANKS:-1}
  if [ "$ranks" -gt 1 ] && ! command -v mpiexec >/dev/null 2>&1; then
    echo "SKIP: mpiexec not found (MPI pvserver)"
    exit 125
  fi
  exec "$here/netns.sh" "$0" "$pvserver" "$pvpython" "$client" "$@"
fi

# Inside the namespace, under Xvfb.
server_port=11111
relay_port=11112
work=$(mktemp -d)
log=$work/pvserver.log
# pvserver ignores SIGTERM while it waits for a client: TERM, then KILL after 5 s.
stop() {
  local pid=$1
  kill "$pid" 2>/dev/null || return 0
  for _ in $(seq 1 50); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  kill -9 "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
}
cleanup() {
  [ -n "${relay_pid:-}" ] && stop "$relay_pid"
  [ -n "${server_pid:-}" ] && stop "$server_pid"
  rm -rf "$work"
}
trap cleanup EXIT

: >"$log"
server_env=()
if [ "${MEDISO_SERVER_PLUGIN_PATH:-0}" = 1 ]; then
  server_env=(env "PV_PLUGIN_PATH=$(dirname "${MEDISO_PLUGIN:?MEDISO_PLUGIN is not set}")")
fi
# shellcheck disable=SC2206
extra=(${MEDISO_SERVER_ARGS:-})
ranks=${MEDISO_SERVER_RANKS:-1}
if [ "$ranks" -gt 1 ]; then
  # mpiexec reads stdin: always </dev/null. -x passes the variables to every rank.
  mpi_env=(-x DISPLAY)
  [ "${MEDISO_SERVER_PLUGIN_PATH:-0}" = 1 ] && mpi_env+=(-x PV_PLUGIN_PATH)
  "${server_env[@]}" mpiexec --allow-run-as-root --oversubscribe -n "$ranks" "${mpi_env[@]}" \
    "$pvserver" --force-offscreen-rendering --server-port=$server_port "${extra[@]}" \
    </dev/null >"$log" 2>&1 &
else
  "${server_env[@]}" "$pvserver" --no-mpi --force-offscreen-rendering \
    --server-port=$server_port "${extra[@]}" </dev/null >"$log" 2>&1 &
fi
server_pid=$!
for _ in $(seq 1 600); do
  grep -q "Accepting connection" "$log" && break
  if ! kill -0 "$server_pid" 2>/dev/null; then
    echo "pvserver exited before accepting connections:" >&2
    cat "$log" >&2
    exit 1
  fi
  sleep 0.1
done
grep -q "Accepting connection" "$log" || { echo "pvserver did not start:" >&2; cat "$log" >&2; exit 1; }

python3 "$here/byte_relay.py" --listen $relay_port --target $server_port \
  --control "$work/relay.sock" --ready-file "$work/relay.ready" &
relay_pid=$!
for _ in $(seq 1 100); do
  [ -s "$work/relay.ready" ] && break
  sleep 0.05
done
[ -s "$work/relay.ready" ] || { echo "the byte relay did not start" >&2; exit 1; }

"$pvpython" --force-offscreen-rendering "$client" --port "$relay_port" \
  --server-port "$server_port" --server-pid "$server_pid" --server-log "$log" \
  --plugin "${MEDISO_PLUGIN:?MEDISO_PLUGIN (the plugin library) is not set}" --relay-control "$work/relay.sock" "$@"
status=$?
if [ $status -ne 0 ]; then
  echo "--- pvserver output ---"
  cat "$log"
fi
exit $status
