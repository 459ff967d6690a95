#!/usr/bin/env bash
# The CLI as a process (docs/cli.md): --progress json prints one JSON object per progress event
# on stderr; -q prints no progress at all; the documented exit codes 4 (server unreachable),
# 5 (server failure: a gRPC server without the Inbetween service answers UNIMPLEMENTED) and
# 130 (Ctrl-C: SIGINT cancels the running stage, and nothing is written; against a server the
# remote call ends CANCELLED).
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples/square_hexagon"
cd "$WORK"

# --progress json: every event a JSON object with stage, fraction in [0, 1], elapsed_s and an
# optional detail; the build and the frames both report.
"$CLI_BIN" --progress json animate "$ex/square.svg" "$ex/hexagon.svg" --frames 6 --format json \
  --out json_out 2>progress.err >progress.out
python3 - progress.err <<'PY'
import json, sys
events = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
assert len(events) >= 5, events
for e in events:
    assert {"stage", "fraction", "elapsed_s"} <= set(e) <= {"stage", "fraction", "detail",
                                                             "elapsed_s"}, e
    assert 0.0 <= e["fraction"] <= 1.0 and e["elapsed_s"] >= 0.0, e
stages = {e["stage"] for e in events}
assert {"triangulate", "map", "frames"} <= stages, stages
print(f"progress json: {len(events)} events, stages {sorted(stages)}")
PY

# optimize, whose end is not known: one event per iterate and topology pass under the stage
# "optimize", fraction 0, the detail naming the iterate's counters and energies.
"$CLI_BIN" --progress json optimize "$ex/square.svg" "$ex/hexagon.svg" --out opt_out \
  2>optimize.err >optimize.out
python3 - optimize.err <<'PY'
import json, sys
events = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
opt = [e for e in events if e["stage"] == "optimize"]
iterates = [e for e in opt if e.get("detail", "").startswith("outer ")
            and " inner " in e["detail"] and " map " in e["detail"]]
passes = [e for e in opt if ": " in e.get("detail", "") and "flips" in e["detail"]]
assert len(iterates) >= 10 and passes, opt[:3]
assert all(e["fraction"] == 0.0 for e in opt), opt
inner = [int(e["detail"].split()[3]) for e in iterates]
assert inner == sorted(inner) and len(set(inner)) == len(inner), inner
print(f"optimize progress: {len(iterates)} iterates, {len(passes)} passes")
PY
# report.json: the paper's columns and the worst triangle quality of multimesh.json's shapes.
python3 - opt_out <<'PY'
import json, math, os, sys
report = json.load(open(os.path.join(sys.argv[1], "report.json")))
for key in ("vertices_before", "vertices_after", "inner", "outer", "seconds", "map_energy",
            "mesh_energy", "worst_quality", "corner_matched_loops", "overlays"):
    assert key in report, (key, report)
assert report["corner_matched_loops"] == 0, report  # square -> hexagon: arc length meshes it
assert report["overlays"] == 0, report
mesh = json.load(open(os.path.join(sys.argv[1], "multimesh.json")))
worst = 1.0
for shape in (s["vertices"] for s in mesh["shapes"]):
    for a, b, c in mesh["triangles"]:
        (ax, ay), (bx, by), (cx, cy) = shape[a], shape[b], shape[c]
        area2 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        edges = sum((p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2
                    for p, q in ((shape[a], shape[b]), (shape[b], shape[c]), (shape[c], shape[a])))
        worst = min(worst, 2 * math.sqrt(3) * area2 / edges)
assert abs(report["worst_quality"] - worst) < 1e-6 and worst >= 0.02, (report, worst)
print(f"report.json: worst quality {worst:.4f}")
PY

# A project's meshing.corner_matching reaches the build: bar -> arch with corners matched from
# the start reports its one loop in report.json and says so on stderr.
cat > corners.json <<JSON
{"version": 1, "drawings": ["$INBETWEEN_SRC/examples/bar_arch/bar.svg",
                            "$INBETWEEN_SRC/examples/bar_arch/arch.svg"],
 "meshing": {"corner_matching": "always"}}
JSON
"$CLI_BIN" optimize --project corners.json --out corners_out 2> corners.err >/dev/null
grep -q "corners matched to corners on 1 loop" corners.err || { cat corners.err; exit 1; }
python3 - corners_out <<'PY'
import json, os, sys
report = json.load(open(os.path.join(sys.argv[1], "report.json")))
assert report["corner_matched_loops"] == 1, report
PY

# Two concave quadrilaterals neither of whose meshes maps onto the other when paired by arc
# length with the even sampling (the project's meshing settings; the feature alignment pairs
# them so that they map directly): built by the overlay, which stderr and report.json say, and
# optimized into a valid multimesh.
for q in "24.30 18.73 L28.52 28.64 L23.79 23.94 L5.13 -8.66" \
         "30.24 37.81 L20.55 29.14 L21.83 44.12 L-4.56 6.21"; do
  n=$(( ${n:-0} + 1 ))
  echo "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"-10 -10 50 60\"><path d=\"M$q Z\"/></svg>" > quad$n.svg
done
cat > overlay.json <<JSON
{"version": 1, "drawings": ["quad1.svg", "quad2.svg"],
 "meshing": {"boundary_alignment": "arc_length", "boundary_tolerance": 0}}
JSON
"$CLI_BIN" optimize --project overlay.json --out overlay_out 2> overlay.err >/dev/null
grep -q "1 overlaid with a triangulation of the drawing" overlay.err || { cat overlay.err; exit 1; }
python3 - overlay_out <<'PY'
import json, os, sys
report = json.load(open(os.path.join(sys.argv[1], "report.json")))
assert report["overlays"] == 1 and report["worst_quality"] > 0, report
print(f"overlay: {report['vertices_before']} -> {report['vertices_after']} vertices")
PY

# -q: no progress output (neither JSON events nor a bar), the result path still on stdout.
"$CLI_BIN" -q animate "$ex/square.svg" "$ex/hexagon.svg" --frames 6 --format json \
  --out quiet_out 2>quiet.err >quiet.out
grep -q "quiet_out/frames.json" quiet.out || { cat quiet.out; exit 1; }
if grep -qE '^\{|%|stage' quiet.err; then echo "-q printed progress:"; cat quiet.err; exit 1; fi

# 4: nothing listens there.
set +e
"$CLI_BIN" --server 127.0.0.1:1 inspect >unreachable.out 2>&1; code=$?
set -e
[[ $code -eq 4 ]] || { echo "unreachable server: exit $code, want 4"; cat unreachable.out; exit 1; }
grep -qi "connect" unreachable.out || { cat unreachable.out; exit 1; }

# 5: a real gRPC server (Debian's python3-grpcio, hence /usr/bin/python3) serving no Inbetween.
/usr/bin/python3 - >bare.log 2>&1 <<'PY' &
import grpc, sys, time
from concurrent import futures
server = grpc.server(futures.ThreadPoolExecutor(max_workers=2))
port = server.add_insecure_port("127.0.0.1:0")
server.start()
print(f"bare grpc server on 127.0.0.1:{port}", flush=True)
time.sleep(60)
PY
PIDS+=($!)
bare=""
for _ in $(seq 1 100); do
  bare=$(grep -oE '127\.0\.0\.1:[0-9]+' bare.log || true)
  [[ -n "$bare" ]] && break
  sleep 0.05
done
[[ -n "$bare" ]] || { cat bare.log; echo "bare server did not start"; exit 1; }
set +e
"$CLI_BIN" --server "$bare" inspect >unimplemented.out 2>&1; code=$?
set -e
[[ $code -eq 5 ]] || { echo "UNIMPLEMENTED: exit $code, want 5"; cat unimplemented.out; exit 1; }

# 3: a drawing that is not UTF-8 text is bad input, named with the drawing, byte and line (the
# request carries SVG text as a protobuf string, which must be UTF-8).
printf '<svg xmlns="http://www.w3.org/2000/svg">\n<path id="\xff" d="M0 0 L1 0 L1 1 Z"/></svg>\n' \
  >latin1.svg
set +e
"$CLI_BIN" -q mesh latin1.svg "$ex/hexagon.svg" --out latin1_out >latin1.out 2>&1; code=$?
set -e
[[ $code -eq 3 ]] || { echo "non-UTF-8 drawing: exit $code, want 3"; cat latin1.out; exit 1; }
grep -q "drawing 1 (latin1.svg): not UTF-8 text: byte 51 (line 2)" latin1.out ||
  { echo "non-UTF-8 drawing: unexpected message"; cat latin1.out; exit 1; }

# 130: SIGINT during a long animate (100000 frames) ends it promptly; no output is left behind.
"$CLI_BIN" -q animate "$ex/square.svg" "$ex/hexagon.svg" --frames 100000 --format json \
  --out interrupted >interrupted.out 2>&1 &
cli=$!
PIDS+=($cli)
sleep 2
kill -INT "$cli"
code=""
for _ in $(seq 1 100); do  # at most 10 s
  if ! kill -0 "$cli" 2>/dev/null; then
    set +e; wait "$cli"; code=$?; set -e
    break
  fi
  sleep 0.1
done
[[ -n "$code" ]] || { echo "animate did not stop within 10 s of SIGINT"; exit 1; }
[[ $code -eq 130 ]] || { echo "SIGINT: exit $code, want 130"; cat interrupted.out; exit 1; }
[[ ! -e interrupted/frames.json ]] || { echo "an interrupted animate wrote frames.json"; exit 1; }

# Ctrl-C against a server cancels the remote job: the CLI exits 130 and the server's Inbetween
# call ends CANCELLED (its solver stopped), while the server keeps serving.
start_server
"$CLI_BIN" -q --server "$SERVER_ADDR" animate "$ex/square.svg" "$ex/hexagon.svg" \
  --frames 100000 --format json --out remote_interrupted >remote.out 2>&1 &
cli=$!
PIDS+=($cli)
for _ in $(seq 1 100); do  # until the stream runs (the build finished), at most 10 s
  grep -q "rpc=BuildMultimesh .*status=OK" "$WORK/server.log" && break
  sleep 0.1
done
sleep 0.5
kill -INT "$cli"
code=""
for _ in $(seq 1 100); do
  if ! kill -0 "$cli" 2>/dev/null; then
    set +e; wait "$cli"; code=$?; set -e
    break
  fi
  sleep 0.1
done
[[ "$code" == 130 ]] || { echo "remote SIGINT: exit '$code', want 130"; cat remote.out; exit 1; }
for _ in $(seq 1 50); do
  grep -q "rpc=Inbetween .*status=CANCELLED" "$WORK/server.log" && break
  sleep 0.1
done
grep -q "rpc=Inbetween .*status=CANCELLED" "$WORK/server.log" ||
  { echo "the server's Inbetween did not end CANCELLED"; tail -5 "$WORK/server.log"; exit 1; }
"$CLI_BIN" --server "$SERVER_ADDR" inspect >/dev/null  # still serving
echo "ok"
