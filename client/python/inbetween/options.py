"""Call options shared by the sync and asyncio clients: deadlines per call kind, the retry
policy, retry events and cancellation."""

from __future__ import annotations

import random
import threading
import time
from dataclasses import dataclass
from typing import Callable, List, Optional, Union

from inbetween.errors import InbetweenError

__all__ = ["Deadlines", "RetryPolicy", "RetryEvent", "Cancellation", "UNSET", "Timeout"]


class _Unset:
    """The default of every ``timeout=`` argument: the client's deadline for that call kind."""

    _instance: Optional["_Unset"] = None

    def __new__(cls) -> "_Unset":
        if cls._instance is None:
            cls._instance = super().__new__(cls)
        return cls._instance

    def __repr__(self) -> str:
        return "UNSET"


UNSET = _Unset()
# A per-call timeout: seconds, None (no deadline) or UNSET (the client's Deadlines).
Timeout = Union[float, None, _Unset]


@dataclass(frozen=True)
class Deadlines:
    """Seconds allowed per call, by kind (None = no deadline). One deadline covers a call's
    retries and resumes too, so a call never outlives it. Short for small unary calls, which the
    server answers in milliseconds; long for the heavy stages, which take minutes on large
    drawings; whole-session transfers in between."""

    unary: Optional[float] = 30.0  # CreateSession, GetSession, ListSessions, PutDrawing, ...
    transfer: Optional[float] = 300.0  # ExportSession, ImportSession, GetSession(full=True)
    heavy: Optional[float] = 3600.0  # BuildMultimesh, OptimizeComesh, Inbetween
    edit_stream: Optional[float] = 3600.0  # one EditTopology stream, from open to close

    @classmethod
    def all(cls, seconds: Optional[float]) -> "Deadlines":
        """The same deadline for every kind (the ``timeout=`` of the client's constructor)."""
        return cls(seconds, seconds, seconds, seconds)


@dataclass(frozen=True)
class RetryPolicy:
    """Retries of calls that are safe to repeat after a transient failure (UNAVAILABLE, or a
    stream reset by a proxy whose backend died), with exponential backoff. Which calls: reads
    (GetSession, ListSessions, ExportSession), the Inbetween stream (resumed at the next frame),
    and mutations that carry an expected_version (the server applies one of two identical
    attempts at most; a retry of one that did apply gets ABORTED, flagged ``maybe_applied``):
    PutDrawing, RemoveDrawing, SetCorrespondences, DeleteSession at a version, ImportSession with
    a session id, BuildMultimesh, OptimizeComesh (sent again with ``resume``). Never
    CreateSession, ImportSession without an id, DeleteSession at any version, or an EditTopology
    stream."""

    max_attempts: int = 5  # per call, the first included; 1 = never retry
    initial_backoff: float = 0.1  # seconds before the second attempt
    multiplier: float = 2.0  # each later wait this much longer
    max_backoff: float = 5.0  # cap of one wait
    jitter: float = 0.1  # each wait times a random factor in [1 - jitter, 1 + jitter]

    @classmethod
    def never(cls) -> "RetryPolicy":
        return cls(max_attempts=1)

    def backoff(self, failed_attempt: int) -> float:
        """The wait after attempt ``failed_attempt`` (1 = the first) failed."""
        wait = min(self.max_backoff,
                   self.initial_backoff * self.multiplier ** max(failed_attempt - 1, 0))
        if self.jitter > 0:
            wait *= random.uniform(1.0 - self.jitter, 1.0 + self.jitter)
        return max(wait, 0.0)


@dataclass(frozen=True)
class RetryEvent:
    """One retry about to happen (the clients' ``on_retry`` callback, for logging)."""

    method: str  # "GetSession", "Inbetween", ...
    failed_attempt: int  # 1 = the first attempt failed
    error: InbetweenError  # why it failed
    backoff: float  # seconds before the next attempt
    resume_frame: int = 0  # Inbetween: start_frame of the next attempt
    last_iteration: int = 0  # OptimizeComesh: the last iteration received


class Cancellation:
    """Cancels the calls it is passed to (``cancel=``), from any thread: the call in flight ends
    with CANCELLED (CallCancelledError), the server stops the work, a retry wait is cut short
    and later calls with it fail at once. With the asyncio client, cancel from the event loop's
    thread (or cancel the task instead)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._event = threading.Event()
        self._hooks: List[Callable[[], object]] = []

    def cancel(self) -> None:
        with self._lock:
            self._event.set()
            hooks = list(self._hooks)
        for hook in hooks:
            hook()

    @property
    def cancelled(self) -> bool:
        return self._event.is_set()

    def _attach(self, hook: Callable[[], object]) -> None:
        with self._lock:
            if not self._event.is_set():
                self._hooks.append(hook)
                return
        hook()

    def _detach(self, hook: Callable[[], object]) -> None:
        with self._lock:
            if hook in self._hooks:
                self._hooks.remove(hook)

    def _wait(self, seconds: float) -> bool:
        """Sleeps up to ``seconds``; True when cancelled meanwhile."""
        return self._event.wait(seconds)


class Budget:
    """A call's deadline over all its attempts."""

    def __init__(self, seconds: Optional[float], method: str) -> None:
        self._end = None if seconds is None else time.monotonic() + seconds
        self._method = method

    def remaining(self) -> Optional[float]:
        """Seconds left for the next attempt (None = no deadline); raises DEADLINE_EXCEEDED when
        none are."""
        if self._end is None:
            return None
        left = self._end - time.monotonic()
        if left <= 0:
            raise InbetweenError.of("DEADLINE_EXCEEDED",
                                    "the call's deadline passed before a retry",
                                    method=self._method)
        return left

    def allows_wait(self, seconds: float) -> bool:
        return self._end is None or time.monotonic() + seconds < self._end
