"""Tests of the inbetween Python module against the real inbetween-server binary.

Environment: INBETWEEN_SERVER_BIN (the server binary), INBETWEEN_SRC (the source tree, for the
examples); the stubs' directory must be on sys.path (tests/e2e/python_client_test.sh does it).
"""

import json
import os
import re
import subprocess
import tempfile
import threading
import unittest

import inbetween
from inbetween.v1 import inbetween_pb2 as pb

EXAMPLES = os.path.join(os.environ.get("INBETWEEN_SRC", "."), "examples", "square_hexagon")
SQUARE = os.path.join(EXAMPLES, "square.svg")
HEXAGON = os.path.join(EXAMPLES, "hexagon.svg")
HARD = os.path.join(os.environ.get("INBETWEEN_SRC", "."), "examples", "pentagon_star", "hard1")
PENTAGON = os.path.join(HARD, "pentagon.svg")
STAR = os.path.join(HARD, "star.svg")


def start_server(*flags):
    """Starts inbetween-server on 127.0.0.1:0; returns (process, "127.0.0.1:PORT")."""
    binary = os.environ["INBETWEEN_SERVER_BIN"]
    process = subprocess.Popen([binary, "--listen", "127.0.0.1:0", "--log-level", "warn", *flags],
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    line = process.stdout.readline()
    match = re.search(r"listening on (127\.0\.0\.1:\d+)", line)
    if not match:
        process.kill()
        raise RuntimeError(f"server did not start: {line!r}")
    return process, match.group(1)


def stop_server(process):
    process.terminate()
    try:
        process.wait(timeout=10)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
    process.stdout.close()


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

    def test_stale_version_and_unknown_session_raise_with_their_codes(self):
        session = self.client.create_session("py-errors")
        newer = self.client.put_svg(session, SQUARE)
        with self.assertRaises(inbetween.InbetweenError) as stale:
            self.client.put_svg(session, HEXAGON)  # still at the old version
        self.assertEqual(stale.exception.code, "ABORTED")
        self.assertEqual(self.client.get_session(session.id).version, newer.version)
        with self.assertRaises(inbetween.InbetweenError) as missing:
            self.client.get_session("0000000000000000")
        self.assertEqual(missing.exception.code, "NOT_FOUND")
        with self.assertRaises(inbetween.InbetweenError) as early:
            list(self.client.frames(session.id, frames=4))
        self.assertEqual(early.exception.code, "FAILED_PRECONDITION")

    def test_export_import_and_list(self):
        session = self.built_session("py-export")
        path = self.client.export_session(session.id, os.path.join(self.out, "session.inbsession"))
        copy = self.client.import_session(path)
        self.assertNotEqual(copy.id, session.id)
        self.assertEqual(copy.stage, pb.STAGE_MULTIMESH)
        self.assertEqual(len(copy.drawings), 2)
        ids = [s.id for s in self.client.list_sessions(page_size=1)]
        self.assertIn(session.id, ids)
        self.assertIn(copy.id, ids)
        self.client.delete_session(copy)
        self.assertNotIn(copy.id, [s.id for s in self.client.list_sessions()])
        # The imported copy animates without a rebuild.
        self.assertEqual(len(self.client.stream_frames(session, self.out, frames=3)), 3)

    def test_progress_callback_can_cancel_an_optimization(self):
        session = self.built_session("py-cancel")
        seen = []

        def stop_after_first(event):
            seen.append(event)
            return False

        with self.assertRaises(inbetween.InbetweenError) as cancelled:
            self.client.optimize(session, on_progress=stop_after_first)
        self.assertEqual(cancelled.exception.code, "CANCELLED")
        self.assertEqual(len(seen), 1)
        # Nothing was stored: the session is still at its built version.
        after = self.client.get_session(session.id)
        self.assertEqual(after.version, session.version)
        self.assertEqual(after.stage, pb.STAGE_MULTIMESH)


class BusyServerTest(unittest.TestCase):
    """With one heavy slot and no queue, a second heavy call is RESOURCE_EXHAUSTED with a retry
    hint while the first runs."""

    def test_full_pool_is_resource_exhausted_with_retry_hint(self):
        server, address = start_server("--max-heavy-jobs", "1", "--heavy-queue", "0")
        try:
            with inbetween.Client(address, timeout=120) as client:
                # Pentagon -> star with the iteration limits at their maximum optimizes for
                # minutes: the only slot stays taken until the client cancels.
                session = client.build(client.upload_svgs(client.create_session("busy"),
                                                          [PENTAGON, STAR]))
                started, release = threading.Event(), threading.Event()

                def hold(event):
                    started.set()
                    release.wait(60)
                    return False  # then cancel

                holder = threading.Thread(target=lambda: self.assertRaises(
                    inbetween.InbetweenError, client.optimize, session, hold,
                    max_outer_iterations=1000, max_inner_iterations=100000, tolerance=1e-15))
                holder.start()
                self.assertTrue(started.wait(60))
                with self.assertRaises(inbetween.InbetweenError) as busy:
                    list(client.frames(session.id, frames=3))
                release.set()
                holder.join(60)
                self.assertEqual(busy.exception.code, "RESOURCE_EXHAUSTED")
                self.assertIsNotNone(busy.exception.retry_after_ms)
                self.assertGreater(busy.exception.retry_after_ms, 0)
        finally:
            stop_server(server)


if __name__ == "__main__":
    unittest.main()
