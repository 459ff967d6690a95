#!/usr/bin/env bash
# Cancellation and admission over real TCP: with one heavy slot and no queue, a long
# OptimizeComesh (pentagon -> star, iteration limits at their maximum) holds the slot; a second
# heavy call is RESOURCE_EXHAUSTED with retry-after-ms; the client cancels the optimization and
# the server is idle again within a second (metrics: no heavy job running, queue empty), a new
# heavy call is admitted, and the cancelled optimization stored nothing. A 1 s deadline on an
# optimization of a finely meshed copy ends it with DEADLINE_EXCEEDED and the server is idle again
# within a second.
source "$(dirname "$0")/lib/common.sh"
PY=/usr/bin/python3
"$INBETWEEN_SRC/client/python/generate_stubs.sh" "$WORK/stubs"
start_server --max-heavy-jobs 1 --heavy-queue 0 --metrics-listen 127.0.0.1:0
for _ in $(seq 1 100); do
  METRICS=$(grep -oE 'metrics on 127\.0\.0\.1:[0-9]+' "$WORK/server.log" | awk '{print $3}' || true)
  [[ -n "$METRICS" ]] && break
  sleep 0.05
done
[[ -n "$METRICS" ]] || { cat "$WORK/server.log"; echo "no metrics address logged"; exit 1; }

export PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$WORK/stubs:$INBETWEEN_SRC/client/python"
ex="$INBETWEEN_SRC/examples/pentagon_star/hard1"
timeout 120 "$PY" - "$SERVER_ADDR" "$METRICS" "$ex/pentagon.svg" "$ex/star.svg" <<'PYEOF'
import re, sys, threading, time, urllib.request
import inbetween
from inbetween.v1 import inbetween_pb2 as pb

address, metrics, drawings = sys.argv[1], sys.argv[2], sys.argv[3:]

def gauge(name):
    text = urllib.request.urlopen(f"http://{metrics}/metrics", timeout=5).read().decode()
    return float(re.search(rf"^{name} (\S+)$", text, re.M).group(1))

client = inbetween.Client(address, timeout=100)
session = client.build(client.upload_svgs(client.create_session("cancel"), drawings))
other = client.build(client.upload_svgs(client.create_session("other"), drawings))
assert gauge("inbetween_heavy_jobs_running") == 0

iterations, running, cancel = [0], threading.Event(), threading.Event()
def progress(event):
    if isinstance(event, pb.ComeshIteration):
        iterations[0] += 1
        if iterations[0] == 20:
            running.set()
    return not cancel.is_set()  # False cancels the call

outcome = {}
def optimize():
    try:
        client.optimize(session, progress, max_outer_iterations=1000,
                        max_inner_iterations=100000, tolerance=1e-15)
        outcome["code"] = "OK"
    except inbetween.InbetweenError as e:
        outcome["code"] = e.code
worker = threading.Thread(target=optimize)
worker.start()
assert running.wait(60), "the optimization did not start iterating"
assert gauge("inbetween_heavy_jobs_running") == 1

# The pool is full: another heavy call over TCP is refused with a retry hint.
try:
    list(client.frames(other.id, frames=3))
    raise SystemExit("a heavy call was admitted while the only slot was taken")
except inbetween.InbetweenError as e:
    assert e.code == "RESOURCE_EXHAUSTED", e
    assert e.retry_after_ms and e.retry_after_ms > 0, e
    assert "--max-heavy-jobs" in e.details or "heavy" in e.details, e.details

cancel.set()
cancelled_at = time.monotonic()
worker.join(30)
assert outcome.get("code") == "CANCELLED", outcome
# Idle again within a second (bounded poll).
deadline, idle_after = cancelled_at + 1.0, None
while time.monotonic() < deadline:
    if gauge("inbetween_heavy_jobs_running") == 0 and gauge("inbetween_heavy_queue_depth") == 0:
        idle_after = time.monotonic() - cancelled_at
        break
    time.sleep(0.01)
assert idle_after is not None, "a heavy job was still running 1 s after the client cancelled"
# The slot is free: a heavy call is admitted and completes.
assert len(list(client.frames(other.id, frames=3))) == 4  # header + 3 frames
after = client.get_session(session.id)
assert after.version == session.version and after.stage == pb.STAGE_MULTIMESH, after

# A deadline stops the work the same way: DEADLINE_EXCEEDED, then idle within a second. The pair
# is meshed finely (~20k vertices): at the default size the optimizer's Newton-type inner loop
# converges within the second.
long = client.build(client.upload_svgs(client.create_session("long"), drawings),
                    boundary_vertices=800, max_edge_relative=0.008)
with inbetween.Client(address, timeout=1.0) as hurried:
    try:
        hurried.optimize(long, max_outer_iterations=1000, max_inner_iterations=100000,
                         tolerance=1e-15)
        raise SystemExit("a minutes-long optimization finished within its 1 s deadline")
    except inbetween.InbetweenError as e:
        assert e.code == "DEADLINE_EXCEEDED", e
expired_at = time.monotonic()
deadline, idle_after_deadline = expired_at + 1.0, None
while time.monotonic() < deadline:
    if gauge("inbetween_heavy_jobs_running") == 0:
        idle_after_deadline = time.monotonic() - expired_at
        break
    time.sleep(0.01)
assert idle_after_deadline is not None, "still running 1 s after the deadline"
client.close()
print(f"cancelled after {iterations[0]} iterations; idle {idle_after * 1000:.0f} ms after the "
      f"cancel, {idle_after_deadline * 1000:.0f} ms after the deadline (polled, upper bounds)")
PYEOF
grep -q "rpc=OptimizeComesh.*status=CANCELLED" "$WORK/server.log" || { cat "$WORK/server.log"; exit 1; }
echo "ok"
