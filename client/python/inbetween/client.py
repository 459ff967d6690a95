"""A small synchronous client of inbetween.v1.Inbetween: sessions, SVG upload, multimesh build,
comesh optimization with progress, inbetween frames streamed to files, export/import.

Every session-mutating call takes the session (as last returned) and sends its version as
``expected_version``; the returned session is the new one. Errors are raised as InbetweenError
with the gRPC status code name (e.g. "ABORTED" for a stale version, "RESOURCE_EXHAUSTED" with
``retry_after_ms`` when the server's heavy-job pool is full).
"""

import json
import os

import grpc

from inbetween.art import FrameArt
from inbetween.v1 import inbetween_pb2 as pb
from inbetween.v1 import inbetween_pb2_grpc as pb_grpc

METHODS = {
    "zhu17": pb.METHOD_ZHU17,
    "alexa": pb.METHOD_ALEXA,
    "linear": pb.METHOD_LINEAR,
}


class InbetweenError(Exception):
    """A failed call: ``code`` is the gRPC status name, ``details`` the server's message."""

    def __init__(self, code, details, retry_after_ms=None):
        super().__init__(f"{code}: {details}")
        self.code = code
        self.details = details
        self.retry_after_ms = retry_after_ms

    @staticmethod
    def from_rpc_error(error):
        retry = None
        trailing = error.trailing_metadata() if hasattr(error, "trailing_metadata") else None
        for key, value in trailing or ():
            if key == "retry-after-ms":
                retry = int(value)
        return InbetweenError(error.code().name, error.details(), retry)


def _session_metadata(session_id, token):
    metadata = []
    if session_id:
        metadata.append(("x-session-id", session_id))
    if token:
        metadata.append(("authorization", f"Bearer {token}"))
    return metadata


class Client:
    """A channel to one server. ``token``: bearer token (servers started with --tokens);
    ``root_certificates``: PEM bytes to use TLS; ``timeout``: seconds per call (None = none)."""

    def __init__(self, target, token=None, root_certificates=None, timeout=None):
        options = [
            ("grpc.max_receive_message_length", 64 * 1024 * 1024),
            ("grpc.max_send_message_length", 64 * 1024 * 1024),
        ]
        if root_certificates is not None:
            credentials = grpc.ssl_channel_credentials(root_certificates=root_certificates)
            self._channel = grpc.secure_channel(target, credentials, options=options)
        else:
            self._channel = grpc.insecure_channel(target, options=options)
        self._stub = pb_grpc.InbetweenStub(self._channel)
        self._token = token
        self._timeout = timeout

    def close(self):
        self._channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _unary(self, method, request, session_id=""):
        try:
            return getattr(self._stub, method)(
                request, timeout=self._timeout, metadata=_session_metadata(session_id, self._token))
        except grpc.RpcError as error:
            raise InbetweenError.from_rpc_error(error) from None

    def _stream(self, method, request, session_id):
        """Yields the responses of a server stream; the generator's .cancel() ends the call."""
        call = getattr(self._stub, method)(
            request, timeout=self._timeout, metadata=_session_metadata(session_id, self._token))
        return call

    # Sessions ---------------------------------------------------------------------------------

    def create_session(self, display_name=""):
        request = pb.CreateSessionRequest(display_name=display_name)
        return self._unary("CreateSession", request).session

    def get_session(self, session_id, full=False):
        """The session (and, with full=True, a (session, multimesh) pair)."""
        response = self._unary("GetSession", pb.GetSessionRequest(session_id=session_id, full=full),
                               session_id)
        return (response.session, response.multimesh) if full else response.session

    def list_sessions(self, page_size=0):
        """Every session of the caller (all pages), as summaries."""
        sessions, token = [], ""
        while True:
            response = self._unary("ListSessions",
                                   pb.ListSessionsRequest(page_size=page_size, page_token=token))
            sessions.extend(response.sessions)
            token = response.next_page_token
            if not token:
                return sessions

    def delete_session(self, session, any_version=False):
        request = pb.DeleteSessionRequest(session_id=session.id,
                                          expected_version=0 if any_version else session.version)
        self._unary("DeleteSession", request, session.id)

    def export_session(self, session_id, path):
        """Writes the session as one file (an opaque SessionArchive) and returns the path."""
        data = self._unary("ExportSession", pb.ExportSessionRequest(session_id=session_id),
                           session_id).data
        with open(path, "wb") as out:
            out.write(data)
        return path

    def import_session(self, path, session_id=""):
        with open(path, "rb") as source:
            data = source.read()
        request = pb.ImportSessionRequest(data=data, session_id=session_id)
        return self._unary("ImportSession", request, session_id).session

    # Drawings ---------------------------------------------------------------------------------

    def put_svg(self, session, svg, name=None):
        """Adds one drawing from an SVG file path or SVG text; returns the new session."""
        if not svg.lstrip().startswith("<"):
            name = name or os.path.basename(svg)
            with open(svg, encoding="utf-8") as source:
                svg = source.read()
        drawing = pb.Drawing(name=name or "", svg=svg)
        request = pb.PutDrawingRequest(session_id=session.id, expected_version=session.version,
                                       drawing=drawing)
        return self._unary("PutDrawing", request, session.id).session

    def upload_svgs(self, session, paths):
        for path in paths:
            session = self.put_svg(session, path)
        return session

    # Heavy stages -----------------------------------------------------------------------------

    def _run_stage(self, method, request, session_id, on_progress, result_field):
        """Runs a server stream to its result. on_progress(event) gets every non-result message
        (Progress or ComeshIteration); returning False from it cancels the call (CANCELLED)."""
        call = self._stream(method, request, session_id)
        result = None
        try:
            for response in call:
                event = response.WhichOneof("event")
                if event == result_field:
                    result = getattr(response, event)
                elif on_progress is not None and on_progress(getattr(response, event)) is False:
                    call.cancel()
        except grpc.RpcError as error:
            raise InbetweenError.from_rpc_error(error) from None
        if result is None:
            raise InbetweenError("INTERNAL", f"{method} ended without a result")
        return result

    def build(self, session, on_progress=None, boundary_vertices=0, max_edge_relative=0.0):
        """BuildMultimesh; returns the session at STAGE_MULTIMESH. boundary_vertices and
        max_edge_relative (MeshingParameters): 0 = the session's parameters."""
        request = pb.BuildMultimeshRequest(session_id=session.id, expected_version=session.version)
        if boundary_vertices or max_edge_relative:
            request.meshing.CopyFrom(pb.MeshingParameters(boundary_vertices=boundary_vertices,
                                                          max_edge_relative=max_edge_relative))
        return self._run_stage("BuildMultimesh", request, session.id, on_progress,
                               "result").session

    def optimize(self, session, on_progress=None, max_outer_iterations=0, max_inner_iterations=0,
                 tolerance=0.0):
        """OptimizeComesh; on_progress gets each ComeshIteration / Progress (return False to
        cancel). 0 = the server's default for each limit. Returns the session at
        STAGE_OPTIMIZED."""
        comesh = pb.ComeshParameters(max_outer_iterations=max_outer_iterations,
                                     max_inner_iterations=max_inner_iterations,
                                     tolerance=tolerance)
        request = pb.OptimizeComeshRequest(session_id=session.id, expected_version=session.version,
                                           comesh=comesh)
        return self._run_stage("OptimizeComesh", request, session.id, on_progress,
                               "result").session

    def frames(self, session_id, frames, method="zhu17"):
        """Yields ("header", InbetweenHeader) then ("frame", InbetweenFrame) in order. The header
        comes with all its art: the layers of the art messages that follow it on the wire
        (InbetweenHeader.art_messages) are appended to its KeyArt of the same key."""
        parameters = pb.InbetweenParameters(method=METHODS[method], frames=frames)
        request = pb.InbetweenRequest(session_id=session_id, parameters=parameters)
        call = self._stream("Inbetween", request, session_id)
        try:
            header, pending = None, 0
            for response in call:
                event = response.WhichOneof("event")
                if event == "header":
                    header, pending = response.header, response.header.art_messages
                elif event == "art" and header is not None and pending > 0:
                    key_art = next(k for k in header.art if k.key == response.art.key)
                    key_art.layers.extend(response.art.layers)
                    pending -= 1
                elif event == "frame":
                    yield event, response.frame
                    continue
                else:
                    continue
                if pending == 0:
                    yield "header", header
        except grpc.RpcError as error:
            raise InbetweenError.from_rpc_error(error) from None
        finally:
            call.cancel()  # a consumer that stops early ends the stream (no-op when finished)

    def stream_frames(self, session, out_dir, frames, method="zhu17", art=True):
        """Streams the inbetween frames into out_dir as they arrive: frame_NNNN.svg and
        frame_NNNN.json (index, time, weights, vertices). The SVG draws the frame's art
        (frame_art_svg, viewBox from that frame's bounds) when ``art`` is true and the drawings
        have art, else the mesh's triangles. Returns the paths of the JSON files in frame
        order."""
        os.makedirs(out_dir, exist_ok=True)
        session_id = session if isinstance(session, str) else session.id
        triangles, paths, drawing = [], [], None
        for kind, message in self.frames(session_id, frames, method):
            if kind == "header":
                triangles = [(t.a, t.b, t.c) for t in message.triangles]
                drawing = FrameArt(message) if art and message.art else None
                if drawing is not None and not drawing.has_art():
                    drawing = None  # every drawing came without art: draw the triangles
                continue
            vertices = [(p.x, p.y) for p in message.vertices]
            stem = os.path.join(out_dir, f"frame_{message.index:04d}")
            with open(stem + ".json", "w", encoding="utf-8") as out:
                json.dump({"index": message.index, "time": message.time,
                           "weights": list(message.weights), "vertices": vertices}, out)
            with open(stem + ".svg", "w", encoding="utf-8") as out:
                out.write(drawing.svg(message) if drawing else _frame_svg(vertices, triangles))
            paths.append(stem + ".json")
        return paths


def place_art(header, frame):
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


def _frame_svg(vertices, triangles):
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
