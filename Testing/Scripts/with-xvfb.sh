#!/usr/bin/env bash
# Run one command under its own private Xvfb server.
#
# Usage: with-xvfb.sh COMMAND [ARGS...]
#
# The display number is chosen by Xvfb itself (-displayfd), never fixed, so
# concurrent jobs cannot collide; -noreset keeps the server alive when its last
# client disconnects (MPI ranks connect one after another). The server is
# stopped when the command ends, and the command's exit status is returned.
# Exit 125 (ctest's SKIP_RETURN_CODE for our tests) when Xvfb is not installed.
set -u
if ! command -v Xvfb >/dev/null 2>&1; then
  echo "SKIP: Xvfb is not installed (apt-get install xvfb)"
  exit 125
fi
fifo_dir=$(mktemp -d)
trap 'rm -rf "$fifo_dir"' EXIT
mkfifo "$fifo_dir/display"
Xvfb -displayfd 3 -screen 0 1920x1080x24 -nolisten tcp -noreset \
  3>"$fifo_dir/display" 2>"$fifo_dir/xvfb.log" &
xvfb_pid=$!
display=""
# Xvfb writes the display number once it is ready to accept clients.
if ! read -r -t 30 display <"$fifo_dir/display" || [ -z "$display" ]; then
  echo "with-xvfb.sh: Xvfb did not start:" >&2
  cat "$fifo_dir/xvfb.log" >&2
  kill "$xvfb_pid" 2>/dev/null
  exit 1
fi
trap 'kill "$xvfb_pid" 2>/dev/null; wait "$xvfb_pid" 2>/dev/null; rm -rf "$fifo_dir"' EXIT
export DISPLAY=":$display"
"$@"
