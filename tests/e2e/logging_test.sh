#!/usr/bin/env bash
# The server's per-RPC log lines (observability), in both formats: one line per finished
# RPC with its request id, method, session, status and duration (and the error for a failure).
# --log-format json: every line on stderr/stdout that is not the port banner is one JSON object;
# an RPC line has {"time","level","thread","msg"} plus "request", "method", "status" (strings),
# "seconds" (a number), "session" when known and "error" when not OK; any other line has exactly
# {"time","level","thread","msg"}. Whatever a client put in names (a session id with quotes,
# backslashes and a newline) goes through escaped.
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
BASE = {"time", "level", "thread", "msg"}
RPC = {"request", "method", "session", "status", "seconds", "error"}
calls = []  # one dict per RPC line: level, request, method, session, status, seconds, error
for line in lines:
    if line.startswith("inbetween-server listening on"):
        continue  # the port banner on stdout, for scripts
    if fmt == "json":
        obj = json.loads(line)  # raises on anything that is not one JSON object per line
        assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z", obj["time"]), obj
        assert isinstance(obj["thread"], int) and isinstance(obj["msg"], str), obj
        if "request" not in obj:
            assert set(obj) == BASE, obj
            continue
        assert BASE <= set(obj) <= BASE | RPC, obj
        for key in ("request", "method", "status", "session", "error"):
            assert key not in obj or (isinstance(obj[key], str) and obj[key]), (key, obj)
        assert {"request", "method", "status", "seconds"} <= set(obj), obj
        assert type(obj["seconds"]) in (int, float) and obj["seconds"] >= 0, obj
        assert ("error" in obj) == (obj["status"] != "OK"), obj
        calls.append({k: obj.get(k) for k in RPC | {"level"}})
    else:
        m = re.fullmatch(r"\[\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d{3}\] \[(\w+)\] (.*)", line)
        assert m, line
        if not m.group(2).startswith("request="):
            continue
        c = re.fullmatch(r"request=(\S+) rpc=(\w+)(?: session=(\S+))? status=(\w+) "
                         r"seconds=(\d+\.\d{3})(?: error=(.*))?", m.group(2))
        assert c, line
        calls.append(dict(level=m.group(1), request=c.group(1), method=c.group(2),
                          session=c.group(3), status=c.group(4), seconds=float(c.group(5)),
                          error=c.group(6)))
methods = [c["method"] for c in calls]
for want in ["CreateSession", "PutDrawing", "BuildMultimesh", "GetSession"]:
    assert want in methods, (want, methods)
ids = [c["request"] for c in calls]
assert len(set(ids)) == len(ids), "request ids repeat"
ok = [c for c in calls if c["status"] == "OK"]
assert all(c["session"] == session for c in ok if c["method"] != "CreateSession" or c["session"]), ok
assert all(c["error"] is None for c in ok), ok
bad = [c for c in calls if c["status"] != "OK"]
assert len(bad) == 1 and bad[0]["status"] == "NOT_FOUND", bad
assert bad[0]["level"] in ("warning", "warn"), bad[0]["level"]
assert bad[0]["session"] == "deadbeefdeadbeef" and "not found" in bad[0]["error"], bad
print(f"{fmt}: {len(calls)} RPC lines ok")
PY
done

# JSON escaping of client text: a session id with a quote, a backslash and a newline is echoed
# in the NOT_FOUND line (its session and error fields); the line must still be one JSON object
# holding it.
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
hits = [o for o in objs if o.get("session") == weird]
assert hits, ("the id is not in any line", objs)
assert weird in hits[0]["error"] and hits[0]["status"] == "NOT_FOUND", hits[0]
print("escaping ok:", json.dumps(hits[0])[:160])
PY
echo "ok"
