#!/usr/bin/env bash
# Every output format of `inbetween animate` on one example with fill colours: the Lottie file
# validates against tests/data/lottie_subset.schema.json (Debian's python3-jsonschema), the GIF
# and WebP decode to the right frame count and size, the SVG frames carry the drawings' fill;
# `render --fill` overrides it; inbetween parameters from flags reach the server (linear timing
# with key times moves the middle key).
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples/principles_squash_stretch"
here="$INBETWEEN_SRC/tests/e2e"
cd "$WORK"

"$CLI_BIN" animate --project "$ex/project.json" --frames 8 --out all -q \
  --format svg,json,png,gif,webp,lottie,contact --size 96 > /dev/null
/usr/bin/python3 "$here/cli_formats_check.py" all 8 "$INBETWEEN_SRC/tests/data/lottie_subset.schema.json"
fill=$(python3 -c "import json; print(json.load(open('all/frames.json'))['fills'][0])")
grep -q "fill=\"$fill\"" "$ex/1_round.svg" || { echo "fill $fill is not the drawing's"; exit 1; }

# An explicit colour wins over the drawings' fills.
"$CLI_BIN" render all/frames.json --out over --format svg --fill '#00ff00' -q > /dev/null
grep -q 'fill="#00ff00"' over/frame_0000.svg
! grep -q "fill=\"$fill\"" over/frame_0000.svg

# Key times from the command line: 3 drawings, 13 frames, keys at t = 0, 0.25, 1.
"$CLI_BIN" animate --project "$ex/project.json" --frames 13 --key-times 0,0.25,1 \
  --timing linear --tau 0.2 --alpha 0.3 --lambda 2 --max-iterations 10 --format json --out keyed -q > /dev/null
python3 -c "
import json; d = json.load(open('keyed/frames.json'))
assert d['keys'] == [0, 3, 12], d['keys']
"
echo ok
