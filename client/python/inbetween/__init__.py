"""Python client of the Inbetween gRPC service (proto/inbetween/v1/inbetween.proto).

The protobuf/gRPC stubs are generated, not committed: run ``client/python/generate_stubs.sh DIR``
and put DIR on ``sys.path`` (or PYTHONPATH) next to this package; ``inbetween.v1`` is then found
there (this package's path is extended over every ``inbetween`` directory on ``sys.path``).

    import inbetween
    with inbetween.Client("127.0.0.1:50051") as client:
        session = client.create_session("walk")
        session = client.upload_svgs(session, ["a.svg", "b.svg"])
        session = client.build(session)
        session = client.optimize(session, on_progress=print)
        paths = client.stream_frames(session, "out", frames=24)  # SVGs draw the art

        events = client.frames(session.id, 24)
        header = next(events)[1]
        layers = inbetween.frame_art(header, next(events)[1])  # paint + placed paths
"""

import pkgutil

__path__ = pkgutil.extend_path(__path__, __name__)

from inbetween.art import FrameArt, FrameArtOptions, frame_art, frame_art_svg  # noqa: E402
from inbetween.client import Client, InbetweenError, place_art  # noqa: E402

__all__ = ["Client", "FrameArt", "FrameArtOptions", "InbetweenError", "frame_art",
           "frame_art_svg", "place_art"]
