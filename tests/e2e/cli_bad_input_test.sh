#!/usr/bin/env bash
# The catalogue of malformed drawings, project files and flags in tests/data/bad_cli/cases.tsv:
# each case must exit with its documented code (docs/cli.md), print the message fragment on
# stderr, and leave nothing behind in --out (not even the directory).
source "$(dirname "$0")/lib/common.sh"
data="$INBETWEEN_SRC/tests/data/bad_cli"
cd "$data"
before=$(ls -A "$data")
failures=0
count=0
# all_in 'A && B' FILE: every ' && '-separated fixed string occurs in FILE.
all_in() {
  local rest=$1 part
  while [[ -n "$rest" ]]; do
    part=${rest%% && *}
    grep -qF -- "$part" "$2" || return 1
    [[ "$rest" == *" && "* ]] && rest=${rest#* && } || rest=""
  done
}
while IFS=$'\t' read -r name want fragment args; do
  [[ -z "$name" || "$name" == \#* ]] && continue
  out="$WORK/out_$name"
  set +e
  # shellcheck disable=SC2086  # the arguments column is split on purpose
  "$CLI_BIN" $args --out "$out" -q > "$WORK/$name.stdout" 2> "$WORK/$name.stderr"
  code=$?
  set -e
  count=$((count + 1))
  if [[ $code -ne $want ]]; then
    echo "case $name: exit $code, expected $want"; cat "$WORK/$name.stderr"; failures=$((failures + 1))
  elif ! all_in "$fragment" "$WORK/$name.stderr"; then
    echo "case $name: stderr lacks '$fragment':"; cat "$WORK/$name.stderr"; failures=$((failures + 1))
  elif [[ -e "$out" ]]; then
    echo "case $name: $out was written"; ls -la "$out"; failures=$((failures + 1))
  fi
done < cases.tsv
# Nothing may be written next to the inputs either (e.g. a project file or staging folder).
[[ "$(ls -A "$data")" == "$before" ]] || { echo "files appeared in $data"; failures=$((failures + 1)); }
[[ $failures -eq 0 ]] || { echo "$failures of $count cases failed"; exit 1; }
echo "ok: $count cases"
