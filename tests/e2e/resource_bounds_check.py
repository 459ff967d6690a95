"""Driver of tests/e2e/resource_bounds_test.sh: the largest requests the server's limits allow,
and requests just over them, against a live inbetween-server (its pid is given, to read its
memory from /proc). Prints every measurement; exits non-zero on the first failed check.

Phases (each phase's peak RSS is read from VmHWM, then reset through /proc/PID/clear_refs):
  setup     a small healthy session H (examples/square_hexagon), built, its frames recorded
  put       sessions B1 and B2: max-drawings drawings each of exactly max-drawing-points points
  refuse    over the limits: max+1 points (polylines, SVG, outline + cut), one drawing more than
            max-drawings, a message over max-message-bytes, a session over max-sessions
  build     BuildMultimesh of B1 and B2 at once with a fine mesh near max-mesh-vertices, while H
            streams its frames again and again (the three heavy slots all busy)
  overmesh  BuildMultimesh asking for more than max-mesh-vertices (boundary_vertices = max + 1;
            a finer max_edge_relative whose refinement passes the limit), frames = max + 1
  frames    Inbetween of B1 and B2 at once, exactly max-frames frames each, read to the end
  queue     every heavy slot and the queue full: one more heavy call is refused with
            retry-after-ms
  after     H's frames identical to the ones recorded first, B1 readable, Health SERVING
"""

import argparse
import faulthandler
import math
import sys
import threading
import time

import grpc

from inbetween.v1 import inbetween_pb2 as pb
from inbetween.v1 import inbetween_pb2_grpc as pb_grpc

def check(condition, what):
    if not condition:
        print(f"FAIL: {what}", flush=True)
        raise SystemExit(1)


def proc_status(pid):
    """VmRSS, VmHWM, VmSize, VmPeak of the server in MiB (floats)."""
    values = {}
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            key, _, rest = line.partition(":")
            if key in ("VmRSS", "VmHWM", "VmSize", "VmPeak"):
                values[key] = int(rest.split()[0]) / 1024.0
    return values


class Memory:
    """Per-phase peak RSS (VmHWM, reset after each phase) plus a 20 ms VmRSS sampler as a
    cross-check (and the only source when clear_refs cannot be written)."""

    def __init__(self, pid):
        self.pid = pid
        self.phases = []
        self.sampled_peak = 0.0
        self.samples = 0
        self._stop = threading.Event()
        self.can_reset = self._reset()
        self._thread = threading.Thread(target=self._sample, daemon=True)
        self._thread.start()

    def _reset(self):
        try:
            with open(f"/proc/{self.pid}/clear_refs", "w") as clear:
                clear.write("5")  # resets VmHWM to the current RSS
            return True
        except OSError:
            return False

    def _sample(self):
        while not self._stop.is_set():
            try:
                self.sampled_peak = max(self.sampled_peak, proc_status(self.pid)["VmRSS"])
                self.samples += 1
            except (OSError, KeyError):
                return
            self._stop.wait(0.02)

    def end_phase(self, name, seconds):
        status = proc_status(self.pid)
        self.phases.append((name, status["VmHWM"], status["VmRSS"], seconds))
        print(f"phase {name:9s} {seconds:6.2f} s  peak RSS {status['VmHWM']:7.1f} MiB  "
              f"RSS now {status['VmRSS']:7.1f} MiB  VmSize {status['VmSize']:7.1f} MiB",
              flush=True)
        if self.can_reset:
            self._reset()

    def stop(self):
        self._stop.set()
        self._thread.join()

    def peak(self):
        return max([p[1] for p in self.phases] + [self.sampled_peak])


def outline(kind, n):
    """A smooth closed outline of exactly n points (no corners, no near-duplicates), positive
    signed area with y down: 0 circle, 1 ellipse, 2 superellipse (a rounded square)."""
    points = []
    for i in range(n):
        t = 2.0 * math.pi * i / n
        c, s = math.cos(t), math.sin(t)
        if kind == 0:
            x, y = 100.0 * c, 100.0 * s
        elif kind == 1:
            x, y = 140.0 * c, 70.0 * s
        else:
            x, y = 100.0 * math.copysign(abs(c) ** 0.6, c), 100.0 * math.copysign(abs(s) ** 0.6, s)
        points.append(pb.Point(x=x + 200.0, y=y + 200.0))
    return points


def polyline_drawing(name, points):
    outline_element = pb.TopologyElement(kind=pb.ELEMENT_KIND_OUTLINE,
                                         polyline=pb.Polyline(points=points))
    return pb.Drawing(name=name, polylines=pb.DrawingPolylines(elements=[outline_element]))


def svg_polygon(n):
    points = outline(0, n)
    path = "M" + " L".join(f"{p.x:.6f},{p.y:.6f}" for p in points) + " Z"
    return f'<svg xmlns="http://www.w3.org/2000/svg"><path fill="#000" d="{path}"/></svg>'


class Driver:
    def __init__(self, args):
        self.args = args
        options = [("grpc.max_receive_message_length", 256 << 20),
                   ("grpc.max_send_message_length", 256 << 20)]
        self.options = options
        self.channel = grpc.insecure_channel(args.server, options=options)
        self.stub = pb_grpc.InbetweenStub(self.channel)
        self.timings = {}

    def md(self, session_id):
        return [("x-session-id", session_id)]

    def create(self, name):
        return self.stub.CreateSession(pb.CreateSessionRequest(display_name=name),
                                       timeout=30).session

    def put(self, session, drawing, topology=()):
        request = pb.PutDrawingRequest(session_id=session.id, expected_version=session.version,
                                       drawing=drawing, topology=list(topology))
        return self.stub.PutDrawing(request, timeout=60, metadata=self.md(session.id))

    def build(self, session, meshing=None):
        request = pb.BuildMultimeshRequest(session_id=session.id, expected_version=session.version)
        if meshing is not None:
            request.meshing.CopyFrom(meshing)
        result = None
        for message in self.stub.BuildMultimesh(request, timeout=self.args.request_timeout,
                                                metadata=self.md(session.id)):
            if message.HasField("result"):
                result = message.result
        check(result is not None, f"BuildMultimesh of {session.id} ended without a result")
        return result

    def frames(self, session_id, count, on_frame=None):
        """Streams `count` frames to the end; returns (header, [vertex lists]) and keeps only
        what on_frame returns per frame (default: the vertices as tuples)."""
        request = pb.InbetweenRequest(session_id=session_id,
                                      parameters=pb.InbetweenParameters(frames=count))
        header, frames = None, []
        for message in self.stub.Inbetween(request, timeout=self.args.request_timeout,
                                           metadata=self.md(session_id)):
            if message.HasField("header"):
                header = message.header
            elif message.HasField("frame"):
                frame = message.frame
                frames.append(on_frame(frame) if on_frame else
                              [(p.x, p.y) for p in frame.vertices])
        return header, frames

    def expect_error(self, what, call, codes, needles):
        """Runs call(); it must fail with one of `codes` and a message containing every needle."""
        start = time.monotonic()
        try:
            call()
        except grpc.RpcError as error:
            seconds = time.monotonic() - start
            code, details = error.code(), error.details() or ""
            print(f"refused   {what}: {code.name} in {seconds:.2f} s: {details}", flush=True)
            check(code in codes, f"{what}: expected {[c.name for c in codes]}, got {code.name}: "
                                 f"{details}")
            for needle in needles:
                check(needle in details, f"{what}: the message does not name {needle!r}: {details}")
            check(seconds < self.args.refuse_seconds,
                  f"{what}: refused after {seconds:.1f} s (bound {self.args.refuse_seconds} s)")
            return error
        check(False, f"{what}: accepted, expected {[c.name for c in codes]}")

    def run(self):
        a = self.args
        pid = a.pid
        baseline = proc_status(pid)
        print(f"limits: drawing points {a.max_drawing_points}, drawings {a.max_drawings}, mesh "
              f"vertices {a.max_mesh_vertices}, frames {a.max_frames}, message bytes "
              f"{a.max_message_bytes}, sessions {a.max_sessions}, heavy jobs {a.max_heavy_jobs} "
              f"+ queue {a.heavy_queue}", flush=True)
        print(f"server idle: RSS {baseline['VmRSS']:.1f} MiB, VmSize {baseline['VmSize']:.1f} MiB",
              flush=True)
        check(a.max_heavy_jobs_per_token > a.max_heavy_jobs + a.heavy_queue,
              "--max-heavy-jobs-per-token must exceed jobs + queue (one owner without --tokens), "
              "else the per-token bound refuses before the queue fills")
        memory = Memory(pid)
        print(f"per-phase peaks from VmHWM + clear_refs: {memory.can_reset}", flush=True)
        started = time.monotonic()

        # --- setup: the healthy session H ------------------------------------------------------
        t = time.monotonic()
        h = self.create("healthy")
        for name in ("square.svg", "hexagon.svg"):
            with open(f"{a.examples}/square_hexagon/{name}", encoding="utf-8") as source:
                h = self.put(h, pb.Drawing(name=name, svg=source.read())).session
        h = self.build(h).session
        _, reference = self.frames(h.id, a.healthy_frames)
        check(len(reference) == a.healthy_frames, "H: wrong frame count")
        memory.end_phase("setup", time.monotonic() - t)

        # --- put: B1 and B2, max-drawings drawings of exactly max-drawing-points points ---------
        t = time.monotonic()
        big = []
        for b in range(2):
            s = self.create(f"big{b + 1}")
            for k in range(a.max_drawings):
                t0 = time.monotonic()
                reply = self.put(s, polyline_drawing(f"big{b + 1}-{k + 1}",
                                                     outline(k % 3, a.max_drawing_points)))
                s = reply.session
                stored = sum(len(e.polyline.points) for e in reply.drawing.elements)
                check(stored == a.max_drawing_points,
                      f"B{b + 1} drawing {k + 1}: stored {stored} points, sent "
                      f"{a.max_drawing_points}")
                self.timings.setdefault("PutDrawing (max points)", []).append(time.monotonic() - t0)
            big.append(s)
        memory.end_phase("put", time.monotonic() - t)

        # --- refuse: requests just over the limits ---------------------------------------------
        t = time.monotonic()
        b1 = big[0]
        over = a.max_drawing_points + 1
        fresh = self.create("over")
        self.expect_error(f"PutDrawing of {over} points (polylines)",
                          lambda: self.put(fresh, polyline_drawing("over", outline(0, over))),
                          [grpc.StatusCode.RESOURCE_EXHAUSTED], ["--max-drawing-points"])
        self.expect_error(f"PutDrawing of {over} points (SVG path)",
                          lambda: self.put(fresh, pb.Drawing(name="over.svg",
                                                             svg=svg_polygon(over))),
                          [grpc.StatusCode.RESOURCE_EXHAUSTED], ["--max-drawing-points"])
        cut = [pb.Point(x=180.0, y=200.0), pb.Point(x=220.0, y=200.0)]
        self.expect_error(f"PutDrawing of {a.max_drawing_points} outline points + a 2-point cut",
                          lambda: self.put(fresh, polyline_drawing(
                              "over", outline(0, a.max_drawing_points)), topology=[
                                  pb.TopologyElement(kind=pb.ELEMENT_KIND_CUT,
                                                     polyline=pb.Polyline(points=cut))]),
                          [grpc.StatusCode.RESOURCE_EXHAUSTED], ["--max-drawing-points"])
        self.expect_error(f"PutDrawing of drawing {a.max_drawings + 1}",
                          lambda: self.put(b1, polyline_drawing("one more", outline(0, 64))),
                          [grpc.StatusCode.RESOURCE_EXHAUSTED], ["--max-drawings"])
        # gRPC refuses it before any handler, with its own text; the C++ client (and so the CLI)
        # rewords it naming --max-message-bytes (client/inbetween_client.h, FromGrpcStatus).
        huge = pb.Drawing(name="huge.svg", svg="<svg>" + " " * (a.max_message_bytes + 1) + "</svg>")
        self.expect_error(f"PutDrawing of {a.max_message_bytes + 1}+ bytes",
                          lambda: self.put(fresh, huge),
                          [grpc.StatusCode.RESOURCE_EXHAUSTED], ["larger than max"])
        # Sessions so far: H, B1, B2, fresh. Fill up to max-sessions, then one more is refused.
        extra = [self.create(f"extra{i}") for i in range(a.max_sessions - 4)]
        self.expect_error(f"CreateSession number {a.max_sessions + 1}",
                          lambda: self.create("one too many"),
                          [grpc.StatusCode.RESOURCE_EXHAUSTED],
                          [f"maximum of {a.max_sessions} sessions (--max-sessions {a.max_sessions})"])
        for s in extra + [fresh]:
            self.stub.DeleteSession(pb.DeleteSessionRequest(session_id=s.id), timeout=30,
                                    metadata=self.md(s.id))
        for s in big:  # nothing refused changed a session
            now = self.stub.GetSession(pb.GetSessionRequest(session_id=s.id), timeout=30,
                                       metadata=self.md(s.id)).session
            check(now.version == s.version and len(now.drawings) == a.max_drawings,
                  f"{s.id}: a refused call changed the session")
        memory.end_phase("refuse", time.monotonic() - t)

        # --- build: B1 and B2 at once near max-mesh-vertices, H streaming meanwhile -------------
        t = time.monotonic()
        fine = pb.MeshingParameters(boundary_vertices=a.boundary_vertices,
                                    max_edge_relative=a.max_edge_relative)
        results, errors = [None, None], []

        def build_big(i):
            try:
                t0 = time.monotonic()
                results[i] = self.build(big[i], fine)
                self.timings.setdefault("BuildMultimesh (near max vertices)", []).append(
                    time.monotonic() - t0)
            except (grpc.RpcError, SystemExit) as error:
                errors.append(f"BuildMultimesh B{i + 1}: {error}")

        healthy_runs = self._while_streaming_healthy(
            h, reference, [threading.Thread(target=build_big, args=(i,)) for i in range(2)])
        check(not errors, "; ".join(errors))
        for i, result in enumerate(results):
            v = result.stats.vertices
            print(f"B{i + 1} multimesh: {v} vertices ({100.0 * v / a.max_mesh_vertices:.1f}% of "
                  f"the limit), {result.stats.triangles} triangles, result message "
                  f"{result.ByteSize()} bytes", flush=True)
            check(v <= a.max_mesh_vertices, f"B{i + 1}: {v} vertices above the limit")
            check(v >= a.min_mesh_fraction * a.max_mesh_vertices,
                  f"B{i + 1}: {v} vertices, not near the limit {a.max_mesh_vertices} "
                  f"(wanted >= {a.min_mesh_fraction:.0%}): retune --boundary-vertices / "
                  f"--max-edge-relative")
            big[i] = result.session
        print(f"H streamed {healthy_runs} times during the builds, identical frames", flush=True)
        check(healthy_runs >= 1, "H did not stream during the builds")
        vertices = results[0].stats.vertices
        memory.end_phase("build", time.monotonic() - t)

        # --- overmesh: more than max-mesh-vertices, max-frames + 1 -------------------------------
        t = time.monotonic()
        b1 = big[0]
        too_many = pb.MeshingParameters(boundary_vertices=a.max_mesh_vertices + 1)
        self.expect_error(f"BuildMultimesh with boundary_vertices = {a.max_mesh_vertices + 1}",
                          lambda: self.build(b1, too_many),
                          [grpc.StatusCode.RESOURCE_EXHAUSTED], ["--max-mesh-vertices"])
        finer = pb.MeshingParameters(boundary_vertices=a.boundary_vertices,
                                     max_edge_relative=a.over_edge_relative)
        self.expect_error(f"BuildMultimesh with max_edge_relative = {a.over_edge_relative}",
                          lambda: self.build(b1, finer),
                          [grpc.StatusCode.RESOURCE_EXHAUSTED],
                          [str(a.max_mesh_vertices), "--max-mesh-vertices"])
        self.expect_error(f"Inbetween of {a.max_frames + 1} frames",
                          lambda: self.frames(b1.id, a.max_frames + 1),
                          [grpc.StatusCode.RESOURCE_EXHAUSTED], ["--max-frames"])
        now = self.stub.GetSession(pb.GetSessionRequest(session_id=b1.id), timeout=30,
                                   metadata=self.md(b1.id)).session
        check(now.version == b1.version and now.multimesh_stats.vertices == vertices,
              "B1: a refused build changed the session")
        memory.end_phase("overmesh", time.monotonic() - t)

        # --- frames: exactly max-frames frames of B1 and B2 at once, read to the end -------------
        t = time.monotonic()
        streamed, errors = [None, None], []

        def stream_big(i):
            try:
                t0 = time.monotonic()
                first = []

                def on_frame(frame):
                    if not first:
                        first.append(time.monotonic() - t0)
                    return (frame.index, len(frame.vertices), frame.stats.inverted_triangles)

                header, frames = self.frames(big[i].id, a.max_frames, on_frame)
                streamed[i] = (header, frames, first[0], time.monotonic() - t0)
            except grpc.RpcError as error:
                errors.append(f"Inbetween B{i + 1}: {error.code().name}: {error.details()}")

        threads = [threading.Thread(target=stream_big, args=(i,)) for i in range(2)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        check(not errors, "; ".join(errors))
        for i, (header, frames, first, seconds) in enumerate(streamed):
            n = big[i].multimesh_stats.vertices
            check(header is not None and header.frames == a.max_frames, f"B{i + 1}: header")
            check([f[0] for f in frames] == list(range(a.max_frames)),
                  f"B{i + 1}: got frames {len(frames)}, expected 0..{a.max_frames - 1}")
            check(all(f[1] == n for f in frames), f"B{i + 1}: a frame without {n} vertices")
            check(all(f[2] == 0 for f in frames), f"B{i + 1}: a frame with inverted triangles")
            print(f"B{i + 1}: {len(frames)} frames of {n} vertices, first after {first:.2f} s, "
                  f"all after {seconds:.2f} s", flush=True)
            self.timings.setdefault("Inbetween (max frames)", []).append(seconds)
        memory.end_phase("frames", time.monotonic() - t)

        # --- queue: every heavy slot and the queue taken, one more call refused ------------------
        t = time.monotonic()
        calls, channels = [], []

        def own_stub():  # a connection per call, as separate clients would have
            # Without BDP probing the connection's flow-control window stays at its initial size,
            # so a stream the client does not read blocks the server's writes: with the small
            # meshes of a sanitizer run, a grown window took all max-frames frames, the handler
            # finished and freed its slot, and the sixth call was admitted.
            channels.append(grpc.insecure_channel(
                a.server, options=list(self.options) + [("grpc.http2.bdp_probe", 0)]))
            return pb_grpc.InbetweenStub(channels[-1])

        try:
            # One call at a time, so that each has reached its slot or the queue before the next
            # (a handler loads the session before it asks the pool: a later call on a smaller
            # session could overtake it).
            for i in range(a.max_heavy_jobs + a.heavy_queue):
                request = pb.InbetweenRequest(
                    session_id=b1.id, parameters=pb.InbetweenParameters(frames=a.max_frames))
                call = own_stub().Inbetween(request, timeout=a.request_timeout,
                                            metadata=self.md(b1.id))
                calls.append(call)
                if i < a.max_heavy_jobs:
                    next(call)  # the header: this call holds a slot (the client reads no further)
                else:
                    settle = time.monotonic() + a.queue_settle_seconds
                    while time.monotonic() < settle and not call.done():
                        time.sleep(0.05)
                    if call.done():  # (code() would wait for the end of a call still queued)
                        check(False, f"heavy call {i + 1} (queue place {i + 1 - a.max_heavy_jobs}"
                                     f" of {a.heavy_queue}) ended: {call.code().name}: "
                                     f"{call.details()}")
            # One more heavy call (on the small session) must be refused at once, not queued.
            one_more = pb.InbetweenRequest(session_id=h.id,
                                           parameters=pb.InbetweenParameters(frames=2))
            refused = self.expect_error(
                f"Inbetween number {a.max_heavy_jobs + a.heavy_queue + 1} at once",
                lambda: next(own_stub().Inbetween(one_more, timeout=a.refuse_seconds,
                                                  metadata=self.md(h.id))),
                [grpc.StatusCode.RESOURCE_EXHAUSTED], ["--max-heavy-jobs", "--heavy-queue"])
            trailing = dict(refused.trailing_metadata() or ())
            check("retry-after-ms" in trailing, "a busy refusal without retry-after-ms")
        finally:
            # The queued calls first, so that they leave the queue rather than take the slots
            # the running ones give back.
            for call in calls[a.max_heavy_jobs:]:
                call.cancel()
            time.sleep(0.3)
            for call in calls[:a.max_heavy_jobs]:
                call.cancel()
            for channel in channels:
                channel.close()
        memory.end_phase("queue", time.monotonic() - t)

        # --- after: the server still serves; H unaffected ----------------------------------------
        t = time.monotonic()
        deadline = time.monotonic() + 30
        while True:  # the cancelled calls give their slots back
            try:
                _, again = self.frames(h.id, a.healthy_frames)
                break
            except grpc.RpcError as error:
                check(error.code() == grpc.StatusCode.RESOURCE_EXHAUSTED and
                      time.monotonic() < deadline, f"H after the run: {error.code().name}")
                time.sleep(0.2)
        check(again == reference, "H: frames after the run differ from the frames before it")
        full = self.stub.GetSession(pb.GetSessionRequest(session_id=b1.id, full=True), timeout=30,
                                    metadata=self.md(b1.id))
        check(len(full.multimesh.shapes) == a.max_drawings and
              len(full.multimesh.shapes[0].vertices) == vertices, "B1: GetSession(full)")
        # grpc.health.v1.Health/Check without its stubs: HealthCheckRequest{service} in, and
        # HealthCheckResponse{status: SERVING (1)} = bytes 08 01 out.
        check_health = self.channel.unary_unary("/grpc.health.v1.Health/Check")
        for service in ("", "inbetween.v1.Inbetween"):
            name = service.encode()
            request = (b"\x0a" + bytes([len(name)]) + name) if name else b""
            check(check_health(request, timeout=30) == b"\x08\x01",
                  f"Health/Check({service!r}) is not SERVING")
        memory.end_phase("after", time.monotonic() - t)
        memory.stop()
        total = time.monotonic() - started

        print("timings (s):", flush=True)
        for name, values in self.timings.items():
            print(f"  {name}: " + ", ".join(f"{v:.2f}" for v in values), flush=True)
        peak = memory.peak()
        final = proc_status(pid)
        bound = f"bound {a.max_rss_mb:.0f} MiB" if a.max_rss_mb > 0 else "no bound"
        print(f"server peak RSS {peak:.1f} MiB ({bound}; sampled VmRSS peak "
              f"{memory.sampled_peak:.1f} MiB over {memory.samples} samples), VmPeak "
              f"{final['VmPeak']:.1f} MiB, RSS at the end {final['VmRSS']:.1f} MiB, driver "
              f"{total:.1f} s", flush=True)
        if a.max_rss_mb > 0:
            check(peak < a.max_rss_mb, f"server peak RSS {peak:.1f} MiB above the bound "
                                       f"{a.max_rss_mb} MiB")
        for name, values in self.timings.items():
            check(max(values) < a.request_seconds,
                  f"{name} took {max(values):.1f} s (bound {a.request_seconds} s)")

    def _while_streaming_healthy(self, h, reference, threads):
        """Starts threads, streams H's frames until they end (each run must equal reference);
        returns the number of complete healthy runs."""
        runs = 0
        for thread in threads:
            thread.start()
        while any(thread.is_alive() for thread in threads):
            _, frames = self.frames(h.id, len(reference))
            check(frames == reference, "H: frames during the big builds differ from before")
            runs += 1
            time.sleep(0.05)  # leave the cores to the builds
        for thread in threads:
            thread.join()
        return runs


def main():
    # A hang shows where it is: every thread's stack, shortly before the shell's timeout.
    faulthandler.dump_traceback_later(200, exit=True)
    parser = argparse.ArgumentParser()
    parser.add_argument("--server", required=True)
    parser.add_argument("--pid", type=int, required=True)
    parser.add_argument("--examples", required=True)
    for name in ("max-drawing-points", "max-drawings", "max-mesh-vertices", "max-frames",
                 "max-message-bytes", "max-sessions", "max-heavy-jobs", "heavy-queue",
                 "max-heavy-jobs-per-token", "boundary-vertices"):
        parser.add_argument(f"--{name}", type=int, required=True)
    parser.add_argument("--max-edge-relative", type=float, required=True)
    parser.add_argument("--over-edge-relative", type=float, required=True)
    parser.add_argument("--min-mesh-fraction", type=float, default=0.8)
    parser.add_argument("--healthy-frames", type=int, default=12)
    parser.add_argument("--max-rss-mb", type=float, default=0, help="0 = report only")
    parser.add_argument("--request-seconds", type=float, default=60,
                        help="bound on each largest request")
    parser.add_argument("--refuse-seconds", type=float, default=15,
                        help="bound on each refusal")
    parser.add_argument("--request-timeout", type=float, default=120)
    parser.add_argument("--queue-settle-seconds", type=float, default=1.5,
                        help="time a queued call gets to reach the pool's queue")
    try:
        Driver(parser.parse_args()).run()
    except grpc.RpcError as error:  # a call the checks above did not expect to fail
        print(f"FAIL: unexpected {error.code().name}: {error.details()}", flush=True)
        return 1
    print("resource bounds: all checks passed", flush=True)


if __name__ == "__main__":
    sys.exit(main())
