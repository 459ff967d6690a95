"""Builders of request messages from plain Python values: points as (x, y) pairs, enums by name
("zhu17", "catmull-rom") or value, unset optional fields left unset (the server's defaults).
Every builder also accepts the protobuf message itself, so callers can mix both."""

from __future__ import annotations

from typing import Iterable, Mapping, Optional, Sequence, Tuple, Union

from inbetween.v1 import inbetween_pb2 as pb

__all__ = [
    "PointLike", "PointsLike", "point", "polyline", "topology_element", "stiffness_region",
    "inbetween_parameters", "meshing_parameters", "comesh_parameters", "parameters",
    "polyline_drawing", "METHODS", "TIMINGS", "ELEMENT_KINDS", "CORNER_MATCHINGS",
    "BOUNDARY_ALIGNMENTS",
]

PointLike = Union[Tuple[float, float], Sequence[float], "pb.Point"]
PointsLike = Union[Iterable[PointLike], "pb.Polyline"]
EnumLike = Union[str, int]

METHODS = {"zhu17": pb.METHOD_ZHU17, "alexa": pb.METHOD_ALEXA, "linear": pb.METHOD_LINEAR}
TIMINGS = {"linear": pb.TIMING_CURVE_LINEAR, "catmull-rom": pb.TIMING_CURVE_CATMULL_ROM,
           "ease-in-out": pb.TIMING_CURVE_EASE_IN_OUT}
ELEMENT_KINDS = {"outline": pb.ELEMENT_KIND_OUTLINE, "cut": pb.ELEMENT_KIND_CUT,
                 "opening": pb.ELEMENT_KIND_OPENING}
CORNER_MATCHINGS = {"when-arc-length-fails": pb.CORNER_MATCHING_WHEN_ARC_LENGTH_FAILS,
                    "never": pb.CORNER_MATCHING_NEVER, "always": pb.CORNER_MATCHING_ALWAYS}
BOUNDARY_ALIGNMENTS = {"features": pb.BOUNDARY_ALIGNMENT_FEATURES,
                       "arc-length": pb.BOUNDARY_ALIGNMENT_ARC_LENGTH}


def _enum(value: EnumLike, names: Mapping[str, int], what: str) -> int:
    if isinstance(value, str):
        key = value.lower().replace("_", "-")
        if key not in names:
            raise ValueError(f"{what}: {value!r} is none of {', '.join(names)}")
        return names[key]
    return int(value)


def point(p: PointLike) -> "pb.Point":
    if isinstance(p, pb.Point):
        return p
    x, y = p
    return pb.Point(x=float(x), y=float(y))


def polyline(points: PointsLike) -> "pb.Polyline":
    if isinstance(points, pb.Polyline):
        return points
    return pb.Polyline(points=[point(p) for p in points])


def topology_element(kind: EnumLike, points: PointsLike, element_id: int = 0
                     ) -> "pb.TopologyElement":
    """An outline, cut or opening (kind "outline" / "cut" / "opening" or an ElementKind);
    ``element_id`` 0 = a new element."""
    return pb.TopologyElement(id=element_id, kind=_enum(kind, ELEMENT_KINDS, "kind"),
                              polyline=polyline(points))


def stiffness_region(polygon: PointsLike, kappa: float) -> "pb.StiffnessRegion":
    """Triangles whose centroid in drawing 1 lies inside ``polygon`` get stiffness ``kappa``."""
    return pb.StiffnessRegion(polygon=polyline(polygon), kappa=kappa)


def inbetween_parameters(
        base: Optional["pb.InbetweenParameters"] = None, *,
        frames: Optional[int] = None,
        method: Optional[EnumLike] = None,
        timing: Optional[EnumLike] = None,
        ease: Optional[Iterable[float]] = None,
        stiffness: Optional[Iterable[Union["pb.StiffnessRegion",
                                           Tuple[PointsLike, float]]]] = None,
        lambda_: Optional[float] = None,
        tau: Optional[float] = None,
        alpha: Optional[float] = None,
        epsilon: Optional[float] = None,
        rho: Optional[float] = None,
        timestep: Optional[float] = None,
        max_iterations: Optional[int] = None,
        key_times: Optional[Iterable[float]] = None) -> "pb.InbetweenParameters":
    """InbetweenParameters (proto: ranges and defaults): ``base`` (copied) with every argument
    that is not None set over it. ``method``: "zhu17" | "alexa" | "linear"; ``timing``: "linear" |
    "catmull-rom" | "ease-in-out"; ``ease``: one per segment between keys; ``stiffness``:
    StiffnessRegion or (polygon, kappa) pairs; ``lambda_`` is the proto's ``lambda``."""
    out = pb.InbetweenParameters()
    if base is not None:
        out.CopyFrom(base)
    if frames is not None:
        out.frames = frames
    if method is not None:
        out.method = _enum(method, METHODS, "method")
    if timing is not None:
        out.timing = _enum(timing, TIMINGS, "timing")
    if ease is not None:
        del out.ease[:]
        out.ease.extend(float(e) for e in ease)
    if stiffness is not None:
        del out.stiffness[:]
        for region in stiffness:
            out.stiffness.append(region if isinstance(region, pb.StiffnessRegion)
                                 else stiffness_region(region[0], region[1]))
    # `lambda` is a Python keyword: set it by name.
    for name, value in (("lambda", lambda_), ("tau", tau), ("alpha", alpha),
                        ("epsilon", epsilon), ("rho", rho), ("timestep", timestep),
                        ("max_iterations", max_iterations)):
        if value is not None:
            setattr(out, name, value)
    if key_times is not None:
        del out.key_times[:]
        out.key_times.extend(float(t) for t in key_times)
    return out


def meshing_parameters(
        base: Optional["pb.MeshingParameters"] = None, *,
        boundary_vertices: Optional[int] = None,
        max_edge_relative: Optional[float] = None,
        shape_bound: Optional[float] = None,
        corner_matching: Optional[EnumLike] = None,
        boundary_tolerance: Optional[float] = None,
        boundary_alignment: Optional[EnumLike] = None) -> "pb.MeshingParameters":
    """MeshingParameters: ``base`` with every argument that is not None set over it.
    ``corner_matching``: "when-arc-length-fails" | "never" | "always"; ``boundary_alignment``:
    "features" | "arc-length"."""
    out = pb.MeshingParameters()
    if base is not None:
        out.CopyFrom(base)
    for name, value in (("boundary_vertices", boundary_vertices),
                        ("max_edge_relative", max_edge_relative), ("shape_bound", shape_bound),
                        ("boundary_tolerance", boundary_tolerance)):
        if value is not None:
            setattr(out, name, value)
    if corner_matching is not None:
        out.corner_matching = _enum(corner_matching, CORNER_MATCHINGS, "corner_matching")
    if boundary_alignment is not None:
        out.boundary_alignment = _enum(boundary_alignment, BOUNDARY_ALIGNMENTS,
                                       "boundary_alignment")
    return out


def comesh_parameters(
        base: Optional["pb.ComeshParameters"] = None, *,
        map_weight: Optional[float] = None,
        max_outer_iterations: Optional[int] = None,
        max_inner_iterations: Optional[int] = None,
        tolerance: Optional[float] = None,
        outer_tolerance: Optional[float] = None,
        outline_corner_degrees: Optional[float] = None,
        min_quality: Optional[float] = None,
        slide_window: Optional[float] = None) -> "pb.ComeshParameters":
    """ComeshParameters: ``base`` with every argument that is not None set over it."""
    out = pb.ComeshParameters()
    if base is not None:
        out.CopyFrom(base)
    for name, value in (("map_weight", map_weight), ("max_outer_iterations", max_outer_iterations),
                        ("max_inner_iterations", max_inner_iterations), ("tolerance", tolerance),
                        ("outer_tolerance", outer_tolerance),
                        ("outline_corner_degrees", outline_corner_degrees),
                        ("min_quality", min_quality), ("slide_window", slide_window)):
        if value is not None:
            setattr(out, name, value)
    return out


def parameters(meshing: Optional["pb.MeshingParameters"] = None,
               comesh: Optional["pb.ComeshParameters"] = None,
               inbetween: Optional["pb.InbetweenParameters"] = None) -> "pb.Parameters":
    """A session's Parameters (CreateSession), from the three groups."""
    out = pb.Parameters()
    if meshing is not None:
        out.meshing.CopyFrom(meshing)
    if comesh is not None:
        out.comesh.CopyFrom(comesh)
    if inbetween is not None:
        out.inbetween.CopyFrom(inbetween)
    return out


def polyline_drawing(outlines: Iterable[PointsLike], *,
                     cuts: Iterable[PointsLike] = (),
                     openings: Iterable[PointsLike] = (),
                     marks: Union[Mapping[int, PointLike],
                                  Iterable[Tuple[int, PointLike]]] = (),
                     name: str = "", key_time: Optional[float] = None,
                     drawing_id: int = 0) -> "pb.Drawing":
    """A Drawing given by explicit polylines: closed outlines (positive signed area = inside,
    negative = a hole), cuts and openings (open polylines), and correspondence marks as
    {mark id: (x, y)} or (id, (x, y)) pairs."""
    elements = [topology_element("outline", o) for o in outlines]
    elements += [topology_element("cut", c) for c in cuts]
    elements += [topology_element("opening", o) for o in openings]
    drawing = pb.Drawing(id=drawing_id, name=name,
                         polylines=pb.DrawingPolylines(elements=elements))
    items = marks.items() if isinstance(marks, Mapping) else marks
    for mark_id, p in items:
        drawing.marks.add(id=mark_id, point=point(p))
    if key_time is not None:
        drawing.key_time = key_time
    return drawing
