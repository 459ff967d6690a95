"""The synchronous client of inbetween.v1.Inbetween (proto/inbetween/v1/inbetween.proto): the
whole API, with deadlines per call kind, retries of what is safe to repeat, progress as
callbacks or iterators, cancellation, and resume of a broken Inbetween stream.

Every session-mutating call takes the session as last returned and sends its version as
``expected_version``; the returned session is the new one. Calls that only read take a session
or its id. Failures raise InbetweenError (a subclass per status code) with the gRPC status and
the server's message.
"""

from __future__ import annotations

import json
import os
import queue
import time
from typing import (Any, Callable, Iterable, Iterator, List, Literal, Mapping, Optional, Sequence,
                    Tuple, Union, overload)

import grpc

from inbetween._calls import (NEVER, READ, VERSIONED, FramesResult, FramesRun, SessionRef,
                              StageRun, call_metadata, final_error, retry_wait, session_id_of)
from inbetween.art import FrameArt
from inbetween.errors import InbetweenError, error_from_rpc
from inbetween.messages import (METHODS, EnumLike, PointLike, PointsLike, comesh_parameters,
                                inbetween_parameters, meshing_parameters, point, polyline_drawing,
                                topology_element)
from inbetween.options import (UNSET, Budget, Cancellation, Deadlines, RetryEvent, RetryPolicy,
                               Timeout)
from inbetween.v1 import inbetween_pb2 as pb
from inbetween.v1 import inbetween_pb2_grpc as pb_grpc

__all__ = ["Client", "TopologyEditor", "FramesResult", "place_art", "METHODS", "PathLike",
           "ProgressCallback"]

PathLike = Union[str, "os.PathLike[str]"]
# A progress callback gets each Progress / ComeshIteration; returning False cancels the call.
ProgressCallback = Callable[[Any], Optional[bool]]
# Options of every channel: no receive limit of the client's own, so that a size refusal is
# always the server's --max-message-bytes (as the C++ client's CreateChannelForServer).
CHANNEL_OPTIONS: List[Tuple[str, Any]] = [("grpc.max_receive_message_length", -1),
                                          ("grpc.max_send_message_length", -1)]


def _read_svg(svg: str, name: Optional[str]) -> Tuple[str, str]:
    """(name, text) of an SVG given as a file path or as its text."""
    if svg.lstrip().startswith("<"):
        return name or "", svg
    with open(svg, encoding="utf-8") as source:
        return name or os.path.basename(svg), source.read()


# Requests of the heavy stages, shared with the asyncio client.

def build_request(session: "pb.Session", meshing: Optional["pb.MeshingParameters"],
                  boundary_vertices: int, max_edge_relative: float
                  ) -> "pb.BuildMultimeshRequest":
    request = pb.BuildMultimeshRequest(session_id=session.id, expected_version=session.version)
    if meshing is not None or boundary_vertices or max_edge_relative:
        request.meshing.CopyFrom(meshing_parameters(
            meshing, boundary_vertices=boundary_vertices or None,
            max_edge_relative=max_edge_relative or None))
    return request


def optimize_request(session: "pb.Session", comesh: Optional["pb.ComeshParameters"],
                     resume: bool, **limits: Any) -> "pb.OptimizeComeshRequest":
    """The iteration limits and tolerance (``limits``) are set over ``comesh`` when non-zero."""
    request = pb.OptimizeComeshRequest(session_id=session.id, expected_version=session.version,
                                       resume=resume)
    given = {k: v for k, v in limits.items() if v}
    if comesh is not None or given:
        request.comesh.CopyFrom(comesh_parameters(comesh, **given))
    return request


def inbetween_request(session: SessionRef, frames: int, method: Optional[EnumLike],
                      parameters: Optional["pb.InbetweenParameters"], start_frame: int
                      ) -> "pb.InbetweenRequest":
    params = inbetween_parameters(parameters, frames=frames or None, method=method)
    return pb.InbetweenRequest(session_id=session_id_of(session), parameters=params,
                               start_frame=start_frame)


class Client:
    """A channel to one server.

    ``target``: "HOST:PORT"; ``token``: bearer token (servers started with --tokens);
    ``root_certificates``: PEM bytes to use TLS; ``timeout``: one deadline in seconds for every
    call (None = none; the legacy form of ``deadlines``); ``deadlines``: per call kind (default
    Deadlines()); ``retry``: RetryPolicy (default RetryPolicy(); RetryPolicy.never() turns
    retries off); ``on_retry``: called with a RetryEvent before each retry's wait; ``channel``: a
    grpc.Channel to use instead of one made from ``target`` (e.g. with interceptors);
    ``options``: extra channel arguments.
    """

    def __init__(self, target: str = "", token: Optional[str] = None,
                 root_certificates: Optional[bytes] = None, timeout: Timeout = UNSET, *,
                 deadlines: Optional[Deadlines] = None, retry: Optional[RetryPolicy] = None,
                 on_retry: Optional[Callable[[RetryEvent], None]] = None,
                 channel: Optional[grpc.Channel] = None,
                 options: Sequence[Tuple[str, Any]] = ()) -> None:
        if channel is None:
            if not target:
                raise ValueError("Client: a target (HOST:PORT) or a channel is needed")
            all_options = CHANNEL_OPTIONS + list(options)
            if root_certificates is not None:
                credentials = grpc.ssl_channel_credentials(root_certificates=root_certificates)
                channel = grpc.secure_channel(target, credentials, options=all_options)
            else:
                channel = grpc.insecure_channel(target, options=all_options)
        self._channel = channel
        self._stub = pb_grpc.InbetweenStub(channel)
        self._token = token
        if deadlines is None:
            deadlines = Deadlines() if timeout is UNSET else Deadlines.all(timeout)  # type: ignore
        self.deadlines = deadlines
        self.retry = retry or RetryPolicy()
        self.on_retry = on_retry

    # Lifetime ---------------------------------------------------------------------------------

    def close(self) -> None:
        self._channel.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def wait_ready(self, timeout: Optional[float] = 10.0) -> None:
        """Blocks until the channel is connected (raises UNAVAILABLE after ``timeout``)."""
        try:
            grpc.channel_ready_future(self._channel).result(timeout=timeout)
        except grpc.FutureTimeoutError:
            raise InbetweenError.of("UNAVAILABLE", f"not connected within {timeout} s") from None

    # Call machinery ---------------------------------------------------------------------------

    def _seconds(self, kind: str, timeout: Timeout) -> Optional[float]:
        return getattr(self.deadlines, kind) if timeout is UNSET else timeout  # type: ignore

    def _wait(self, seconds: float, cancel: Optional[Cancellation]) -> None:
        if cancel is None:
            time.sleep(seconds)
        elif cancel._wait(seconds):
            raise InbetweenError.of("CANCELLED", "cancelled while waiting to retry")

    def _retry_or_raise(self, method: str, mode: str, attempt: int, error: InbetweenError,
                        budget: Budget, cancel: Optional[Cancellation], heavy: bool = False,
                        resume_frame: int = 0, last_iteration: int = 0) -> None:
        """Waits before the next attempt, or raises ``error`` when it is final."""
        wait = retry_wait(self.retry, mode, attempt, error, budget, cancel, heavy)
        if wait is None:
            raise final_error(error, attempt) from None
        if self.on_retry is not None:
            self.on_retry(RetryEvent(method, attempt, error, wait, resume_frame, last_iteration))
        self._wait(wait, cancel)

    def _unary(self, method: str, request: Any, session_id: str = "", *, mode: str = NEVER,
               kind: str = "unary", timeout: Timeout = UNSET,
               cancel: Optional[Cancellation] = None) -> Any:
        budget = Budget(self._seconds(kind, timeout), method)
        rpc = getattr(self._stub, method)
        attempt = 0
        while True:
            attempt += 1
            if cancel is not None and cancel.cancelled:
                raise InbetweenError.of("CANCELLED", "cancelled", method=method)
            try:
                future = rpc.future(request, timeout=budget.remaining(),
                                    metadata=call_metadata(session_id, self._token))
                if cancel is not None:
                    cancel._attach(future.cancel)
                try:
                    return future.result()
                finally:
                    if cancel is not None:
                        cancel._detach(future.cancel)
            except grpc.RpcError as rpc_error:
                error = error_from_rpc(rpc_error, method)
            except grpc.FutureCancelledError:
                error = InbetweenError.of("CANCELLED", "cancelled", method=method)
            self._retry_or_raise(method, mode, attempt, error, budget, cancel)

    # Sessions ---------------------------------------------------------------------------------

    def create_session(self, display_name: str = "",
                       parameters: Optional["pb.Parameters"] = None, *,
                       timeout: Timeout = UNSET) -> "pb.Session":
        """A new empty session (version 1). Not retried: a lost reply would leave a second
        session behind."""
        request = pb.CreateSessionRequest(display_name=display_name, parameters=parameters)
        return self._unary("CreateSession", request, timeout=timeout).session

    @overload
    def get_session(self, session: SessionRef, full: Literal[False] = ..., *,
                    timeout: Timeout = UNSET) -> "pb.Session": ...

    @overload
    def get_session(self, session: SessionRef, full: Literal[True], *,
                    timeout: Timeout = UNSET) -> Tuple["pb.Session", "pb.Multimesh"]: ...

    def get_session(self, session: SessionRef, full: bool = False, *,
                    timeout: Timeout = UNSET) -> Any:
        """The session (compact: drawings without SVG text and art); with ``full=True`` a
        (session, multimesh) pair with everything. Retried."""
        session_id = session_id_of(session)
        response = self._unary("GetSession", pb.GetSessionRequest(session_id=session_id, full=full),
                               session_id, mode=READ, kind="transfer" if full else "unary",
                               timeout=timeout)
        return (response.session, response.multimesh) if full else response.session

    def list_sessions(self, page_size: int = 0, *, timeout: Timeout = UNSET
                      ) -> List["pb.Session"]:
        """Every session of the caller (all pages), as summaries. Each page is retried."""
        return list(self.iter_sessions(page_size, timeout=timeout))

    def iter_sessions(self, page_size: int = 0, *, timeout: Timeout = UNSET
                      ) -> Iterator["pb.Session"]:
        """The caller's sessions page by page (``page_size`` 0 = the server's default)."""
        token = ""
        while True:
            response = self._unary("ListSessions",
                                   pb.ListSessionsRequest(page_size=page_size, page_token=token),
                                   mode=READ, timeout=timeout)
            yield from response.sessions
            token = response.next_page_token
            if not token:
                return

    def delete_session(self, session: SessionRef, any_version: bool = False, *,
                       timeout: Timeout = UNSET) -> None:
        """Deletes the session at its version (ABORTED if it changed meanwhile), or at any
        version with ``any_version`` (or a bare id). Retried at a version only; a retry that
        finds the session gone counts as done (the earlier attempt deleted it)."""
        version = 0 if any_version or isinstance(session, str) else session.version
        session_id = session_id_of(session)
        request = pb.DeleteSessionRequest(session_id=session_id, expected_version=version)
        try:
            self._unary("DeleteSession", request, session_id,
                        mode=VERSIONED if version else NEVER, timeout=timeout)
        except InbetweenError as error:
            if error.code == "NOT_FOUND" and version and error.attempts > 1:
                return
            raise

    def export_session(self, session: SessionRef, path: Optional[PathLike] = None, *,
                       timeout: Timeout = UNSET) -> Any:
        """The session as one opaque blob (a SessionArchive: drawings, topology,
        correspondences, parameters, multimesh): written to ``path`` (returned) when given, else
        returned as bytes. Retried."""
        session_id = session_id_of(session)
        data = self._unary("ExportSession", pb.ExportSessionRequest(session_id=session_id),
                           session_id, mode=READ, kind="transfer", timeout=timeout).data
        if path is None:
            return data
        with open(path, "wb") as out:
            out.write(data)
        return path

    def import_session(self, source: Union[bytes, PathLike], session_id: str = "", *,
                       timeout: Timeout = UNSET) -> "pb.Session":
        """A session from an exported blob (bytes, or the path of a file holding one), under a
        new id or ``session_id`` (ALREADY_EXISTS if taken). Retried only with a session_id (a
        retry then cannot create a second copy)."""
        if isinstance(source, (bytes, bytearray)):
            data = bytes(source)
        else:
            with open(source, "rb") as blob:
                data = blob.read()
        request = pb.ImportSessionRequest(data=data, session_id=session_id)
        return self._unary("ImportSession", request, session_id,
                           mode=VERSIONED if session_id else NEVER, kind="transfer",
                           timeout=timeout).session

    # Drawings ---------------------------------------------------------------------------------

    def put_drawing(self, session: "pb.Session", drawing: "pb.Drawing", *,
                    flatten_tolerance: float = 0.0,
                    topology: Iterable["pb.TopologyElement"] = (),
                    gap_tolerance: float = 0.0, min_area_fraction: float = 0.0,
                    timeout: Timeout = UNSET) -> "pb.PutDrawingResponse":
        """PutDrawing: ``drawing.id`` 0 adds it at the end, an existing id replaces that drawing.
        ``topology``: cuts/openings added in the same call (topology_element("cut", points)).
        Returns the whole response: ``session``, ``drawing`` (as imported: id, elements, art,
        import report) and ``equivalence_class``. Retried (expected_version)."""
        request = pb.PutDrawingRequest(
            session_id=session.id, expected_version=session.version, drawing=drawing,
            flatten_tolerance=flatten_tolerance, topology=list(topology),
            gap_tolerance=gap_tolerance, min_area_fraction=min_area_fraction)
        return self._unary("PutDrawing", request, session.id, mode=VERSIONED, timeout=timeout)

    def put_svg(self, session: "pb.Session", svg: str, name: Optional[str] = None, *,
                drawing_id: int = 0, key_time: Optional[float] = None,
                cuts: Iterable[PointsLike] = (), openings: Iterable[PointsLike] = (),
                flatten_tolerance: float = 0.0, gap_tolerance: float = 0.0,
                min_area_fraction: float = 0.0, timeout: Timeout = UNSET) -> "pb.Session":
        """Adds (or, with ``drawing_id``, replaces) one drawing from an SVG file path or SVG
        text, with optional cuts and openings in its coordinates; returns the new session."""
        name, text = _read_svg(svg, name)
        drawing = pb.Drawing(id=drawing_id, name=name, svg=text)
        if key_time is not None:
            drawing.key_time = key_time
        topology = ([topology_element("cut", c) for c in cuts]
                    + [topology_element("opening", o) for o in openings])
        return self.put_drawing(session, drawing, topology=topology,
                                flatten_tolerance=flatten_tolerance, gap_tolerance=gap_tolerance,
                                min_area_fraction=min_area_fraction, timeout=timeout).session

    def upload_svgs(self, session: "pb.Session", paths: Iterable[str], *,
                    timeout: Timeout = UNSET) -> "pb.Session":
        """Adds every SVG in order; returns the last session."""
        for path in paths:
            session = self.put_svg(session, path, timeout=timeout)
        return session

    def put_polylines(self, session: "pb.Session", outlines: Iterable[PointsLike], *,
                      cuts: Iterable[PointsLike] = (), openings: Iterable[PointsLike] = (),
                      marks: Union[Mapping[int, PointLike], Iterable[Tuple[int, PointLike]]] = (),
                      name: str = "", key_time: Optional[float] = None, drawing_id: int = 0,
                      timeout: Timeout = UNSET) -> "pb.PutDrawingResponse":
        """Adds (or replaces) a drawing given by explicit polylines (messages.polyline_drawing):
        outlines, cuts, openings and correspondence marks."""
        drawing = polyline_drawing(outlines, cuts=cuts, openings=openings, marks=marks,
                                   name=name, key_time=key_time, drawing_id=drawing_id)
        return self.put_drawing(session, drawing, timeout=timeout)

    def remove_drawing(self, session: "pb.Session", drawing_id: int, *,
                       timeout: Timeout = UNSET) -> "pb.Session":
        """Drops a drawing (and the multimesh); returns the new session. Retried."""
        request = pb.RemoveDrawingRequest(session_id=session.id, expected_version=session.version,
                                          drawing_id=drawing_id)
        return self._unary("RemoveDrawing", request, session.id, mode=VERSIONED,
                           timeout=timeout).session

    # Topology ---------------------------------------------------------------------------------

    def edit_topology(self, session: "pb.Session", *, timeout: Timeout = UNSET
                      ) -> "TopologyEditor":
        """An EditTopology stream for interactive edits, one TopologyState per edit:

            with client.edit_topology(session) as editor:
                state = editor.add_cut(drawing_id, [(10, 10), (20, 20)])
                editor.move(drawing_id, state.elements[-1].id, [(10, 12), (20, 22)])
            session = client.get_session(session.id)

        Not retried: a broken stream raises, and ``editor.version`` is the version after the
        last edit that was answered."""
        return TopologyEditor(self, session, self._seconds("edit_stream", timeout))

    def _one_edit(self, session: "pb.Session", timeout: Timeout,
                  edit: Callable[["TopologyEditor"], "pb.TopologyState"]) -> "pb.TopologyState":
        with TopologyEditor(self, session, self._seconds("unary", timeout)) as editor:
            return edit(editor)

    def add_cut(self, session: "pb.Session", drawing_id: int, points: PointsLike, *,
                timeout: Timeout = UNSET) -> "pb.TopologyState":
        """Adds a cut to a drawing (one edit); the state's ``version`` is the session's new
        version."""
        return self._one_edit(session, timeout, lambda e: e.add_cut(drawing_id, points))

    def add_opening(self, session: "pb.Session", drawing_id: int, points: PointsLike, *,
                    timeout: Timeout = UNSET) -> "pb.TopologyState":
        return self._one_edit(session, timeout, lambda e: e.add_opening(drawing_id, points))

    def add_outline(self, session: "pb.Session", drawing_id: int, points: PointsLike, *,
                    timeout: Timeout = UNSET) -> "pb.TopologyState":
        return self._one_edit(session, timeout, lambda e: e.add_outline(drawing_id, points))

    def move_element(self, session: "pb.Session", drawing_id: int, element_id: int,
                     points: PointsLike, *, timeout: Timeout = UNSET) -> "pb.TopologyState":
        return self._one_edit(session, timeout,
                              lambda e: e.move(drawing_id, element_id, points))

    def delete_element(self, session: "pb.Session", drawing_id: int, element_id: int, *,
                       timeout: Timeout = UNSET) -> "pb.TopologyState":
        return self._one_edit(session, timeout, lambda e: e.delete(drawing_id, element_id))

    # Correspondences --------------------------------------------------------------------------

    def set_correspondences(self, session: "pb.Session",
                            correspondences: Iterable[Union["pb.Correspondence",
                                                            Sequence[PointLike]]], *,
                            timeout: Timeout = UNSET) -> "pb.Session":
        """Replaces every correspondence mark: each one point per drawing, in drawing order, on
        the drawings' boundaries. Empty = automatic correspondence. Retried."""
        marks = [c if isinstance(c, pb.Correspondence)
                 else pb.Correspondence(points=[point(p) for p in c]) for c in correspondences]
        request = pb.SetCorrespondencesRequest(session_id=session.id,
                                               expected_version=session.version,
                                               correspondences=marks)
        return self._unary("SetCorrespondences", request, session.id, mode=VERSIONED,
                           timeout=timeout).session

    def clear_correspondences(self, session: "pb.Session", *, timeout: Timeout = UNSET
                              ) -> "pb.Session":
        return self.set_correspondences(session, [], timeout=timeout)

    # Heavy stages -----------------------------------------------------------------------------

    def _stage_events(self, run: StageRun, session_id: str, timeout: Timeout,
                      cancel: Optional[Cancellation]) -> Iterator[Any]:
        """Every event of a heavy stage over its attempts, the result last."""
        budget = Budget(self._seconds("heavy", timeout), run.method)
        rpc = getattr(self._stub, run.method)
        attempt = 0
        while True:
            attempt += 1
            if cancel is not None and cancel.cancelled:
                raise InbetweenError.of("CANCELLED", "cancelled", method=run.method)
            call = rpc(run.request_for(attempt), timeout=budget.remaining(),
                       metadata=call_metadata(session_id, self._token))
            if cancel is not None:
                cancel._attach(call.cancel)
            error: Optional[InbetweenError] = None
            try:
                for response in call:
                    event = run.accept(response)
                    if event is not None:
                        yield event
            except grpc.RpcError as rpc_error:
                error = error_from_rpc(rpc_error, run.method)
            finally:
                call.cancel()  # a consumer that stops early ends the call (no-op when finished)
                if cancel is not None:
                    cancel._detach(call.cancel)
            # The result is the last message, sent after the session was written: done even
            # when the connection broke after it.
            if run.result is not None:
                return
            if error is None:
                raise InbetweenError.of("INTERNAL", f"{run.method} ended without a result",
                                        method=run.method)
            self._retry_or_raise(run.method, VERSIONED, attempt, error, budget, cancel,
                                 heavy=True, last_iteration=run.last_iteration)

    def _run_stage(self, run: StageRun, session_id: str, on_progress: Optional[ProgressCallback],
                   timeout: Timeout, cancel: Optional[Cancellation]) -> Any:
        """Runs a stage to its result; on_progress(event) gets every other event, and returning
        False from it cancels the call (CANCELLED)."""
        own = Cancellation()
        if cancel is not None:
            cancel._attach(own.cancel)
        result = None
        try:
            # The stream is read to its end (the result is its last message), so the call
            # finishes with its own status rather than a cancel.
            for event in self._stage_events(run, session_id, timeout, own):
                if event is run.result:
                    result = event
                elif on_progress is not None and on_progress(event) is False:
                    own.cancel()
        finally:
            if cancel is not None:
                cancel._detach(own.cancel)
        if result is None:
            raise InbetweenError.of("INTERNAL", f"{run.method} ended without a result")
        return result

    def stream_build(self, session: "pb.Session", *,
                     meshing: Optional["pb.MeshingParameters"] = None,
                     boundary_vertices: int = 0, max_edge_relative: float = 0.0,
                     timeout: Timeout = UNSET, cancel: Optional[Cancellation] = None
                     ) -> Iterator[Any]:
        """BuildMultimesh as an iterator: Progress messages, then the BuildMultimeshResult
        (session, stats, multimesh). Leaving the loop early cancels the build."""
        run = StageRun("BuildMultimesh",
                       build_request(session, meshing, boundary_vertices, max_edge_relative))
        return self._stage_events(run, session.id, timeout, cancel)

    def build_multimesh(self, session: "pb.Session",
                        on_progress: Optional[ProgressCallback] = None, *,
                        meshing: Optional["pb.MeshingParameters"] = None,
                        boundary_vertices: int = 0, max_edge_relative: float = 0.0,
                        timeout: Timeout = UNSET, cancel: Optional[Cancellation] = None
                        ) -> "pb.BuildMultimeshResult":
        """BuildMultimesh to its result (session at STAGE_MULTIMESH, stats, multimesh).
        ``meshing``: MeshingParameters (messages.meshing_parameters; unset = the session's);
        ``boundary_vertices`` / ``max_edge_relative`` set over it. Retried with the same
        expected_version."""
        run = StageRun("BuildMultimesh",
                       build_request(session, meshing, boundary_vertices, max_edge_relative))
        return self._run_stage(run, session.id, on_progress, timeout, cancel)

    def build(self, session: "pb.Session", on_progress: Optional[ProgressCallback] = None,
              boundary_vertices: int = 0, max_edge_relative: float = 0.0, *,
              meshing: Optional["pb.MeshingParameters"] = None, timeout: Timeout = UNSET,
              cancel: Optional[Cancellation] = None) -> "pb.Session":
        """build_multimesh, returning the session at STAGE_MULTIMESH."""
        return self.build_multimesh(session, on_progress, meshing=meshing,
                                    boundary_vertices=boundary_vertices,
                                    max_edge_relative=max_edge_relative, timeout=timeout,
                                    cancel=cancel).session

    def stream_optimize(self, session: "pb.Session", *,
                        comesh: Optional["pb.ComeshParameters"] = None,
                        max_outer_iterations: int = 0, max_inner_iterations: int = 0,
                        tolerance: float = 0.0, resume: bool = False, timeout: Timeout = UNSET,
                        cancel: Optional[Cancellation] = None) -> Iterator[Any]:
        """OptimizeComesh as an iterator: ComeshIteration and Progress messages (each iteration
        once, also across a resume), then the OptimizeComeshResult. Leaving the loop early
        cancels the optimization."""
        run = StageRun("OptimizeComesh", optimize_request(
            session, comesh, resume, max_outer_iterations=max_outer_iterations,
            max_inner_iterations=max_inner_iterations, tolerance=tolerance))
        return self._stage_events(run, session.id, timeout, cancel)

    def optimize_comesh(self, session: "pb.Session",
                        on_progress: Optional[ProgressCallback] = None, *,
                        comesh: Optional["pb.ComeshParameters"] = None,
                        max_outer_iterations: int = 0, max_inner_iterations: int = 0,
                        tolerance: float = 0.0, resume: bool = False, timeout: Timeout = UNSET,
                        cancel: Optional[Cancellation] = None) -> "pb.OptimizeComeshResult":
        """OptimizeComesh to its result. ``comesh``: ComeshParameters (messages.comesh_parameters;
        unset = the session's), the iteration limits and tolerance set over it when non-zero.
        on_progress gets each ComeshIteration / Progress (return False to cancel). A transient
        failure sends the request again with ``resume``: the server continues from the checkpoint
        of its last topology pass, and the result equals an uninterrupted run's."""
        run = StageRun("OptimizeComesh", optimize_request(
            session, comesh, resume, max_outer_iterations=max_outer_iterations,
            max_inner_iterations=max_inner_iterations, tolerance=tolerance))
        return self._run_stage(run, session.id, on_progress, timeout, cancel)

    def optimize(self, session: "pb.Session", on_progress: Optional[ProgressCallback] = None,
                 max_outer_iterations: int = 0, max_inner_iterations: int = 0,
                 tolerance: float = 0.0, *, comesh: Optional["pb.ComeshParameters"] = None,
                 resume: bool = False, timeout: Timeout = UNSET,
                 cancel: Optional[Cancellation] = None) -> "pb.Session":
        """optimize_comesh, returning the session at STAGE_OPTIMIZED."""
        return self.optimize_comesh(session, on_progress, comesh=comesh,
                                    max_outer_iterations=max_outer_iterations,
                                    max_inner_iterations=max_inner_iterations,
                                    tolerance=tolerance, resume=resume, timeout=timeout,
                                    cancel=cancel).session

    # Inbetween --------------------------------------------------------------------------------

    def frames(self, session: SessionRef, frames: int = 0, method: Optional[EnumLike] = None,
               *, parameters: Optional["pb.InbetweenParameters"] = None, start_frame: int = 0,
               on_progress: Optional[ProgressCallback] = None, timeout: Timeout = UNSET,
               cancel: Optional[Cancellation] = None) -> Iterator[Tuple[str, Any]]:
        """The Inbetween stream: yields ("header", InbetweenHeader) once, whole (its art
        messages appended), then ("frame", InbetweenFrame) in order. ``frames`` (0 = the
        parameters', else 24) and ``method`` ("zhu17" | "alexa" | "linear") are set over
        ``parameters`` (messages.inbetween_parameters: timing, ease, stiffness, lambda, tau,
        alpha, epsilon, rho, timestep, max_iterations, key_times). ``start_frame`` resumes a
        stream of one's own from that frame. A broken connection resumes at the next frame
        (``start_frame``); Progress goes to ``on_progress`` (return False to cancel). Leaving the
        loop early cancels the stream."""
        run = FramesRun(inbetween_request(session, frames, method, parameters, start_frame))
        return self._frame_events(run, timeout, cancel, on_progress)

    def _frame_events(self, run: FramesRun, timeout: Timeout, cancel: Optional[Cancellation],
                      on_progress: Optional[ProgressCallback]) -> Iterator[Tuple[str, Any]]:
        budget = Budget(self._seconds("heavy", timeout), "Inbetween")
        attempt = 0
        while True:
            attempt += 1
            if cancel is not None and cancel.cancelled:
                raise InbetweenError.of("CANCELLED", "cancelled", method="Inbetween")
            call = self._stub.Inbetween(run.request_for(attempt), timeout=budget.remaining(),
                                        metadata=call_metadata(run.session_id, self._token))
            if cancel is not None:
                cancel._attach(call.cancel)
            error: Optional[InbetweenError] = None
            try:
                for response in call:
                    for kind, message in run.accept(response):
                        if kind == "progress":
                            if on_progress is not None and on_progress(message) is False:
                                call.cancel()
                            continue
                        yield kind, message
            except grpc.RpcError as rpc_error:
                error = error_from_rpc(rpc_error, "Inbetween")
            finally:
                call.cancel()
                if cancel is not None:
                    cancel._detach(call.cancel)
            if error is None or run.done():
                run.finish()
                return
            self._retry_or_raise("Inbetween", READ, attempt, error, budget, cancel, heavy=True,
                                 resume_frame=run.next_frame)

    def inbetween(self, session: SessionRef, frames: int = 0, method: Optional[EnumLike] = None,
                  *, parameters: Optional["pb.InbetweenParameters"] = None,
                  start_frame: int = 0,
                  on_frame: Optional[Callable[["pb.InbetweenFrame", int], Optional[bool]]] = None,
                  on_progress: Optional[ProgressCallback] = None, timeout: Timeout = UNSET,
                  cancel: Optional[Cancellation] = None) -> FramesResult:
        """The whole Inbetween stream (as ``frames``) collected: FramesResult(header, frames).
        ``on_frame(frame, total)`` sees each frame as it arrives (return False to cancel)."""
        result: Optional[FramesResult] = None
        events = self.frames(session, frames, method, parameters=parameters,
                             start_frame=start_frame, on_progress=on_progress, timeout=timeout,
                             cancel=cancel)
        try:
            for kind, message in events:
                if kind == "header":
                    result = FramesResult(message)
                    continue
                assert result is not None
                result.frames.append(message)
                if on_frame is not None and on_frame(message, result.header.frames) is False:
                    raise InbetweenError.of("CANCELLED", "cancelled by on_frame",
                                            method="Inbetween")
        finally:
            events.close()  # type: ignore[attr-defined]
        assert result is not None
        return result

    def stream_frames(self, session: SessionRef, out_dir: PathLike, frames: int = 0,
                      method: Optional[EnumLike] = None, art: bool = True, *,
                      parameters: Optional["pb.InbetweenParameters"] = None,
                      timeout: Timeout = UNSET, cancel: Optional[Cancellation] = None
                      ) -> List[str]:
        """Streams the frames into out_dir as they arrive: frame_NNNN.svg and frame_NNNN.json
        (index, time, weights, vertices). The SVG draws the frame's art (frame_art_svg, viewBox
        from that frame's bounds) when ``art`` is true and the drawings have art, else the mesh's
        triangles. Returns the paths of the JSON files in frame order."""
        os.makedirs(out_dir, exist_ok=True)
        triangles: List[Tuple[int, int, int]] = []
        paths: List[str] = []
        drawing: Optional[FrameArt] = None
        for kind, message in self.frames(session, frames, method, parameters=parameters,
                                         timeout=timeout, cancel=cancel):
            if kind == "header":
                triangles = [(t.a, t.b, t.c) for t in message.triangles]
                drawing = FrameArt(message) if art and message.art else None
                if drawing is not None and not drawing.has_art():
                    drawing = None  # every drawing came without art: draw the triangles
                continue
            paths.append(_write_frame(out_dir, message, drawing, triangles))
        return paths


def _write_frame(out_dir: PathLike, frame: Any, drawing: Optional[FrameArt],
                 triangles: List[Tuple[int, int, int]]) -> str:
    vertices = [(p.x, p.y) for p in frame.vertices]
    stem = os.path.join(out_dir, f"frame_{frame.index:04d}")
    with open(stem + ".json", "w", encoding="utf-8") as out:
        json.dump({"index": frame.index, "time": frame.time, "weights": list(frame.weights),
                   "vertices": vertices}, out)
    with open(stem + ".svg", "w", encoding="utf-8") as out:
        out.write(drawing.svg(frame) if drawing else _frame_svg(vertices, triangles))
    return stem + ".json"


class TopologyEditor:
    """One EditTopology stream (Client.edit_topology): each edit is sent with the version the
    previous one produced and waits for its TopologyState. Use as a context manager, or call
    close(). A bad edit ends the stream with INVALID_ARGUMENT (raised by that edit)."""

    _END = object()

    def __init__(self, client: Client, session: "pb.Session", seconds: Optional[float]) -> None:
        self.session_id = session.id
        self.version = session.version  # the session's version after the last answered edit
        self.states: List["pb.TopologyState"] = []
        self._requests: "queue.Queue[object]" = queue.Queue()
        self._closed = False
        self._call = client._stub.EditTopology(
            iter(self._requests.get, self._END), timeout=seconds,
            metadata=call_metadata(session.id, client._token))

    def __enter__(self) -> "TopologyEditor":
        return self

    def __exit__(self, exc_type: object, *rest: object) -> None:
        if exc_type is None:
            self.close()
        else:
            self.cancel()

    def edit(self, drawing_id: int, **edit: Any) -> "pb.TopologyState":
        """Sends one TopologyEdit (``add=``, ``move=`` or ``delete_element=``) and returns its
        state."""
        if self._closed:
            raise InbetweenError.of("FAILED_PRECONDITION", "the EditTopology stream is closed",
                                    method="EditTopology")
        self._requests.put(pb.TopologyEdit(session_id=self.session_id,
                                           expected_version=self.version,
                                           drawing_id=drawing_id, **edit))
        try:
            state = next(self._call)
        except grpc.RpcError as rpc_error:
            self._closed = True
            raise error_from_rpc(rpc_error, "EditTopology") from None
        except StopIteration:
            self._closed = True
            raise InbetweenError.of("INTERNAL", "EditTopology ended without a reply",
                                    method="EditTopology") from None
        self.version = state.version
        self.states.append(state)
        return state

    def add(self, drawing_id: int, kind: EnumLike, points: PointsLike) -> "pb.TopologyState":
        return self.edit(drawing_id, add=topology_element(kind, points))

    def add_cut(self, drawing_id: int, points: PointsLike) -> "pb.TopologyState":
        return self.add(drawing_id, "cut", points)

    def add_opening(self, drawing_id: int, points: PointsLike) -> "pb.TopologyState":
        return self.add(drawing_id, "opening", points)

    def add_outline(self, drawing_id: int, points: PointsLike) -> "pb.TopologyState":
        return self.add(drawing_id, "outline", points)

    def move(self, drawing_id: int, element_id: int, points: PointsLike,
             kind: EnumLike = 0) -> "pb.TopologyState":
        """Replaces the polyline of element ``element_id``."""
        return self.edit(drawing_id, move=topology_element(kind, points, element_id))

    def delete(self, drawing_id: int, element_id: int) -> "pb.TopologyState":
        return self.edit(drawing_id, delete_element=element_id)

    def close(self) -> None:
        """Ends the stream (half-close) and waits for the server to finish it."""
        if self._closed:
            return
        self._closed = True
        self._requests.put(self._END)
        try:
            for _ in self._call:
                pass
        except grpc.RpcError as rpc_error:
            raise error_from_rpc(rpc_error, "EditTopology") from None

    def cancel(self) -> None:
        self._closed = True
        self._call.cancel()
        self._requests.put(self._END)


def _frame_svg(vertices: List[Tuple[float, float]], triangles: List[Tuple[int, int, int]]
               ) -> str:
    """A frame drawn as its mesh's triangles (for drawings without art)."""
    if not vertices:
        return '<svg xmlns="http://www.w3.org/2000/svg"/>\n'
    xs, ys = [v[0] for v in vertices], [v[1] for v in vertices]
    pad = 0.05 * max(max(xs) - min(xs), max(ys) - min(ys), 1e-9)
    box = (min(xs) - pad, min(ys) - pad, max(xs) - min(xs) + 2 * pad, max(ys) - min(ys) + 2 * pad)
    path = " ".join(
        "M{:.4f},{:.4f}L{:.4f},{:.4f}L{:.4f},{:.4f}Z".format(*vertices[a], *vertices[b],
                                                              *vertices[c])
        for a, b, c in triangles)
    return ('<svg xmlns="http://www.w3.org/2000/svg" viewBox="{:.4f} {:.4f} {:.4f} {:.4f}">'
            '<path d="{}" fill="#8ab" stroke="#234" stroke-width="{:.4f}"/></svg>\n').format(
                *box, path, box[2] / 400)


def place_art(header: Any, frame: Any) -> List[Tuple[int, float, List[Tuple[Any, List[Any]]]]]:
    """The drawings' art placed in ``frame`` (an InbetweenFrame), from ``header.art`` (the
    stream's InbetweenHeader): one ``(key, weight, layers)`` per key active in the frame (weight
    > 0), each layer a ``(paint, paths)`` pair with ``paint`` the key's ArtLayer (no paths) and
    each path ``(closed, [(x, y), ...])``. Point i of a path is b0*v[a] + b1*v[b] + b2*v[c] for
    its triangle (a, b, c) and the frame's vertices v. At a key frame this is that drawing's art
    as drawn; in between, morph corresponding layers and cross-fade the others by weight
    (docs/api.md, "Drawing a frame's art"; frame_art does so). Empty when the header has no
    art."""
    triangles = [(t.a, t.b, t.c) for t in header.triangles]
    vertices = [(p.x, p.y) for p in frame.vertices]
    placed = []
    for key_art in header.art:
        weight = frame.weights[key_art.key]
        if weight <= 0:
            continue
        layers = []
        for layer in key_art.layers:
            paths = []
            for path in layer.paths:
                b = path.barycentric
                points = []
                for i, t in enumerate(path.triangles):
                    (ax, ay), (bx, by), (cx, cy) = (vertices[c] for c in triangles[t])
                    b0, b1, b2 = b[3 * i], b[3 * i + 1], b[3 * i + 2]
                    points.append((b0 * ax + b1 * bx + b2 * cx, b0 * ay + b1 * by + b2 * cy))
                paths.append((path.closed, points))
            layers.append((layer.paint, paths))
        placed.append((key_art.key, weight, layers))
    return placed
