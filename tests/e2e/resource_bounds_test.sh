#!/usr/bin/env bash
# Resource bounds (docs/hardening.md, "Resource bounds"): inbetween-server with small explicit
# limits, under a hard address-space cap (prlimit --as), gets the largest requests the limits
# allow and requests just over them (resource_bounds_check.py: max-points drawings, a multimesh
# near max-mesh-vertices, max-frames streams, two of each at once, the heavy-job queue full).
# Every over-limit request must be refused naming its limit; the server's peak RSS must stay under
# MAX_RSS_MB; a small healthy session must stream identical frames before, during and after;
# the server must still serve and stop cleanly on SIGTERM.
# Sanitizer builds (ASan/TSan reserve terabytes of shadow memory and multiply RSS): no cap and
# no RSS bound, smaller limits, the refusals are still checked.
source "$(dirname "$0")/lib/common.sh"
PY=/usr/bin/python3
"$PY" -c "import grpc, google.protobuf" || { echo "python3-grpcio/python3-protobuf missing"; exit 1; }
"$INBETWEEN_SRC/client/python/generate_stubs.sh" "$WORK/stubs"

sanitizer=""
if [[ -n "${INBETWEEN_SANITIZER:-}" ]]; then
  sanitizer=$INBETWEEN_SANITIZER
else
  # ldd's output captured first: `ldd | grep -q` under pipefail fails when grep exits before
  # ldd has written everything (SIGPIPE): build/asan's server once ran under the cap that way.
  libs=$(ldd "$SERVER_BIN" 2>/dev/null || true)
  symbols=$(nm -D "$SERVER_BIN" 2>/dev/null || true)
  if [[ $libs =~ lib(asan|tsan)\.so ]]; then
    sanitizer=lib${BASH_REMATCH[1]}
  elif [[ $symbols =~ \ __(asan|tsan)_init ]]; then
    sanitizer=static
  fi
fi

# The limits (flags of inbetween-server). The largest allowed session: 3 drawings of 20,000
# points, a multimesh of 20,497 vertices (85% of 24,000), 48 frames per request.
POINTS=${RB_MAX_DRAWING_POINTS:-20000}
DRAWINGS=${RB_MAX_DRAWINGS:-3}
VERTICES=${RB_MAX_MESH_VERTICES:-24000}
FRAMES=${RB_MAX_FRAMES:-48}
BOUNDARY=${RB_BOUNDARY_VERTICES:-3000}   # the fine mesh: boundary vertices per shape
EDGE=${RB_MAX_EDGE_RELATIVE:-0.008}      # and its max edge, relative to the diagonal
OVER_EDGE=${RB_OVER_EDGE_RELATIVE:-0.005}  # needs ~2.5x more vertices than EDGE: over the limit
MESSAGE=$((8 * 1024 * 1024))
SESSIONS=8
JOBS=3; QUEUE=2; PER_TOKEN=8
# Bounds, derived in docs/hardening.md ("Resource bounds") from measurements at these limits on a
# shared 2-core machine (RSS, MiB): idle server 21; a stored session at the limits (3 drawings of
# 20,000 points + its multimesh, with what glibc keeps of the build) 65; one heavy job's working
# set 70 (a build; an Inbetween ~25); plus 64 for gRPC buffers and allocator slack. The run
# stores 2 big sessions and keeps all 3 heavy slots busy at once.
MAX_RSS_MB=${MAX_RSS_MB:-$((21 + 2 * 65 + JOBS * 70 + 64))}  # peak RSS (VmHWM): 425
AS_HEADROOM_MB=${AS_HEADROOM_MB:-1536}  # hard cap: idle address space + this (growth seen <= 700)
REQUEST_SECONDS=${RB_REQUEST_SECONDS:-60}
if [[ -n "$sanitizer" ]]; then
  echo "sanitizer build ($sanitizer): no address-space cap, no RSS bound, smaller limits"
  POINTS=${RB_MAX_DRAWING_POINTS:-4000}; VERTICES=${RB_MAX_MESH_VERTICES:-4000}
  BOUNDARY=${RB_BOUNDARY_VERTICES:-800}; EDGE=${RB_MAX_EDGE_RELATIVE:-0.02}
  OVER_EDGE=${RB_OVER_EDGE_RELATIVE:-0.01}; MAX_RSS_MB=0; REQUEST_SECONDS=600
fi

start_server --log-level "${RB_LOG_LEVEL:-warn}" --solver-threads 1 \
  --max-drawing-points "$POINTS" --max-drawings "$DRAWINGS" --max-mesh-vertices "$VERTICES" \
  --max-frames "$FRAMES" --max-message-bytes "$MESSAGE" --max-sessions "$SESSIONS" \
  --max-heavy-jobs "$JOBS" --heavy-queue "$QUEUE" --max-heavy-jobs-per-token "$PER_TOKEN"

if [[ -z "$sanitizer" ]]; then
  idle_kb=$(awk '/^VmSize:/{print $2}' "/proc/$SERVER_PID/status")
  cap=$(( (idle_kb / 1024 + AS_HEADROOM_MB) * 1024 * 1024 ))
  prlimit --pid "$SERVER_PID" --as="$cap:$cap"
  echo "address-space cap: $((cap / 1024 / 1024)) MiB" \
    "(idle $((idle_kb / 1024)) MiB + $AS_HEADROOM_MB MiB)"
  [[ "$(prlimit --pid "$SERVER_PID" --as --noheadings --raw -o SOFT)" == "$cap" ]] ||
    { echo "the cap did not take"; exit 1; }
fi

start=$(date +%s.%N)
PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$WORK/stubs" timeout 240 "$PY" \
  "$INBETWEEN_SRC/tests/e2e/resource_bounds_check.py" --server "$SERVER_ADDR" --pid "$SERVER_PID" \
  --examples "$INBETWEEN_SRC/examples" \
  --max-drawing-points "$POINTS" --max-drawings "$DRAWINGS" --max-mesh-vertices "$VERTICES" \
  --max-frames "$FRAMES" --max-message-bytes "$MESSAGE" --max-sessions "$SESSIONS" \
  --max-heavy-jobs "$JOBS" --heavy-queue "$QUEUE" --max-heavy-jobs-per-token "$PER_TOKEN" \
  --boundary-vertices "$BOUNDARY" --max-edge-relative "$EDGE" --over-edge-relative "$OVER_EDGE" \
  --max-rss-mb "$MAX_RSS_MB" --request-seconds "$REQUEST_SECONDS" ||
  { rc=$?; kill -0 "$SERVER_PID" 2>/dev/null || echo "the server died"; cat "$WORK/server.log"
    exit "$rc"; }
echo "driver: $(awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN{printf "%.1f", e - s}') s"

kill -0 "$SERVER_PID" || { cat "$WORK/server.log"; echo "server died"; exit 1; }
if grep -qiE 'bad_alloc|terminate|out of memory' "$WORK/server.log"; then
  cat "$WORK/server.log"; echo "the server ran out of memory under the cap"; exit 1
fi
kill -TERM "$SERVER_PID"
for _ in $(seq 1 200); do kill -0 "$SERVER_PID" 2>/dev/null || break; sleep 0.05; done
if kill -0 "$SERVER_PID" 2>/dev/null; then echo "server did not stop on SIGTERM"; exit 1; fi
wait "$SERVER_PID" || { rc=$?; tail -20 "$WORK/server.log"; echo "server exit $rc"; exit 1; }
echo "ok"
