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

# One piece vs two: the dumbbell is cut across its bar (4 high) and animates into two squares.
svg "M0 0H20V8H30V0H50V20H30V12H20V20H0Z" dumbbell.svg
svg "M0 0H20V20H0Z M30 0H50V20H30Z" apart.svg
"$CLI_BIN" animate dumbbell.svg apart.svg --auto-topology --frames 5 --format json --out split \
  > /dev/null 2> split.err
grep -q "auto-topology: drawing 1: cut across the piece" split.err
python3 "$lib/check_frames.py" split/frames.json 5 0,4
python3 - <<'PY'
import json
(x0, y0), (x1, y1) = json.load(open("split/project.json"))["drawings"][0]["cuts"][0]
assert abs(x0 - x1) < 1e-9 and 20 <= x0 <= 30 and abs(abs(y1 - y0) - 4.08) < 1e-6, (x0, y0, x1, y1)
PY

# A thin ring cannot be split by a straight cut: refused with advice (exit 3), nothing written.
svg "M10 50A40 40 0 1 0 90 50A40 40 0 1 0 10 50Z M12 50A38 38 0 1 0 88 50A38 38 0 1 0 12 50Z" thin_ring.svg
svg "M0 0H10V10H0Z M2 2H4V4H2Z M20 0H30V10H20Z M22 2H24V4H22Z" two_rings.svg
set +e
"$CLI_BIN" animate thin_ring.svg two_rings.svg --auto-topology --out never2 -q 2> comp.err; code=$?
set -e
[[ $code -eq 3 ]] || { echo "exit $code for an unsplittable ring"; cat comp.err; exit 1; }
grep -q "no straight cut splits a piece of drawing 1" comp.err
[[ ! -e never2 ]]
echo ok
