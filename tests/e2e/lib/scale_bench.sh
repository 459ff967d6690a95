#!/usr/bin/env bash
# Scale benchmark (scripts/bench scale; docs/scale-out.md): a real redis-server, 3 replicas on it
# and nginx from deploy/nginx/inbetween.conf, all on loopback; inbetween-loadgen drives N
# virtual studios through nginx while a chaos loop SIGKILLs a random replica every K seconds and
# restarts it on the same port. Writes {"studios", "seconds", "requests", "errors_by_code",
# "lost_sessions", "unary_p99_ms", "replica_kills", "frames_identical", ...} with --json.
#   INBETWEEN_BIN=BUILD INBETWEEN_SRC=SRC scale_bench.sh [--short] [--studios N] [--seconds S]
#       [--kill-every K] [--json FILE]
# Long form (default): 64 studios, 120 s, a kill every 20 s. --short: 8 studios, 20 s, every 5 s.
# --keep-logs DIR copies the replicas', nginx's and the load generator's logs there.
source "$(dirname "$0")/common.sh"
source "$(dirname "$0")/cluster.sh"
LOADGEN_BIN="$INBETWEEN_BIN/tools/loadgen/inbetween-loadgen"
studios=64 seconds=120 kill_every=20 json="" keep=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --short) studios=8 seconds=20 kill_every=5 ;;
    --studios) studios=$2; shift ;;
    --seconds) seconds=$2; shift ;;
    --kill-every) kill_every=$2; shift ;;
    --json) json=$2; shift ;;
    --keep-logs) keep=$2; shift ;;
    *) echo "unknown argument $1"; exit 2 ;;
  esac
  shift
done
[[ "$kill_every" -ge 1 && "$seconds" -ge 1 && "$studios" -ge 1 ]] || { echo "bad bounds"; exit 2; }

FLAGS=(--solver-threads 1 --log-level warn)
start_redis
store="redis://127.0.0.1:$REDIS_PORT"
for n in 1 2 3; do start_replica "$n" 0 --store "$store" "${FLAGS[@]}"; done
start_nginx "${REPLICA_PORT[1]}" "${REPLICA_PORT[2]}" "${REPLICA_PORT[3]}"
echo "redis :$REDIS_PORT, replicas :${REPLICA_PORT[1]} :${REPLICA_PORT[2]} :${REPLICA_PORT[3]}, nginx $NGINX_ADDR"

sq="$INBETWEEN_SRC/examples/square_hexagon"
"$LOADGEN_BIN" --target "$NGINX_ADDR" --studios "$studios" --seconds "$seconds" \
  --max-requests 10000000 --drawings "$sq/square.svg" "$sq/hexagon.svg" --frames 24 \
  --json "$WORK/loadgen.json" >"$WORK/loadgen.txt" 2>"$WORK/loadgen.err" &
LOADGEN_PID=$!
PIDS+=("$LOADGEN_PID")

# Chaos: while the load runs, every kill_every seconds one random replica gets SIGKILL and is
# restarted on its port (so nginx's upstream list stays valid).
kills=0
end=$((SECONDS + seconds))
while (( SECONDS + kill_every < end )) && kill -0 "$LOADGEN_PID" 2>/dev/null; do
  sleep "$kill_every"
  n=$((RANDOM % 3 + 1))
  kill_replica "$n"
  kills=$((kills + 1))
  echo "chaos: SIGKILL replica $n (:${REPLICA_PORT[$n]}), restarting"
  start_replica "$n" "${REPLICA_PORT[$n]}" --store "$store" "${FLAGS[@]}"
done
status=0
wait "$LOADGEN_PID" || status=$?
if [[ -n "$keep" ]]; then
  mkdir -p "$keep"
  cp "$WORK"/replica-*.log "$WORK"/nginx/*.log "$WORK"/loadgen.* "$keep"/ 2>/dev/null || true
fi
[[ $status -eq 0 ]] || { cat "$WORK/loadgen.err"; echo "loadgen failed"; exit 1; }
cat "$WORK/loadgen.txt"
echo "replica kills: $kills"
"$PY" - "$WORK/loadgen.json" "$kills" "${json:-/dev/null}" <<'PYEOF'
import json, sys
report = json.load(open(sys.argv[1]))
report["replica_kills"] = int(sys.argv[2])
with open(sys.argv[3], "w") as out:
    json.dump(report, out, indent=2)
    out.write("\n")
PYEOF
[[ -n "$json" ]] && echo "wrote $json"
exit 0
