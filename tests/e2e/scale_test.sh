#!/usr/bin/env bash
# Scale-out, short form (docs/scale-out.md): a real redis-server, three inbetween-server replicas
# on it (--store redis://) and a real nginx from deploy/nginx/inbetween.conf, all on loopback.
# Through nginx, the CLI creates sessions, builds and streams frames. Chaos: twice, the replica
# serving a long Inbetween stream is killed with SIGKILL mid-stream (the CLI is paused after its
# first frame, so the replica still has frames to send) and restarted; the CLI must resume on
# another replica from the next frame and write a frames.json identical to an uninterrupted run.
# Then a replica is killed while idle: every session still answers through nginx (nothing lost),
# and again after its restart.
source "$(dirname "$0")/lib/common.sh"
source "$(dirname "$0")/lib/cluster.sh"

FLAGS=(--solver-threads 1 --log-format text)
start_redis
store="redis://127.0.0.1:$REDIS_PORT"
for n in 1 2 3; do start_replica "$n" 0 --store "$store" "${FLAGS[@]}"; done
start_nginx "${REPLICA_PORT[1]}" "${REPLICA_PORT[2]}" "${REPLICA_PORT[3]}"
echo "redis :$REDIS_PORT, replicas :${REPLICA_PORT[1]} :${REPLICA_PORT[2]} :${REPLICA_PORT[3]}, nginx $NGINX_ADDR"

cli() { "$CLI_BIN" --server "$NGINX_ADDR" "$@"; }
SESSIONS=()
session_of() { grep -oE '^session [0-9a-f]+' "$1" | awk '{print $2}'; }

# A few small sessions (spread over the replicas by their ids).
sq="$INBETWEEN_SRC/examples/square_hexagon"
for i in 1 2 3 4; do
  cli -q animate "$sq/square.svg" "$sq/hexagon.svg" --frames 12 --format json --out "$WORK/small-$i" \
    >"$WORK/small-$i.out"
  SESSIONS+=("$(session_of "$WORK/small-$i.out")")
done

# Affinity (no replica down yet): every call naming a small session reached one replica.
# (CreateSession, round-robin as it names no session yet, is left out.)
for sid in "${SESSIONS[@]}"; do
  serving=0
  for n in 1 2 3; do
    c=$(grep "session=$sid" "$WORK/replica-$n.log" | grep -vc 'rpc=CreateSession' || true)
    [[ "$c" -gt 0 ]] && serving=$((serving + 1))
  done
  [[ $serving -eq 1 ]] || { echo "session $sid was served by $serving replicas"; exit 1; }
done

# The long stream: walk, 6000 frames (~15 MB: 154 vertices, 2.5 kB per frame message), far more
# than the buffers between the replica and a paused CLI hold. (1200 frames, ~3 MB, sometimes fit:
# the replica had sent everything before it was killed and nothing was resumed.)
WALK=("$INBETWEEN_SRC"/examples/walk/0[1-8]_*.svg)
FRAMES=6000
LONG=(animate "${WALK[@]}" --frames "$FRAMES" --format json)
cli -q "${LONG[@]}" --out "$WORK/reference" >"$WORK/reference.out"
SESSIONS+=("$(session_of "$WORK/reference.out")")

# chaos_try R A: a long stream; after the CLI's first frame, pause the CLI, SIGKILL the replica
# serving its session (the one that answered its BuildMultimesh, in nginx's access log), resume
# the CLI, restart the replica. Returns 2 when the stream turned out to run on another replica
# (nginx moved it, e.g. off a stale keepalive connection): nothing was interrupted, try again.
KILLS=0
chaos_try() {
  local r=$1 a=$2 out="$WORK/chaos-$1-$2" err="$WORK/chaos-$1-$2.err" cli_pid line sid up
  local victim="" resume streamed
  cli "${LONG[@]}" --out "$out" >"$out.txt" 2>"$err" &
  cli_pid=$!
  wait_first_frame "$cli_pid" "$err" || { cat "$err"; echo "round $r: no frame arrived"; return 1; }
  kill -STOP "$cli_pid" || return 1
  # The CLI's session: the last one built (calls are sequential in this test).
  line=$(grep '|/inbetween.v1.Inbetween/BuildMultimesh|' "$WORK/nginx/access.log" | tail -1)
  sid=$(cut -d'|' -f1 <<<"$line")
  up=$(cut -d'|' -f2 <<<"$line" | awk -F', ' '{print $NF}')  # the one that answered
  for n in 1 2 3; do [[ "$up" == "127.0.0.1:${REPLICA_PORT[$n]}" ]] && victim=$n; done
  [[ -n "$victim" ]] || { echo "round $r: no replica for upstream '$up'"; return 1; }
  echo "round $r: session $sid streams from replica $victim ($up): SIGKILL"
  kill_replica "$victim"
  KILLS=$((KILLS + 1))
  kill -CONT "$cli_pid"
  wait "$cli_pid" || { cat "$err"; echo "round $r: the CLI failed after the failover"; return 1; }
  start_replica "$victim" "${REPLICA_PORT[$victim]}" --store "$store" "${FLAGS[@]}" || return 1
  [[ "$(session_of "$out.txt")" == "$sid" ]] || { echo "round $r: other session"; return 1; }
  SESSIONS+=("$sid")
  cmp "$WORK/reference/frames.json" "$out/frames.json" ||
    { echo "round $r: frames differ from the uninterrupted run"; return 1; }
  # Resumed mid-stream (not from the start, not after the end).
  resume=$(grep -oE 'retry: Inbetween attempt 1 failed .*resuming at frame [0-9]+' "$err" |
           grep -oE '[0-9]+$' | head -1 || true)
  if [[ -z "$resume" ]]; then
    streamed=$(grep "^$sid|.*|/inbetween.v1.Inbetween/Inbetween|" "$WORK/nginx/access.log" |
               cut -d'|' -f2 | awk -F', ' '{print $NF}')
    if [[ -n "$streamed" && "$streamed" != "$up" ]]; then
      echo "round $r: the stream ran on $streamed, not on the killed replica; again"
      rm -rf "$out"
      return 2
    fi
    cat "$err"; echo "round $r: no mid-stream resume reported"; return 1
  fi
  [[ "$resume" -gt 0 && "$resume" -lt "$FRAMES" ]] || { echo "round $r: resumed at $resume"; return 1; }
  echo "round $r: resumed at frame $resume on another replica; $FRAMES frames identical"
  rm -rf "$out"
}
chaos_round() {
  local rc
  for a in 1 2 3; do
    rc=0
    chaos_try "$1" "$a" || rc=$?
    [[ $rc -eq 2 ]] || return "$rc"
  done
  echo "round $1: the killed replica never carried the stream"; return 1
}
chaos_round 1
chaos_round 2

# Every session answers through nginx: with a replica down (idle kill: nginx moves its calls to
# another replica), then after it is back.
check_sessions() {
  for sid in "${SESSIONS[@]}"; do
    [[ -n "$sid" ]] || { echo "a run printed no session id"; return 1; }
    cli inspect "$sid" >"$WORK/inspect.out" 2>&1 || { cat "$WORK/inspect.out"; echo "session $sid lost ($1)"; return 1; }
    grep -q "$sid" "$WORK/inspect.out" || { cat "$WORK/inspect.out"; echo "inspect $sid: no id"; return 1; }
  done
}
kill_replica 2
KILLS=$((KILLS + 1))
check_sessions "replica 2 down"
start_replica 2 "${REPLICA_PORT[2]}" --store "$store" "${FLAGS[@]}"
check_sessions "replica 2 restarted"
listed=$(cli inspect | grep -cE '[0-9a-f]{16}' || true)
[[ "$listed" -ge "${#SESSIONS[@]}" ]] || { cli inspect; echo "ListSessions: $listed < ${#SESSIONS[@]}"; exit 1; }

# Each replica served calls (affinity spreads sessions), and the multimesh of a session was
# never rebuilt by a failover (one BuildMultimesh per session, in nginx's log).
for n in 1 2 3; do
  grep -q 'rpc=' "$WORK/replica-$n.log" || { echo "replica $n served nothing"; exit 1; }
done
builds=$(grep -c '|/inbetween.v1.Inbetween/BuildMultimesh|' "$WORK/nginx/access.log")
[[ "$builds" -eq "${#SESSIONS[@]}" ]] || { echo "$builds builds for ${#SESSIONS[@]} sessions"; exit 1; }
echo "ok: ${#SESSIONS[@]} sessions, $KILLS replica kills, 0 sessions lost, frames identical"
