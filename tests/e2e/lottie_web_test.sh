#!/usr/bin/env bash
# The CLI's Lottie output plays in lottie-web: `inbetween animate --format lottie --frames 12` on
# examples/square_hexagon as the silhouette (--render silhouette), examples/bird (--project) and
# tests/data/lottie_face as art (a layer per art layer: a stroked head and a stroked mouth that
# morph, two eye dots that cross-fade into two eye strokes; also as PNG frames), each file
# validated against tests/data/lottie_subset.schema.json (Debian's python3-jsonschema); then
# client/web/e2e/lottie_test.mjs loads each animation.lottie.json with lottie-web (pinned in
# client/web/package.json, served from node_modules on 127.0.0.1) in Debian's headless Chromium
# via playwright-core: no page error, no data_failed/error event, totalFrames 12, the visible
# paths differ between frames 0, 6 and 11 and stay inside w×h; for the face, at key frame 0,
# middle frame 6 and key frame 11: 5, 7 and 5 visible paths (lottie-web draws a fill and a stroke
# as two), 4 of them fading mid-way, the drawings' fill and stroke colours, and the page's pixels
# those of the CLI's PNG frame (cairo; under 1 % of the pixels off); corrupted copies
# (keyframes removed, op changed, vertices off the canvas, truncated JSON, a 404, the face's
# layers spanning every frame, the face's layers in reverse paint order) must each be caught.
source "$(dirname "$0")/lib/common.sh"
WEB="$INBETWEEN_SRC/client/web"
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
FRAMES=12
[[ -x "$CHROMIUM" ]] || { echo "FAIL: $CHROMIUM not found (scripts/setup installs chromium)" >&2; exit 1; }

# Only the npm packages: rebuilding dist/ here could break a web_test running alongside.
"$WEB/scripts/prepare.sh" --deps

ex="$INBETWEEN_SRC/examples"
face="$INBETWEEN_SRC/tests/data/lottie_face"
timeout 120 "$CLI_BIN" animate "$ex/square_hexagon/square.svg" "$ex/square_hexagon/hexagon.svg" \
  --render silhouette --format lottie --frames "$FRAMES" --out "$WORK/square_hexagon" -q >/dev/null
timeout 120 "$CLI_BIN" animate --project "$ex/bird/project.json" \
  --format lottie --frames "$FRAMES" --out "$WORK/bird" -q >/dev/null
timeout 120 "$CLI_BIN" animate "$face/1_open.svg" "$face/2_closed.svg" \
  --format lottie,png --frames "$FRAMES" --out "$WORK/face" -q >/dev/null
for d in square_hexagon bird face; do
  [[ -s "$WORK/$d/animation.lottie.json" ]] || { echo "FAIL: $d: no animation.lottie.json" >&2; exit 1; }
done
/usr/bin/python3 - "$INBETWEEN_SRC/tests/data/lottie_subset.schema.json" "$WORK" <<'PY'
import json, sys
import jsonschema
schema = json.load(open(sys.argv[1]))
docs = {d: json.load(open(f"{sys.argv[2]}/{d}/animation.lottie.json"))
        for d in ("square_hexagon", "bird", "face")}
for doc in docs.values():
    jsonschema.Draft202012Validator(schema).validate(doc)
# --render silhouette: the one silhouette layer (its paths are the outline's loops).
assert [l["nm"] for l in docs["square_hexagon"]["layers"]] == ["Shape"], docs["square_hexagon"]["layers"]
layers = docs["face"]["layers"]
assert len(layers) == 6, [l["nm"] for l in layers]  # head, mouth, 2 + 2 eyes
assert sorted((l["ip"], l["op"]) for l in layers) == [(0, 11)] * 2 + [(0, 12)] * 2 + [(1, 12)] * 2, \
    [(l["ip"], l["op"]) for l in layers]
PY

# Key 1: head fill #f2c79b, outline and eye dots #2b2233, mouth #8a2b2b; key 2: the eyes are
# #2b2233 strokes. Mid-way both keys' eyes show, faded.
expect='{"0":  {"paths": 5, "faded": 0, "fill": ["#f2c79b", "#2b2233"], "stroke": ["#2b2233", "#8a2b2b"]},
         "6":  {"paths": 7, "faded": 4, "fill": ["#f2c79b", "#2b2233"], "stroke": ["#2b2233", "#8a2b2b"]},
         "11": {"paths": 5, "faded": 0, "fill": ["#f2c79b"], "stroke": ["#2b2233", "#8a2b2b"]}}'
(cd "$WEB" && timeout 150 node e2e/lottie_test.mjs --frames "$FRAMES" --chromium "$CHROMIUM" \
  "$WORK/square_hexagon/animation.lottie.json" "$WORK/bird/animation.lottie.json" \
  --layered "$WORK/face/animation.lottie.json" --expect "$expect" --reference "$WORK/face")
