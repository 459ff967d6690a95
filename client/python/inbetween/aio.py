"""The asyncio client of inbetween.v1.Inbetween (grpc.aio): the same API as inbetween.Client,
with coroutines for the calls and async iterators for the streams. Deadlines, retries, resume and
errors are the sync client's (inbetween.options, inbetween._calls).

    async with inbetween.AsyncClient("127.0.0.1:50051") as client:
        session = await client.create_session("walk")
        session = await client.upload_svgs(session, ["a.svg", "b.svg"])
        async for event in client.stream_build(session):
            print(event)
        async for kind, message in client.frames(session.id, 24):
            ...

Cancelling the task that awaits a call cancels the call (asyncio.CancelledError, as asyncio
does); a progress callback returning False, or a Cancellation, ends it with CallCancelledError.
Callbacks may be plain functions or coroutine functions. Leaving an ``async for`` early ends the
stream once the iterator is closed (``contextlib.aclosing``, or when it is collected).
"""

from __future__ import annotations

import asyncio
import inspect
import os
from typing import (Any, AsyncIterator, Awaitable, Callable, Iterable, List, Literal, Mapping,
                    Optional, Sequence, Tuple, Union, overload)

import grpc
import grpc.aio

from inbetween._calls import (NEVER, READ, VERSIONED, FramesResult, FramesRun, SessionRef,
                              StageRun, call_metadata, final_error, retry_wait, session_id_of)
from inbetween.art import FrameArt
from inbetween.client import (CHANNEL_OPTIONS, PathLike, _read_svg, _write_frame, build_request,
                              inbetween_request, optimize_request)
from inbetween.errors import InbetweenError, error_from_rpc
from inbetween.messages import (EnumLike, PointLike, PointsLike, point, polyline_drawing,
                                topology_element)
from inbetween.options import (UNSET, Budget, Cancellation, Deadlines, RetryEvent, RetryPolicy,
                               Timeout)
from inbetween.v1 import inbetween_pb2 as pb
from inbetween.v1 import inbetween_pb2_grpc as pb_grpc

__all__ = ["AsyncClient", "AsyncTopologyEditor", "AsyncProgressCallback"]

# A progress callback (plain or async) gets each Progress / ComeshIteration; returning False
# cancels the call.
AsyncProgressCallback = Callable[[Any], Union[Optional[bool], Awaitable[Optional[bool]]]]


async def _call_back(callback: Optional[Callable[..., Any]], *args: Any) -> Any:
    if callback is None:
        return None
    result = callback(*args)
    if inspect.isawaitable(result):
        result = await result
    return result


def _cancelled(method: str, why: str = "cancelled") -> InbetweenError:
    return InbetweenError.of("CANCELLED", why, method=method)


class AsyncClient:
    """A grpc.aio channel to one server; the arguments are Client's. Create it inside a running
    event loop; close it with ``await client.close()`` or ``async with``."""

    def __init__(self, target: str = "", token: Optional[str] = None,
                 root_certificates: Optional[bytes] = None, timeout: Timeout = UNSET, *,
                 deadlines: Optional[Deadlines] = None, retry: Optional[RetryPolicy] = None,
                 on_retry: Optional[Callable[[RetryEvent], Any]] = None,
                 channel: Optional[grpc.aio.Channel] = None,
                 options: Sequence[Tuple[str, Any]] = ()) -> None:
        if channel is None:
            if not target:
                raise ValueError("AsyncClient: a target (HOST:PORT) or a channel is needed")
            all_options = CHANNEL_OPTIONS + list(options)
            if root_certificates is not None:
                credentials = grpc.ssl_channel_credentials(root_certificates=root_certificates)
                channel = grpc.aio.secure_channel(target, credentials, options=all_options)
            else:
                channel = grpc.aio.insecure_channel(target, options=all_options)
        self._channel = channel
        self._stub = pb_grpc.InbetweenStub(channel)
        self._token = token
        if deadlines is None:
            deadlines = Deadlines() if timeout is UNSET else Deadlines.all(timeout)  # type: ignore
        self.deadlines = deadlines
        self.retry = retry or RetryPolicy()
        self.on_retry = on_retry

    # Lifetime ---------------------------------------------------------------------------------

    async def close(self) -> None:
        await self._channel.close()

    async def __aenter__(self) -> "AsyncClient":
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()

    async def wait_ready(self, timeout: Optional[float] = 10.0) -> None:
        """Waits until the channel is connected (raises UNAVAILABLE after ``timeout``)."""
        try:
            await asyncio.wait_for(self._channel.channel_ready(), timeout)
        except asyncio.TimeoutError:
            raise InbetweenError.of("UNAVAILABLE", f"not connected within {timeout} s") from None

    # Call machinery ---------------------------------------------------------------------------

    def _seconds(self, kind: str, timeout: Timeout) -> Optional[float]:
        return getattr(self.deadlines, kind) if timeout is UNSET else timeout  # type: ignore

    async def _retry_or_raise(self, method: str, mode: str, attempt: int, error: InbetweenError,
                              budget: Budget, cancel: Optional[Cancellation], heavy: bool = False,
                              resume_frame: int = 0, last_iteration: int = 0) -> None:
        wait = retry_wait(self.retry, mode, attempt, error, budget, cancel, heavy)
        if wait is None:
            raise final_error(error, attempt) from None
        await _call_back(self.on_retry,
                         RetryEvent(method, attempt, error, wait, resume_frame, last_iteration))
        if cancel is None:
            await asyncio.sleep(wait)
            return
        # A Cancellation cuts the wait short.
        waiter = asyncio.get_running_loop().create_future()

        def wake() -> None:
            if not waiter.done():
                waiter.set_result(None)

        cancel._attach(wake)
        try:
            await asyncio.wait_for(asyncio.shield(waiter), wait)
        except asyncio.TimeoutError:
            pass
        finally:
            cancel._detach(wake)
        if cancel.cancelled:
            raise _cancelled(method, "cancelled while waiting to retry")

    async def _unary(self, method: str, request: Any, session_id: str = "", *,
                     mode: str = NEVER, kind: str = "unary", timeout: Timeout = UNSET,
                     cancel: Optional[Cancellation] = None) -> Any:
        budget = Budget(self._seconds(kind, timeout), method)
        rpc = getattr(self._stub, method)
        attempt = 0
        while True:
            attempt += 1
            if cancel is not None and cancel.cancelled:
                raise _cancelled(method)
            call = rpc(request, timeout=budget.remaining(),
                       metadata=call_metadata(session_id, self._token))
            if cancel is not None:
                cancel._attach(call.cancel)
            try:
                return await call
            except grpc.RpcError as rpc_error:
                error = error_from_rpc(rpc_error, method)
            except asyncio.CancelledError:
                if cancel is not None and cancel.cancelled:
                    raise _cancelled(method) from None
                raise
            finally:
                if cancel is not None:
                    cancel._detach(call.cancel)
            await self._retry_or_raise(method, mode, attempt, error, budget, cancel)

    # Sessions ---------------------------------------------------------------------------------

    async def create_session(self, display_name: str = "",
                             parameters: Optional["pb.Parameters"] = None, *,
                             timeout: Timeout = UNSET) -> "pb.Session":
        """Client.create_session. Not retried."""
        request = pb.CreateSessionRequest(display_name=display_name, parameters=parameters)
        return (await self._unary("CreateSession", request, timeout=timeout)).session

    @overload
    async def get_session(self, session: SessionRef, full: Literal[False] = ..., *,
                          timeout: Timeout = UNSET) -> "pb.Session": ...

    @overload
    async def get_session(self, session: SessionRef, full: Literal[True], *,
                          timeout: Timeout = UNSET) -> Tuple["pb.Session", "pb.Multimesh"]: ...

    async def get_session(self, session: SessionRef, full: bool = False, *,
                          timeout: Timeout = UNSET) -> Any:
        """Client.get_session. Retried."""
        session_id = session_id_of(session)
        response = await self._unary(
            "GetSession", pb.GetSessionRequest(session_id=session_id, full=full), session_id,
            mode=READ, kind="transfer" if full else "unary", timeout=timeout)
        return (response.session, response.multimesh) if full else response.session

    async def list_sessions(self, page_size: int = 0, *, timeout: Timeout = UNSET
                            ) -> List["pb.Session"]:
        """Every session of the caller (all pages). Each page is retried."""
        return [s async for s in self.iter_sessions(page_size, timeout=timeout)]

    async def iter_sessions(self, page_size: int = 0, *, timeout: Timeout = UNSET
                            ) -> AsyncIterator["pb.Session"]:
        token = ""
        while True:
            response = await self._unary(
                "ListSessions", pb.ListSessionsRequest(page_size=page_size, page_token=token),
                mode=READ, timeout=timeout)
            for session in response.sessions:
                yield session
            token = response.next_page_token
            if not token:
                return

    async def delete_session(self, session: SessionRef, any_version: bool = False, *,
                             timeout: Timeout = UNSET) -> None:
        """Client.delete_session."""
        version = 0 if any_version or isinstance(session, str) else session.version
        session_id = session_id_of(session)
        request = pb.DeleteSessionRequest(session_id=session_id, expected_version=version)
        try:
            await self._unary("DeleteSession", request, session_id,
                              mode=VERSIONED if version else NEVER, timeout=timeout)
        except InbetweenError as error:
            if error.code == "NOT_FOUND" and version and error.attempts > 1:
                return
            raise

    async def export_session(self, session: SessionRef, path: Optional[PathLike] = None, *,
                             timeout: Timeout = UNSET) -> Any:
        """Client.export_session: bytes, or ``path`` after writing them there. Retried."""
        session_id = session_id_of(session)
        data = (await self._unary("ExportSession", pb.ExportSessionRequest(session_id=session_id),
                                  session_id, mode=READ, kind="transfer", timeout=timeout)).data
        if path is None:
            return data
        with open(path, "wb") as out:
            out.write(data)
        return path

    async def import_session(self, source: Union[bytes, PathLike], session_id: str = "", *,
                             timeout: Timeout = UNSET) -> "pb.Session":
        """Client.import_session. Retried only with a session_id."""
        if isinstance(source, (bytes, bytearray)):
            data = bytes(source)
        else:
            with open(source, "rb") as blob:
                data = blob.read()
        request = pb.ImportSessionRequest(data=data, session_id=session_id)
        return (await self._unary("ImportSession", request, session_id,
                                  mode=VERSIONED if session_id else NEVER, kind="transfer",
                                  timeout=timeout)).session

    # Drawings ---------------------------------------------------------------------------------

    async def put_drawing(self, session: "pb.Session", drawing: "pb.Drawing", *,
                          flatten_tolerance: float = 0.0,
                          topology: Iterable["pb.TopologyElement"] = (),
                          gap_tolerance: float = 0.0, min_area_fraction: float = 0.0,
                          timeout: Timeout = UNSET) -> "pb.PutDrawingResponse":
        """Client.put_drawing. Retried (expected_version)."""
        request = pb.PutDrawingRequest(
            session_id=session.id, expected_version=session.version, drawing=drawing,
            flatten_tolerance=flatten_tolerance, topology=list(topology),
            gap_tolerance=gap_tolerance, min_area_fraction=min_area_fraction)
        return await self._unary("PutDrawing", request, session.id, mode=VERSIONED,
                                 timeout=timeout)

    async def put_svg(self, session: "pb.Session", svg: str, name: Optional[str] = None, *,
                      drawing_id: int = 0, key_time: Optional[float] = None,
                      cuts: Iterable[PointsLike] = (), openings: Iterable[PointsLike] = (),
                      flatten_tolerance: float = 0.0, gap_tolerance: float = 0.0,
                      min_area_fraction: float = 0.0, timeout: Timeout = UNSET
                      ) -> "pb.Session":
        """Client.put_svg."""
        name, text = _read_svg(svg, name)
        drawing = pb.Drawing(id=drawing_id, name=name, svg=text)
        if key_time is not None:
            drawing.key_time = key_time
        topology = ([topology_element("cut", c) for c in cuts]
                    + [topology_element("opening", o) for o in openings])
        response = await self.put_drawing(
            session, drawing, topology=topology, flatten_tolerance=flatten_tolerance,
            gap_tolerance=gap_tolerance, min_area_fraction=min_area_fraction, timeout=timeout)
        return response.session

    async def upload_svgs(self, session: "pb.Session", paths: Iterable[str], *,
                          timeout: Timeout = UNSET) -> "pb.Session":
        for path in paths:
            session = await self.put_svg(session, path, timeout=timeout)
        return session

    async def put_polylines(self, session: "pb.Session", outlines: Iterable[PointsLike], *,
                            cuts: Iterable[PointsLike] = (), openings: Iterable[PointsLike] = (),
                            marks: Union[Mapping[int, PointLike],
                                         Iterable[Tuple[int, PointLike]]] = (),
                            name: str = "", key_time: Optional[float] = None,
                            drawing_id: int = 0, timeout: Timeout = UNSET
                            ) -> "pb.PutDrawingResponse":
        """Client.put_polylines."""
        drawing = polyline_drawing(outlines, cuts=cuts, openings=openings, marks=marks,
                                   name=name, key_time=key_time, drawing_id=drawing_id)
        return await self.put_drawing(session, drawing, timeout=timeout)

    async def remove_drawing(self, session: "pb.Session", drawing_id: int, *,
                             timeout: Timeout = UNSET) -> "pb.Session":
        request = pb.RemoveDrawingRequest(session_id=session.id, expected_version=session.version,
                                          drawing_id=drawing_id)
        return (await self._unary("RemoveDrawing", request, session.id, mode=VERSIONED,
                                  timeout=timeout)).session

    # Topology ---------------------------------------------------------------------------------

    def edit_topology(self, session: "pb.Session", *, timeout: Timeout = UNSET
                      ) -> "AsyncTopologyEditor":
        """An EditTopology stream (``async with client.edit_topology(session) as editor:``),
        as Client.edit_topology. Not retried."""
        return AsyncTopologyEditor(self, session, self._seconds("edit_stream", timeout))

    async def _one_edit(self, session: "pb.Session", timeout: Timeout,
                        edit: Callable[["AsyncTopologyEditor"], Awaitable["pb.TopologyState"]]
                        ) -> "pb.TopologyState":
        async with AsyncTopologyEditor(self, session, self._seconds("unary", timeout)) as editor:
            return await edit(editor)

    async def add_cut(self, session: "pb.Session", drawing_id: int, points: PointsLike, *,
                      timeout: Timeout = UNSET) -> "pb.TopologyState":
        return await self._one_edit(session, timeout, lambda e: e.add_cut(drawing_id, points))

    async def add_opening(self, session: "pb.Session", drawing_id: int, points: PointsLike, *,
                          timeout: Timeout = UNSET) -> "pb.TopologyState":
        return await self._one_edit(session, timeout,
                                    lambda e: e.add_opening(drawing_id, points))

    async def add_outline(self, session: "pb.Session", drawing_id: int, points: PointsLike, *,
                          timeout: Timeout = UNSET) -> "pb.TopologyState":
        return await self._one_edit(session, timeout,
                                    lambda e: e.add_outline(drawing_id, points))

    async def move_element(self, session: "pb.Session", drawing_id: int, element_id: int,
                           points: PointsLike, *, timeout: Timeout = UNSET
                           ) -> "pb.TopologyState":
        return await self._one_edit(session, timeout,
                                    lambda e: e.move(drawing_id, element_id, points))

    async def delete_element(self, session: "pb.Session", drawing_id: int, element_id: int, *,
                             timeout: Timeout = UNSET) -> "pb.TopologyState":
        return await self._one_edit(session, timeout,
                                    lambda e: e.delete(drawing_id, element_id))

    # Correspondences --------------------------------------------------------------------------

    async def set_correspondences(self, session: "pb.Session",
                                  correspondences: Iterable[Union["pb.Correspondence",
                                                                  Sequence[PointLike]]], *,
                                  timeout: Timeout = UNSET) -> "pb.Session":
        """Client.set_correspondences. Retried."""
        marks = [c if isinstance(c, pb.Correspondence)
                 else pb.Correspondence(points=[point(p) for p in c]) for c in correspondences]
        request = pb.SetCorrespondencesRequest(session_id=session.id,
                                               expected_version=session.version,
                                               correspondences=marks)
        return (await self._unary("SetCorrespondences", request, session.id, mode=VERSIONED,
                                  timeout=timeout)).session

    async def clear_correspondences(self, session: "pb.Session", *, timeout: Timeout = UNSET
                                    ) -> "pb.Session":
        return await self.set_correspondences(session, [], timeout=timeout)

    # Heavy stages -----------------------------------------------------------------------------

    async def _stage_events(self, run: StageRun, session_id: str, timeout: Timeout,
                            cancel: Optional[Cancellation]) -> AsyncIterator[Any]:
        budget = Budget(self._seconds("heavy", timeout), run.method)
        rpc = getattr(self._stub, run.method)
        attempt = 0
        while True:
            attempt += 1
            if cancel is not None and cancel.cancelled:
                raise _cancelled(run.method)
            call = rpc(run.request_for(attempt), timeout=budget.remaining(),
                       metadata=call_metadata(session_id, self._token))
            if cancel is not None:
                cancel._attach(call.cancel)
            error: Optional[InbetweenError] = None
            try:
                async for response in call:
                    event = run.accept(response)
                    if event is not None:
                        yield event
            except grpc.RpcError as rpc_error:
                error = error_from_rpc(rpc_error, run.method)
            except asyncio.CancelledError:
                # grpc.aio reports a local cancel so: ours (a Cancellation) is CANCELLED, the
                # task's own cancellation goes on as asyncio.CancelledError.
                if cancel is not None and cancel.cancelled:
                    raise _cancelled(run.method) from None
                raise
            finally:
                call.cancel()
                if cancel is not None:
                    cancel._detach(call.cancel)
            if run.result is not None:
                return
            if error is None:
                raise InbetweenError.of("INTERNAL", f"{run.method} ended without a result",
                                        method=run.method)
            await self._retry_or_raise(run.method, VERSIONED, attempt, error, budget, cancel,
                                       heavy=True, last_iteration=run.last_iteration)

    async def _run_stage(self, run: StageRun, session_id: str,
                         on_progress: Optional[AsyncProgressCallback], timeout: Timeout,
                         cancel: Optional[Cancellation]) -> Any:
        own = Cancellation()
        if cancel is not None:
            cancel._attach(own.cancel)
        result = None
        try:
            async for event in self._stage_events(run, session_id, timeout, own):
                if event is run.result:
                    result = event
                elif await _call_back(on_progress, event) is False:
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
                     ) -> AsyncIterator[Any]:
        """Client.stream_build as an async iterator."""
        run = StageRun("BuildMultimesh",
                       build_request(session, meshing, boundary_vertices, max_edge_relative))
        return self._stage_events(run, session.id, timeout, cancel)

    async def build_multimesh(self, session: "pb.Session",
                              on_progress: Optional[AsyncProgressCallback] = None, *,
                              meshing: Optional["pb.MeshingParameters"] = None,
                              boundary_vertices: int = 0, max_edge_relative: float = 0.0,
                              timeout: Timeout = UNSET, cancel: Optional[Cancellation] = None
                              ) -> "pb.BuildMultimeshResult":
        """Client.build_multimesh."""
        run = StageRun("BuildMultimesh",
                       build_request(session, meshing, boundary_vertices, max_edge_relative))
        return await self._run_stage(run, session.id, on_progress, timeout, cancel)

    async def build(self, session: "pb.Session",
                    on_progress: Optional[AsyncProgressCallback] = None,
                    boundary_vertices: int = 0, max_edge_relative: float = 0.0, *,
                    meshing: Optional["pb.MeshingParameters"] = None, timeout: Timeout = UNSET,
                    cancel: Optional[Cancellation] = None) -> "pb.Session":
        return (await self.build_multimesh(session, on_progress, meshing=meshing,
                                           boundary_vertices=boundary_vertices,
                                           max_edge_relative=max_edge_relative, timeout=timeout,
                                           cancel=cancel)).session

    def stream_optimize(self, session: "pb.Session", *,
                        comesh: Optional["pb.ComeshParameters"] = None,
                        max_outer_iterations: int = 0, max_inner_iterations: int = 0,
                        tolerance: float = 0.0, resume: bool = False, timeout: Timeout = UNSET,
                        cancel: Optional[Cancellation] = None) -> AsyncIterator[Any]:
        """Client.stream_optimize as an async iterator."""
        run = StageRun("OptimizeComesh", optimize_request(
            session, comesh, resume, max_outer_iterations=max_outer_iterations,
            max_inner_iterations=max_inner_iterations, tolerance=tolerance))
        return self._stage_events(run, session.id, timeout, cancel)

    async def optimize_comesh(self, session: "pb.Session",
                              on_progress: Optional[AsyncProgressCallback] = None, *,
                              comesh: Optional["pb.ComeshParameters"] = None,
                              max_outer_iterations: int = 0, max_inner_iterations: int = 0,
                              tolerance: float = 0.0, resume: bool = False,
                              timeout: Timeout = UNSET, cancel: Optional[Cancellation] = None
                              ) -> "pb.OptimizeComeshResult":
        """Client.optimize_comesh."""
        run = StageRun("OptimizeComesh", optimize_request(
            session, comesh, resume, max_outer_iterations=max_outer_iterations,
            max_inner_iterations=max_inner_iterations, tolerance=tolerance))
        return await self._run_stage(run, session.id, on_progress, timeout, cancel)

    async def optimize(self, session: "pb.Session",
                       on_progress: Optional[AsyncProgressCallback] = None,
                       max_outer_iterations: int = 0, max_inner_iterations: int = 0,
                       tolerance: float = 0.0, *, comesh: Optional["pb.ComeshParameters"] = None,
                       resume: bool = False, timeout: Timeout = UNSET,
                       cancel: Optional[Cancellation] = None) -> "pb.Session":
        return (await self.optimize_comesh(session, on_progress, comesh=comesh,
                                           max_outer_iterations=max_outer_iterations,
                                           max_inner_iterations=max_inner_iterations,
                                           tolerance=tolerance, resume=resume, timeout=timeout,
                                           cancel=cancel)).session

    # Inbetween --------------------------------------------------------------------------------

    def frames(self, session: SessionRef, frames: int = 0, method: Optional[EnumLike] = None,
               *, parameters: Optional["pb.InbetweenParameters"] = None, start_frame: int = 0,
               on_progress: Optional[AsyncProgressCallback] = None, timeout: Timeout = UNSET,
               cancel: Optional[Cancellation] = None) -> AsyncIterator[Tuple[str, Any]]:
        """Client.frames as an async iterator of ("header", InbetweenHeader) then ("frame",
        InbetweenFrame) pairs, resumed at the next frame after a broken connection."""
        run = FramesRun(inbetween_request(session, frames, method, parameters, start_frame))
        return self._frame_events(run, timeout, cancel, on_progress)

    async def _frame_events(self, run: FramesRun, timeout: Timeout,
                            cancel: Optional[Cancellation],
                            on_progress: Optional[AsyncProgressCallback]
                            ) -> AsyncIterator[Tuple[str, Any]]:
        budget = Budget(self._seconds("heavy", timeout), "Inbetween")
        own = Cancellation()  # a progress callback's False; also fired by `cancel`
        if cancel is not None:
            cancel._attach(own.cancel)
        attempt = 0
        try:
            while True:
                attempt += 1
                if own.cancelled:
                    raise _cancelled("Inbetween")
                call = self._stub.Inbetween(run.request_for(attempt), timeout=budget.remaining(),
                                            metadata=call_metadata(run.session_id, self._token))
                own._attach(call.cancel)
                error: Optional[InbetweenError] = None
                try:
                    async for response in call:
                        for kind, message in run.accept(response):
                            if kind == "progress":
                                if await _call_back(on_progress, message) is False:
                                    own.cancel()
                                continue
                            yield kind, message
                except grpc.RpcError as rpc_error:
                    error = error_from_rpc(rpc_error, "Inbetween")
                except asyncio.CancelledError:
                    if own.cancelled:
                        raise _cancelled("Inbetween") from None
                    raise
                finally:
                    call.cancel()
                    own._detach(call.cancel)
                if error is None or run.done():
                    run.finish()
                    return
                await self._retry_or_raise("Inbetween", READ, attempt, error, budget, own,
                                           heavy=True, resume_frame=run.next_frame)
        finally:
            if cancel is not None:
                cancel._detach(own.cancel)

    async def inbetween(self, session: SessionRef, frames: int = 0,
                        method: Optional[EnumLike] = None, *,
                        parameters: Optional["pb.InbetweenParameters"] = None,
                        start_frame: int = 0,
                        on_frame: Optional[Callable[..., Any]] = None,
                        on_progress: Optional[AsyncProgressCallback] = None,
                        timeout: Timeout = UNSET, cancel: Optional[Cancellation] = None
                        ) -> FramesResult:
        """Client.inbetween: the whole stream collected; ``on_frame(frame, total)`` (plain or
        async) sees each frame as it arrives (return False to cancel)."""
        result: Optional[FramesResult] = None
        events = self._frame_events(
            FramesRun(inbetween_request(session, frames, method, parameters, start_frame)),
            timeout, cancel, on_progress)
        try:
            async for kind, message in events:
                if kind == "header":
                    result = FramesResult(message)
                    continue
                assert result is not None
                result.frames.append(message)
                if await _call_back(on_frame, message, result.header.frames) is False:
                    raise _cancelled("Inbetween", "cancelled by on_frame")
        finally:
            await events.aclose()  # type: ignore[attr-defined]
        assert result is not None
        return result

    async def stream_frames(self, session: SessionRef, out_dir: PathLike, frames: int = 0,
                            method: Optional[EnumLike] = None, art: bool = True, *,
                            parameters: Optional["pb.InbetweenParameters"] = None,
                            timeout: Timeout = UNSET, cancel: Optional[Cancellation] = None
                            ) -> List[str]:
        """Client.stream_frames."""
        os.makedirs(out_dir, exist_ok=True)
        triangles: List[Tuple[int, int, int]] = []
        paths: List[str] = []
        drawing: Optional[FrameArt] = None
        events = self.frames(session, frames, method, parameters=parameters, timeout=timeout,
                             cancel=cancel)
        try:
            async for kind, message in events:
                if kind == "header":
                    triangles = [(t.a, t.b, t.c) for t in message.triangles]
                    drawing = FrameArt(message) if art and message.art else None
                    if drawing is not None and not drawing.has_art():
                        drawing = None
                    continue
                paths.append(_write_frame(out_dir, message, drawing, triangles))
        finally:
            await events.aclose()  # type: ignore[attr-defined]
        return paths


class AsyncTopologyEditor:
    """One EditTopology stream of the asyncio client (TopologyEditor's methods, awaited)."""

    def __init__(self, client: AsyncClient, session: "pb.Session",
                 seconds: Optional[float]) -> None:
        self.session_id = session.id
        self.version = session.version
        self.states: List["pb.TopologyState"] = []
        self._closed = False
        self._call = client._stub.EditTopology(
            timeout=seconds, metadata=call_metadata(session.id, client._token))

    async def __aenter__(self) -> "AsyncTopologyEditor":
        return self

    async def __aexit__(self, exc_type: object, *rest: object) -> None:
        if exc_type is None:
            await self.close()
        else:
            self.cancel()

    async def edit(self, drawing_id: int, **edit: Any) -> "pb.TopologyState":
        if self._closed:
            raise InbetweenError.of("FAILED_PRECONDITION", "the EditTopology stream is closed",
                                    method="EditTopology")
        try:
            await self._call.write(pb.TopologyEdit(session_id=self.session_id,
                                                   expected_version=self.version,
                                                   drawing_id=drawing_id, **edit))
            state = await self._call.read()
        except grpc.RpcError as rpc_error:
            self._closed = True
            raise error_from_rpc(rpc_error, "EditTopology") from None
        if state is grpc.aio.EOF:
            self._closed = True
            raise error_from_rpc(await self._status_error(), "EditTopology")
        self.version = state.version
        self.states.append(state)
        return state

    async def _status_error(self) -> Any:
        """The call's status as an error-like object (a stream that ended early)."""
        code = await self._call.code()
        details = await self._call.details()
        trailing = await self._call.trailing_metadata()

        class _Status(grpc.RpcError):
            def code(self) -> Any:
                return code if code != grpc.StatusCode.OK else grpc.StatusCode.INTERNAL

            def details(self) -> str:
                return details or "EditTopology ended without a reply"

            def trailing_metadata(self) -> Any:
                return trailing

        return _Status()

    async def add(self, drawing_id: int, kind: EnumLike, points: PointsLike
                  ) -> "pb.TopologyState":
        return await self.edit(drawing_id, add=topology_element(kind, points))

    async def add_cut(self, drawing_id: int, points: PointsLike) -> "pb.TopologyState":
        return await self.add(drawing_id, "cut", points)

    async def add_opening(self, drawing_id: int, points: PointsLike) -> "pb.TopologyState":
        return await self.add(drawing_id, "opening", points)

    async def add_outline(self, drawing_id: int, points: PointsLike) -> "pb.TopologyState":
        return await self.add(drawing_id, "outline", points)

    async def move(self, drawing_id: int, element_id: int, points: PointsLike,
                   kind: EnumLike = 0) -> "pb.TopologyState":
        return await self.edit(drawing_id, move=topology_element(kind, points, element_id))

    async def delete(self, drawing_id: int, element_id: int) -> "pb.TopologyState":
        return await self.edit(drawing_id, delete_element=element_id)

    async def close(self) -> None:
        """Ends the stream (half-close) and waits for its status."""
        if self._closed:
            return
        self._closed = True
        try:
            await self._call.done_writing()
            while await self._call.read() is not grpc.aio.EOF:
                pass
            code = await self._call.code()
        except grpc.RpcError as rpc_error:
            raise error_from_rpc(rpc_error, "EditTopology") from None
        if code != grpc.StatusCode.OK:
            raise error_from_rpc(await self._status_error(), "EditTopology")

    def cancel(self) -> None:
        self._closed = True
        self._call.cancel()
