"""A frame's art: the drawings' layered paint, placed from an InbetweenHeader's art (every art
point as a triangle and barycentric coordinates) at an InbetweenFrame's vertices, combined by the
frame's example weights, and written as SVG. A port of the C++ rule with the same arithmetic and
tie-breaks, so that it draws what the CLI's SVG frames draw:

- placement: solver/art/art_embedding.h (PlacePath);
- resampling and blending of corresponding paths: solver/art/blend_paths.h;
- which layers morph and which cross-fade, paint blending, draw order: solver/art/frame_art.h
  (ArtForFrame), whose header states the rule; client/web/src/page/art.js is the same port;
- SVG: solver/art/art_svg.cpp (ArtToSvgPaths) inside client/render/svg_frames.cpp's frame.

Stdlib only. Messages are read by field name, so any InbetweenHeader / InbetweenFrame (or objects
shaped like them) will do.
"""

import math
from dataclasses import dataclass, field
from typing import Any, Callable, List, NamedTuple, Optional, Sequence, Tuple

XY = Tuple[float, float]
# An embedded art point: its triangle's vertices (a, b, c) and barycentric coordinates.
Corner = Tuple[int, int, int, float, float, float]
# A correspondence group's member: (key, layer index, normalized weight).
Member = Tuple[int, int, float]

# inbetween.v1 LineCap / LineJoin values (UNSPECIFIED and unknown values = butt / miter).
_CAPS = {2: "round", 3: "square"}
_JOINS = {2: "round", 3: "bevel"}


@dataclass
class FrameArtOptions:
    """solver/art/frame_art.h FrameArtOptions, with the same defaults."""

    match_by_name: bool = True  # layers with equal non-empty names correspond
    match_by_order: bool = True  # unnamed layers aligned in paint order correspond
    max_alignment_cells: float = 4e6  # above it, unnamed layers align index to index
    merge_fraction: float = 1e-9  # arc-length samples closer than this are one


@dataclass
class Fill:
    rgb: int  # 0xRRGGBB
    opacity: float
    even_odd: bool


@dataclass
class Stroke:
    rgb: int
    opacity: float
    width: float
    cap: str  # "butt" | "round" | "square"
    join: str  # "miter" | "round" | "bevel"
    miter_limit: float
    dashes: List[float]
    dash_offset: float


class Path(NamedTuple):
    """A placed path, as place_art's: ``(closed, [(x, y), ...])``."""

    closed: bool
    points: List[Tuple[float, float]]


@dataclass
class Layer:
    """One layer of a frame's art (solver/core/art.h ArtLayer): paint and placed paths."""

    id: str = ""
    name: str = ""
    opacity: float = 1.0
    fill: Optional[Fill] = None
    stroke: Optional[Stroke] = None
    paths: List[Path] = field(default_factory=list)


# ------------------------------------------------------------------------------------------
# The header's art

class _KeyLayer:
    """One embedded layer: paint (a Layer without paths) and paths as (closed, corners) with
    corners a list of (a, b, c, b0, b1, b2) per point."""

    __slots__ = ("paint", "paths")

    def __init__(self, paint: "Layer", paths: List[Tuple[bool, List[Corner]]]) -> None:
        self.paint = paint
        self.paths = paths


def _paint(p: Any) -> Layer:
    fill = stroke = None
    if p.HasField("fill"):
        fill = Fill(p.fill.rgb, p.fill.opacity, p.fill.even_odd)
    if p.HasField("stroke"):
        s = p.stroke
        stroke = Stroke(s.rgb, s.opacity, s.width, _CAPS.get(s.cap, "butt"),
                        _JOINS.get(s.join, "miter"), s.miter_limit, list(s.dashes), s.dash_offset)
    return Layer(p.id, p.name, p.opacity, fill, stroke)


def _copy_paint(paint: Layer) -> Layer:
    fill = Fill(**vars(paint.fill)) if paint.fill else None
    stroke = None
    if paint.stroke:
        stroke = Stroke(**vars(paint.stroke))
        stroke.dashes = list(stroke.dashes)
    return Layer(paint.id, paint.name, paint.opacity, fill, stroke)


def _keys_from_header(header: Any) -> List[List[_KeyLayer]]:
    """Per drawing (index = KeyArt.key) its layers, triangle indices resolved to vertices."""
    triangles = [(t.a, t.b, t.c) for t in header.triangles]
    count = max([k.key + 1 for k in header.art] + [len(header.keys)])
    keys = [[] for _ in range(count)]
    for k in header.art:
        layers = []
        for l, layer in enumerate(k.layers):
            paths = []
            for p, path in enumerate(layer.paths):
                where = f"art of drawing {k.key + 1}, layer {l + 1}, path {p + 1}"
                b = path.barycentric
                if len(b) != 3 * len(path.triangles):
                    raise ValueError(f"{where}: {len(b)} barycentric coordinates for "
                                     f"{len(path.triangles)} points")
                corners = []
                for i, t in enumerate(path.triangles):
                    if t >= len(triangles):
                        raise ValueError(f"{where}: triangle {t} of {len(triangles)}")
                    corners.append((*triangles[t], b[3 * i], b[3 * i + 1], b[3 * i + 2]))
                paths.append((path.closed, corners))
            layers.append(_KeyLayer(_paint(layer.paint), paths))
        keys[k.key] = layers
    return keys


# ------------------------------------------------------------------------------------------
# Placement (art_embedding.h)

def _place(corners: List[Corner], xy: Sequence[XY]) -> List[XY]:
    """b0 v[a] + b1 v[b] + b2 v[c] per point."""
    out = []
    for a, b, c, b0, b1, b2 in corners:
        (ax, ay), (bx, by), (cx, cy) = xy[a], xy[b], xy[c]
        out.append((b0 * ax + b1 * bx + b2 * cx, b0 * ay + b1 * by + b2 * cy))
    return out


def _check_vertices(keys: List[List[_KeyLayer]], xy: Sequence[XY]) -> None:
    for k, layers in enumerate(keys):
        for layer in layers:
            for _, corners in layer.paths:
                for point in corners:
                    if max(point[:3]) >= len(xy):
                        raise ValueError(f"frame art: drawing {k + 1}'s art uses vertex "
                                         f"{max(point[:3])}, the frame has {len(xy)}")


# ------------------------------------------------------------------------------------------
# Morph of corresponding paths (blend_paths.h)

def _norm(p: Tuple[float, float], q: Tuple[float, float]) -> float:
    dx, dy = q[0] - p[0], q[1] - p[1]
    return math.sqrt(dx * dx + dy * dy)  # as Eigen's norm (not math.hypot)


def _arc_length_parameters(path: List[XY], closed: bool) -> List[float]:
    n = len(path)
    params = [0.0] * n
    for i in range(1, n):
        params[i] = params[i - 1] + _norm(path[i - 1], path[i])
    total = 0.0 if n == 0 else params[n - 1] + (_norm(path[n - 1], path[0]) if closed else 0.0)
    if not total > 0.0:
        return [0.0] * n
    params = [p / total for p in params]
    if not closed:
        params[n - 1] = 1.0  # exactly, whatever the rounding of the sum
    return params


def _upper_bound(params: List[float], u: float) -> int:
    """std::upper_bound: the first index whose parameter is > u (len(params) if none)."""
    lo, hi = 0, len(params)
    while lo < hi:
        mid = (lo + hi) // 2
        if params[mid] > u:
            hi = mid
        else:
            lo = mid + 1
    return lo


def _point_at_parameter(path: List[XY], closed: bool, params: List[float], u: float) -> XY:
    n = len(path)
    if n == 1 or params[-1] == 0.0:
        return path[0]
    lo = _upper_bound(params, u)
    a = 0 if lo == 0 else lo - 1
    if a + 1 == n and not closed:
        return path[n - 1]
    b = (a + 1) % n
    end = 1.0 if a + 1 == n else params[b]
    span = end - params[a]
    t = min(max((u - params[a]) / span, 0.0), 1.0) if span > 0.0 else 0.0
    if t == 0.0:
        return path[a]
    (ax, ay), (bx, by) = path[a], path[b]
    return (ax + t * (bx - ax), ay + t * (by - ay))


def _blend_paths(paths: List[List[XY]], closed: bool, weights: List[float],
                 merge_fraction: float) -> List[XY]:
    if len(paths) == 1:
        return paths[0]
    params = [_arc_length_parameters(p, closed) for p in paths]
    total_weight = 0.0
    for w in weights:
        total_weight += w
    samples = []
    for u in sorted(u for ps in params for u in ps):
        if not samples or u - samples[-1] > merge_fraction:
            samples.append(u)
    if not closed:
        samples[-1] = 1.0  # the ends stay the ends
    out = []
    for u in samples:
        x = y = 0.0
        for path, ps, w in zip(paths, params, weights):
            px, py = _point_at_parameter(path, closed, ps, u)
            x += w * px
            y += w * py
        out.append((x / total_weight, y / total_weight))
    return out


_ALIGN_SAMPLES = 64


def _polygon_signed_area2(path: List[XY]) -> float:
    n = len(path)
    total = 0.0
    for i in range(n):
        (ax, ay), (bx, by) = path[i], path[(i + 1) % n]
        total += ax * by - ay * bx
    return total


def _uniform_samples(path: List[XY], params: List[float], shift: float) -> List[XY]:
    out = []
    for i in range(_ALIGN_SAMPLES):
        u = i / _ALIGN_SAMPLES + shift
        u -= math.floor(u)
        out.append(_point_at_parameter(path, True, params, u))
    return out


def _squared_distances(a: List[XY], b: List[XY]) -> float:
    total = 0.0
    for (ax, ay), (bx, by) in zip(a, b):
        dx, dy = ax - bx, ay - by
        total += dx * dx + dy * dy
    return total


def _restart_at(path: List[XY], params: List[float], u: float) -> List[XY]:
    n = len(path)
    a = _upper_bound(params, u) - 1
    start = _point_at_parameter(path, True, params, u)
    out = [start]
    for k in range(1, n + 1):
        p = path[(a + k) % n]
        if k == n and p == start:
            break  # the offset fell on vertex a
        if k == 1 and p == start:
            continue  # or on vertex a + 1
        out.append(p)
    return out


def _align_closed_path(reference: List[XY], path: List[XY]) -> List[XY]:
    """blend_paths.h AlignClosedPath: ``path`` restarted (and reversed when its direction
    differs) to run along ``reference``."""
    if len(reference) < 3 or len(path) < 3:
        return path
    p = list(path)
    if _polygon_signed_area2(reference) * _polygon_signed_area2(p) < 0.0:
        p = [p[0]] + p[:0:-1]  # the other direction, from the same first point
    ref_params = _arc_length_parameters(reference, True)
    params = _arc_length_parameters(p, True)
    if ref_params[-1] == 0.0 or params[-1] == 0.0:
        return p
    ref = _uniform_samples(reference, ref_params, 0.0)
    grid = _uniform_samples(p, params, 0.0)
    best, best_cost = 0, 0.0
    for k in range(_ALIGN_SAMPLES):
        cost = 0.0
        for i in range(_ALIGN_SAMPLES):
            (ax, ay), (bx, by) = ref[i], grid[(i + k) % _ALIGN_SAMPLES]
            dx, dy = ax - bx, ay - by
            cost += dx * dx + dy * dy
        if k == 0 or cost < best_cost:
            best, best_cost = k, cost

    def cost_at(shift: float) -> float:
        return _squared_distances(ref, _uniform_samples(p, params, shift))

    step = 1.0 / _ALIGN_SAMPLES
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    lo, hi = (best - 1) * step, (best + 1) * step
    x1, x2 = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
    f1, f2 = cost_at(x1), cost_at(x2)
    for _ in range(40):
        if f1 <= f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - ratio * (hi - lo)
            f1 = cost_at(x1)
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + ratio * (hi - lo)
            f2 = cost_at(x2)
    shift = x1 if f1 <= f2 else x2
    if min(f1, f2) >= cost_at(0.0):
        return p  # the drawn start is as good
    shift -= math.floor(shift)
    for v in params:
        if abs(v - shift) < 1e-9:
            shift = v
    if shift >= 1.0 - 1e-9 or shift == 0.0:
        return p
    return _restart_at(p, params, shift)


def _mean_squared_distance(a: List[XY], b: List[XY]) -> float:
    if len(a) < 3 or len(b) < 3:
        return math.inf
    pa, pb = _arc_length_parameters(a, True), _arc_length_parameters(b, True)
    if pa[-1] == 0.0 or pb[-1] == 0.0:
        return math.inf
    return _squared_distances(_uniform_samples(a, pa, 0.0),
                              _uniform_samples(b, pb, 0.0)) / _ALIGN_SAMPLES


def _path_length(path: List[XY]) -> float:
    length = 0.0
    n = len(path)
    for i in range(n):
        length += _norm(path[i], path[(i + 1) % n])
    return length


# ------------------------------------------------------------------------------------------
# Which layers correspond (frame_art.cpp). A group member is (key, layer, weight), the weight
# normalized over the active keys; a group has one member per active key, in key order.

def _same_kind(a: Layer, b: Layer) -> bool:
    return (a.fill is not None) == (b.fill is not None) and \
        (a.stroke is not None) == (b.stroke is not None)


def _all_closed_and_drawn(layer: _KeyLayer) -> bool:
    return bool(layer.paths) and all(closed and corners for closed, corners in layer.paths)


def _same_geometry(keys: List[List[_KeyLayer]], group: List[Member]) -> bool:
    if all(_all_closed_and_drawn(keys[key][l]) for key, l, _ in group):
        return True
    first = keys[group[0][0]][group[0][1]].paths
    for key, l, _ in group:
        paths = keys[key][l].paths
        if len(paths) != len(first):
            return False
        for (closed, corners), (first_closed, first_corners) in zip(paths, first):
            if closed != first_closed or (not corners) != (not first_corners):
                return False
    return True


def _compatible(a: _KeyLayer, b: _KeyLayer) -> bool:
    if not _same_kind(a.paint, b.paint):
        return False
    if _all_closed_and_drawn(a) and _all_closed_and_drawn(b):
        return True
    if len(a.paths) != len(b.paths):
        return False
    return all(p[0] == q[0] for p, q in zip(a.paths, b.paths))


def _centroid(layer: _KeyLayer, xy: Sequence[XY]) -> XY:
    sx = sy = 0.0
    count = 0
    for _, corners in layer.paths:
        for x, y in _place(corners, xy):
            sx += x
            sy += y
            count += 1
    return (sx / count, sy / count) if count else (sx, sy)


def _align_layers(a: List[_KeyLayer], b: List[_KeyLayer], xy: Sequence[XY],
                  named: Callable[[_KeyLayer], bool], max_cells: float) -> List[int]:
    """The paint-order alignment of b's unnamed layers to a's: an index into b per layer of a,
    or -1 (frame_art.cpp AlignLayers; ties: pair, then skip a, then skip b)."""
    n, m = len(a), len(b)
    match = [-1] * n

    def ok(i: int, j: int) -> bool:
        return not named(a[i]) and not named(b[j]) and _compatible(a[i], b[j])

    if n * m > max_cells:
        if n == m:
            match = [i if ok(i, i) else -1 for i in range(n)]
        return match
    if xy:
        min_x = min(x for x, _ in xy)
        min_y = min(y for _, y in xy)
        dx, dy = max(x for x, _ in xy) - min_x, max(y for _, y in xy) - min_y
        size = max(math.sqrt(dx * dx + dy * dy), 1e-300)
    else:
        size = 1e-300
    ca = [_centroid(layer, xy) for layer in a]
    cb = [_centroid(layer, xy) for layer in b]

    def score(i: int, j: int) -> float:
        if not ok(i, j):
            return 0.0
        p, q = a[i].paint, b[j].paint
        same = (not p.fill or p.fill.rgb == q.fill.rgb) and \
            (not p.stroke or p.stroke.rgb == q.stroke.rgb)
        ex, ey = ca[i][0] - cb[j][0], ca[i][1] - cb[j][1]
        return (2.0 if same else 1.0) + 1.0 / (1.0 + math.sqrt(ex * ex + ey * ey) / size)

    # best[i][j]: the best score aligning a[i:] with b[j:]; step 0 pair, 1 skip a[i], 2 skip b[j].
    best = [[0.0] * (m + 1) for _ in range(n + 1)]
    step = [[1] * (m + 1) for _ in range(n + 1)]
    for i in range(n - 1, -1, -1):
        for j in range(m - 1, -1, -1):
            s = score(i, j)
            value, choice = (s + best[i + 1][j + 1] if s > 0 else -1.0), 0
            if best[i + 1][j] > value:
                value, choice = best[i + 1][j], 1
            if best[i][j + 1] > value:
                value, choice = best[i][j + 1], 2
            best[i][j], step[i][j] = value, choice
    i = j = 0
    while i < n and j < m:
        s = step[i][j]
        if s == 0:
            match[i] = j
            i, j = i + 1, j + 1
        elif s == 1:
            i += 1
        else:
            j += 1
    return match


def _match_layers(keys: List[List[_KeyLayer]], active: List[Tuple[int, float]],
                  xy: Sequence[XY], options: FrameArtOptions) -> List[List[Member]]:
    """The morphing groups among ``active`` ((key, weight), keys ascending), ordered by their
    layer in the first active key (the backbone)."""
    groups = []

    def named(layer: _KeyLayer) -> bool:
        return options.match_by_name and layer.paint.name != ""

    if options.match_by_name:
        by_name = {}  # name -> occurrence -> group (dicts keep insertion order, as a JS Map)
        for key, weight in active:
            seen = {}
            for l, layer in enumerate(keys[key]):
                if not named(layer):
                    continue
                occurrence = seen.get(layer.paint.name, 0)
                seen[layer.paint.name] = occurrence + 1
                by_name.setdefault(layer.paint.name, {}).setdefault(occurrence, []).append(
                    (key, l, weight))
        for of_name in by_name.values():
            groups.extend(g for g in of_name.values() if len(g) == len(active))
    if options.match_by_order:
        first_key, first_weight = active[0]
        backbone = keys[first_key]
        by_layer = [[] if named(layer) else [(first_key, l, first_weight)]
                    for l, layer in enumerate(backbone)]
        for key, weight in active[1:]:
            match = _align_layers(backbone, keys[key], xy, named, options.max_alignment_cells)
            for l, j in enumerate(match):
                if j >= 0:
                    by_layer[l].append((key, j, weight))
        groups.extend(g for g in by_layer if len(g) == len(active))
    groups = [g for g in groups if _same_geometry(keys, g)]
    groups.sort(key=lambda g: g[0][1])  # stable: each backbone layer is in one group at most
    return groups


# ------------------------------------------------------------------------------------------
# Morph of a group's paint (frame_art.cpp Morph)

def _round_half_away(v: float) -> int:
    r = math.floor(v)
    return r + 1 if v - r >= 0.5 else r


def _blend_rgb(colours: List[Tuple[int, float]]) -> int:
    """Per 8-bit channel, the weighted mean over (rgb, weight) pairs, rounded."""
    total = 0.0
    for _, w in colours:
        total += w
    out = 0
    for shift in (16, 8, 0):
        v = 0.0
        for rgb, w in colours:
            v += w * ((rgb >> shift) & 0xFF)
        out |= min(max(_round_half_away(v / total), 0), 255) << shift
    return out


def _heaviest(group: List[Member], has: Callable[[Member], bool]) -> Optional[Member]:
    """The heaviest member for which ``has`` holds (ties: the lower key)."""
    best = None
    for m in group:
        if has(m) and (best is None or m[2] > best[2]):
            best = m
    return best


def _polygon_contains(polygon: List[XY], q: XY) -> bool:
    """polygon.h PolygonContains: even-odd crossing test."""
    inside = False
    n = len(polygon)
    j = n - 1
    for i in range(n):
        (ax, ay), (bx, by) = polygon[i], polygon[j]
        if (ay > q[1]) != (by > q[1]):
            x = ax + (q[1] - ay) * (bx - ax) / (by - ay)
            if q[0] < x:
                inside = not inside
        j = i
    return inside


_PAIR_DISTANCE = 0.02


def _morph_unequal_counts(paths_of: List[List[Tuple[bool, List[Corner]]]], xy: Sequence[XY],
                          weights: List[float], most: int,
                          merge_fraction: float) -> Optional[List[Path]]:
    """frame_art.cpp MorphUnequalCounts: closed paths in different counts pair nearest first; a
    member without a partner lends the fullest member's placement; None when a pair is far."""
    full = [_place(corners, xy) for _, corners in paths_of[most]]
    partner: List[List[Optional[List[XY]]]] = []
    for m, paths in enumerate(paths_of):
        row: List[Optional[List[XY]]] = [None] * len(full)
        partner.append(row)
        if m == most:
            for j in range(len(full)):
                row[j] = full[j]
            continue
        own = [_place(corners, xy) for _, corners in paths]
        pairs = []
        for i, path in enumerate(own):
            for j, target in enumerate(full):
                aligned = _align_closed_path(target, path)
                pairs.append((_mean_squared_distance(target, aligned), i, j, aligned))
        pairs.sort(key=lambda pair: pair[0])  # stable, as std::stable_sort
        used = [False] * len(own)
        for cost, i, j, aligned in pairs:
            if used[i] or row[j] is not None:
                continue
            length = _path_length(full[j])
            if not cost <= _PAIR_DISTANCE * _PAIR_DISTANCE * length * length:
                return None
            used[i] = True
            row[j] = aligned
        # A path this member lacks is carried only if it lies inside one it has (a hole).
        for j in range(len(full)):
            if row[j] is None and not any(
                    k != j and row[k] is not None and _polygon_contains(full[k], full[j][0])
                    for k in range(len(full))):
                return None
    out = []
    for j in range(len(full)):
        placed = [row[j] if row[j] is not None else full[j] for row in partner]
        out.append(Path(True, _blend_paths(placed, True, weights, merge_fraction)))
    return out


def _morph_layer(keys: List[List[_KeyLayer]], group: List[Member], xy: Sequence[XY],
                 options: FrameArtOptions) -> Optional[Layer]:
    """The group's morphed layer, or None when its closed paths come in different counts and
    do not pair up closely (then its layers cross-fade)."""
    def layer_of(m: Member) -> _KeyLayer:
        return keys[m[0]][m[1]]

    top = _heaviest(group, lambda m: True)
    out = _copy_paint(layer_of(top).paint)
    out.opacity = 0.0
    for m in group:
        out.opacity += m[2] * layer_of(m).paint.opacity
    out.fill = _morph_fill(group, layer_of)
    out.stroke = _morph_stroke(group, layer_of)
    weights = [m[2] for m in group]
    counts = [len(layer_of(m).paths) for m in group]
    most = 0
    for m, count in enumerate(counts):
        if count > counts[most]:
            most = m
    if any(count != counts[most] for count in counts):
        paths = _morph_unequal_counts([layer_of(m).paths for m in group], xy, weights, most,
                                      options.merge_fraction)
        if paths is None:
            return None
        out.paths = paths
        return out
    for j, (closed, _) in enumerate(layer_of(top).paths):
        placed = [_place(layer_of(m).paths[j][1], xy) for m in group]
        if closed and placed[0]:
            placed = [placed[0]] + [_align_closed_path(placed[0], p) for p in placed[1:]]
        points = _blend_paths(placed, closed, weights, options.merge_fraction) if placed[0] else []
        out.paths.append(Path(closed, points))
    return out


def _morph_fill(group: List[Member], layer_of: Callable[[Member], _KeyLayer]
                ) -> Optional[Fill]:
    """Colour blended among the members that fill, opacity among all (a member without a fill
    counts as opacity 0, so it fades in)."""
    top = _heaviest(group, lambda m: layer_of(m).paint.fill is not None)
    if top is None:
        return None
    fill = Fill(**vars(layer_of(top).paint.fill))
    colours = []
    fill.opacity = 0.0
    for m in group:
        f = layer_of(m).paint.fill
        if f is None:
            continue
        colours.append((f.rgb, m[2]))
        fill.opacity += m[2] * f.opacity
    fill.rgb = _blend_rgb(colours)
    return fill


def _morph_stroke(group: List[Member], layer_of: Callable[[Member], _KeyLayer]
                  ) -> Optional[Stroke]:
    def has(m: Member) -> bool:
        return layer_of(m).paint.stroke is not None

    top = _heaviest(group, has)
    if top is None:
        return None
    stroke = Stroke(**vars(layer_of(top).paint.stroke))
    stroke.dashes = list(stroke.dashes)
    dashes = len(stroke.dashes)
    same_dashes = True
    present = 0.0
    for m in group:
        if has(m):
            present += m[2]
            same_dashes = same_dashes and len(layer_of(m).paint.stroke.dashes) == dashes
    colours = []
    stroke.opacity = stroke.width = stroke.miter_limit = 0.0
    if same_dashes:
        stroke.dashes = [0.0] * dashes
        stroke.dash_offset = 0.0
    for m in group:
        if not has(m):
            continue
        s = layer_of(m).paint.stroke
        w = m[2] / present  # among the members that stroke
        colours.append((s.rgb, m[2]))
        stroke.opacity += m[2] * s.opacity
        stroke.width += w * s.width
        stroke.miter_limit += w * s.miter_limit
        if not same_dashes:
            continue
        for d in range(dashes):
            stroke.dashes[d] += w * s.dashes[d]
        stroke.dash_offset += w * s.dash_offset
    stroke.rgb = _blend_rgb(colours)
    return stroke


# ------------------------------------------------------------------------------------------
# The frame's art (ArtForFrame)

class FrameArt:
    """The header's art prepared once (triangles resolved), for the art of many frames."""

    def __init__(self, header: Any, options: Optional[FrameArtOptions] = None) -> None:
        self.options = options or FrameArtOptions()
        self._keys = _keys_from_header(header)

    def has_art(self) -> bool:
        """True when some drawing has a layer: the frames have art to draw."""
        return any(self._keys)

    def layers(self, frame: Any) -> List[Layer]:
        """The frame's layers in paint order (see frame_art)."""
        return _art_for_frame(self._keys, [(p.x, p.y) for p in frame.vertices],
                              list(frame.weights), self.options)

    def svg(self, frame: Any,
            bounds: Optional[Tuple[float, float, float, float]] = None) -> str:
        """The frame's art as an SVG document (see frame_art_svg)."""
        xy = [(p.x, p.y) for p in frame.vertices]
        if bounds is None:
            bounds = (min((x for x, _ in xy), default=0.0), min((y for _, y in xy), default=0.0),
                      max((x for x, _ in xy), default=0.0), max((y for _, y in xy), default=0.0))
        min_x, min_y, max_x, max_y = bounds
        margin = 0.05 * max(max_x - min_x, max_y - min_y)
        layers = _art_for_frame(self._keys, xy, list(frame.weights), self.options)
        return ('<svg xmlns="http://www.w3.org/2000/svg" viewBox="%s %s %s %s">\n'
                "<!-- inbetween frame %d, time %.6f -->\n%s</svg>\n") % (
                    _g6(min_x - margin), _g6(min_y - margin), _g6(max_x - min_x + 2 * margin),
                    _g6(max_y - min_y + 2 * margin), frame.index, frame.time, svg_paths(layers))


def _art_for_frame(keys: List[List[_KeyLayer]], xy: Sequence[XY], weights: List[float],
                   options: FrameArtOptions) -> List[Layer]:
    if len(weights) != len(keys):
        raise ValueError(f"frame art: {len(weights)} weights for the art of {len(keys)} keys")
    total = 0.0
    for k, w in enumerate(weights):
        if not math.isfinite(w):
            raise ValueError(f"frame art: weight {k + 1} is not finite")
        if w > 0:
            total += w
    _check_vertices(keys, xy)
    if not total > 0:
        raise ValueError("frame art: no key has a weight > 0")
    # w / total is exactly 1 for a key frame's only active key: its art comes out unchanged.
    active = [(k, w / total) for k, w in enumerate(weights) if w > 0]
    groups = _match_layers(keys, active, xy, options)
    group_of = {}
    for g, group in enumerate(groups):
        for key, l, _ in group:
            group_of[(key, l)] = g
    # slots[g + 1]: cross-faded layers drawn right after group g (slots[0]: before every group).
    slots = [[] for _ in range(len(groups) + 1)]
    for key, weight in active:
        last = -1
        for l, layer in enumerate(keys[key]):
            if (key, l) in group_of:
                last = group_of[(key, l)]
                continue
            slots[last + 1].append(_faded_layer(layer, weight, xy))
    out = slots[0]
    for g, group in enumerate(groups):
        morphed = _morph_layer(keys, group, xy, options)
        if morphed is not None:
            out.append(morphed)
        else:  # not morphable in this frame: its members cross-fade where the group stands
            out.extend(_faded_layer(keys[key][l], weight, xy) for key, l, weight in group)
        out.extend(slots[g + 1])
    return out


def _faded_layer(layer: _KeyLayer, weight: float, xy: Sequence[XY]) -> Layer:
    faded = _copy_paint(layer.paint)
    faded.opacity *= weight
    faded.paths = [Path(closed, _place(corners, xy)) for closed, corners in layer.paths]
    return faded


def frame_art(header: Any, frame: Any, options: Optional[FrameArtOptions] = None
              ) -> List[Layer]:
    """The art of ``frame`` (an InbetweenFrame) from ``header.art`` (its stream's
    InbetweenHeader, every art message appended, as Client.frames yields it): a list of Layer in
    paint order, each with its paint and placed paths (solver/art/frame_art.h ArtForFrame: at a
    key frame that drawing's art; in between, corresponding layers morph, the others cross-fade
    with opacity times their key's weight). Empty when the header has no art. Raises ValueError
    on weights that do not match the art, no weight > 0, or art outside the mesh."""
    art = FrameArt(header, options)
    return art.layers(frame) if art.has_art() else []


def frame_art_svg(header: Any, frame: Any,
                  bounds: Optional[Tuple[float, float, float, float]] = None,
                  options: Optional[FrameArtOptions] = None) -> str:
    """``frame``'s art as an SVG document, as the CLI's frame_NNNN.svg draws it
    (client/render/svg_frames.cpp): one <path> per drawn layer in paint order
    (svg_paths). The viewBox is ``bounds`` (min_x, min_y, max_x, max_y), default the frame's
    vertices' bounds, plus 5% of its larger side on every edge; the CLI uses the union over every
    frame."""
    return FrameArt(header, options).svg(frame, bounds)


# ------------------------------------------------------------------------------------------
# SVG (solver/art/art_svg.cpp)

def _g6(v: float) -> str:
    return "%.6g" % v


def _number(v: float) -> str:
    return "%.9g" % v


def _colour(rgb: int) -> str:
    return "#%06x" % (rgb & 0xFFFFFF)


def _escaped(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace(
        '"', "&quot;")


def svg_paths(layers: Sequence[Layer]) -> str:
    """``layers`` (frame_art) as SVG <path> elements, one line each (ArtToSvgPaths): a layer
    with neither fill nor stroke, or no points, is skipped; subpaths "M x y L x y ... Z";
    data-layer = its name; fill, stroke and opacity attributes, defaults left out; numbers with 9
    significant digits."""
    out = []
    for layer in layers:
        if layer.fill is None and layer.stroke is None:
            continue
        d = []
        for closed, points in layer.paths:
            for i, (x, y) in enumerate(points):
                d.append(("M" if i == 0 else "L") + _number(x) + " " + _number(y))
            if closed and points:
                d[-1] += "Z"
        if not d:
            continue
        attrs = ["<path"]
        if layer.name:
            attrs.append(f' data-layer="{_escaped(layer.name)}"')
        f = layer.fill
        if f is None:
            attrs.append(' fill="none"')
        else:
            attrs.append(f' fill="{_colour(f.rgb)}"')
            if f.opacity != 1.0:
                attrs.append(f' fill-opacity="{_number(f.opacity)}"')
            if f.even_odd:
                attrs.append(' fill-rule="evenodd"')
        s = layer.stroke
        if s is None:
            attrs.append(' stroke="none"')
        else:
            attrs.append(f' stroke="{_colour(s.rgb)}" stroke-width="{_number(s.width)}"')
            if s.opacity != 1.0:
                attrs.append(f' stroke-opacity="{_number(s.opacity)}"')
            if s.cap != "butt":
                attrs.append(f' stroke-linecap="{s.cap}"')
            if s.join != "miter":
                attrs.append(f' stroke-linejoin="{s.join}"')
            elif s.miter_limit != 4.0:
                attrs.append(f' stroke-miterlimit="{_number(s.miter_limit)}"')
            if s.dashes:
                attrs.append(' stroke-dasharray="%s"' % " ".join(_number(v) for v in s.dashes))
                if s.dash_offset != 0.0:
                    attrs.append(f' stroke-dashoffset="{_number(s.dash_offset)}"')
        if layer.opacity != 1.0:
            attrs.append(f' opacity="{_number(layer.opacity)}"')
        attrs.append(' d="%s"/>\n' % " ".join(d))
        out.append("".join(attrs))
    return "".join(out)
