#!/usr/bin/env bash
# Inbetween parameters from the project file and the command line: `init` writes the flags into
# the project; stiffness regions (project only) reach the solver (a stiff left half changes the
# inbetweens but never the keys); a flag overrides the project's value. Import settings likewise:
# `init` writes them, `validate` reports each drawing's import with them, a flag overrides them
# and a value out of range is refused naming the flag.
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples/principles_squash_stretch"
lib="$INBETWEEN_SRC/tests/e2e/lib"
cd "$WORK"
cp "$ex"/*.svg .

"$CLI_BIN" init 1_round.svg 2_stretch.svg 3_squash.svg -o p.json --frames 7 --tau 0.2 \
  --alpha 0.25 --max-iterations 30 --key-times 0,0.4,1 --ease 0.5 > /dev/null
python3 - <<'PY'
import json
p = json.load(open("p.json"))
ib = p["inbetween"]
assert ib["frames"] == 7 and ib["tau"] == 0.2 and ib["alpha"] == 0.25, ib
assert ib["max_iterations"] == 30 and ib["timing"] == "ease_in_out" and ib["ease"] == [0.5, 0.5], ib
assert [d["key_time"] for d in p["drawings"]] == [0, 0.4, 1], p["drawings"]
PY
"$CLI_BIN" animate --project p.json --format json --out plain -q > /dev/null
python3 "$lib/check_frames.py" plain/frames.json 7 0,2,6 > /dev/null

# A stiff region over the left half of drawing 1 (kappa 50).
python3 - <<'PY'
import json
frames = json.load(open("plain/frames.json"))
xs = [v[0] for v in frames["frames"][0]["vertices"]]
ys = [v[1] for v in frames["frames"][0]["vertices"]]
mid, lo, hi = (min(xs) + max(xs)) / 2, min(ys) - 1, max(ys) + 1
p = json.load(open("p.json"))
p["inbetween"]["stiffness"] = [{"polygon": [[min(xs) - 1, lo], [mid, lo], [mid, hi], [min(xs) - 1, hi]],
                                "kappa": 50}]
json.dump(p, open("stiff.json", "w"))
PY
"$CLI_BIN" animate --project stiff.json --format json --out stiff -q > /dev/null
python3 "$lib/check_frames.py" stiff/frames.json 7 0,2,6 > /dev/null
python3 - <<'PY'
import json
a = json.load(open("plain/frames.json"))["frames"]
b = json.load(open("stiff/frames.json"))["frames"]
diff = lambda f: max(abs(p - q) for u, v in zip(a[f]["vertices"], b[f]["vertices"]) for p, q in zip(u, v))
for key in (0, 2, 6):
    assert diff(key) < 1e-9, f"key frame {key} moved by {diff(key)}"
assert max(diff(f) for f in (1, 3, 4, 5)) > 1e-6, "the stiffness region changed nothing"
PY

# A flag overrides the project: --key-times moves the middle key back to the centre.
"$CLI_BIN" animate --project p.json --key-times 0,0.5,1 --format json --out keyed -q > /dev/null
python3 -c "import json; k = json.load(open('keyed/frames.json'))['keys']; assert k == [0, 3, 6], k"

# Import settings. A face with an eye painted on it, and text (not imported: a warning).
cat > face.svg <<'SVG'
<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">
  <circle id="face" cx="50" cy="50" r="40" fill="#f0c080"/>
  <circle id="eye" cx="35" cy="40" r="6" fill="#203040" stroke="#000000" stroke-width="1.5"/>
  <text id="label" x="10" y="95">face</text>
</svg>
SVG
"$CLI_BIN" init face.svg face.svg -o imp.json --gap-tolerance 0.01 --min-area-fraction 0 > /dev/null
python3 - <<'PY'
import json
i = json.load(open("imp.json"))["import"]
assert i == {"gap_tolerance": 0.01, "min_area_fraction": 0}, i
PY
"$CLI_BIN" validate --project imp.json -q > imp.out 2>/dev/null || { cat imp.out; exit 1; }
facts='silhouette [a-z ]+; [0-9]+ art layers?; gaps closed [0-9]+, slits closed [0-9]+, islands dropped [0-9]+, holes dropped [0-9]+'
for n in 1 2; do
  grep -qE "^drawing $n \(.*face.svg\): $facts \(gap width [0-9.e+-]*[1-9][0-9.e+-]*, area threshold 0\)$" imp.out &&
    grep -q "^drawing $n (.*face.svg): warning: .*text" imp.out || { cat imp.out; exit 1; }
done
grep -qx ok imp.out || { cat imp.out; exit 1; }
# The flag overrides the project: no gap closing.
"$CLI_BIN" validate --project imp.json --gap-tolerance 0 -q > imp0.out 2>/dev/null || { cat imp0.out; exit 1; }
grep -qE "^drawing 1 .*\(gap width 0, area threshold 0\)$" imp0.out || { cat imp0.out; exit 1; }
# Out of range: exit 3 naming the flag (validate and animate alike); not a number: usage, exit 2.
set +e
"$CLI_BIN" validate --project imp.json --gap-tolerance 0.2 -q > bad_gap.out 2>&1; code=$?
"$CLI_BIN" animate face.svg face.svg --min-area-fraction 1 --out never -q 2> bad_area.err; code2=$?
"$CLI_BIN" animate face.svg face.svg --gap-tolerance wide --out never -q 2> bad_nan.err; code3=$?
set -e
[[ $code -eq 3 && $code2 -eq 3 && $code3 -eq 2 ]] || { echo "exit codes $code $code2 $code3"; exit 1; }
grep -qF -- "--gap-tolerance: value 0.2 is not in [0, 0.1]" bad_gap.out || { cat bad_gap.out; exit 1; }
grep -qF -- "--min-area-fraction: value 1 is not in [0, 0.1]" bad_area.err || { cat bad_area.err; exit 1; }
grep -qF -- "--gap-tolerance" bad_nan.err || { cat bad_nan.err; exit 1; }
[[ ! -e never ]] || { echo "a refused animate wrote output"; exit 1; }
echo ok
