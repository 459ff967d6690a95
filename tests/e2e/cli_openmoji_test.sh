#!/usr/bin/env bash
# Layered drawings: OpenMoji colour emoji (openmoji 17.0.0 from npm, CC BY-SA 4.0, pinned in
# tests/data/openmoji/package-lock.json and installed by tests/data/openmoji/prepare.sh; never
# committed). Each is a stack of fills and strokes painted over each other (a face, eyes and
# mouth painted on it, black line work over the colours): its outline is the boundary of the
# union of all paint, every element is kept as art (docs/hardening.md, "Layered drawings").
# Selection (tests/e2e/cli_openmoji_check.py; rows of data/openmoji.csv in the file's order,
# skin-tone variants, i.e. a non-empty skintone column, left out everywhere):
#   drawings: groups smileys-emotion, people-body, animals-nature, food-drink, travel-places,
#     objects (no flags, symbols, extras) with at least 3 painted elements (filled or stroked);
#     of those every OPENMOJI_EVERYth (default 6: 218 drawings), starting with the first;
#   pairs of related drawings: a face and the same face with another expression (two rows next
#     to each other in the csv within one subgroup of face-smiling, face-affection, face-tongue,
#     face-hand, face-neutral-skeptical, face-sleepy, face-unwell, face-concerned,
#     face-negative, face-costume, cat-face, monkey-face) and an animal and its variant (rows of
#     one animal-* subgroup whose annotations end in the same noun: dog / guide dog, bear /
#     polar bear); 124 pairs, of those every OPENMOJI_PAIR_EVERYth (default 2: 62 pairs),
#     starting with the first.
# Stage 1, import: `inbetween validate SVG SVG` (the drawing against itself): imported (exit 0,
#   "ok"; or exit 3 with only a "build:" problem: imported, not built with itself, counted apart)
#   or refused (exit 3, the problem lines name the drawing and the reason). The import's
#   warnings are counted by cause.
# Stage 2, pairs: `inbetween animate A B --frames 6 --format json`: animated (exit 0, frames.json
#   passes tests/e2e/lib/check_frames.py: every frame valid, 0 inverted triangles, 0 boundary
#   overlaps) or refused (exit 3, an "error:" line, nothing written to --out but
#   --auto-topology's project.json). Pairs are also counted apart for faces and animals.
# Anything else (a signal, a timeout of OPENMOJI_TIMEOUT s, another exit code, broken frames)
# fails the test, and so do rates below MIN_IMPORT_PERCENT / MIN_ANIMATE_PERCENT (the product's
# targets). Refusals are counted by cause (the message without numbers, places, file names).
# The summary table is printed and written as JSON (summary.json) with every run's outcome;
# OPENMOJI_KEEP=DIR keeps it and the runs' logs there. OPENMOJI_EVERY=1 OPENMOJI_PAIR_EVERY=1
# runs everything (1,304 drawings, 124 pairs); OPENMOJI_ONLY="1F600 1F600+1F603" runs just those
# drawings and pairs (no rate limits); OPENMOJI_JOBS (default 2) CLI runs at once;
# OPENMOJI_ANIMATE_FLAGS adds flags to animate (e.g. --auto-topology).
source "$(dirname "$0")/lib/common.sh"
MIN_IMPORT_PERCENT=95
MIN_ANIMATE_PERCENT=90
here="$INBETWEEN_SRC/tests/e2e"
data="$INBETWEEN_SRC/tests/data/openmoji"
"$data/prepare.sh"
package="$data/node_modules/openmoji"
every=${OPENMOJI_EVERY:-6}
pair_every=${OPENMOJI_PAIR_EVERY:-2}
jobs=${OPENMOJI_JOBS:-2}
frames=6
export CLI_BIN package WORK frames
export OPENMOJI_TIMEOUT=${OPENMOJI_TIMEOUT:-120} OPENMOJI_ANIMATE_FLAGS=${OPENMOJI_ANIMATE_FLAGS:-}
[[ -x "$CLI_BIN" ]] || { echo "FAIL: no CLI at $CLI_BIN"; exit 1; }

if [[ -n "${OPENMOJI_ONLY:-}" ]]; then
  tr ' ' '\n' <<< "$OPENMOJI_ONLY" | grep -v '+' | grep . > "$WORK/drawings" || true
  tr ' ' '\n' <<< "$OPENMOJI_ONLY" | grep '+' | tr '+' ' ' > "$WORK/pairs" || true
else
  python3 "$here/cli_openmoji_check.py" drawings "$package" "$every" > "$WORK/drawings"
  python3 "$here/cli_openmoji_check.py" pairs "$package" "$pair_every" > "$WORK/pairs"
  n_drawings=$(wc -l < "$WORK/drawings") n_pairs=$(wc -l < "$WORK/pairs")
  # The floors hold for the default sampling or denser (the selection itself is checked).
  [[ $every -gt 6 || $n_drawings -ge 200 ]] || { echo "FAIL: only $n_drawings drawings"; exit 1; }
  [[ $pair_every -gt 3 || $n_pairs -ge 60 ]] || { echo "FAIL: only $n_pairs pairs"; exit 1; }
fi

# One CLI run: RUNS/ID.{cmd,code,out,err[,dir]}, judged afterwards by cli_openmoji_check.py.
run_one() {
  local id=$1
  shift
  printf '%q ' "$@" > "$WORK/runs/$id.cmd"
  set +e
  timeout -k 5 "$OPENMOJI_TIMEOUT" "$@" > "$WORK/runs/$id.out" 2> "$WORK/runs/$id.err"
  echo $? > "$WORK/runs/$id.code"
}
run_drawing() {
  local svg="$package/color/svg/$1.svg"
  run_one "d-$1" "$CLI_BIN" validate "$svg" "$svg"  # the CLI takes 2 to 16 drawings
}
run_pair() {
  local id="p-$1_$2" out="$WORK/out/$1_$2"
  echo "$out" > "$WORK/runs/$id.dir"
  # shellcheck disable=SC2086  # OPENMOJI_ANIMATE_FLAGS: words on purpose
  run_one "$id" "$CLI_BIN" animate "$package/color/svg/$1.svg" "$package/color/svg/$2.svg" \
    --frames "$frames" --format json --size 96 --out "$out" -q $OPENMOJI_ANIMATE_FLAGS
}
export -f run_one run_drawing run_pair
mkdir -p "$WORK/runs" "$WORK/out"

start=$SECONDS
xargs -a "$WORK/drawings" -P "$jobs" -n 1 bash -c 'run_drawing "$1"' _
import_seconds=$((SECONDS - start))
start=$SECONDS
xargs -a "$WORK/pairs" -P "$jobs" -n 2 bash -c 'run_pair "$1" "$2"' _
animate_seconds=$((SECONDS - start))

limits=("$MIN_IMPORT_PERCENT" "$MIN_ANIMATE_PERCENT")
[[ -n "${OPENMOJI_ONLY:-}" ]] && limits=(0 0)
set +e
python3 "$here/cli_openmoji_check.py" report "$package" "$WORK/runs" "$frames" "${limits[@]}" \
  "$WORK/summary.json"
code=$?
set -e
sampled="(OPENMOJI_ONLY)"
[[ -n "${OPENMOJI_ONLY:-}" ]] || sampled="(1 in $every, pairs 1 in $pair_every)"
echo "openmoji 17.0.0: $(wc -l < "$WORK/drawings") drawings, $(wc -l < "$WORK/pairs") pairs" \
     "$sampled, $jobs at once: import ${import_seconds}s," \
     "animate ${animate_seconds}s, total ${SECONDS}s; CLI $CLI_BIN" \
     "($(date -r "$CLI_BIN" '+%Y-%m-%d %H:%M:%S'))"
if [[ -n "${OPENMOJI_KEEP:-}" ]]; then  # the summary, every run's logs and frames.json
  mkdir -p "$OPENMOJI_KEEP"
  keep=$(cd "$OPENMOJI_KEEP" && pwd)
  cp "$WORK/summary.json" "$WORK/drawings" "$WORK/pairs" "$keep/"
  rm -rf "$keep/runs" "$keep/out" && cp -r "$WORK/runs" "$WORK/out" "$keep/"
  # So that `cli_openmoji_check.py report PACKAGE KEEP/runs ...` judges the kept runs again.
  find "$keep/runs" -name '*.dir' -exec sed -i "s#^$WORK/out/#$keep/out/#" {} +
  echo "kept in $keep"
fi
[[ $code -eq 0 ]] || exit 1
echo "ok"
