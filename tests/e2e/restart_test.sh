#!/usr/bin/env bash
# --store dir:PATH survives kill -9: create a session and build its multimesh, kill the server
# hard, restart it on the same directory; the session and its multimesh are there (read with
# GetSession only, nothing is rebuilt), and the session goes on from its version.
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples/square_hexagon"
store="$WORK/store"

start_server --store "dir:$store"
"$CLI_BIN" mesh "$ex/square.svg" "$ex/hexagon.svg" --out "$WORK/mesh" --server "$SERVER_ADDR" \
  --quiet >"$WORK/mesh.out"
id=$(awk '/^session /{print $2}' "$WORK/mesh.out" | head -1)
[[ -n "$id" ]] || { echo "no session id printed:"; cat "$WORK/mesh.out"; exit 1; }
"$CLI_BIN" --server "$SERVER_ADDR" inspect "$id" >"$WORK/before.txt"
grep -q "stage STAGE_MULTIMESH" "$WORK/before.txt" || { cat "$WORK/before.txt"; exit 1; }

kill -9 "$SERVER_PID"
wait "$SERVER_PID" 2>/dev/null || true
# start_server reads the port from server.log: keep the first log out of its way.
mv "$WORK/server.log" "$WORK/server-1.log"

start_server --store "dir:$store"
"$CLI_BIN" --server "$SERVER_ADDR" inspect "$id" >"$WORK/after.txt"
diff "$WORK/before.txt" "$WORK/after.txt" || { echo "session changed across kill -9"; exit 1; }
grep -q "^multimesh: 2 shapes" "$WORK/after.txt" || { cat "$WORK/after.txt"; exit 1; }
"$CLI_BIN" --server "$SERVER_ADDR" inspect >"$WORK/list.txt"
grep -q "^$id" "$WORK/list.txt" || { echo "session not listed:"; cat "$WORK/list.txt"; exit 1; }
if grep -q "rpc=BuildMultimesh" "$WORK/server.log"; then
  echo "the restarted server rebuilt the multimesh"; exit 1
fi
# Work goes on with the stored multimesh: frames from the restarted server.
"$CLI_BIN" animate "$ex/square.svg" "$ex/hexagon.svg" --frames 4 --out "$WORK/out" \
  --server "$SERVER_ADDR" --quiet
python3 "$INBETWEEN_SRC/tests/e2e/lib/check_frames.py" "$WORK/out/frames.json" 4 0,3
echo "ok"
