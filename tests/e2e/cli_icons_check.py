#!/usr/bin/env python3
"""Checks the multimeshes `inbetween mesh` built from third-party icons (cli_icons_test.sh).

Usage: cli_icons_check.py MANIFEST
MANIFEST: one line per meshed icon, "NAME<TAB>MULTIMESH_JSON<TAB>SVG_1<TAB>SVG_2...": the mesh and
the drawings it was built from. Each one is checked against the SVGs read by this file's own
reader (independent of the C++ import: every path command, arcs, circle/rect/ellipse/polygon,
transforms, fill, fill-rule):

- structure: the documented keys, one vertex array per drawing, all of the same length, indices
  in range, no cohesive edge (the icons have no cuts);
- in every shape every triangle is positive, its height above 1e-6 of its longest edge;
- the triangles form one consistently oriented planar domain: every directed edge once, boundary
  edges closing into simple loops (no pinch vertex), Euler characteristic = components - holes,
  every vertex in a triangle, "boundary" = the boundary vertices;
- in every shape no two boundary segments cross (with the orientation: an embedding);
- the boundary matches the drawing: as many loops and components as the SVG has outlines and
  outer outlines under docs/svg-convention.md (fill-rule per element, even-odd nesting across
  elements, subpaths of no area dropped); every boundary corner (a vertex where the boundary
  turns; the mesher's Steiner points lie on chords between them) within 0.06 of the SVG outline
  (import tolerance 0.05 + this reader's flattening), each loop along one outline, loops and
  outlines one to one; the mesh region and the SVG's differ by at most 50% of its area in
  symmetric difference (1024 scanlines; the coarse default boundary resampling cuts chords into
  round ends, typically a few percent).

Prints one line per icon ("ok NAME: ..." with its numbers, or "FAIL NAME: reason") and a summary;
exits 1 when any icon fails. Also counts icons whose painted area under SVG's own rendering (the
union of elements) differs by more than 1% from the convention's even-odd nesting of elements.
"""
import json
import math
import re
import sys
import xml.etree.ElementTree as ET

SVG_NS = "{http://www.w3.org/2000/svg}"
FLATTEN_TOL = 0.005
IMPORT_TOL = 0.05
MIN_HEIGHT = 1e-6  # a triangle's height over its longest edge, at least
MAX_AREA_OFF = 0.5
ROWS = 1024


class CheckError(Exception):
    pass


# ---------------------------------------------------------------------------- SVG reading

def mat_mul(a, b):
    """Affine matrices as (a, b, c, d, e, f): x' = a x + c y + e, y' = b x + d y + f."""
    return (a[0] * b[0] + a[2] * b[1], a[1] * b[0] + a[3] * b[1],
            a[0] * b[2] + a[2] * b[3], a[1] * b[2] + a[3] * b[3],
            a[0] * b[4] + a[2] * b[5] + a[4], a[1] * b[4] + a[3] * b[5] + a[5])


IDENTITY = (1.0, 0.0, 0.0, 1.0, 0.0, 0.0)
NUM_RE = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def parse_transform(text):
    m = IDENTITY
    for name, args in re.findall(r"(\w+)\s*\(([^)]*)\)", text or ""):
        v = [float(x) for x in NUM_RE.findall(args)]
        if name == "matrix":
            t = tuple(v)
        elif name == "translate":
            t = (1, 0, 0, 1, v[0], v[1] if len(v) > 1 else 0)
        elif name == "scale":
            t = (v[0], 0, 0, v[1] if len(v) > 1 else v[0], 0, 0)
        elif name == "rotate":
            a = math.radians(v[0])
            t = (math.cos(a), math.sin(a), -math.sin(a), math.cos(a), 0, 0)
            if len(v) == 3:
                t = mat_mul(mat_mul((1, 0, 0, 1, v[1], v[2]), t), (1, 0, 0, 1, -v[1], -v[2]))
        elif name == "skewX":
            t = (1, 0, math.tan(math.radians(v[0])), 1, 0, 0)
        elif name == "skewY":
            t = (1, math.tan(math.radians(v[0])), 0, 1, 0, 0)
        else:
            raise CheckError(f"transform {name} not understood by the checker")
        m = mat_mul(m, t)
    return m


def apply(m, p):
    return (m[0] * p[0] + m[2] * p[1] + m[4], m[1] * p[0] + m[3] * p[1] + m[5])


def cubic(p0, p1, p2, p3, out):
    dd = max(math.hypot(p0[0] - 2 * p1[0] + p2[0], p0[1] - 2 * p1[1] + p2[1]),
             math.hypot(p1[0] - 2 * p2[0] + p3[0], p1[1] - 2 * p2[1] + p3[1]))
    n = max(1, math.ceil(math.sqrt(0.75 * dd / FLATTEN_TOL)))
    for i in range(1, n + 1):
        t = i / n
        u = 1 - t
        out.append((u * u * u * p0[0] + 3 * u * u * t * p1[0] + 3 * u * t * t * p2[0] + t * t * t * p3[0],
                    u * u * u * p0[1] + 3 * u * u * t * p1[1] + 3 * u * t * t * p2[1] + t * t * t * p3[1]))


def arc(p1, rx, ry, phi_deg, large, sweep, p2, out):
    """SVG 1.1 F.6.5 endpoint to centre parameterisation, sampled within FLATTEN_TOL."""
    if p1 == p2:
        return
    rx, ry = abs(rx), abs(ry)
    if rx == 0 or ry == 0:
        out.append(p2)
        return
    phi = math.radians(phi_deg)
    c, s = math.cos(phi), math.sin(phi)
    hx, hy = (p1[0] - p2[0]) / 2, (p1[1] - p2[1]) / 2
    x1, y1 = c * hx + s * hy, -s * hx + c * hy
    lam = x1 * x1 / (rx * rx) + y1 * y1 / (ry * ry)
    if lam > 1:
        rx, ry = rx * math.sqrt(lam), ry * math.sqrt(lam)
    num = rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1
    den = rx * rx * y1 * y1 + ry * ry * x1 * x1
    coef = math.sqrt(max(0.0, num / den)) if den > 0 else 0.0
    if large == sweep:
        coef = -coef
    cx1, cy1 = coef * rx * y1 / ry, -coef * ry * x1 / rx
    cx = c * cx1 - s * cy1 + (p1[0] + p2[0]) / 2
    cy = s * cx1 + c * cy1 + (p1[1] + p2[1]) / 2
    th1 = math.atan2((y1 - cy1) / ry, (x1 - cx1) / rx)
    th2 = math.atan2((-y1 - cy1) / ry, (-x1 - cx1) / rx)
    dth = th2 - th1
    if not sweep and dth > 0:
        dth -= 2 * math.pi
    if sweep and dth < 0:
        dth += 2 * math.pi
    r = max(rx, ry)
    step = 2 * math.acos(max(-1.0, 1 - FLATTEN_TOL / r)) if r > FLATTEN_TOL else math.pi / 2
    n = max(1, math.ceil(abs(dth) / step))
    for i in range(1, n + 1):
        t = th1 + dth * i / n
        ex, ey = rx * math.cos(t), ry * math.sin(t)
        out.append(p2 if i == n else (c * ex - s * ey + cx, s * ex + c * ey + cy))


def parse_path(d):
    """Path data -> list of (points, closed) subpaths, curves flattened."""
    s, i, n = d, 0, len(d)
    subpaths = []
    cur = None
    pen = start = (0.0, 0.0)
    last_ctrl = None  # (kind, point) for S/T reflection
    cmd = None

    def skip(i):
        while i < n and (s[i].isspace() or s[i] == ","):
            i += 1
        return i

    def number(i):
        i = skip(i)
        m = NUM_RE.match(s, i)
        if not m:
            raise CheckError(f"path data: number expected at {i}: {s[i:i + 20]!r}")
        return float(m.group()), m.end()

    def flag(i):
        i = skip(i)
        if i >= n or s[i] not in "01":
            raise CheckError(f"path data: arc flag expected at {i}")
        return s[i] == "1", i + 1

    def begin(p):
        nonlocal cur
        cur = [p]
        subpaths.append([cur, False])

    # Both read the loop's current ox, oy, pen and last_ctrl when called.
    def point(i):
        x, i = number(i)
        y, i = number(i)
        return (ox + x, oy + y), i

    def reflected(kind):
        # S and T: the previous control point of the same kind mirrored about the pen, else the
        # pen itself.
        if last_ctrl and last_ctrl[0] == kind:
            return (2 * pen[0] - last_ctrl[1][0], 2 * pen[1] - last_ctrl[1][1])
        return pen

    while True:
        i = skip(i)
        if i >= n:
            break
        if s[i].isalpha():
            cmd = s[i]
            i += 1
            if cmd in "Zz":
                if cur is not None:
                    subpaths[-1][1] = True
                pen = start
                cur = None
                last_ctrl = None
                continue
        elif cmd is None or cmd in "Zz":
            raise CheckError(f"path data: command expected at {i}")
        rel = cmd.islower()
        C = cmd.upper()
        ox, oy = pen if rel else (0.0, 0.0)
        if C == "M":
            pen, i = point(i)
            start = pen
            begin(pen)
            cmd = "l" if rel else "L"
            last_ctrl = None
            continue
        if cur is None:
            begin(pen)
            start = pen

        if C == "L":
            pen, i = point(i)
            cur.append(pen)
            last_ctrl = None
        elif C == "H":
            x, i = number(i)
            pen = (ox + x if rel else x, pen[1])
            cur.append(pen)
            last_ctrl = None
        elif C == "V":
            y, i = number(i)
            pen = (pen[0], oy + y if rel else y)
            cur.append(pen)
            last_ctrl = None
        elif C in "CS":
            if C == "C":
                c1, i = point(i)
            else:
                c1 = reflected("C")
            c2, i = point(i)
            p, i = point(i)
            cubic(pen, c1, c2, p, cur)
            pen, last_ctrl = p, ("C", c2)
        elif C in "QT":
            if C == "Q":
                q, i = point(i)
            else:
                q = reflected("Q")
            p, i = point(i)
            c1 = (pen[0] + 2 / 3 * (q[0] - pen[0]), pen[1] + 2 / 3 * (q[1] - pen[1]))
            c2 = (p[0] + 2 / 3 * (q[0] - p[0]), p[1] + 2 / 3 * (q[1] - p[1]))
            cubic(pen, c1, c2, p, cur)
            pen, last_ctrl = p, ("Q", q)
        elif C == "A":
            rx, i = number(i)
            ry, i = number(i)
            rot, i = number(i)
            large, i = flag(i)
            sweep, i = flag(i)
            p, i = point(i)
            arc(pen, rx, ry, rot, large, sweep, p, cur)
            pen, last_ctrl = p, None
        else:
            raise CheckError(f"path command {cmd} not understood by the checker")
    return [(pts, closed) for pts, closed in subpaths]


def ellipse_path(cx, cy, rx, ry):
    return (f"M{cx + rx} {cy}A{rx} {ry} 0 0 1 {cx} {cy + ry}A{rx} {ry} 0 0 1 {cx - rx} {cy}"
            f"A{rx} {ry} 0 0 1 {cx} {cy - ry}A{rx} {ry} 0 0 1 {cx + rx} {cy}Z")


def rect_path(x, y, w, h, rx, ry):
    if rx is None and ry is None:
        rx = ry = 0.0
    rx = ry if rx is None else rx
    ry = rx if ry is None else ry
    rx, ry = min(rx, w / 2), min(ry, h / 2)
    if rx <= 0 or ry <= 0:
        return f"M{x} {y}H{x + w}V{y + h}H{x}Z"
    return (f"M{x + rx} {y}H{x + w - rx}A{rx} {ry} 0 0 1 {x + w} {y + ry}V{y + h - ry}"
            f"A{rx} {ry} 0 0 1 {x + w - rx} {y + h}H{x + rx}A{rx} {ry} 0 0 1 {x} {y + h - ry}"
            f"V{y + ry}A{rx} {ry} 0 0 1 {x + rx} {y}Z")


def style_of(el):
    out = {}
    for item in (el.get("style") or "").split(";"):
        if ":" in item:
            k, v = item.split(":", 1)
            out[k.strip()] = v.strip()
    return out


def signed_area(pts):
    a = 0.0
    for k in range(len(pts)):
        x0, y0 = pts[k - 1]
        x1, y1 = pts[k]
        a += x0 * y1 - x1 * y0
    return a / 2


def contains(pts, q):
    inside = False
    x, y = q
    for k in range(len(pts)):
        x0, y0 = pts[k - 1]
        x1, y1 = pts[k]
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def read_svg(path):
    """Filled elements of an SVG file: list of (polygons, evenodd), in document coordinates."""
    root = ET.parse(path).getroot()
    elements = []

    def walk(el, ctm, fill, evenodd):
        tag = el.tag.replace(SVG_NS, "")
        st = style_of(el)
        fill = st.get("fill", el.get("fill", fill))
        rule = st.get("fill-rule", el.get("fill-rule"))
        if rule in ("evenodd", "nonzero"):
            evenodd = rule == "evenodd"
        ctm = mat_mul(ctm, parse_transform(el.get("transform")))
        if tag in ("svg", "g"):
            for child in el:
                walk(child, ctm, fill, evenodd)
            return
        g = lambda k, dflt=0.0: float(el.get(k, dflt))
        if tag == "path":
            d = el.get("d", "")
        elif tag == "circle":
            d = ellipse_path(g("cx"), g("cy"), g("r"), g("r"))
        elif tag == "ellipse":
            d = ellipse_path(g("cx"), g("cy"), g("rx"), g("ry"))
        elif tag == "rect":
            rx = float(el.get("rx")) if el.get("rx") is not None else None
            ry = float(el.get("ry")) if el.get("ry") is not None else None
            d = rect_path(g("x"), g("y"), g("width"), g("height"), rx, ry)
        elif tag in ("polygon", "polyline"):
            v = NUM_RE.findall(el.get("points", ""))
            d = "M" + " ".join(v) + "Z"
        else:
            return  # title, desc, defs, ...: not drawn (no <use> in the corpus)
        if fill == "none" or el.get("class", "").split() in (["cut"], ["opening"]):
            return
        polys = []
        for pts, _closed in parse_path(d):
            pts = [apply(ctm, p) for p in pts]
            clean = []
            for p in pts:
                if not clean or p != clean[-1]:
                    clean.append(p)
            while len(clean) > 1 and clean[-1] == clean[0]:
                clean.pop()
            if len(clean) >= 3:
                xs, ys = [p[0] for p in clean], [p[1] for p in clean]
                box2 = (max(xs) - min(xs)) ** 2 + (max(ys) - min(ys)) ** 2
                if abs(signed_area(clean)) > 1e-9 * box2:  # not zero up to rounding
                    polys.append(clean)
        if polys:
            elements.append((polys, evenodd))

    walk(root, IDENTITY, "black", False)
    return elements


def boundary_distance(pts, q):
    return min(point_segment_distance(q, pts[k - 1], pts[k]) for k in range(len(pts)))


def inside(p, q):
    """Whether outline p lies inside outline q (they do not cross): tested at the midpoint of one
    of p's first edges that is not on q (outlines may touch, sharing vertices or edges)."""
    probe = None
    for k in range(min(len(p), 16)):
        m = ((p[k - 1][0] + p[k][0]) / 2, (p[k - 1][1] + p[k][1]) / 2)
        if boundary_distance(q, m) > 1e-7:
            probe = m
            break
    return contains(q, probe if probe is not None else p[0])


def expected_outlines(elements):
    """The outlines docs/svg-convention.md keeps, and for each whether it is an outer one."""
    kept = []
    for polys, evenodd in elements:
        if evenodd or len(polys) < 2:
            kept.extend(polys)
            continue
        sign = [1 if signed_area(p) > 0 else -1 for p in polys]
        for i, p in enumerate(polys):
            w = sign[i] + sum(sign[j] for j, q in enumerate(polys) if j != i and inside(p, q))
            if (w != 0) != (w - sign[i] != 0):
                kept.append(p)
    outer = [sum(1 for j, q in enumerate(kept) if j != i and inside(p, q)) % 2 == 0
             for i, p in enumerate(kept)]
    return kept, outer


def match_loops(candidates, n_outlines):
    """A perfect matching of mesh loops to SVG outlines (candidates[l]: outlines loop l may be),
    or None."""
    owner = [-1] * n_outlines

    def augment(l, seen):
        for o in candidates[l]:
            if o in seen:
                continue
            seen.add(o)
            if owner[o] < 0 or augment(owner[o], seen):
                owner[o] = l
                return True
        return False
    for l in range(len(candidates)):
        if not augment(l, set()):
            return None
    return owner


# ---------------------------------------------------------------------------- scanlines

def row_intervals(polys, evenodd, y0, h, rows):
    """Per scanline row, the filled x intervals of one element under its fill rule."""
    cross = [[] for _ in range(rows)]
    for pts in polys:
        for k in range(len(pts)):
            (xa, ya), (xb, yb) = pts[k - 1], pts[k]
            if ya == yb:
                continue
            lo, hi = (ya, yb) if ya < yb else (yb, ya)
            r0 = max(0, math.ceil((lo - y0) / h - 0.5))
            r1 = min(rows - 1, math.ceil((hi - y0) / h - 0.5) - 1)
            d = 1 if yb > ya else -1
            inv = (xb - xa) / (yb - ya)
            for r in range(r0, r1 + 1):
                y = y0 + (r + 0.5) * h
                cross[r].append((xa + (y - ya) * inv, d))
    out = []
    for c in cross:
        c.sort()
        iv, w = [], 0
        for x, d in c:
            before = (w % 2 != 0) if evenodd else (w != 0)
            w += d
            after = (w % 2 != 0) if evenodd else (w != 0)
            if after and not before:
                start = x
            elif before and not after:
                iv.append((start, x))
        out.append(iv)
    return out


def combine(rows_per_set, h, predicate):
    """Area where predicate(coverage counts per set) holds; sets are lists of per-element rows."""
    total = 0.0
    n_rows = len(rows_per_set[0][0]) if rows_per_set[0] else 0
    for r in range(n_rows):
        events = []
        for s, elements in enumerate(rows_per_set):
            for rows in elements:
                for a, b in rows[r]:
                    events.append((a, s, 1))
                    events.append((b, s, -1))
        if not events:
            continue
        events.sort()
        counts = [0] * len(rows_per_set)
        prev = events[0][0]
        for x, s, d in events:
            if predicate(counts):
                total += x - prev
            counts[s] += d
            prev = x
    return total * h


# ---------------------------------------------------------------------------- mesh checks

def orient(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def segments_cross(p1, p2, q1, q2):
    d1, d2 = orient(q1, q2, p1), orient(q1, q2, p2)
    d3, d4 = orient(p1, p2, q1), orient(p1, p2, q2)
    if ((d1 > 0 and d2 < 0) or (d1 < 0 and d2 > 0)) and ((d3 > 0 and d4 < 0) or (d3 < 0 and d4 > 0)):
        return True
    def on(a, b, p, d):
        return d == 0 and min(a[0], b[0]) <= p[0] <= max(a[0], b[0]) and \
            min(a[1], b[1]) <= p[1] <= max(a[1], b[1])
    return on(q1, q2, p1, d1) or on(q1, q2, p2, d2) or on(p1, p2, q1, d3) or on(p1, p2, q2, d4)


def grid_pairs(segs, cell):
    """Candidate pairs of segments whose bounding boxes share a grid cell."""
    buckets = {}
    for k, (a, b) in enumerate(segs):
        for gx in range(math.floor(min(a[0], b[0]) / cell), math.floor(max(a[0], b[0]) / cell) + 1):
            for gy in range(math.floor(min(a[1], b[1]) / cell), math.floor(max(a[1], b[1]) / cell) + 1):
                buckets.setdefault((gx, gy), []).append(k)
    seen = set()
    for ks in buckets.values():
        for x in range(len(ks)):
            for y in range(x + 1, len(ks)):
                pair = (ks[x], ks[y])
                if pair not in seen:
                    seen.add(pair)
                    yield pair


def point_segment_distance(p, a, b):
    dx, dy = b[0] - a[0], b[1] - a[1]
    L = dx * dx + dy * dy
    t = 0.0 if L == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / L))
    return math.hypot(a[0] + t * dx - p[0], a[1] + t * dy - p[1])


def scale_of(elements):
    """Size of the drawing: its bounding-box diagonal."""
    xs = [p[0] for polys, _ in elements for pts in polys for p in pts]
    ys = [p[1] for polys, _ in elements for pts in polys for p in pts]
    return min(xs), min(ys), max(xs), max(ys)


def check_icon(mm_path, svg_paths, notes):
    doc = json.load(open(mm_path))
    for key in ("triangles", "shapes", "cohesive_edges", "boundary"):
        if key not in doc:
            raise CheckError(f"missing key {key}")
    shapes, tris = doc["shapes"], doc["triangles"]
    if len(shapes) != len(svg_paths):
        raise CheckError(f"{len(shapes)} shapes for {len(svg_paths)} drawings")
    n = len(shapes[0]["vertices"])
    if any(len(s["vertices"]) != n for s in shapes):
        raise CheckError(f"vertex counts differ: {[len(s['vertices']) for s in shapes]}")
    if doc["cohesive_edges"]:
        raise CheckError(f"{len(doc['cohesive_edges'])} cohesive edges without any cut")
    if not tris:
        raise CheckError("no triangle")
    used = set()
    directed = {}
    for t, tri in enumerate(tris):
        if len(tri) != 3 or not all(isinstance(i, int) and 0 <= i < n for i in tri) or len(set(tri)) != 3:
            raise CheckError(f"triangle {t} {tri}: bad indices")
        used.update(tri)
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            if (a, b) in directed:
                raise CheckError(f"edge {a}-{b} in triangles {directed[(a, b)]} and {t} the same way")
            directed[(a, b)] = t
    if len(used) != n:
        raise CheckError(f"{n - len(used)} vertices in no triangle")
    # Topology: boundary edges are the directed edges without their reverse.
    bnext = {}
    for (a, b) in directed:
        if (b, a) not in directed:
            if a in bnext:
                raise CheckError(f"boundary pinches at vertex {a}")
            bnext[a] = b
    if sorted(bnext.values()) != sorted(bnext):
        raise CheckError("boundary edges do not close into loops")
    if set(doc["boundary"]) != set(bnext) or len(doc["boundary"]) != len(bnext):
        raise CheckError("\"boundary\" is not the set of boundary vertices")
    loops, seen = [], set()
    for v in bnext:
        if v in seen:
            continue
        loop = [v]
        seen.add(v)
        w = bnext[v]
        while w != v:
            loop.append(w)
            seen.add(w)
            w = bnext[w]
        loops.append(loop)
    parent = list(range(n))

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x
    for a, b, c in tris:
        parent[find(a)] = find(b)
        parent[find(b)] = find(c)
    components = len({find(v) for v in range(n)})
    edges = len({(min(a, b), max(a, b)) for a, b in directed})
    holes = len(loops) - components
    euler = n - edges + len(tris)
    if holes < 0 or euler != components - holes:
        raise CheckError(f"not a planar domain: V-E+F = {euler}, {components} components, "
                         f"{len(loops)} boundary loops")
    # Per shape: orientation, crossings, fidelity to its SVG.
    for d, (shape, svg) in enumerate(zip(shapes, svg_paths)):
        v = [tuple(p) for p in shape["vertices"]]
        if not all(math.isfinite(x) and math.isfinite(y) for x, y in v):
            raise CheckError(f"shape {d}: non-finite vertex")
        elements = read_svg(svg)
        x0, y0, x1, y1 = scale_of(elements)
        diag = math.hypot(x1 - x0, y1 - y0)
        for t, (a, b, c) in enumerate(tris):
            area2 = orient(v[a], v[b], v[c])
            longest2 = max((v[a][0] - v[b][0]) ** 2 + (v[a][1] - v[b][1]) ** 2,
                           (v[b][0] - v[c][0]) ** 2 + (v[b][1] - v[c][1]) ** 2,
                           (v[c][0] - v[a][0]) ** 2 + (v[c][1] - v[a][1]) ** 2)
            if not area2 > MIN_HEIGHT * longest2:
                raise CheckError(f"shape {d}: triangle {t} {'inverted' if area2 <= 0 else 'degenerate'}"
                                 f" (doubled area {area2:.3g}, longest edge {math.sqrt(longest2):.3g})")
        segs = [(v[a], v[b]) for a, b in bnext.items()]
        ends = [(a, b) for a, b in bnext.items()]
        cell = max(diag / 64, 1e-9)
        for i, j in grid_pairs(segs, cell):
            if set(ends[i]) & set(ends[j]):
                continue
            if segments_cross(*segs[i], *segs[j]):
                raise CheckError(f"shape {d}: boundary segments {ends[i]} and {ends[j]} cross")
        kept, outer = expected_outlines(elements)
        if (len(loops), components) != (len(kept), sum(outer)):
            raise CheckError(f"shape {d}: {len(loops)} loops / {components} components, the SVG has "
                             f"{len(kept)} outlines / {sum(outer)} outer ones")
        # Every corner of the boundary (a vertex where it turns: the resampled outline points;
        # the mesher's Steiner points lie on the chords between them) within the import
        # tolerance of the SVG outline, each loop along one outline, loops and outlines one to one.
        tol = IMPORT_TOL + 2 * FLATTEN_TOL
        cell = max(tol, diag / 128)
        buckets = {}
        for o, pts in enumerate(kept):
            for k in range(len(pts)):
                a, b = pts[k - 1], pts[k]
                for gx in range(math.floor((min(a[0], b[0]) - tol) / cell),
                                math.floor((max(a[0], b[0]) + tol) / cell) + 1):
                    for gy in range(math.floor((min(a[1], b[1]) - tol) / cell),
                                    math.floor((max(a[1], b[1]) + tol) / cell) + 1):
                        buckets.setdefault((gx, gy), []).append((o, a, b))
        candidates, worst = [], 0.0
        for l, loop in enumerate(loops):
            near = None
            for k, vi in enumerate(loop):
                p, prev, nxt = v[vi], v[loop[k - 1]], v[loop[(k + 1) % len(loop)]]
                chord2 = (nxt[0] - prev[0]) ** 2 + (nxt[1] - prev[1]) ** 2
                if abs(orient(prev, p, nxt)) <= 1e-9 * chord2:
                    continue  # on the chord between its neighbours
                dist = {}
                for o, a, b in buckets.get((math.floor(p[0] / cell), math.floor(p[1] / cell)), []):
                    dist[o] = min(dist.get(o, math.inf), point_segment_distance(p, a, b))
                close = {o for o, x in dist.items() if x <= tol}
                if not close:
                    raise CheckError(f"shape {d}: boundary vertex {vi} at ({p[0]:.4g}, {p[1]:.4g}) is "
                                     f"{min(dist.values(), default=math.inf):.3g} from the SVG outline "
                                     f"(more than {tol:.3g})")
                worst = max(worst, min(dist[o] for o in close))
                near = close if near is None else near & close
                if not near:
                    raise CheckError(f"shape {d}: boundary loop {l} runs along more than one SVG outline"
                                     f" (at vertex {vi}, ({p[0]:.4g}, {p[1]:.4g}))")
            candidates.append(sorted(near or []))
        if match_loops(candidates, len(kept)) is None:
            raise CheckError(f"shape {d}: boundary loops do not match the SVG outlines one to one")
        # Area: mesh region vs the convention's region (even-odd nesting of the outlines, which
        # is the parity of covering elements when elements do not cross).
        h = (y1 - y0) / ROWS
        svg_rows = [row_intervals(polys, eo, y0, h, ROWS) for polys, eo in elements]
        mesh_rows = [row_intervals([[v[i] for i in loop] for loop in loops], True, y0, h, ROWS)]
        parity = combine([svg_rows], h, lambda c: c[0] % 2 == 1)
        union = combine([svg_rows], h, lambda c: c[0] > 0)
        mesh_area = sum(orient(v[a], v[b], v[c]) for a, b, c in tris) / 2
        symdiff = combine([svg_rows, mesh_rows], h, lambda c: (c[0] % 2 == 1) != (c[1] > 0))
        if symdiff > MAX_AREA_OFF * parity:
            raise CheckError(f"shape {d}: mesh and SVG regions differ by {100 * symdiff / parity:.1f}% "
                             f"of the area (mesh {mesh_area:.4g}, SVG {parity:.4g})")
        if abs(union - parity) > 0.01 * union:
            notes.add("differs from rendering")
        min_ratio = min(orient(v[a], v[b], v[c]) / max(
            (v[a][0] - v[b][0]) ** 2 + (v[a][1] - v[b][1]) ** 2,
            (v[b][0] - v[c][0]) ** 2 + (v[b][1] - v[c][1]) ** 2,
            (v[c][0] - v[a][0]) ** 2 + (v[c][1] - v[a][1]) ** 2) for a, b, c in tris)
        if d == 0:
            stats = [n, len(tris), len(loops), components, worst, symdiff / parity, min_ratio]
        else:
            stats[4] = max(stats[4], worst)
            stats[5] = max(stats[5], symdiff / parity)
            stats[6] = min(stats[6], min_ratio)
    return stats


def main():
    manifest = sys.argv[1]
    failures = 0
    count = 0
    differs = []
    for line in open(manifest):
        if not line.strip():
            continue
        name, mm, *svgs = line.rstrip("\n").split("\t")
        count += 1
        notes = set()
        try:
            n, t, loops, comps, worst, rel, amin = check_icon(mm, svgs, notes)
            extra = f" ({', '.join(sorted(notes))})" if notes else ""
            print(f"ok {name}: {n} vertices, {t} triangles, {loops} loops, {comps} components, "
                  f"corners within {worst:.3g} of the SVG, area off by {100 * rel:.1f}%, "
                  f"flattest triangle height {amin:.2g} x its longest edge{extra}")
            if notes:
                differs.append(name)
        except (CheckError, ValueError, KeyError, TypeError, ET.ParseError) as e:
            failures += 1
            print(f"FAIL {name}: {e}")
    print(f"cli_icons_check: {count - failures} ok, {failures} failed; "
          f"{len(differs)} where even-odd nesting of elements differs from SVG rendering"
          + (f": {' '.join(differs)}" if differs else ""))
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
