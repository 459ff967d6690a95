#!/usr/bin/env bash
# The README's main job: `inbetween animate` with the service embedded (no server process).
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples/square_hexagon"
for method in zhu17 alexa; do
  "$CLI_BIN" animate "$ex/square.svg" "$ex/hexagon.svg" --frames 24 --out "$WORK/$method" \
    --method "$method" --quiet >"$WORK/stdout"
  grep -q "$WORK/$method/frames.json" "$WORK/stdout" || { echo "CLI did not print the frames path"; exit 1; }
  python3 "$INBETWEEN_SRC/tests/e2e/lib/check_frames.py" "$WORK/$method/frames.json" 24 0,23
done
# Usage errors exit 2; one drawing is bad input (exit 3) with a message saying what is needed.
set +e
"$CLI_BIN" animate "$ex/square.svg" "$ex/hexagon.svg" --out "$WORK/x" --no-such-flag 2>/dev/null
code=$?
"$CLI_BIN" animate "$ex/square.svg" --out "$WORK/x" 2>"$WORK/one.err"; code1=$?
set -e
[[ $code -eq 2 ]] || { echo "expected usage exit code 2, got $code"; exit 1; }
[[ $code1 -eq 3 ]] || { echo "expected exit code 3 for one drawing, got $code1"; exit 1; }
grep -q "need 2 to 16 drawings" "$WORK/one.err" || { cat "$WORK/one.err"; exit 1; }
echo "ok"
