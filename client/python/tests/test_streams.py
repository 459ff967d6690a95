"""The streaming calls' state over their attempts (inbetween._calls), on hand-made responses; no
server. The chunked header art is only sent for art over 1 MiB, which the server tests cover;
here its assembly across a broken and resumed stream is checked message by message."""

import unittest

import inbetween
from inbetween._calls import FramesRun, StageRun, retry_wait, NEVER, READ
from inbetween.options import Budget
from inbetween.v1 import inbetween_pb2 as pb


def header(art_messages, version=7, frames=3):
    h = pb.InbetweenHeader(frames=frames, session_version=version, art_messages=art_messages,
                           keys=[0, frames - 1])
    h.triangles.add(a=0, b=1, c=2)
    for key in (0, 1):
        h.art.add(key=key).layers.add(paint=pb.ArtLayer(name=f"first of {key}"))
    return pb.InbetweenResponse(header=h)


def art(key, name):
    message = pb.KeyArt(key=key)
    message.layers.add(paint=pb.ArtLayer(name=name))
    return pb.InbetweenResponse(art=message)


def frame(index):
    return pb.InbetweenResponse(frame=pb.InbetweenFrame(index=index, weights=[1.0, 0.0]))


class FramesRunTest(unittest.TestCase):
    def test_chunked_art_is_appended_and_collected_again_after_a_break(self):
        run = FramesRun(pb.InbetweenRequest(session_id="s"))
        self.assertEqual(run.request_for(1).start_frame, 0)
        self.assertEqual(run.accept(header(2)), [])  # not whole yet
        self.assertEqual(run.accept(art(0, "second of 0")), [])
        # The connection breaks here: the resumed stream sends the header and all art again.
        self.assertEqual(run.request_for(2).start_frame, 0)
        self.assertEqual(run.accept(header(2)), [])
        self.assertEqual(run.accept(art(0, "second of 0")), [])
        [(kind, whole)] = run.accept(art(1, "second of 1"))
        self.assertEqual(kind, "header")
        self.assertEqual([[l.paint.name for l in k.layers] for k in whole.art],
                         [["first of 0", "second of 0"], ["first of 1", "second of 1"]])
        self.assertEqual(run.accept(frame(0)), [("frame", frame(0).frame)])
        # Another break after frame 0: resume at frame 1; the repeated header and art are
        # dropped, the header is not delivered twice.
        self.assertEqual(run.request_for(3).start_frame, 1)
        self.assertEqual(run.accept(header(2)), [])
        self.assertEqual(run.accept(art(0, "second of 0")), [])
        self.assertEqual(len(whole.art[0].layers), 2)
        self.assertEqual([k for k, _ in run.accept(frame(1))], ["frame"])
        self.assertFalse(run.done())
        run.accept(frame(2))
        self.assertTrue(run.done())
        run.finish()

    def test_a_resumed_stream_of_another_version_or_out_of_order_frames_fail(self):
        run = FramesRun(pb.InbetweenRequest(session_id="s"))
        run.accept(header(0))
        run.accept(frame(0))
        with self.assertRaises(inbetween.AbortedError) as changed:
            run.accept(header(0, version=8))
        self.assertIn("changed from version 7 to 8", changed.exception.details)
        with self.assertRaises(inbetween.InternalError):
            run.accept(frame(2))
        short = FramesRun(pb.InbetweenRequest(session_id="s"))
        short.accept(header(0))
        with self.assertRaises(inbetween.InternalError):
            short.finish()  # 0 of 3 frames

    def test_optimize_iterations_once_across_a_resume(self):
        run = StageRun("OptimizeComesh", pb.OptimizeComeshRequest(session_id="s"))
        self.assertFalse(run.request_for(1).resume)
        it = [pb.OptimizeComeshResponse(iteration=pb.ComeshIteration(outer=0, inner=i))
              for i in (1, 2, 3)]
        self.assertEqual([run.accept(r) is not None for r in it[:2]], [True, True])
        self.assertTrue(run.request_for(2).resume)
        self.assertIsNone(run.accept(it[1]))  # the checkpoint's iteration, seen before
        self.assertIsNotNone(run.accept(it[2]))
        result = pb.OptimizeComeshResponse(result=pb.OptimizeComeshResult(outer_iterations=1))
        self.assertIs(run.accept(result), run.result)

    def test_retry_decisions(self):
        policy = inbetween.RetryPolicy(max_attempts=3, initial_backoff=0.1, jitter=0.0)
        budget = Budget(None, "GetSession")
        unavailable = inbetween.InbetweenError.of("UNAVAILABLE", "down")
        reset = inbetween.InbetweenError.of("INTERNAL", "Received RST_STREAM with error code 2")
        self.assertEqual(retry_wait(policy, READ, 1, unavailable, budget, None), 0.1)
        self.assertAlmostEqual(retry_wait(policy, READ, 2, reset, budget, None), 0.2)
        self.assertIsNone(retry_wait(policy, READ, 3, unavailable, budget, None))  # used up
        self.assertIsNone(retry_wait(policy, NEVER, 1, unavailable, budget, None))
        internal = inbetween.InbetweenError.of("INTERNAL", "a bug")
        self.assertIsNone(retry_wait(policy, READ, 1, internal, budget, None))
        busy = inbetween.InbetweenError.of("RESOURCE_EXHAUSTED", "over --max-heavy-jobs-per-token 1",
                                           reason="HEAVY_JOBS_PER_TOKEN")
        self.assertIsNone(retry_wait(policy, READ, 1, busy, budget, None, heavy=True))
        self.assertEqual(retry_wait(policy, READ, 2, busy, budget, None, heavy=True), 0.5)
        self.assertIsNone(retry_wait(policy, READ, 1, unavailable, Budget(0.05, "x"), None))
        cancel = inbetween.Cancellation()
        cancel.cancel()
        self.assertIsNone(retry_wait(policy, READ, 1, unavailable, budget, cancel))

    def test_error_names_the_message_size_limit(self):
        class Fake(Exception):
            def code(self):
                import grpc
                return grpc.StatusCode.RESOURCE_EXHAUSTED

            def details(self):
                return "Received message larger than max (70000000 vs. 67108864)"

            def trailing_metadata(self):
                return (("retry-after-ms", "250"),)

        error = inbetween.errors.error_from_rpc(Fake(), "PutDrawing")
        self.assertIsInstance(error, inbetween.ResourceExhaustedError)
        self.assertIn("--max-message-bytes 67108864", error.details)
        self.assertEqual(error.retry_after_ms, 250)
        self.assertEqual(error.method, "PutDrawing")


if __name__ == "__main__":
    unittest.main()
