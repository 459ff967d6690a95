#!/usr/bin/env bash
# Web front-end end to end: the gateway's unit tests, then the real inbetween-server behind the
# real gateway (client/web) on loopback, driven in Debian's headless Chromium by playwright-core
# (client/web/e2e/browser_test.mjs): a server error shown next to its control, two SVGs
# uploaded, a cut drawn with the mouse, build, optimize (energy chart), inbetweens played on the
# canvas as the drawings' art, GIF/Lottie downloads, phone layout, two layered drawings played as
# their art (client/web/e2e/data/face_*.svg). Before the browser: the page's art rule
# (src/page/art.js) against the CLI's own frames of those drawings (client/web/e2e/art_parity.mjs).
# Screenshots and downloads are kept in $INBETWEEN_BIN/tests/e2e/web_test_output/.
source "$(dirname "$0")/lib/common.sh"
WEB="$INBETWEEN_SRC/client/web"
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
[[ -x "$CHROMIUM" ]] || { echo "FAIL: $CHROMIUM not found (scripts/setup installs chromium)" >&2; exit 1; }

"$WEB/scripts/prepare.sh"
(cd "$WEB" && node --test test/)

OUT="$INBETWEEN_BIN/tests/e2e/web_test_output"
rm -rf "$OUT"
mkdir -p "$OUT"

# The page's frame art computed by art.js must be what the C++ rule (solver/art/frame_art.h) drew
# into the CLI's SVG frames: two keys (eyes morph, a nose cross-fades, dashes differ), then three
# keys with Catmull-Rom timing (in the second segment key 2, with the nose, leads the alignment).
FACES="$WEB/e2e/data"
"$CLI_BIN" animate "$FACES/face_1.svg" "$FACES/face_2.svg" --frames 7 --method linear \
  --format svg,json --out "$OUT/art_parity_2" -q >/dev/null
(cd "$WEB" && node e2e/art_parity.mjs "$OUT/art_parity_2")
"$CLI_BIN" animate "$FACES/face_1.svg" "$FACES/face_2.svg" "$FACES/face_1.svg" --frames 9 \
  --method linear --timing catmull-rom --format svg,json --out "$OUT/art_parity_3" -q >/dev/null
(cd "$WEB" && node e2e/art_parity.mjs "$OUT/art_parity_3")

start_server
node "$WEB/src/gateway/main.mjs" --upstream "$SERVER_ADDR" --listen 127.0.0.1:0 \
  >"$WORK/gateway.log" 2>&1 &
PIDS+=($!)
GATEWAY_URL=""
for _ in $(seq 1 200); do
  GATEWAY_URL=$(grep -oE 'listening on http://127\.0\.0\.1:[0-9]+/' "$WORK/gateway.log" |
                awk '{print $3}' || true)
  [[ -n "$GATEWAY_URL" ]] && break
  sleep 0.05
done
[[ -n "$GATEWAY_URL" ]] || { cat "$WORK/gateway.log"; echo "FAIL: gateway did not start" >&2; exit 1; }
echo "server $SERVER_ADDR, gateway $GATEWAY_URL"

# Drawing 1 of examples/split without its cut: the test draws the cut with the mouse, so the
# two drawings only agree (2 components each) once the edit has been applied by the server.
sed '/class="cut"/d' "$INBETWEEN_SRC/examples/split/1_whole.svg" >"$WORK/1_whole_uncut.svg"
grep -q 'class="cut"' "$WORK/1_whole_uncut.svg" && { echo "FAIL: cut not removed" >&2; exit 1; }
# An SVG without a single filled shape: the server refuses it (INVALID_ARGUMENT).
printf '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 10"><title>empty</title></svg>\n' \
  >"$WORK/empty.svg"

status=0
(cd "$WEB" && node e2e/browser_test.mjs --url "$GATEWAY_URL" --out "$OUT" --chromium "$CHROMIUM" \
  --first "$WORK/1_whole_uncut.svg" --second "$INBETWEEN_SRC/examples/split/2_two.svg" \
  --bad "$WORK/empty.svg" --cut 60,20,60,80 \
  --art-first "$FACES/face_1.svg" --art-second "$FACES/face_2.svg") || status=$?
if ((status != 0)); then
  echo "--- gateway log"; cat "$WORK/gateway.log"
  echo "--- server log"; tail -50 "$WORK/server.log"
  exit "$status"
fi
echo "screenshots: $OUT"
