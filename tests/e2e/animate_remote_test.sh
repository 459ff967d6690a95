#!/usr/bin/env bash
# The real inbetween-server on a loopback port, the real CLI against it with --server; then a
# graceful SIGTERM shutdown that must exit 0.
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples/square_hexagon"

start_server --log-format json
"$CLI_BIN" animate "$ex/square.svg" "$ex/hexagon.svg" --frames 12 --out "$WORK/out" \
  --server "$SERVER_ADDR" --quiet
python3 "$INBETWEEN_SRC/tests/e2e/lib/check_frames.py" "$WORK/out/frames.json" 12 0,11
[[ -f "$WORK/out/frame_0000.svg" && -f "$WORK/out/frame_0011.svg" ]] || { echo "missing SVG frames"; exit 1; }

# A broken drawing is refused with exit code 3 and a message, and the server keeps serving.
printf '<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0 0 L' >"$WORK/broken.svg"
set +e
"$CLI_BIN" animate "$ex/square.svg" "$WORK/broken.svg" --out "$WORK/bad" --server "$SERVER_ADDR" \
  --quiet 2>"$WORK/bad.err"
code=$?
set -e
[[ $code -eq 3 ]] || { echo "expected exit 3 for a broken drawing, got $code"; cat "$WORK/bad.err"; exit 1; }
grep -q "drawing 2" "$WORK/bad.err" || { echo "error does not name drawing 2:"; cat "$WORK/bad.err"; exit 1; }
"$CLI_BIN" animate "$ex/square.svg" "$ex/hexagon.svg" --frames 5 --out "$WORK/out2" \
  --server "$SERVER_ADDR" --quiet
python3 "$INBETWEEN_SRC/tests/e2e/lib/check_frames.py" "$WORK/out2/frames.json" 5 0,4

# Graceful shutdown on SIGTERM: exit status 0.
kill -TERM "$SERVER_PID"
set +e
wait "$SERVER_PID"
code=$?
set -e
[[ $code -eq 0 ]] || { echo "server exited with $code after SIGTERM"; cat "$WORK/server.log"; exit 1; }
echo "ok"
