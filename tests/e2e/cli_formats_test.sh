#!/usr/bin/env bash
# Every output format of `inbetween animate` on one example with fill colours: the Lottie file
# validates against tests/data/lottie_subset.schema.json (Debian's python3-jsonschema), the GIF
# and WebP decode to the right frame count and size, the SVG frames carry the drawings' fill;
# `render --fill` overrides it; inbetween parameters from flags reach the server (key times move
# the middle key; ease-in-out and Catmull-Rom timing change the weights the way they should).
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
# --overlay mesh draws the triangle edges (as --mesh), the default does not.
"$CLI_BIN" render all/frames.json --out overlay --format svg --overlay mesh -q > /dev/null
grep -q 'stroke="#222"' overlay/frame_0003.svg
! grep -q 'stroke="#222"' over/frame_0003.svg

# Key times from the command line: 3 drawings, 13 frames, keys at t = 0, 0.25, 1.
"$CLI_BIN" animate --project "$ex/project.json" --frames 13 --key-times 0,0.25,1 \
  --timing linear --tau 0.2 --alpha 0.3 --lambda 2 --max-iterations 10 --format json --out keyed -q > /dev/null
python3 -c "
import json; d = json.load(open('keyed/frames.json'))
assert d['keys'] == [0, 3, 12], d['keys']
"

# Timing flags: with 9 frames and 3 keys the second frame sits a quarter into segment 1. Linear
# gives drawing 2 the weight 0.25; ease-in-out starts slower (less), ease 0 is linear again, and
# the segment midpoint stays 0.5 by symmetry. Catmull-Rom on a 4-key example differs from linear
# between keys and still hits every key (one-hot weights).
for run in "lin --timing linear" "ease8 --ease 0.8" "ease0 --timing ease-in-out --ease 0"; do
  set -- $run
  "$CLI_BIN" animate --project "$ex/project.json" --frames 9 "${@:2}" --format json --out "$1" -q > /dev/null
done
arcs="$INBETWEEN_SRC/examples/principles_arcs/project.json"
"$CLI_BIN" animate --project "$arcs" --frames 9 --timing catmull-rom --format json --out cr -q > /dev/null
"$CLI_BIN" animate --project "$arcs" --frames 9 --timing linear --format json --out crlin -q > /dev/null
python3 - <<'PY'
import json
w = lambda run, f: json.load(open(f"{run}/frames.json"))["frames"][f]["weights"]
assert abs(w("lin", 1)[1] - 0.25) < 1e-12, w("lin", 1)
assert w("ease8", 1)[1] < 0.25 - 0.01, w("ease8", 1)
assert abs(w("ease8", 2)[1] - 0.5) < 1e-9, w("ease8", 2)
assert all(abs(a - b) < 1e-12 for a, b in zip(w("ease0", 1), w("lin", 1))), w("ease0", 1)
cr = json.load(open("cr/frames.json"))
lin = json.load(open("crlin/frames.json"))
assert cr["keys"] == lin["keys"], (cr["keys"], lin["keys"])
for d, k in enumerate(cr["keys"]):
    assert cr["frames"][k]["weights"] == [1.0 if j == d else 0.0 for j in range(4)], cr["frames"][k]
between = [f for f in range(9) if f not in cr["keys"]]
assert max(max(abs(a - b) for a, b in zip(cr["frames"][f]["weights"], lin["frames"][f]["weights"]))
           for f in between) > 1e-3, "catmull-rom weights equal linear ones"
PY
echo ok
