#!/usr/bin/env bash
# The CLI's Lottie output plays in lottie-web (issue 8): `inbetween animate --format lottie
# --frames 12` on examples/square_hexagon (two SVGs) and examples/bird (--project), then
# client/web/e2e/lottie_test.mjs loads each animation.lottie.json with lottie-web (pinned in
# client/web/package.json, served from node_modules on 127.0.0.1) in Debian's headless Chromium
# via playwright-core: no page error, no data_failed/error event, totalFrames 12, the rendered
# path differs between frames 0, 6 and 11 and stays inside w×h; corrupted copies (keyframes
# removed, op changed, vertices off the canvas, truncated JSON, a 404) must each be caught.
source "$(dirname "$0")/lib/common.sh"
WEB="$INBETWEEN_SRC/client/web"
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
FRAMES=12
[[ -x "$CHROMIUM" ]] || { echo "FAIL: $CHROMIUM not found (scripts/setup installs chromium)" >&2; exit 1; }

# Only the npm packages: rebuilding dist/ here could break a web_test running alongside.
"$WEB/scripts/prepare.sh" --deps

ex="$INBETWEEN_SRC/examples"
timeout 120 "$CLI_BIN" animate "$ex/square_hexagon/square.svg" "$ex/square_hexagon/hexagon.svg" \
  --format lottie --frames "$FRAMES" --out "$WORK/square_hexagon" -q >/dev/null
timeout 120 "$CLI_BIN" animate --project "$ex/bird/project.json" \
  --format lottie --frames "$FRAMES" --out "$WORK/bird" -q >/dev/null
for d in square_hexagon bird; do
  [[ -s "$WORK/$d/animation.lottie.json" ]] || { echo "FAIL: $d: no animation.lottie.json" >&2; exit 1; }
done

(cd "$WEB" && timeout 150 node e2e/lottie_test.mjs --frames "$FRAMES" --chromium "$CHROMIUM" \
  "$WORK/square_hexagon/animation.lottie.json" "$WORK/bird/animation.lottie.json")
