"""What the sync and asyncio clients share besides I/O: which calls are retried, the backoff
decision, metadata, and the state of the streaming calls over their attempts (progress
deduplicated across a resumed OptimizeComesh, the Inbetween stream's chunked header art and
resume at the next frame, as client/inbetween_client.cpp does)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple, Union

from inbetween.errors import InbetweenError
from inbetween.options import Budget, Cancellation, RetryPolicy
from inbetween.v1 import inbetween_pb2 as pb

# How a call may be repeated after a transient failure.
NEVER = "never"  # not idempotent and nothing to make it so (CreateSession)
READ = "read"  # changes nothing (GetSession, ListSessions, ExportSession)
VERSIONED = "versioned"  # a mutation at an expected_version / a named id: applied once at most

# The least wait before retrying a refusal by the server's --max-heavy-jobs-per-token that
# follows a transient failure: the earlier, broken attempt's job is usually still winding down
# on the server until it notices the cancellation.
ORPHAN_JOB_BACKOFF = 0.5

SessionRef = Union[str, "pb.Session"]


def session_id_of(session: SessionRef) -> str:
    return session if isinstance(session, str) else session.id


def is_transient(error: InbetweenError) -> bool:
    """UNAVAILABLE (unreachable, draining, connection lost), or a stream reset by a proxy whose
    backend died mid-call (gRPC reports INTERNAL "Received RST_STREAM ..."; no server handler
    sends that message)."""
    return error.code == "UNAVAILABLE" or (
        error.code == "INTERNAL" and error.details.startswith("Received RST_STREAM"))


def retry_wait(policy: RetryPolicy, mode: str, attempt: int, error: InbetweenError,
               budget: Budget, cancel: Optional[Cancellation], heavy: bool = False
               ) -> Optional[float]:
    """The wait before attempt ``attempt + 1``, or None when ``error`` is final."""
    if mode == NEVER or (cancel is not None and cancel.cancelled):
        return None
    orphan = heavy and attempt > 1 and error.reason == "HEAVY_JOBS_PER_TOKEN"
    if not (is_transient(error) or orphan) or attempt >= policy.max_attempts:
        return None
    wait = policy.backoff(attempt)
    if orphan:
        wait = max(wait, ORPHAN_JOB_BACKOFF)
    return wait if budget.allows_wait(wait) else None


def final_error(error: InbetweenError, attempts: int) -> InbetweenError:
    """``error`` as raised after ``attempts`` attempts: after a retry, ABORTED or ALREADY_EXISTS
    may be the earlier attempt's own success (it applied, its reply was lost), which the caller
    must know."""
    error.attempts = attempts
    if attempts > 1 and error.code in ("ABORTED", "ALREADY_EXISTS"):
        error.maybe_applied = True
        error.details += (" (an earlier attempt of this call failed in transit and may have been "
                          "applied: re-read the session)")
        error.args = (f"{error.code}: {error.details}",)
    return error


def _legal(value: str) -> bool:
    # gRPC refuses metadata values outside printable ASCII: such a value is not sent (the server
    # then judges the id in the request itself, or sees no token), as the C++ client does.
    return all(" " <= c <= "~" for c in value)


def call_metadata(session_id: str, token: Optional[str]) -> List[Tuple[str, str]]:
    """x-session-id (proxies' session affinity) and the bearer token."""
    metadata = []
    if session_id and _legal(session_id):
        metadata.append(("x-session-id", session_id))
    if token and _legal(token):
        metadata.append(("authorization", f"Bearer {token}"))
    return metadata


class StageRun:
    """One BuildMultimesh or OptimizeComesh call over its attempts. Every attempt names the
    version the first one started from: a build that died before storing its multimesh left the
    session unchanged, so the same request builds it again (one that stored it makes the retry
    ABORTED); an optimization is sent again with ``resume`` and continues from its last
    checkpoint, its iterations numbered on."""

    def __init__(self, method: str, request: object) -> None:
        self.method = method
        self.request = request
        self.result: Optional[object] = None
        self.last_iteration = 0  # iterations up to this one were delivered already

    def request_for(self, attempt: int) -> object:
        if self.method == "OptimizeComesh" and attempt > 1:
            self.request.resume = True  # type: ignore[attr-defined]
        return self.request

    def accept(self, response: object) -> Optional[object]:
        """The event to deliver for one response (Progress, ComeshIteration or the result), or
        None for an iteration already delivered before a resume."""
        which = response.WhichOneof("event")  # type: ignore[attr-defined]
        if which is None:
            return None
        message = getattr(response, which)
        if which == "result":
            self.result = message
        elif which == "iteration":
            if message.inner <= self.last_iteration:
                return None
            self.last_iteration = message.inner
        return message


@dataclass
class FramesResult:
    """A whole Inbetween stream: the header (every art message appended to its KeyArt) and the
    frames in order."""

    header: "pb.InbetweenHeader"
    frames: List["pb.InbetweenFrame"] = field(default_factory=list)


class FramesRun:
    """One Inbetween call over its attempts: the header is delivered once, whole (the layers of
    the InbetweenResponse.art messages that follow it appended to its KeyArt of the same key),
    frames once each in order; a broken stream resumes at the next frame (``start_frame``), and a
    resumed stream computed from another session version is ABORTED rather than mixed."""

    def __init__(self, request: "pb.InbetweenRequest") -> None:
        self.request = request
        self.session_id = request.session_id
        self.header: Optional["pb.InbetweenHeader"] = None
        self.header_delivered = False
        self.art_received = 0
        self.first_frame = request.start_frame
        self.next_frame = request.start_frame

    def request_for(self, attempt: int) -> "pb.InbetweenRequest":
        self.request.start_frame = self.next_frame
        return self.request

    def done(self) -> bool:
        """Every frame arrived (a broken connection after that leaves nothing to resume)."""
        return self.header_delivered and self.next_frame >= self.header.frames  # type: ignore

    def _error(self, code: str, details: str) -> InbetweenError:
        return InbetweenError.of(code, details, method="Inbetween")

    def accept(self, response: "pb.InbetweenResponse") -> Sequence[Tuple[str, object]]:
        which = response.WhichOneof("event")
        if which == "progress":
            return [("progress", response.progress)]
        if which == "header":
            incoming = response.header
            if self.header is None:
                self.header = pb.InbetweenHeader()
                self.header.CopyFrom(incoming)
            elif (incoming.session_version != self.header.session_version
                  or incoming.frames != self.header.frames
                  or len(incoming.triangles) != len(self.header.triangles)):
                raise self._error(
                    "ABORTED",
                    f"session {self.session_id} changed from version "
                    f"{self.header.session_version} to {incoming.session_version} while its "
                    f"frames were streamed ({self.next_frame - self.first_frame} of "
                    f"{self.header.frames - self.first_frame} received); start again")
            elif not self.header_delivered:
                # The art was cut off with the connection: collect it again from this header.
                del self.header.art[:]
                self.header.art.extend(incoming.art)
                self.art_received = 0
            return self._header_if_whole()
        if which == "art":
            if self.header is None:
                raise self._error("INTERNAL", "Inbetween stream sent art before its header")
            if self.header_delivered:
                return []  # a resumed stream's copy of art already received
            key = next((k for k in self.header.art if k.key == response.art.key), None)
            if key is None:
                raise self._error("INTERNAL", f"Inbetween stream sent art for key "
                                  f"{response.art.key}, not in its header")
            key.layers.extend(response.art.layers)
            self.art_received += 1
            return self._header_if_whole()
        if which == "frame":
            if not self.header_delivered:
                raise self._error("INTERNAL", "Inbetween stream sent a frame before its header "
                                  "and all of the header's art")
            if response.frame.index != self.next_frame:
                raise self._error("INTERNAL", f"Inbetween stream sent frame "
                                  f"{response.frame.index}, expected {self.next_frame}")
            self.next_frame += 1
            return [("frame", response.frame)]
        return []

    def _header_if_whole(self) -> Sequence[Tuple[str, object]]:
        assert self.header is not None
        if self.header_delivered or self.art_received < self.header.art_messages:
            return []
        self.header_delivered = True
        return [("header", self.header)]

    def finish(self) -> None:
        """Checks a stream that ended OK."""
        if self.header is None:
            raise self._error("INTERNAL", "Inbetween stream ended without a header")
        if self.art_received != self.header.art_messages and not self.header_delivered:
            raise self._error("INTERNAL", f"Inbetween stream sent {self.art_received} art "
                              f"messages, header announced {self.header.art_messages}")
        if self.next_frame != self.header.frames:
            raise self._error("INTERNAL", f"Inbetween stream sent "
                              f"{self.next_frame - self.first_frame} frames, header announced "
                              f"{self.header.frames - self.first_frame}")
