"""Tests of the synchronous client (inbetween.Client) against the real inbetween-server binary.

Environment: INBETWEEN_SERVER_BIN (the server binary), INBETWEEN_SRC (the source tree, for the
examples). The package must be importable (installed, as tests/e2e/python_client_test.sh does).
"""

import json
import os
import pathlib
import tempfile
import threading
import time
import unittest

import grpc

import inbetween
from inbetween.v1 import inbetween_pb2 as pb
from support import (HEXAGON, SLOW_COMESH, SLOW_DRAWINGS, SLOW_MESHING, SQUARE, BreakingProxy,
                     FlakyUnary, bytes_through_frame, start_server, stop_server)

# Retries fast enough for tests, many enough to outlast a server restart.
FAST_RETRY = inbetween.RetryPolicy(max_attempts=8, initial_backoff=0.05, max_backoff=0.5)


def vertices(frame):
    return [(p.x, p.y) for p in frame.vertices]


class ClientTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server, cls.address = start_server()
        cls.client = inbetween.Client(cls.address, timeout=120)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        stop_server(cls.server)

    def setUp(self):
        self.out = tempfile.mkdtemp(prefix="inbetween_py_")

    def built_session(self, name):
        session = self.client.create_session(name)
        session = self.client.upload_svgs(session, [SQUARE, HEXAGON])
        self.assertEqual(len(session.drawings), 2)
        self.assertEqual(session.stage, pb.STAGE_DRAWINGS)
        return self.client.build(session)

    def test_whole_job_build_optimize_with_progress_and_frames_to_files(self):
        session = self.built_session("py-whole-job")
        self.assertEqual(session.stage, pb.STAGE_MULTIMESH)
        events = []
        session = self.client.optimize(session, on_progress=events.append, max_outer_iterations=2)
        self.assertEqual(session.stage, pb.STAGE_OPTIMIZED)
        self.assertTrue(any(isinstance(e, pb.ComeshIteration) for e in events), events[:3])

        _, mesh = self.client.get_session(session.id, full=True)
        paths = self.client.stream_frames(session, self.out, frames=5)
        self.assertEqual([os.path.basename(p) for p in paths],
                         [f"frame_{i:04d}.json" for i in range(5)])
        frames = []
        for path in paths:
            with open(path, encoding="utf-8") as source:
                frames.append(json.load(source))
            self.assertTrue(os.path.getsize(path[:-5] + ".svg") > 0)
        # Frames 0 and 4 are the keys: the optimized shapes' vertices.
        for frame, shape in ((frames[0], mesh.shapes[0]), (frames[-1], mesh.shapes[1])):
            self.assertEqual(len(frame["vertices"]), len(shape.vertices))
            for (x, y), p in zip(frame["vertices"], shape.vertices):
                self.assertAlmostEqual(x, p.x, places=6)
                self.assertAlmostEqual(y, p.y, places=6)
        self.assertEqual([f["index"] for f in frames], list(range(5)))
        self.assertAlmostEqual(frames[2]["time"], 0.5)

    def test_build_and_optimize_as_iterators_end_with_their_result(self):
        session = self.client.upload_svgs(self.client.create_session("py-iter"), [SQUARE, HEXAGON])
        events = list(self.client.stream_build(
            session, meshing=inbetween.meshing_parameters(corner_matching="never")))
        self.assertIsInstance(events[-1], pb.BuildMultimeshResult)
        self.assertTrue(all(isinstance(e, pb.Progress) for e in events[:-1]), events[:-1])
        self.assertGreater(events[-1].stats.vertices, 0)
        built = events[-1].session
        events = list(self.client.stream_optimize(
            built, comesh=inbetween.comesh_parameters(max_outer_iterations=1, min_quality=0.02,
                                                     slide_window=0.15)))
        result = events[-1]
        self.assertIsInstance(result, pb.OptimizeComeshResult)
        inner = [e.inner for e in events if isinstance(e, pb.ComeshIteration)]
        self.assertTrue(inner)
        self.assertEqual(inner, sorted(set(inner)))  # each iteration once, in order
        self.assertEqual(result.session.stage, pb.STAGE_OPTIMIZED)
        self.assertEqual(result.session.version, built.version + 1)

    def test_inbetween_takes_every_parameter_and_start_frame(self):
        session = self.built_session("py-params")
        parameters = inbetween.inbetween_parameters(
            timing="ease-in-out", ease=[0.5], lambda_=2.0, tau=0.2, alpha=0.4, epsilon=0.0,
            rho=1.0, timestep=1 / 24, max_iterations=10, key_times=[0.0, 1.0],
            stiffness=[([(10, 10), (60, 10), (60, 60), (10, 60)], 4.0)])
        progress = []
        whole = self.client.inbetween(session, frames=7, method="zhu17", parameters=parameters,
                                      on_progress=progress.append)
        self.assertEqual(whole.header.frames, 7)
        self.assertEqual([f.index for f in whole.frames], list(range(7)))
        self.assertEqual(list(whole.header.keys), [0, 6])
        # Ease in/out: the middle frame is at half time, the first step shorter than linear.
        self.assertAlmostEqual(whole.frames[3].time, 0.5)
        self.assertLess(whole.frames[1].weights[1], 1 / 6)
        # A stream started at frame 4 sends the same frames 4..6.
        tail = self.client.inbetween(session, frames=7, method="zhu17", parameters=parameters,
                                     start_frame=4)
        self.assertEqual([f.index for f in tail.frames], [4, 5, 6])
        for a, b in zip(tail.frames, whole.frames[4:]):
            self.assertEqual(vertices(a), vertices(b))
        with self.assertRaises(inbetween.InvalidArgumentError) as bad:
            self.client.inbetween(session, parameters=inbetween.inbetween_parameters(alpha=2.0))
        self.assertEqual(bad.exception.status_code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("alpha", bad.exception.details)

    def test_header_art_places_each_key_as_drawn(self):
        session = self.built_session("py-art")
        drawings = self.client.get_session(session.id, full=True)[0].drawings
        events = list(self.client.frames(session.id, 3, method="linear"))
        header, frames = events[0][1], [message for _, message in events[1:]]
        self.assertEqual([k.key for k in header.art], [0, 1])
        for key, frame in ((0, frames[0]), (1, frames[-1])):
            placed = inbetween.place_art(header, frame)
            self.assertEqual([(k, w) for k, w, _ in placed], [(key, 1.0)])
            layers = placed[0][2]
            self.assertEqual(len(layers), len(drawings[key].art))
            for (paint, paths), drawn in zip(layers, drawings[key].art):
                self.assertEqual(paint.fill, drawn.fill)
                self.assertEqual(len(paths), len(drawn.paths))
                for (closed, points), drawn_path in zip(paths, drawn.paths):
                    self.assertEqual(closed, drawn_path.closed)
                    # The drawn points, in order, with edge crossings inserted between them.
                    rest = iter(points)
                    for p in drawn_path.points:
                        self.assertTrue(any(abs(x - p.x) < 1e-6 and abs(y - p.y) < 1e-6
                                            for x, y in rest), (key, p))
        middle = inbetween.place_art(header, frames[1])
        self.assertEqual([k for k, _, _ in middle], [0, 1])

    def test_stream_frames_draws_the_frames_art(self):
        session = self.built_session("py-art-svg")
        drawings = self.client.get_session(session.id, full=True)[0].drawings
        events = list(self.client.frames(session.id, 3, method="linear"))
        header, frames = events[0][1], [message for _, message in events[1:]]
        self.client.stream_frames(session, self.out, frames=3, method="linear")
        for frame in frames:
            with open(os.path.join(self.out, f"frame_{frame.index:04d}.svg"),
                      encoding="utf-8") as source:
                self.assertEqual(source.read(), inbetween.frame_art_svg(header, frame))
        # A key frame draws its drawing's layers; the middle one both keys' (morphed or faded).
        for key, frame in ((0, frames[0]), (1, frames[-1])):
            layers = inbetween.frame_art(header, frame)
            self.assertEqual([l.fill for l in layers],
                             [inbetween.art.Fill(a.fill.rgb, a.fill.opacity, a.fill.even_odd)
                              if a.HasField("fill") else None for a in drawings[key].art])
        self.assertTrue(inbetween.frame_art(header, frames[1]))
        mesh = os.path.join(self.out, "mesh")
        self.client.stream_frames(session, mesh, frames=3, method="linear", art=False)
        with open(os.path.join(mesh, "frame_0001.svg"), encoding="utf-8") as source:
            self.assertIn('fill="#8ab"', source.read())  # the triangles, as without art

    def test_errors_carry_the_servers_reason(self):
        # A square and a square with a hole: the build fails with the reason TOPOLOGY_DIFFERS,
        # read from the status details, not from the message.
        session = self.client.create_session("reason")
        session = self.client.put_svg(
            session, '<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0 H10 V10 H0 Z"/></svg>')
        session = self.client.put_svg(
            session, '<svg xmlns="http://www.w3.org/2000/svg"><path fill-rule="evenodd" '
                     'd="M0 0 H10 V10 H0 Z M3 3 H7 V7 H3 Z"/></svg>')
        with self.assertRaises(inbetween.InbetweenError) as failed:
            self.client.build(session)
        self.assertEqual(failed.exception.reason, "TOPOLOGY_DIFFERS")
        with self.assertRaises(inbetween.NotFoundError) as missing:
            self.client.get_session("no-such-session")
        self.assertIsNone(missing.exception.reason)
        self.assertIsNone(missing.exception.field)

    def test_errors_name_the_offending_field(self):
        # An SVG without paint: INVALID_ARGUMENT with the field from a google.rpc.BadRequest.
        session = self.client.create_session("field")
        with self.assertRaises(inbetween.InvalidArgumentError) as failed:
            self.client.put_svg(session, '<svg xmlns="http://www.w3.org/2000/svg"></svg>')
        self.assertEqual(failed.exception.field, "drawing.svg")
        self.assertIn("drawing.svg", failed.exception.details)

    def test_topology_edits_add_move_delete_and_a_bad_edit(self):
        session = self.client.put_svg(self.client.create_session("py-topology"), SQUARE)
        drawing = session.drawings[0].id
        with self.client.edit_topology(session) as editor:
            added = editor.add_opening(drawing, [(40, 60), (80, 60)])
            self.assertEqual(added.version, session.version + 1)
            self.assertEqual(len(added.elements), 2)
            self.assertEqual(added.classes[0].holes, 1)
            opening = added.elements[1].id
            moved = editor.move(drawing, opening, [(40, 60), (60, 66), (80, 60)])
            self.assertEqual(len(moved.elements[1].polyline.points), 3)
            self.assertEqual(len(moved.cohesive_edges), 2)
            deleted = editor.delete(drawing, opening)
            self.assertEqual(len(deleted.elements), 1)
            self.assertEqual(editor.version, session.version + 3)
        # One-edit helpers; a bad edit raises INVALID_ARGUMENT naming the element.
        session = self.client.get_session(session.id)
        state = self.client.add_cut(session, drawing, [(60, 40), (60, 80)])
        self.assertEqual(state.version, session.version + 1)
        with self.assertRaises(inbetween.InvalidArgumentError) as bad:
            self.client.add_cut(self.client.get_session(session.id), drawing,
                                [(200, 200), (300, 300)])
        self.assertIn("outside the shape", bad.exception.details)
        # Cuts and openings can also come with the drawing.
        response = self.client.put_drawing(
            self.client.get_session(session.id),
            pb.Drawing(name="with opening", svg=pathlib.Path(SQUARE).read_text(encoding="utf-8")),
            topology=[inbetween.topology_element("opening", [(40, 60), (80, 60)])])
        self.assertEqual(response.equivalence_class.holes, 1)
        self.assertEqual(len(response.session.drawings), 2)

    def test_polylines_marks_correspondences_and_remove_drawing(self):
        square = [(0, 0), (100, 0), (100, 100), (0, 100)]
        wide = [(0, 0), (200, 0), (200, 100), (0, 100)]
        session = self.client.create_session(
            "py-polylines", parameters=inbetween.parameters(
                inbetween=inbetween.inbetween_parameters(frames=4)))
        # key_time goes on every drawing or on none (INVALID_ARGUMENT at Inbetween otherwise).
        session = self.client.put_polylines(session, [square], marks={1: (0, 0)},
                                            name="square", key_time=0.0).session
        self.assertTrue(session.drawings[0].HasField("key_time"))
        response = self.client.put_polylines(session, [wide], marks=[(1, (0, 0))], key_time=1.0)
        self.assertEqual(response.drawing.marks[0].id, 1)
        self.assertEqual(response.drawing.key_time, 1.0)
        session = self.client.set_correspondences(response.session,
                                                  [[(100, 0), (200, 0)], [(0, 100), (0, 100)]])
        self.assertEqual(len(session.correspondences), 2)
        session = self.client.clear_correspondences(session)
        self.assertEqual(len(session.correspondences), 0)
        session = self.client.build(session)
        whole = self.client.inbetween(session, method="linear")
        self.assertEqual(len(whole.frames), 4)  # the session's frames
        self.assertEqual(list(whole.header.keys), [0, 3])
        extra = self.client.put_polylines(session, [square], key_time=0.5).session
        self.assertEqual(len(extra.drawings), 3)
        after = self.client.remove_drawing(extra, extra.drawings[-1].id)
        self.assertEqual(len(after.drawings), 2)
        self.assertEqual(after.stage, pb.STAGE_DRAWINGS)  # the multimesh was dropped

    def test_errors_carry_code_and_message(self):
        session = self.client.create_session("py-errors")
        newer = self.client.put_svg(session, SQUARE)
        with self.assertRaises(inbetween.InbetweenError) as stale:
            self.client.put_svg(session, HEXAGON)  # still at the old version
        self.assertIsInstance(stale.exception, inbetween.AbortedError)
        self.assertEqual(stale.exception.code, "ABORTED")
        self.assertEqual(stale.exception.status_code, grpc.StatusCode.ABORTED)
        self.assertFalse(stale.exception.maybe_applied)
        self.assertEqual(stale.exception.method, "PutDrawing")
        self.assertEqual(self.client.get_session(session.id).version, newer.version)
        with self.assertRaises(inbetween.NotFoundError) as missing:
            self.client.get_session("0000000000000000")
        self.assertEqual(missing.exception.code, "NOT_FOUND")
        self.assertTrue(missing.exception.details)
        with self.assertRaises(inbetween.FailedPreconditionError):
            list(self.client.frames(session.id, frames=4))
        with self.assertRaises(inbetween.InvalidArgumentError) as bad:
            self.client.put_svg(newer, HEXAGON, flatten_tolerance=-1.0)
        self.assertIn("flatten_tolerance", bad.exception.details)

    def test_export_import_and_list(self):
        session = self.built_session("py-export")
        path = self.client.export_session(session.id, os.path.join(self.out, "session.inbsession"))
        copy = self.client.import_session(path)
        self.assertNotEqual(copy.id, session.id)
        self.assertEqual(copy.stage, pb.STAGE_MULTIMESH)
        self.assertEqual(len(copy.drawings), 2)
        # Bytes both ways, and a chosen id (taken the second time).
        data = self.client.export_session(session)
        self.assertIsInstance(data, bytes)
        named = self.client.import_session(data, session_id="py-import-named")
        self.assertEqual(named.id, "py-import-named")
        with self.assertRaises(inbetween.AlreadyExistsError):
            self.client.import_session(data, session_id="py-import-named")
        ids = [s.id for s in self.client.list_sessions(page_size=1)]
        self.assertIn(session.id, ids)
        self.assertIn(copy.id, ids)
        self.client.delete_session(copy)
        self.client.delete_session(named.id)  # a bare id: any version
        ids = [s.id for s in self.client.list_sessions()]
        self.assertNotIn(copy.id, ids)
        self.assertNotIn(named.id, ids)
        # The imported copy animates without a rebuild.
        self.assertEqual(len(self.client.stream_frames(session, self.out, frames=3)), 3)

    def slow_session(self, name):
        """A session whose optimization (SLOW_COMESH) takes seconds."""
        session = self.client.upload_svgs(self.client.create_session(name), SLOW_DRAWINGS)
        return self.client.build(session, **SLOW_MESHING)

    def test_progress_callback_can_cancel_an_optimization(self):
        session = self.slow_session("py-cancel")
        seen = []

        def stop_after_first(event):
            seen.append(event)
            return False

        with self.assertRaises(inbetween.CallCancelledError) as cancelled:
            self.client.optimize(session, on_progress=stop_after_first, comesh=SLOW_COMESH)
        self.assertEqual(cancelled.exception.code, "CANCELLED")
        self.assertEqual(len(seen), 1)
        # Nothing was stored: the session is still at its built version.
        after = self.client.get_session(session.id)
        self.assertEqual(after.version, session.version)
        self.assertEqual(after.stage, pb.STAGE_MULTIMESH)

    def test_cancellation_from_another_thread_and_a_deadline(self):
        session = self.slow_session("py-cancel-thread")
        cancel = inbetween.Cancellation()
        started = threading.Event()

        def on_progress(event):
            started.set()

        timer = threading.Thread(target=lambda: started.wait(60) and cancel.cancel())
        timer.start()
        begun = time.monotonic()
        with self.assertRaises(inbetween.CallCancelledError):
            self.client.optimize(session, on_progress, comesh=SLOW_COMESH, cancel=cancel)
        timer.join()
        self.assertLess(time.monotonic() - begun, 60)
        with self.assertRaises(inbetween.CallCancelledError):  # a fired Cancellation stays so
            self.client.optimize(session, cancel=cancel)
        # A per-call deadline overrides the client's (120 s): DEADLINE_EXCEEDED, not retried. One
        # millisecond is far below any optimization's time, also the fastest one.
        with self.assertRaises(inbetween.DeadlineExceededError) as late:
            self.client.optimize(session, comesh=SLOW_COMESH, timeout=0.001)
        self.assertEqual(late.exception.status_code, grpc.StatusCode.DEADLINE_EXCEEDED)
        self.assertEqual(late.exception.attempts, 1)
        self.assertEqual(self.client.get_session(session.id).version, session.version)


class RetryTest(unittest.TestCase):
    """Retries of what is safe to repeat: reads across a server restart, versioned mutations
    after a fake UNAVAILABLE, the Inbetween stream resumed and OptimizeComesh resumed after a
    connection cut in the middle; nothing retried that is not safe."""

    @classmethod
    def setUpClass(cls):
        cls.store = tempfile.mkdtemp(prefix="inbetween_py_store_")
        cls.server, cls.address = start_server("--store", f"dir:{cls.store}")

    @classmethod
    def tearDownClass(cls):
        stop_server(cls.server)

    def client(self, **kwargs):
        events = []
        kwargs.setdefault("retry", FAST_RETRY)
        kwargs.setdefault("on_retry", events.append)
        client = inbetween.Client(kwargs.pop("target", self.address), timeout=120, **kwargs)
        self.addCleanup(client.close)
        return client, events

    def test_reads_are_retried_across_a_server_restart(self):
        # The server is killed, and started again on the same port and store when the client
        # reports its first failed attempt: the read fails while the server is down, and the
        # retry finds the new server (a restart on a timer instead raced the client's retries
        # and the channel's own reconnect backoff).
        cls = type(self)
        events = []
        restarted = []

        def restart_on_first_failure(event):
            events.append(event)
            if not restarted:
                cls.server, _ = start_server("--store", f"dir:{cls.store}", listen=cls.address)
                restarted.append(event)

        client, _ = self.client(on_retry=restart_on_first_failure)
        session = client.put_svg(client.create_session("py-restart"), SQUARE)
        stop_server(cls.server, kill=True)
        again = client.get_session(session.id)
        self.assertEqual(len(restarted), 1)
        self.assertEqual(again.version, session.version)
        self.assertTrue(events)
        self.assertTrue(all(e.method == "GetSession" and e.error.code == "UNAVAILABLE"
                            for e in events), events)
        self.assertEqual([e.failed_attempt for e in events], list(range(1, len(events) + 1)))

    def test_create_session_is_not_retried_but_reads_are(self):
        with socketless_address() as nowhere:
            client, events = self.client(target=nowhere)
            with self.assertRaises(inbetween.UnavailableError) as down:
                client.create_session("py-nowhere")
            self.assertEqual(events, [])
            self.assertEqual(down.exception.attempts, 1)
            with self.assertRaises(inbetween.UnavailableError) as read:
                client.list_sessions()
            self.assertEqual(len(events), FAST_RETRY.max_attempts - 1)
            self.assertEqual(read.exception.attempts, FAST_RETRY.max_attempts)

    def test_versioned_mutations_are_retried_once_applied_at_most(self):
        plain, _ = self.client()
        session = plain.create_session("py-flaky")
        # Lost before the server: the retry applies it.
        before = FlakyUnary("PutDrawing", failures=1)
        client, events = self.client(channel=grpc.intercept_channel(
            grpc.insecure_channel(self.address), before))
        after_put = client.put_svg(session, SQUARE)
        self.assertEqual(before.calls, 2)
        self.assertEqual(len(after_put.drawings), 1)
        self.assertEqual([e.method for e in events], ["PutDrawing"])
        # Lost after the server applied it: the retry is ABORTED and says it may have applied.
        lost = FlakyUnary("PutDrawing", failures=1, after=True)
        client, events = self.client(channel=grpc.intercept_channel(
            grpc.insecure_channel(self.address), lost))
        with self.assertRaises(inbetween.AbortedError) as aborted:
            client.put_svg(after_put, HEXAGON)
        self.assertTrue(aborted.exception.maybe_applied)
        self.assertEqual(aborted.exception.attempts, 2)
        self.assertEqual(len(plain.get_session(session.id).drawings), 2)  # applied once
        # CreateSession is never retried, even when the failure came before the server.
        never = FlakyUnary("CreateSession", failures=1)
        client, events = self.client(channel=grpc.intercept_channel(
            grpc.insecure_channel(self.address), never))
        with self.assertRaises(inbetween.UnavailableError):
            client.create_session("py-not-twice")
        self.assertEqual(never.calls, 1)
        # DeleteSession at a version: a retry that finds the session gone is done.
        gone = FlakyUnary("DeleteSession", failures=1, after=True)
        client, events = self.client(channel=grpc.intercept_channel(
            grpc.insecure_channel(self.address), gone))
        client.delete_session(plain.get_session(session.id))
        self.assertEqual(gone.calls, 2)
        with self.assertRaises(inbetween.NotFoundError):
            plain.get_session(session.id)

    def test_inbetween_resumes_after_a_broken_connection(self):
        plain, _ = self.client()
        session = plain.build(plain.upload_svgs(plain.create_session("py-resume"),
                                                [SQUARE, HEXAGON]))
        reference = plain.inbetween(session, frames=12, method="zhu17")
        proxy = BreakingProxy(self.address)
        self.addCleanup(proxy.close)
        client, events = self.client(target=proxy.address)
        client.wait_ready()
        # The proxy passes the stream up to frame 8 (measured on a stream of the same request),
        # then holds the rest back: the call is still open when the client, having read frame
        # 2, cuts it. The count is an estimate (HTTP/2 framing, control frames), so the hold
        # sits frames after the cut: frame 2 always arrives whole.
        proxy.hold_after(bytes_through_frame(self.address, session, 8, frames=12,
                                             method="zhu17"))

        def break_after_third(frame, total):
            if frame.index == 2 and proxy.breaks == 0:
                proxy.break_all()

        resumed = client.inbetween(session, frames=12, method="zhu17", on_frame=break_after_third)
        self.assertEqual(proxy.breaks, 1)
        self.assertEqual(len(events), 1, events)
        self.assertEqual(events[0].method, "Inbetween")
        self.assertEqual(events[0].error.code, "UNAVAILABLE")
        # Resumed after the last frame the client had received: past the cut, before the hold.
        self.assertTrue(3 <= events[0].resume_frame <= 8, events[0].resume_frame)
        self.assertEqual([f.index for f in resumed.frames], list(range(12)))
        self.assertEqual(resumed.header.session_version, reference.header.session_version)
        for a, b in zip(resumed.frames, reference.frames):
            self.assertEqual(vertices(a), vertices(b))
            self.assertEqual(list(a.weights), list(b.weights))

    def test_optimize_resumes_after_a_broken_connection(self):
        plain, _ = self.client()
        session = plain.build(plain.upload_svgs(plain.create_session("py-opt-resume"),
                                                SLOW_DRAWINGS), **SLOW_MESHING)
        proxy = BreakingProxy(self.address)
        self.addCleanup(proxy.close)
        client, events = self.client(target=proxy.address)
        inner = []

        def on_progress(event):
            if isinstance(event, pb.ComeshIteration):
                inner.append(event.inner)
                if event.outer >= 1 and proxy.breaks == 0:
                    proxy.break_all()

        # The cut comes in the second topology pass, seconds before the optimization would end.
        result = client.optimize_comesh(session, on_progress, comesh=SLOW_COMESH)
        self.assertEqual(result.session.stage, pb.STAGE_OPTIMIZED)
        self.assertEqual(result.session.version, session.version + 1)
        self.assertEqual(inner, sorted(set(inner)))  # no iteration twice across the resume
        self.assertEqual(proxy.breaks, 1)
        self.assertTrue(events)
        self.assertEqual(events[0].method, "OptimizeComesh")
        self.assertGreater(events[0].last_iteration, 0)


class socketless_address:
    """A loopback address nothing listens on (a port bound, then released)."""

    def __enter__(self):
        import socket
        s = socket.socket()
        s.bind(("127.0.0.1", 0))
        self.address = "127.0.0.1:%d" % s.getsockname()[1]
        s.close()
        return self.address

    def __exit__(self, *exc):
        return False


class BusyServerTest(unittest.TestCase):
    """With one heavy slot and no queue, a second heavy call is RESOURCE_EXHAUSTED with a retry
    hint while the first runs (not retried: the pool is busy, not the connection)."""

    def test_full_pool_is_resource_exhausted_with_retry_hint(self):
        server, address = start_server("--max-heavy-jobs", "1", "--heavy-queue", "0")
        try:
            with inbetween.Client(address, timeout=120) as client:
                # An optimization of seconds: the only slot stays taken while it runs (the
                # client cancels it once the refusal was seen).
                session = client.build(client.upload_svgs(client.create_session("busy"),
                                                          SLOW_DRAWINGS), **SLOW_MESHING)
                started, release = threading.Event(), threading.Event()

                def hold(event):
                    started.set()
                    release.wait(60)
                    return False  # then cancel

                holder = threading.Thread(target=lambda: self.assertRaises(
                    inbetween.InbetweenError, client.optimize, session, hold,
                    comesh=SLOW_COMESH))
                holder.start()
                self.assertTrue(started.wait(60))
                with self.assertRaises(inbetween.ResourceExhaustedError) as busy:
                    list(client.frames(session.id, frames=3))
                release.set()
                holder.join(60)
                self.assertEqual(busy.exception.code, "RESOURCE_EXHAUSTED")
                self.assertIsNotNone(busy.exception.retry_after_ms)
                self.assertGreater(busy.exception.retry_after_ms, 0)
                self.assertEqual(busy.exception.attempts, 1)
        finally:
            stop_server(server)


if __name__ == "__main__":
    unittest.main()
