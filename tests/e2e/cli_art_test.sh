#!/usr/bin/env bash
# Every output shows the drawings' art: two layered drawings (a yellow face with a black outline
# stroke and black eyes; the eyes move down in the second) animated embedded and against a
# server. The SVG frames hold the layers as <path>s with their colours, the key frames' PNGs are
# black where the eyes are and yellow between them, frames.json carries the art; --render
# silhouette and `render --render silhouette` give back one colour.
source "$(dirname "$0")/lib/common.sh"
here="$INBETWEEN_SRC/tests/e2e"
cd "$WORK"

face() {  # face EYE_Y
  cat <<SVG
<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">
  <circle id="face" data-layer="face" cx="50" cy="50" r="40" fill="#ffd700" stroke="#000000" stroke-width="3"/>
  <circle id="left" data-layer="left-eye" cx="35" cy="$1" r="7" fill="#000000"/>
  <circle id="right" data-layer="right-eye" cx="65" cy="$1" r="7" fill="#000000"/>
</svg>
SVG
}
face 38 > face_1.svg
face 55 > face_2.svg

formats=svg,json,png,gif,webp,contact
"$CLI_BIN" animate face_1.svg face_2.svg --frames 5 --method linear --size 200 --format "$formats" \
  --out art -q > /dev/null
python3 "$here/cli_art_check.py" art art
start_server
"$CLI_BIN" --server "$SERVER_ADDR" animate face_1.svg face_2.svg --frames 5 --method linear \
  --size 200 --format "$formats" --out remote -q > /dev/null
python3 "$here/cli_art_check.py" remote art

"$CLI_BIN" animate face_1.svg face_2.svg --frames 5 --method linear --size 200 --format svg,png \
  --render silhouette --out sil -q > /dev/null
python3 "$here/cli_art_check.py" sil silhouette
"$CLI_BIN" render art/frames.json --out rsil --format svg,png --size 200 --render silhouette \
  -q > /dev/null
python3 "$here/cli_art_check.py" rsil silhouette
"$CLI_BIN" render art/frames.json --out rart --format svg,png --size 200 -q > /dev/null
python3 "$here/cli_art_check.py" rart art
echo ok
