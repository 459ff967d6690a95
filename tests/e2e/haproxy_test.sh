#!/usr/bin/env bash
# HAProxy from deploy/haproxy/inbetween.cfg in front of three replicas on a real redis-server
# (all loopback): the CLI animates through it (gRPC over h2 end to end), and session affinity
# holds: every call that named the session (x-session-id) reached one and the same replica.
source "$(dirname "$0")/lib/common.sh"
source "$(dirname "$0")/lib/cluster.sh"

start_redis
store="redis://127.0.0.1:$REDIS_PORT"
for n in 1 2 3; do start_replica "$n" 0 --store "$store" --log-format text; done
start_haproxy "${REPLICA_PORT[1]}" "${REPLICA_PORT[2]}" "${REPLICA_PORT[3]}"

sq="$INBETWEEN_SRC/examples/square_hexagon"
for i in 1 2 3 4; do
  "$CLI_BIN" --server "$HAPROXY_ADDR" -q animate "$sq/square.svg" "$sq/hexagon.svg" --frames 8 \
    --format json --out "$WORK/out-$i" >"$WORK/out-$i.txt"
  sid=$(grep -oE '^session [0-9a-f]+' "$WORK/out-$i.txt" | awk '{print $2}')
  [[ -n "$sid" ]] || { cat "$WORK/out-$i.txt"; echo "no session id"; exit 1; }
  "$PY" "$INBETWEEN_SRC/tests/e2e/lib/check_frames.py" "$WORK/out-$i/frames.json" 8 0,7
  # PutDrawing x2, BuildMultimesh, Inbetween name the session: all on one replica.
  serving=()
  for n in 1 2 3; do
    # CreateSession (no session to hash yet; round-robin) also names the new session: not it.
    c=$(grep "session=$sid" "$WORK/replica-$n.log" | grep -vc 'rpc=CreateSession' || true)
    [[ "$c" -gt 0 ]] && serving+=("$n:$c")
  done
  [[ ${#serving[@]} -eq 1 ]] || { echo "session $sid served by replicas ${serving[*]}"; exit 1; }
  [[ "${serving[0]#*:}" -ge 4 ]] || { echo "session $sid: ${serving[0]} calls"; exit 1; }
  echo "session $sid: all calls on replica ${serving[0]%%:*}"
done
echo "ok"
