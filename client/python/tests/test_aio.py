"""Tests of the asyncio client (inbetween.AsyncClient) against the real inbetween-server binary
(INBETWEEN_SERVER_BIN, INBETWEEN_SRC as test_client.py)."""

import asyncio
import contextlib
import tempfile
import unittest

import grpc

import inbetween
from inbetween.v1 import inbetween_pb2 as pb
from support import (HEXAGON, SLOW_COMESH, SLOW_DRAWINGS, SLOW_MESHING, SQUARE, BreakingProxy,
                     bytes_through_frame, start_server, stop_server)

FAST_RETRY = inbetween.RetryPolicy(max_attempts=8, initial_backoff=0.05, max_backoff=0.5)


class AsyncClientTest(unittest.IsolatedAsyncioTestCase):
    @classmethod
    def setUpClass(cls):
        cls.server, cls.address = start_server()

    @classmethod
    def tearDownClass(cls):
        stop_server(cls.server)

    async def asyncSetUp(self):
        self.retries = []
        self.client = inbetween.AsyncClient(self.address, retry=FAST_RETRY,
                                            on_retry=self.retries.append)
        self.out = tempfile.mkdtemp(prefix="inbetween_aio_")

    async def asyncTearDown(self):
        await self.client.close()

    async def built(self, name, drawings=(SQUARE, HEXAGON), **meshing):
        session = await self.client.upload_svgs(await self.client.create_session(name), drawings)
        return await self.client.build(session, **meshing)

    async def test_whole_job_with_async_progress_and_frames(self):
        session = await self.client.upload_svgs(await self.client.create_session("aio-job"),
                                                [SQUARE, HEXAGON])
        events = [e async for e in self.client.stream_build(session)]
        self.assertIsInstance(events[-1], pb.BuildMultimeshResult)
        session = events[-1].session
        seen = []

        async def on_progress(event):  # a coroutine callback is awaited
            seen.append(event)

        result = await self.client.optimize_comesh(session, on_progress, max_outer_iterations=2)
        self.assertEqual(result.session.stage, pb.STAGE_OPTIMIZED)
        self.assertTrue(any(isinstance(e, pb.ComeshIteration) for e in seen))
        session = result.session
        kinds = []
        async with contextlib.aclosing(self.client.frames(session, 5, "linear")) as stream:
            async for kind, message in stream:
                kinds.append(kind)
                if kind == "header":
                    header = message
        self.assertEqual(kinds, ["header"] + ["frame"] * 5)
        self.assertEqual(header.frames, 5)
        whole = await self.client.inbetween(
            session, parameters=inbetween.inbetween_parameters(frames=5, method="linear",
                                                               timing="catmull-rom"))
        self.assertEqual(len(whole.frames), 5)
        paths = await self.client.stream_frames(session, self.out, frames=3, method="linear")
        self.assertEqual(len(paths), 3)
        with open(paths[1][:-5] + ".svg", encoding="utf-8") as svg:
            self.assertIn("<path", svg.read())
        _, mesh = await self.client.get_session(session.id, full=True)
        self.assertEqual(len(mesh.shapes), 2)
        self.assertEqual(self.retries, [])

    async def test_sessions_export_import_and_errors(self):
        session = await self.built("aio-export")
        data = await self.client.export_session(session)
        copy = await self.client.import_session(data)
        self.assertEqual(copy.stage, pb.STAGE_MULTIMESH)
        ids = [s.id for s in await self.client.list_sessions(page_size=1)]
        self.assertIn(copy.id, ids)
        await self.client.delete_session(copy)
        with self.assertRaises(inbetween.NotFoundError) as missing:
            await self.client.get_session(copy.id)
        self.assertEqual(missing.exception.status_code, grpc.StatusCode.NOT_FOUND)
        with self.assertRaises(inbetween.AbortedError):
            await self.client.remove_drawing(pb.Session(id=session.id, version=1),
                                             session.drawings[0].id)
        with self.assertRaises(inbetween.InvalidArgumentError) as bad:
            await self.client.inbetween(session, parameters=inbetween.inbetween_parameters(
                tau=-1.0))
        self.assertIn("tau", bad.exception.details)

    async def test_topology_editor(self):
        session = await self.client.put_svg(await self.client.create_session("aio-topology"),
                                            SQUARE)
        drawing = session.drawings[0].id
        async with self.client.edit_topology(session) as editor:
            state = await editor.add_opening(drawing, [(40, 60), (80, 60)])
            self.assertEqual(state.classes[0].holes, 1)
            state = await editor.delete(drawing, state.elements[1].id)
            self.assertEqual(len(state.elements), 1)
        self.assertEqual(editor.version, session.version + 2)
        with self.assertRaises(inbetween.InvalidArgumentError):
            await self.client.add_cut(await self.client.get_session(session.id), drawing,
                                      [(200, 200), (300, 300)])
        session = await self.client.get_session(session.id)
        session = await self.client.set_correspondences(session, [])
        self.assertEqual(len(session.correspondences), 0)

    async def test_cancel_by_callback_by_cancellation_and_by_the_task(self):
        # An optimization of seconds: each cancellation comes long before it would end.
        session = await self.built("aio-cancel", SLOW_DRAWINGS, **SLOW_MESHING)
        limits = dict(comesh=SLOW_COMESH)
        with self.assertRaises(inbetween.CallCancelledError):
            await self.client.optimize(session, lambda event: False, **limits)
        cancel = inbetween.Cancellation()
        started = asyncio.Event()
        task = asyncio.ensure_future(
            self.client.optimize(session, lambda event: started.set(), cancel=cancel, **limits))
        await asyncio.wait_for(started.wait(), 60)
        cancel.cancel()
        with self.assertRaises(inbetween.CallCancelledError):
            await task
        started.clear()
        task = asyncio.ensure_future(
            self.client.optimize(session, lambda event: started.set(), **limits))
        await asyncio.wait_for(started.wait(), 60)
        task.cancel()
        with self.assertRaises(asyncio.CancelledError):
            await task
        # A per-call deadline of 1 ms, far below any optimization's time: DEADLINE_EXCEEDED, not
        # retried.
        with self.assertRaises(inbetween.DeadlineExceededError) as late:
            await self.client.optimize(session, timeout=0.001, **limits)
        self.assertEqual(late.exception.status_code, grpc.StatusCode.DEADLINE_EXCEEDED)
        self.assertEqual(late.exception.attempts, 1)
        after = await self.client.get_session(session.id)
        self.assertEqual(after.version, session.version)

    async def test_inbetween_resumes_after_a_broken_connection(self):
        session = await self.built("aio-resume")
        reference = await self.client.inbetween(session, frames=10)
        proxy = BreakingProxy(self.address)
        self.addCleanup(proxy.close)
        retries = []
        # The proxy passes the stream up to frame 7, then holds the rest back: the call is still
        # open when the client, having read frame 1, cuts it (the byte count is an estimate: the
        # hold sits frames after the cut, so frame 1 always arrives whole).
        proxy.hold_after(bytes_through_frame(self.address, session, 7, frames=10))
        async with inbetween.AsyncClient(proxy.address, retry=FAST_RETRY,
                                         on_retry=retries.append) as client:
            def break_once(frame, total):
                if frame.index == 1 and proxy.breaks == 0:
                    proxy.break_all()

            resumed = await client.inbetween(session, frames=10, on_frame=break_once)
            # Reads are retried too: GetSession through the proxy after another cut.
            proxy.break_all()
            self.assertEqual((await client.get_session(session.id)).version, session.version)
        self.assertTrue(retries)
        self.assertEqual(retries[0].method, "Inbetween")
        self.assertEqual(retries[0].error.code, "UNAVAILABLE")
        # Resumed after the last frame the client had received: past the cut, before the hold.
        self.assertTrue(2 <= retries[0].resume_frame <= 7, retries[0].resume_frame)
        self.assertEqual([f.index for f in resumed.frames], list(range(10)))
        for a, b in zip(resumed.frames, reference.frames):
            self.assertEqual([(p.x, p.y) for p in a.vertices], [(p.x, p.y) for p in b.vertices])


if __name__ == "__main__":
    unittest.main()
