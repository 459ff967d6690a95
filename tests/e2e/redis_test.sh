#!/usr/bin/env bash
# --store redis://: a real redis-server on a loopback port backs two inbetween-server replicas.
# A session is created on A (drawings uploaded, multimesh built), continued on B (frames
# streamed, comesh optimized: B loads it lazily from Redis, nothing is rebuilt), A sees B's
# optimization; after kill -9 of A, B still serves the session. Driven by the Python client.
source "$(dirname "$0")/lib/common.sh"
PY=/usr/bin/python3
command -v redis-server >/dev/null || { echo "redis-server is not installed"; exit 1; }
"$INBETWEEN_SRC/client/python/generate_stubs.sh" "$WORK/stubs"

# A free loopback port for Redis (retry if another process takes it first).
for _ in 1 2 3 4 5; do
  port=$("$PY" -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
  redis-server --port "$port" --bind 127.0.0.1 --save '' --appendonly no --loglevel warning \
    >"$WORK/redis.log" 2>&1 &
  REDIS_PID=$!
  PIDS+=("$REDIS_PID")
  for _ in $(seq 1 100); do
    redis-cli -h 127.0.0.1 -p "$port" ping 2>/dev/null | grep -q PONG && break
    kill -0 "$REDIS_PID" 2>/dev/null || break
    sleep 0.05
  done
  # Ours only (another test's redis-server may have taken the port first; ours then exits).
  redis-cli -h 127.0.0.1 -p "$port" info server 2>/dev/null | tr -d '\r' |
    grep -qx "process_id:$REDIS_PID" && break
  kill -9 "$REDIS_PID" 2>/dev/null || true
  port=""
done
[[ -n "$port" ]] || { cat "$WORK/redis.log"; echo "redis-server did not start"; exit 1; }
store="redis://127.0.0.1:$port"

start_server --store "$store"
A_PID=$SERVER_PID A_ADDR=$SERVER_ADDR
mv "$WORK/server.log" "$WORK/server-a.log"
start_server --store "$store"
B_PID=$SERVER_PID B_ADDR=$SERVER_ADDR
mv "$WORK/server.log" "$WORK/server-b.log"

export PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$WORK/stubs:$INBETWEEN_SRC/client/python"
ex="$INBETWEEN_SRC/examples/square_hexagon"
id=$("$PY" - "$A_ADDR" "$ex/square.svg" "$ex/hexagon.svg" <<'PYEOF'
import sys, inbetween
with inbetween.Client(sys.argv[1], timeout=120) as a:
    s = a.build(a.upload_svgs(a.create_session("redis-e2e"), sys.argv[2:]))
    assert s.stage == 2, s
    print(s.id)
PYEOF
)
[[ -n "$id" ]] || { echo "no session id"; exit 1; }

# B continues the session: frames, then an optimization stored for everyone.
"$PY" - "$B_ADDR" "$A_ADDR" "$id" "$WORK/frames-b" "$ex/square.svg" <<'PYEOF'
import json, sys, inbetween
from inbetween.v1 import inbetween_pb2 as pb
b_addr, a_addr, sid, out, square = sys.argv[1:]
with inbetween.Client(b_addr, timeout=120) as b, inbetween.Client(a_addr, timeout=120) as a:
    s, mesh = b.get_session(sid, full=True)
    assert s.stage == 2 and len(mesh.shapes) == 2, s
    paths = b.stream_frames(s, out, frames=6)
    assert len(paths) == 6, paths
    first = json.load(open(paths[0]))["vertices"]
    assert len(first) == len(mesh.shapes[0].vertices)
    assert all(abs(x - p.x) < 1e-6 and abs(y - p.y) < 1e-6
               for (x, y), p in zip(first, mesh.shapes[0].vertices))
    s = b.optimize(s, max_outer_iterations=2)
    assert s.stage == 3, s
    seen = a.get_session(sid)
    assert seen.version == s.version and seen.stage == 3, (seen, s)
    # A stale write on A (version before B's optimization) is ABORTED.
    try:
        a.put_svg(pb.Session(id=sid, version=s.version - 1), square)
        raise SystemExit("stale write across replicas was accepted")
    except inbetween.InbetweenError as e:
        assert e.code == "ABORTED", e
print("continued on B")
PYEOF

kill -9 "$A_PID"
wait "$A_PID" 2>/dev/null || true

"$PY" - "$B_ADDR" "$id" "$WORK/frames-after" <<'PYEOF'
import sys, inbetween
with inbetween.Client(sys.argv[1], timeout=120) as b:
    s = b.get_session(sys.argv[2])
    assert s.stage == 3, s
    assert len(b.stream_frames(s, sys.argv[3], frames=4)) == 4
    assert sys.argv[2] in [x.id for x in b.list_sessions()]
print("served by B after kill -9 of A")
PYEOF

# The multimesh was built once (on A); the optimization ran once (on B).
[[ $(grep -c "rpc=BuildMultimesh" "$WORK/server-a.log") -eq 1 ]] || { cat "$WORK/server-a.log"; exit 1; }
! grep -q "rpc=BuildMultimesh" "$WORK/server-b.log" || { echo "B rebuilt the multimesh"; exit 1; }
grep -q "rpc=Inbetween" "$WORK/server-b.log" || { cat "$WORK/server-b.log"; exit 1; }
echo "ok"
