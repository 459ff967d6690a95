#!/usr/bin/env bash
# --store dir:PATH survives kill -9: several sessions in different stages (a built multimesh, an
# optimized one, one with a cut drawing and its cohesive edges), the server killed hard and
# restarted on the same directory; every session is there as it was (read with GetSession only:
# nothing is rebuilt or re-optimized), and work goes on from the stored state.
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples"
store="$WORK/store"

session_of() { awk '/^session /{print $2}' "$1" | head -1; }

start_server --store "dir:$store"
ids=()
"$CLI_BIN" mesh "$ex/square_hexagon/square.svg" "$ex/square_hexagon/hexagon.svg" \
  --out "$WORK/mesh" --server "$SERVER_ADDR" --quiet >"$WORK/mesh.out"
ids+=("$(session_of "$WORK/mesh.out")")
"$CLI_BIN" optimize "$ex/square_hexagon/square.svg" "$ex/square_hexagon/hexagon.svg" \
  --out "$WORK/optimized" --server "$SERVER_ADDR" --quiet >"$WORK/optimize.out"
ids+=("$(session_of "$WORK/optimize.out")")
"$CLI_BIN" mesh --project "$ex/split/project.json" --out "$WORK/split" --server "$SERVER_ADDR" \
  --quiet >"$WORK/split.out"
ids+=("$(session_of "$WORK/split.out")")
for id in "${ids[@]}"; do
  [[ -n "$id" ]] || { echo "a session id was not printed:"; cat "$WORK"/*.out; exit 1; }
done
for i in "${!ids[@]}"; do
  "$CLI_BIN" --server "$SERVER_ADDR" inspect "${ids[i]}" >"$WORK/before_$i.txt"
done
grep -q "stage STAGE_MULTIMESH" "$WORK/before_0.txt" || { cat "$WORK/before_0.txt"; exit 1; }
grep -q "stage STAGE_OPTIMIZED" "$WORK/before_1.txt" || { cat "$WORK/before_1.txt"; exit 1; }
"$CLI_BIN" --server "$SERVER_ADDR" inspect >"$WORK/list_before.txt"

kill -9 "$SERVER_PID"
wait "$SERVER_PID" 2>/dev/null || true
# start_server reads the port from server.log: keep the first log out of its way.
mv "$WORK/server.log" "$WORK/server-1.log"

start_server --store "dir:$store"
for i in "${!ids[@]}"; do
  "$CLI_BIN" --server "$SERVER_ADDR" inspect "${ids[i]}" >"$WORK/after_$i.txt"
  diff "$WORK/before_$i.txt" "$WORK/after_$i.txt" ||
    { echo "session ${ids[i]} changed across kill -9"; exit 1; }
done
grep -q "^multimesh: 2 shapes" "$WORK/after_0.txt" || { cat "$WORK/after_0.txt"; exit 1; }
"$CLI_BIN" --server "$SERVER_ADDR" inspect >"$WORK/list_after.txt"
diff <(sort "$WORK/list_before.txt") <(sort "$WORK/list_after.txt") ||
  { echo "the session list changed across kill -9"; exit 1; }
for id in "${ids[@]}"; do
  grep -q "^$id" "$WORK/list_after.txt" || { echo "session $id not listed"; exit 1; }
done
if grep -qE "rpc=(BuildMultimesh|OptimizeComesh)" "$WORK/server.log"; then
  echo "the restarted server rebuilt or re-optimized a multimesh"; exit 1
fi
# Work goes on: frames from the restarted server.
"$CLI_BIN" animate "$ex/square_hexagon/square.svg" "$ex/square_hexagon/hexagon.svg" --frames 4 \
  --out "$WORK/out" --server "$SERVER_ADDR" --quiet
python3 "$INBETWEEN_SRC/tests/e2e/lib/check_frames.py" "$WORK/out/frames.json" 4 0,3
echo "ok: ${#ids[@]} sessions"
