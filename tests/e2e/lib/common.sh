# Shared helpers for e2e tests: real binaries, loopback only, everything cleaned up on exit.
set -euo pipefail
: "${INBETWEEN_BIN:?set by ctest: the build directory}"
: "${INBETWEEN_SRC:?set by ctest: the source directory}"
SERVER_BIN="$INBETWEEN_BIN/server/inbetween-server"
CLI_BIN="$INBETWEEN_BIN/client/inbetween"
WORK=$(mktemp -d)
PIDS=()
cleanup() {
  for pid in "${PIDS[@]:-}"; do [[ -n "$pid" ]] && kill -9 "$pid" 2>/dev/null || true; done
  rm -rf "$WORK"
}
trap cleanup EXIT

# start_server [extra flags]: starts inbetween-server on a free loopback port; sets SERVER_PID
# and SERVER_ADDR from the line it prints ("inbetween-server listening on 127.0.0.1:PORT").
start_server() {
  local log="$WORK/server.log"
  "$SERVER_BIN" --listen 127.0.0.1:0 "$@" >"$log" 2>&1 &
  SERVER_PID=$!
  PIDS+=("$SERVER_PID")
  for _ in $(seq 1 200); do
    SERVER_ADDR=$(grep -oE 'inbetween-server listening on 127\.0\.0\.1:[0-9]+' "$log" | head -1 |
                  awk '{print $4}' || true)
    [[ -n "$SERVER_ADDR" ]] && return 0
    kill -0 "$SERVER_PID" 2>/dev/null || { cat "$log"; echo "server died" >&2; return 1; }
    sleep 0.05
  done
  cat "$log"; echo "server did not report its port" >&2; return 1
}

# Waits (up to 60 s) until the CLI running as PID has written its first "frames" line to the file
# ERR; fails when it never does (the process ended first, or the time ran out).
wait_first_frame() {
  local pid=$1 err=$2
  for _ in $(seq 1 1200); do
    grep -q '^frames' "$err" && return 0
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.05
  done
  grep -q '^frames' "$err"
}
