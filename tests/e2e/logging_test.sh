#!/usr/bin/env bash
# The server's per-RPC log lines (observability), in both formats: one line per finished
# RPC with its request id, method, session, status and duration (and the error for a failure).
# --log-format json: every line on stderr/stdout that is not the port banner is one JSON object
# {"time","level","thread","msg"}, whatever a client put in names (a drawing name with quotes,
# backslashes and a newline goes through escaped).
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples/square_hexagon"

for format in json text; do
  start_server --log-format "$format"
  "$CLI_BIN" mesh "$ex/square.svg" "$ex/hexagon.svg" --out "$WORK/mesh_$format" \
    --server "$SERVER_ADDR" --quiet >"$WORK/mesh_$format.out"
  id=$(awk '/^session /{print $2}' "$WORK/mesh_$format.out" | head -1)
  [[ -n "$id" ]] || { echo "no session id"; exit 1; }
  "$CLI_BIN" --server "$SERVER_ADDR" inspect deadbeefdeadbeef >/dev/null 2>&1 && exit 1
  kill -TERM "$SERVER_PID"
  wait "$SERVER_PID" 2>/dev/null || true
  mv "$WORK/server.log" "$WORK/server_$format.log"
  python3 - "$WORK/server_$format.log" "$format" "$id" <<'PY'
import json, re, sys
path, fmt, session = sys.argv[1], sys.argv[2], sys.argv[3]
lines = [l.rstrip("\n") for l in open(path) if l.strip()]
msgs = []
for line in lines:
    if line.startswith("inbetween-server listening on"):
        continue  # the port banner on stdout, for scripts
    if fmt == "json":
        obj = json.loads(line)  # raises on anything that is not one JSON object per line
        assert set(obj) == {"time", "level", "thread", "msg"}, obj
        assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z", obj["time"]), obj
        msgs.append((obj["level"], obj["msg"]))
    else:
        m = re.fullmatch(r"\[\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d{3}\] \[(\w+)\] (.*)", line)
        assert m, line
        msgs.append((m.group(1), m.group(2)))
rpc = re.compile(r"request=(\S+) rpc=(\w+)(?: session=(\S+))? status=(\w+) seconds=(\d+\.\d{3})"
                 r"(?: error=(.*))?")
calls = [(level, rpc.fullmatch(m)) for level, m in msgs if m.startswith("request=")]
assert all(c for _, c in calls), [m for _, m in msgs]
methods = [c.group(2) for _, c in calls]
for want in ["CreateSession", "PutDrawing", "BuildMultimesh", "GetSession"]:
    assert want in methods, (want, methods)
ids = [c.group(1) for _, c in calls]
assert len(set(ids)) == len(ids), "request ids repeat"
ok = [c for level, c in calls if c.group(4) == "OK"]
assert all(c.group(3) == session for c in ok if c.group(2) != "CreateSession" or c.group(3)), ok
bad = [(level, c) for level, c in calls if c.group(4) != "OK"]
assert len(bad) == 1 and bad[0][1].group(4) == "NOT_FOUND", bad
assert bad[0][0] in ("warning", "warn"), bad[0][0]
assert bad[0][1].group(3) == "deadbeefdeadbeef" and "not found" in bad[0][1].group(6), bad
print(f"{fmt}: {len(calls)} RPC lines ok")
PY
done

# JSON escaping of client text: a session id with a quote, a backslash and a newline is echoed
# in the NOT_FOUND line (session= and error=); the line must still be one JSON object holding it.
start_server --log-format json
weird=$'ab"c\\d\ne'
"$CLI_BIN" --server "$SERVER_ADDR" inspect "$weird" >/dev/null 2>&1 && exit 1
kill -TERM "$SERVER_PID"
wait "$SERVER_PID" 2>/dev/null || true
python3 - "$WORK/server.log" "$weird" <<'PY'
import json, sys
weird = sys.argv[2]
lines = [l for l in open(sys.argv[1]) if l.strip() and not l.startswith("inbetween-server listening")]
objs = [json.loads(l) for l in lines]
hits = [o for o in objs if weird in o["msg"]]
assert hits, ("the id is not in any line", [o["msg"] for o in objs])
print("escaping ok:", json.dumps(hits[0]["msg"])[:120])
PY
echo "ok"
