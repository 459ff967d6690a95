#!/usr/bin/env bash
# Inbetween parameters from the project file and the command line: `init` writes the flags into
# the project; stiffness regions (project only) reach the solver (a stiff left half changes the
# inbetweens but never the keys); a flag overrides the project's value.
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
echo ok
