#!/usr/bin/env bash
# `inbetween animate` on every example in examples/ (each with its project.json): exit 0, frames
# valid (tests/e2e/lib/check_frames.py: frame count, finite, no inverted triangle and no boundary overlap in any frame)
# and keys hit (cli_examples_check.py: one-hot weights at every key frame). Few frames and only
# frames.json keep it short; scripts/examples renders the full GIFs.
source "$(dirname "$0")/lib/common.sh"
lib="$INBETWEEN_SRC/tests/e2e/lib"
here="$INBETWEEN_SRC/tests/e2e"
count=0
while IFS= read -r project; do
  name=$(dirname "${project#"$INBETWEEN_SRC/examples/"}" | tr / _)
  # 6 frames, or one inbetween between every two keys where there are more keys (walk: 16)
  keys=$(python3 -c 'import json, sys; print(len(json.load(open(sys.argv[1]))["drawings"]))' "$project")
  frames=$(( 2 * keys - 1 > 6 ? 2 * keys - 1 : 6 ))
  out="$WORK/$name"
  if ! "$CLI_BIN" animate --project "$project" --frames "$frames" --format json --out "$out" \
      -q > "$WORK/$name.log" 2>&1; then
    echo "example $name: animate failed"; cat "$WORK/$name.log"; exit 1
  fi
  keys=$(python3 "$here/cli_examples_check.py" "$project" "$out/frames.json" "$frames") ||
    { echo "example $name: keys"; exit 1; }
  python3 "$lib/check_frames.py" "$out/frames.json" "$frames" "$keys" > /dev/null ||
    { echo "example $name: frames"; exit 1; }
  count=$((count + 1))
done < <(find "$INBETWEEN_SRC/examples" -name project.json | sort)
[[ $count -ge 10 ]] || { echo "only $count examples found"; exit 1; }
echo "ok: $count examples"
