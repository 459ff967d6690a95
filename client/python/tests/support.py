"""Helpers of the client tests: real inbetween-server processes (INBETWEEN_SERVER_BIN) on
127.0.0.1, a TCP proxy that can cut every connection (a server dying mid-stream, as seen by the
client), and a channel interceptor that fakes UNAVAILABLE."""

from __future__ import annotations

import os
import re
import socket
import struct
import subprocess
import threading
from typing import Any, Callable, List, Optional, Tuple

import grpc

import inbetween
from inbetween.v1 import inbetween_pb2 as pb
from inbetween.v1.inbetween_pb2_grpc import InbetweenStub

SRC = os.environ.get("INBETWEEN_SRC", os.path.join(os.path.dirname(__file__), "..", "..", ".."))
EXAMPLES = os.path.join(SRC, "examples", "square_hexagon")
SQUARE = os.path.join(EXAMPLES, "square.svg")
HEXAGON = os.path.join(EXAMPLES, "hexagon.svg")
HARD = os.path.join(SRC, "examples", "pentagon_star", "hard1")
PENTAGON = os.path.join(HARD, "pentagon.svg")
STAR = os.path.join(HARD, "star.svg")

# Work that takes seconds, for tests that must act while it runs (cancel it, cut its connection,
# keep the server's only heavy slot taken): pentagon -> star built with a fine boundary, then
# optimized with every topology pass made (outer_tolerance 0). Its first progress arrives within
# a tenth of a second, the optimization ends seconds later; with the default meshing it ends in
# a tenth of a second, too soon to act on reliably.
SLOW_DRAWINGS = (PENTAGON, STAR)
SLOW_MESHING = dict(boundary_vertices=600, max_edge_relative=0.015)
SLOW_COMESH = inbetween.comesh_parameters(max_outer_iterations=1000, max_inner_iterations=100000,
                                          tolerance=1e-15, outer_tolerance=0.0)


def start_server(*flags: str, listen: str = "127.0.0.1:0") -> Tuple[subprocess.Popen, str]:
    """Starts inbetween-server; returns (process, "127.0.0.1:PORT") from the line it prints."""
    binary = os.environ["INBETWEEN_SERVER_BIN"]
    process = subprocess.Popen([binary, "--listen", listen, "--log-level", "warn", *flags],
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    assert process.stdout is not None
    line = process.stdout.readline()
    match = re.search(r"listening on (127\.0\.0\.1:\d+)", line)
    if not match:
        process.kill()
        process.wait()
        raise RuntimeError(f"server did not start: {line!r}")
    return process, match.group(1)


def stop_server(process: subprocess.Popen, kill: bool = False) -> None:
    if kill:
        process.kill()
    else:
        process.terminate()
    try:
        process.wait(timeout=10)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
    if process.stdout is not None:
        process.stdout.close()


class BreakingProxy:
    """Forwards 127.0.0.1:PORT to ``upstream``; ``break_all()`` resets every open connection
    (later ones pass again), which the client sees as UNAVAILABLE mid-call. ``hold_after(n)``
    forwards n more bytes from ``upstream`` to the client, then nothing until the next break:
    the call stays open with the rest of its replies unsent, so that a break the client makes
    after reading some of them still breaks the call (a fast server has otherwise sent the whole
    stream into the client's buffers before the client read its first reply)."""

    def __init__(self, upstream: str) -> None:
        host, port = upstream.rsplit(":", 1)
        self._upstream = (host, int(port))
        self._listener = socket.socket()
        self._listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._listener.bind(("127.0.0.1", 0))
        self._listener.listen(16)
        self.address = "127.0.0.1:%d" % self._listener.getsockname()[1]
        self._lock = threading.Lock()
        self._open: List[socket.socket] = []
        self.breaks = 0
        self._downstream_budget: Optional[int] = None
        self._holding = False
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while True:
            try:
                client, _ = self._listener.accept()
            except OSError:
                return
            try:
                server = socket.create_connection(self._upstream)
            except OSError:
                client.close()
                continue
            with self._lock:
                self._open += [client, server]
            for a, b, downstream in ((client, server, False), (server, client, True)):
                threading.Thread(target=self._pump, args=(a, b, downstream), daemon=True).start()

    def _pump(self, source: socket.socket, sink: socket.socket, downstream: bool) -> None:
        try:
            while True:
                data = source.recv(65536)
                if not data:
                    break
                if downstream:
                    with self._lock:
                        if self._holding:
                            continue  # dropped: the connection is broken later
                        if self._downstream_budget is not None:
                            if len(data) >= self._downstream_budget:
                                data = data[:self._downstream_budget]
                                self._downstream_budget = None
                                self._holding = True
                            else:
                                self._downstream_budget -= len(data)
                sink.sendall(data)
        except OSError:
            pass
        for s in (source, sink):
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass

    def hold_after(self, downstream_bytes: int) -> None:
        with self._lock:
            self._downstream_budget = downstream_bytes

    def break_all(self) -> None:
        with self._lock:
            victims, self._open = self._open, []
            self.breaks += 1
            # A break ends any hold (also one not reached yet): later connections pass whole.
            self._holding = False
            self._downstream_budget = None
        for s in victims:
            try:
                # A reset rather than an orderly close: the connection dies as with a crash.
                # close() alone does not release a socket that a pump thread is blocked reading
                # (Linux keeps it until that recv returns, and a quiet peer never wakes it: the
                # client would wait on a connection that is neither alive nor reset);
                # shutdown(SHUT_RD) wakes the read without sending anything, and the release
                # then sends the reset.
                s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
                s.shutdown(socket.SHUT_RD)
            except OSError:
                pass
            s.close()

    def close(self) -> None:
        self._listener.close()
        self.break_all()


def bytes_through_frame(address: str, session: Any, index: int, **request: Any) -> int:
    """About how many bytes an Inbetween stream of ``session`` sends up to the end of frame
    ``index``: each reply (progress, header, art, frames) with its 5-byte gRPC prefix and a
    9-byte HTTP/2 frame header, read with the generated stub."""
    with grpc.insecure_channel(address) as channel:
        call = InbetweenStub(channel).Inbetween(pb.InbetweenRequest(
            session_id=session.id, parameters=inbetween.inbetween_parameters(**request)),
            timeout=60)
        total = 0
        for response in call:
            total += response.ByteSize() + 14
            if response.WhichOneof("event") == "frame" and response.frame.index == index:
                call.cancel()
                return total
    raise AssertionError(f"no frame {index}")


class _FakeRpcError(grpc.RpcError, grpc.Call, grpc.Future):  # type: ignore[misc]
    """A failed unary call as the interceptor hands it back (code UNAVAILABLE)."""

    def __init__(self, details: str) -> None:
        super().__init__()
        self._details = details

    # grpc.Call / grpc.RpcError
    def code(self) -> grpc.StatusCode:
        return grpc.StatusCode.UNAVAILABLE

    def details(self) -> str:
        return self._details

    def trailing_metadata(self) -> Any:
        return ()

    def initial_metadata(self) -> Any:
        return ()

    def is_active(self) -> bool:
        return False

    def time_remaining(self) -> Optional[float]:
        return None

    def add_callback(self, callback: Callable[[], None]) -> bool:
        return False

    # grpc.Future
    def cancel(self) -> bool:
        return False

    def cancelled(self) -> bool:
        return False

    def running(self) -> bool:
        return False

    def done(self) -> bool:
        return True

    def result(self, timeout: Optional[float] = None) -> Any:
        raise self

    def exception(self, timeout: Optional[float] = None) -> Any:
        return self

    def traceback(self, timeout: Optional[float] = None) -> Any:
        return None

    def add_done_callback(self, fn: Callable[[Any], None]) -> None:
        fn(self)


class FlakyUnary(grpc.UnaryUnaryClientInterceptor):
    """Fails the first ``failures`` calls of ``method`` with UNAVAILABLE: before they reach the
    server (``after`` false), or after the server applied them, the reply lost (``after``
    true). ``calls`` counts the attempts of ``method``."""

    def __init__(self, method: str, failures: int = 1, after: bool = False) -> None:
        self.method = method
        self.failures = failures
        self.after = after
        self.calls = 0

    def intercept_unary_unary(self, continuation: Any, details: Any, request: Any) -> Any:
        if not details.method.endswith("/" + self.method):
            return continuation(details, request)
        self.calls += 1
        if self.calls > self.failures:
            return continuation(details, request)
        if self.after:
            outcome = continuation(details, request)
            outcome.result()  # applied on the server; the reply is then "lost"
            return _FakeRpcError("fake: the connection broke after the server replied")
        return _FakeRpcError("fake: the connection broke before the request was sent")
