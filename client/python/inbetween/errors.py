"""Errors of the inbetween client: every failed call raises an InbetweenError carrying the gRPC
status code and the server's message (proto/inbetween/v1/inbetween.proto lists what each code
means). A subclass per code lets callers catch one kind (``except inbetween.AbortedError``);
``code`` stays the status name as a string, so ``error.code == "ABORTED"`` works too."""

from __future__ import annotations

import re
from typing import Any, Dict, Optional, Type

import grpc

__all__ = [
    "InbetweenError", "CallCancelledError", "InvalidArgumentError", "DeadlineExceededError",
    "NotFoundError", "AlreadyExistsError", "PermissionDeniedError", "ResourceExhaustedError",
    "FailedPreconditionError", "AbortedError", "UnimplementedError", "InternalError",
    "UnavailableError", "UnauthenticatedError", "error_from_rpc",
]


class InbetweenError(Exception):
    """A failed call. ``code``: the gRPC status name ("ABORTED"); ``status_code``: the same as a
    grpc.StatusCode; ``details``: the server's message; ``method``: the RPC ("PutDrawing");
    ``retry_after_ms``: the server's hint on a busy heavy-job pool (RESOURCE_EXHAUSTED), else
    None; ``maybe_applied``: True when an earlier attempt of this call failed in transit and a
    retry then got ABORTED / ALREADY_EXISTS, so the earlier attempt may have taken effect (re-read
    the session); ``attempts``: how many attempts the call made (retries included); ``reason``:
    the server's machine-readable reason (a google.rpc.ErrorInfo in the status details, domain
    "inbetween.v1": MESH_VERTEX_LIMIT, DRAWING_POINT_LIMIT, TOPOLOGY_DIFFERS,
    HEAVY_JOBS_PER_TOKEN, SERVER_BUSY, SESSIONS_PER_TOKEN, SESSION_LIMIT, STORE_FULL), else None;
    ``field``: the offending request field ("parameters.frames", from a google.rpc.BadRequest)
    of an INVALID_ARGUMENT / OUT_OF_RANGE, else None. ``retry_after_ms`` also comes from a
    google.rpc.RetryInfo when the trailer is absent."""

    def __init__(self, code: str, details: str, retry_after_ms: Optional[int] = None,
                 method: str = "", maybe_applied: bool = False, attempts: int = 1,
                 reason: Optional[str] = None, field: Optional[str] = None) -> None:
        super().__init__(f"{code}: {details}")
        self.code = code
        self.status_code: Optional[grpc.StatusCode] = getattr(grpc.StatusCode, code, None)
        self.details = details
        self.retry_after_ms = retry_after_ms
        self.method = method
        self.maybe_applied = maybe_applied
        self.attempts = attempts
        self.reason = reason
        self.field = field

    @staticmethod
    def from_rpc_error(error: grpc.RpcError, method: str = "") -> "InbetweenError":
        return error_from_rpc(error, method)

    @staticmethod
    def of(code: str, details: str, **kwargs: Any) -> "InbetweenError":
        """The subclass of ``code`` (InbetweenError itself for codes without one)."""
        return _CLASSES.get(code, InbetweenError)(code, details, **kwargs)


class CallCancelledError(InbetweenError):
    """CANCELLED: the client cancelled the call (a progress callback returned False, a
    Cancellation fired) or the server saw it go away. Not asyncio.CancelledError: cancelling the
    task that awaits a call raises that one, as asyncio does."""


class InvalidArgumentError(InbetweenError):
    """INVALID_ARGUMENT: a request field is malformed; the message names it."""


class DeadlineExceededError(InbetweenError):
    """DEADLINE_EXCEEDED: the call's deadline passed; the server stopped the work."""


class NotFoundError(InbetweenError):
    """NOT_FOUND: unknown session or drawing (or another token's session)."""


class AlreadyExistsError(InbetweenError):
    """ALREADY_EXISTS: CreateSession / ImportSession with a session id that is taken."""


class PermissionDeniedError(InbetweenError):
    """PERMISSION_DENIED."""


class ResourceExhaustedError(InbetweenError):
    """RESOURCE_EXHAUSTED: a limit; ``retry_after_ms`` when the heavy-job pool is busy."""


class FailedPreconditionError(InbetweenError):
    """FAILED_PRECONDITION: a stage out of order, or shapes that cannot be matched."""


class AbortedError(InbetweenError):
    """ABORTED: expected_version is not the session's version (optimistic locking)."""


class UnimplementedError(InbetweenError):
    """UNIMPLEMENTED: the server does not implement this RPC or feature."""


class InternalError(InbetweenError):
    """INTERNAL: a bug on the server, or a stream that broke the protocol."""


class UnavailableError(InbetweenError):
    """UNAVAILABLE: the server is unreachable or draining (retried where that is safe)."""


class UnauthenticatedError(InbetweenError):
    """UNAUTHENTICATED: the bearer token is missing or unknown."""


_CLASSES: Dict[str, Type[InbetweenError]] = {
    "CANCELLED": CallCancelledError,
    "INVALID_ARGUMENT": InvalidArgumentError,
    "DEADLINE_EXCEEDED": DeadlineExceededError,
    "NOT_FOUND": NotFoundError,
    "ALREADY_EXISTS": AlreadyExistsError,
    "PERMISSION_DENIED": PermissionDeniedError,
    "RESOURCE_EXHAUSTED": ResourceExhaustedError,
    "FAILED_PRECONDITION": FailedPreconditionError,
    "ABORTED": AbortedError,
    "UNIMPLEMENTED": UnimplementedError,
    "INTERNAL": InternalError,
    "UNAVAILABLE": UnavailableError,
    "UNAUTHENTICATED": UnauthenticatedError,
}

_SIZE = re.compile(r"^(Received|Sent) message larger than max \((\d+) vs\. (\d+)\)")


def _name_size_limit(details: str) -> str:
    """gRPC's own refusal of an oversized message names no flag: say which limit it is, as the
    C++ client does (client/inbetween_client.cpp FromGrpcStatus)."""
    match = _SIZE.match(details)
    if not match:
        return details
    request = match.group(1) == "Received"  # received by the server
    size, limit = match.group(2), match.group(3)
    advice = ("send smaller drawings (fewer points) or raise the server's --max-message-bytes"
              if request else "raise the server's --max-message-bytes or ask for less (a smaller "
              "mesh, fewer vertices per frame)")
    return (f"the {'request' if request else 'reply'} is {size} bytes, over the server's limit of "
            f"{limit} bytes (inbetween-server --max-message-bytes {limit}): {advice} "
            f"[gRPC: {details}]")


def error_from_rpc(error: grpc.RpcError, method: str = "") -> InbetweenError:
    """A grpc.RpcError (sync or asyncio) as an InbetweenError of the same code and message."""
    code_of = getattr(error, "code", None)
    code = code_of() if callable(code_of) else grpc.StatusCode.UNKNOWN
    details_of = getattr(error, "details", None)
    details = (details_of() if callable(details_of) else None) or str(error)
    retry = None
    found = _Details()
    trailing_of = getattr(error, "trailing_metadata", None)
    trailing = trailing_of() if callable(trailing_of) else None
    for item in trailing or ():
        # Sync calls give (key, value) tuples; grpc.aio's Metadata iterates the same way.
        key, value = item if isinstance(item, tuple) else (item, trailing[item])
        if key == "retry-after-ms":
            try:
                retry = int(value)
            except (TypeError, ValueError):
                pass
        elif key == "grpc-status-details-bin":
            found = _details_of(value)
    name = code.name if isinstance(code, grpc.StatusCode) else str(code)
    if name == "RESOURCE_EXHAUSTED":
        details = _name_size_limit(details)
    if retry is None:
        retry = found.retry_after_ms
    return InbetweenError.of(name, details, retry_after_ms=retry, method=method,
                             reason=found.reason, field=found.field)


_ERROR_INFO_TYPE_URL = "type.googleapis.com/google.rpc.ErrorInfo"
_BAD_REQUEST_TYPE_URL = "type.googleapis.com/google.rpc.BadRequest"
_RETRY_INFO_TYPE_URL = "type.googleapis.com/google.rpc.RetryInfo"


class _Details:
    """What a grpc-status-details-bin trailer says: reason, offending field, retry delay."""

    def __init__(self) -> None:
        self.reason: Optional[str] = None
        self.field: Optional[str] = None
        self.retry_after_ms: Optional[int] = None


def _details_of(details_bin: Any) -> _Details:
    """The service's google.rpc.ErrorInfo, BadRequest and RetryInfo in a grpc-status-details-bin
    trailer (inbetween.proto ErrorStatus)."""
    from inbetween.v1 import inbetween_pb2 as pb  # the generated stubs, as the clients use them
    from google.protobuf.message import DecodeError
    found = _Details()
    try:
        status = pb.ErrorStatus.FromString(bytes(details_bin))
        for detail in status.details:
            if detail.type_url == _ERROR_INFO_TYPE_URL:
                info = pb.ErrorInfo.FromString(detail.value)
                if info.domain == "inbetween.v1" and info.reason:
                    found.reason = info.reason
            elif detail.type_url == _BAD_REQUEST_TYPE_URL:
                bad = pb.BadRequest.FromString(detail.value)
                if bad.field_violations:
                    found.field = bad.field_violations[0].field
            elif detail.type_url == _RETRY_INFO_TYPE_URL:
                delay = pb.RetryInfo.FromString(detail.value).retry_delay
                found.retry_after_ms = delay.seconds * 1000 + delay.nanos // 1_000_000
    except (DecodeError, TypeError, ValueError):
        return _Details()
    return found
    return None
