#!/usr/bin/env bash
# --auto-topology end to end: drawings whose topology differs fail with per-drawing advice; with
# the flag the CLI proposes cuts, writes them to OUT/project.json (or rewrites --project), and
# the frames are valid; the written project then works without the flag.
source "$(dirname "$0")/lib/common.sh"
lib="$INBETWEEN_SRC/tests/e2e/lib"
cd "$WORK"
svg() { printf '<svg xmlns="http://www.w3.org/2000/svg"><path fill="#4a7bd0" fill-rule="evenodd" d="%s"/></svg>\n' "$1" > "$2"; }
svg "M10 10H90V90H10Z" disc.svg
svg "M10 10H90V90H10Z M30 30H70V70H30Z" ring.svg
svg "M0 0H120V60H0Z M20 20H40V40H20Z" one_hole.svg
svg "M0 0H120V60H0Z M20 20H40V40H20Z M80 25H90V35H80Z" two_holes.svg

# Without the flag: exit 3, each drawing's class, and what to do.
set +e
"$CLI_BIN" animate disc.svg ring.svg --frames 5 --out never -q 2> plain.err; code=$?
set -e
[[ $code -eq 3 ]] || { echo "exit $code without --auto-topology"; cat plain.err; exit 1; }
grep -q "drawing 1: 1 component, 0 holes; drawing 2: 1 component, 1 hole" plain.err
grep -q -- "--auto-topology" plain.err
[[ ! -e never ]]

# Disc vs ring: one cut in drawing 2, written to OUT/project.json.
"$CLI_BIN" animate disc.svg ring.svg --auto-topology --frames 5 --format json --out ring_out \
  > /dev/null 2> ring.err
grep -q "auto-topology: drawing 2: cut from the hole" ring.err
python3 "$lib/check_frames.py" ring_out/frames.json 5 0,4
python3 - <<'PY'
import json
p = json.load(open("ring_out/project.json"))
assert "cuts" not in p["drawings"][0], p
cuts = p["drawings"][1]["cuts"]
assert len(cuts) == 1 and len(cuts[0]) == 2, cuts
(x0, y0), (x1, y1) = cuts[0]
# Shortest hole-to-outline cut across a 20 wide band (plus 1% overhang at each end).
assert abs(((x1 - x0) ** 2 + (y1 - y0) ** 2) ** 0.5 - 20.4) < 1e-6, cuts
PY
# The written project works on its own, without the flag.
"$CLI_BIN" animate --project ring_out/project.json --frames 5 --format json --out again -q > /dev/null
python3 "$lib/check_frames.py" again/frames.json 5 0,4

# Two holes vs one, with --project: the file itself gets the cut of the smaller hole.
printf '{"version": 1, "drawings": ["one_hole.svg", "two_holes.svg"], "inbetween": {"frames": 5}}\n' > holes.json
"$CLI_BIN" mesh --project holes.json --auto-topology --out holes_mesh -q > /dev/null
python3 "$lib/check_multimesh.py" holes_mesh/multimesh.json 2
python3 - <<'PY'
import json
p = json.load(open("holes.json"))
assert p["inbetween"]["frames"] == 5, p
assert "cuts" not in p["drawings"][0]
(x0, y0), (x1, y1) = p["drawings"][1]["cuts"][0]
assert 80 <= x0 <= 90 and y1 > 60, p["drawings"][1]["cuts"]  # small hole -> bottom edge (25)
PY
[[ ! -e holes_mesh/project.json ]]

# Different component counts are refused with advice (exit 3), nothing written.
printf '<svg xmlns="http://www.w3.org/2000/svg"><rect x="0" y="0" width="10" height="10"/><rect x="20" y="0" width="10" height="10"/></svg>\n' > two.svg
set +e
"$CLI_BIN" animate disc.svg two.svg --auto-topology --out never2 -q 2> comp.err; code=$?
set -e
[[ $code -eq 3 ]] || { echo "exit $code for differing components"; cat comp.err; exit 1; }
grep -q "drawing 2 has 2 components" comp.err
[[ ! -e never2 ]]
echo ok
