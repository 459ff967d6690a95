#!/usr/bin/env bash
# Every `inbetween` subcommand on real files: init -> validate -> mesh -> animate (all formats)
# -> render, embedded; then against the real server: the session id is printed and inspect
# lists it. Malformed input exits 3 with a message and writes nothing.
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples/square_hexagon"
lib="$INBETWEEN_SRC/tests/e2e/lib"
cd "$WORK"
cp "$ex/square.svg" "$ex/hexagon.svg" .

"$CLI_BIN" init square.svg hexagon.svg -o project.json --frames 10 >/dev/null
python3 -c "import json; p=json.load(open('project.json')); assert p['version']==1 and len(p['drawings'])==2 and p['inbetween']['frames']==10, p"
"$CLI_BIN" validate --project project.json -q | grep -qx ok

"$CLI_BIN" mesh --project project.json --out mesh -q >/dev/null
python3 "$lib/check_multimesh.py" mesh/multimesh.json 2
[[ -f mesh/shape_1.svg && -f mesh/shape_2.svg ]]

"$CLI_BIN" animate --project project.json --out anim -q \
  --format svg,json,png,gif,webp,lottie,contact --size 128 >/dev/null
python3 "$lib/check_frames.py" anim/frames.json 10 0,9
for f in frame_0000.svg frame_0009.png animation.gif animation.webp animation.lottie.json contact_sheet.png; do
  [[ -s "anim/$f" ]] || { echo "missing anim/$f"; exit 1; }
done
head -c 6 anim/animation.gif | grep -q GIF89a

"$CLI_BIN" render anim/frames.json --out rendered --format png --size 64 -q >/dev/null
[[ -s rendered/frame_0005.png ]]

# Malformed input: every problem reported, exit code 3, no output directory.
printf '<svg xmlns="http://www.w3.org/2000/svg"><rect width="10"' > broken.svg
printf '<svg xmlns="http://www.w3.org/2000/svg"><g/></svg>' > empty.svg
set +e
"$CLI_BIN" validate square.svg broken.svg empty.svg -q > validate.out 2>&1; code=$?
"$CLI_BIN" animate square.svg broken.svg --out never -q 2>/dev/null; code2=$?
printf '{"version": 1, "drawings": ["square.svg", "hexagon.svg"], "inbetween": {"tau": "x"}}' > bad.json
"$CLI_BIN" animate --project bad.json --out never -q 2> bad.err; code3=$?
set -e
[[ $code -eq 3 && $code2 -eq 3 && $code3 -eq 3 ]] || { echo "exit codes $code $code2 $code3"; cat validate.out; exit 1; }
grep -q "drawing 2" validate.out && grep -q "drawing 3" validate.out || { cat validate.out; exit 1; }
grep -q '\$.inbetween.tau' bad.err || { cat bad.err; exit 1; }
[[ ! -e never ]] || { echo "a failed animate wrote output"; exit 1; }

# Against the real server: the session stays there and inspect finds it.
start_server
"$CLI_BIN" --server "$SERVER_ADDR" animate square.svg hexagon.svg --frames 4 --out remote -q > remote.out
sid=$(awk '/^session /{print $2}' remote.out)
[[ -n "$sid" ]] || { echo "no session id printed"; cat remote.out; exit 1; }
"$CLI_BIN" --server "$SERVER_ADDR" inspect > list.out
grep -q "^$sid" list.out || { echo "inspect does not list $sid"; cat list.out; exit 1; }
grep "^$sid" list.out | grep -q $'\t2 drawings\t' || { echo "inspect miscounts drawings"; cat list.out; exit 1; }
"$CLI_BIN" --server "$SERVER_ADDR" inspect "$sid" | grep -q "STAGE_MULTIMESH"

# validate uploads a project's drawings as animate does: a cut given in the project file (not in
# the SVG) makes the split drawings agree; without it validate names the differing drawing.
mkdir -p cutproj
sed '/class="cut"/d' "$INBETWEEN_SRC/examples/split/1_whole.svg" > cutproj/1_whole.svg
cp "$INBETWEEN_SRC/examples/split/2_two.svg" cutproj/
cat > cutproj/project.json <<'JSON'
{"version": 1,
 "drawings": [{"file": "1_whole.svg", "cuts": [[[60, 20], [60, 80]]]}, "2_two.svg"],
 "inbetween": {"frames": 6}}
JSON
"$CLI_BIN" validate --project cutproj/project.json -q > cutproj/ok.out 2>&1 ||
  { echo "validate refused the project's cut"; cat cutproj/ok.out; exit 1; }
grep -qx ok cutproj/ok.out || { cat cutproj/ok.out; exit 1; }
python3 - <<'PY'
import json
p = json.load(open("cutproj/project.json"))
p["drawings"][0] = "1_whole.svg"
json.dump(p, open("cutproj/nocut.json", "w"))
PY
if "$CLI_BIN" validate --project cutproj/nocut.json -q > cutproj/bad.out 2>&1; then
  echo "validate accepted drawings of different topology"; cat cutproj/bad.out; exit 1
fi
# (validate also prints each drawing's import facts: the build's problem is the one to find.)
grep -q "^build: .*drawing 1" cutproj/bad.out || { cat cutproj/bad.out; exit 1; }
# inspect --project: each drawing's class (the cut makes drawing 1 two components) and the
# multimesh's numbers; without the cut, the classes that differ and why it cannot be built.
"$CLI_BIN" -q inspect --project cutproj/project.json > cutproj/inspect.out 2>/dev/null
grep -q "^drawing 1 .*1 cuts.*; 2 components, 0 holes$" cutproj/inspect.out &&
  grep -q "^drawing 2 .*; 2 components, 0 holes$" cutproj/inspect.out &&
  grep -qE "^multimesh: 2 shapes, [0-9]+ vertices, [0-9]+ triangles, map energy" cutproj/inspect.out ||
  { echo "inspect --project:"; cat cutproj/inspect.out; exit 1; }
"$CLI_BIN" -q inspect --project cutproj/nocut.json > cutproj/inspect_bad.out 2>/dev/null
grep -q "^drawing 1 .*; 1 component, 0 holes$" cutproj/inspect_bad.out &&
  grep -q "^multimesh: not built: .*same topology" cutproj/inspect_bad.out ||
  { echo "inspect --project (no cut):"; cat cutproj/inspect_bad.out; exit 1; }
echo ok
