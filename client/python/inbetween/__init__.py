"""Python client of the Inbetween gRPC service (proto/inbetween/v1/inbetween.proto).

Install with pip (``pip install client/python``): the protobuf/gRPC stubs (``inbetween.v1``) are
generated from the proto when the package is built. Stubs generated elsewhere
(``client/python/generate_stubs.sh DIR`` with DIR on ``sys.path``) are found too: this package's
path extends over every ``inbetween`` directory on ``sys.path``.

    import inbetween
    with inbetween.Client("127.0.0.1:50051") as client:
        session = client.create_session("walk")
        session = client.upload_svgs(session, ["a.svg", "b.svg"])
        session = client.build(session)
        session = client.optimize(session, on_progress=print)
        result = client.inbetween(session, frames=24, method="zhu17")
        layers = inbetween.frame_art(result.header, result.frames[3])  # paint + placed paths

The asyncio client, ``inbetween.AsyncClient``, has the same methods as coroutines and async
iterators.
"""

import pkgutil

__path__ = pkgutil.extend_path(__path__, __name__)

from inbetween.art import FrameArt, FrameArtOptions, frame_art, frame_art_svg  # noqa: E402
from inbetween.errors import (AbortedError, AlreadyExistsError, CallCancelledError,  # noqa: E402
                              DeadlineExceededError, FailedPreconditionError, InbetweenError,
                              InternalError, InvalidArgumentError, NotFoundError,
                              PermissionDeniedError, ResourceExhaustedError,
                              UnauthenticatedError, UnavailableError, UnimplementedError)
from inbetween.options import (UNSET, Cancellation, Deadlines, RetryEvent,  # noqa: E402
                               RetryPolicy)
from inbetween.messages import (comesh_parameters, inbetween_parameters,  # noqa: E402
                                meshing_parameters, parameters, point, polyline,
                                polyline_drawing, stiffness_region, topology_element)
from inbetween._calls import FramesResult  # noqa: E402
from inbetween.client import METHODS, Client, TopologyEditor, place_art  # noqa: E402
from inbetween.aio import AsyncClient, AsyncTopologyEditor  # noqa: E402

__version__ = "1.0.0"

__all__ = [
    "Client", "AsyncClient", "TopologyEditor", "AsyncTopologyEditor", "FramesResult",
    "Deadlines", "RetryPolicy", "RetryEvent", "Cancellation", "UNSET", "METHODS",
    "InbetweenError", "CallCancelledError", "InvalidArgumentError", "DeadlineExceededError",
    "NotFoundError", "AlreadyExistsError", "PermissionDeniedError", "ResourceExhaustedError",
    "FailedPreconditionError", "AbortedError", "UnimplementedError", "InternalError",
    "UnavailableError", "UnauthenticatedError",
    "point", "polyline", "topology_element", "stiffness_region", "polyline_drawing",
    "inbetween_parameters", "meshing_parameters", "comesh_parameters", "parameters",
    "FrameArt", "FrameArtOptions", "frame_art", "frame_art_svg", "place_art",
]
