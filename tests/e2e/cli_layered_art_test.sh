#!/usr/bin/env bash
# The art targets, measured on the rendered frames (tests/e2e/cli_layered_art_check.py):
# - keys reproduced: every key frame the CLI renders (`animate --format png --transparent`,
#   LAYERED_ART_SIZE px wide, default 512) matches its input drawing rendered by an independent
#   renderer (rsvg-convert, librsvg2-bin) in the same viewport: IoU of painted pixels >= MIN_IOU
#   and mean colour error <= MAX_COLOR_ERROR percent. On the layered examples (examples/layered_*)
#   and on pairs of the OpenMoji corpus (tests/data/openmoji, the pairs cli_openmoji_test.sh
#   animates: a face and another expression, an animal and its variant; every
#   LAYERED_ART_PAIR_EVERYth, default 8; the pairs the service refuses are counted, not measured).
# - no art leaves its shape: in every frame of every layered example, every point of the art drawn
#   (frame_NNNN.svg) lies inside the frame's shape (frames.json) or within the gap tolerance.
# Prints a line per key drawing and per example and a summary; LAYERED_ART_KEEP=DIR keeps the
# frames, the references and results.jsonl there.
source "$(dirname "$0")/lib/common.sh"
MIN_IOU=0.98
MAX_COLOR_ERROR=2
here="$INBETWEEN_SRC/tests/e2e"
size=${LAYERED_ART_SIZE:-512}
pair_every=${LAYERED_ART_PAIR_EVERY:-8}
PY=/usr/bin/python3  # Debian's python3 with python3-numpy and python3-pil (scripts/setup)
check="$here/cli_layered_art_check.py"
results="$WORK/results.jsonl"
command -v rsvg-convert >/dev/null || { echo "FAIL: no rsvg-convert (scripts/setup)"; exit 1; }
$PY -c 'import numpy, PIL' || { echo "FAIL: no python3-numpy / python3-pil (scripts/setup)"; exit 1; }
: > "$results"

count=0
for project in "$INBETWEEN_SRC"/examples/layered_*/project.json; do
  dir=$(dirname "$project") name=$(basename "$(dirname "$project")")
  out="$WORK/$name"
  "$CLI_BIN" animate --project "$project" --format svg,png,json --size "$size" --transparent \
    --out "$out" -q > "$WORK/$name.log" 2>&1 ||
    { echo "example $name: animate failed"; cat "$WORK/$name.log"; exit 1; }
  mapfile -t drawings < <($PY -c 'import json, sys
for d in json.load(open(sys.argv[1]))["drawings"]:
    print(d if isinstance(d, str) else d["file"])' "$project")
  $PY "$check" keys "$out" "$results" "$name" "${drawings[@]/#/$dir/}"
  $PY "$check" inside "$out" "$results" "$name"
  count=$((count + 1))
done
[[ $count -ge 4 ]] || { echo "FAIL: only $count layered examples"; exit 1; }

"$INBETWEEN_SRC/tests/data/openmoji/prepare.sh"
package="$INBETWEEN_SRC/tests/data/openmoji/node_modules/openmoji"
python3 "$here/cli_openmoji_check.py" pairs "$package" "$pair_every" > "$WORK/pairs"
while read -r a b; do
  name="openmoji_${a}_${b}" out="$WORK/openmoji/${a}_${b}"
  set +e
  timeout -k 5 120 "$CLI_BIN" animate "$package/color/svg/$a.svg" "$package/color/svg/$b.svg" \
    --frames 2 --format png,json --size "$size" --transparent --out "$out" -q \
    > "$WORK/$name.log" 2>&1
  code=$?
  set -e
  if [[ $code -eq 3 ]]; then  # refused (cli_openmoji_test.sh judges refusals)
    echo "{\"kind\": \"refused\", \"name\": \"$name\"}" >> "$results"
    continue
  fi
  [[ $code -eq 0 ]] || { echo "pair $a $b: animate exit $code"; cat "$WORK/$name.log"; exit 1; }
  $PY "$check" keys "$out" "$results" "$name" "$package/color/svg/$a.svg" \
    "$package/color/svg/$b.svg"
done < "$WORK/pairs"

set +e
$PY "$check" summary "$results" "$MIN_IOU" "$MAX_COLOR_ERROR"
code=$?
set -e
if [[ -n "${LAYERED_ART_KEEP:-}" ]]; then
  mkdir -p "$LAYERED_ART_KEEP"
  cp -r "$WORK"/. "$LAYERED_ART_KEEP/"
  echo "kept in $LAYERED_ART_KEEP"
fi
exit $code
