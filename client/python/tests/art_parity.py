"""The Python client's frame art (inbetween/art.py) against the C++ rule itself: reads the
frames.json and frame_NNNN.svg files that `inbetween animate --format svg,json` wrote into DIR,
computes every frame's art with inbetween.frame_art from frames.json's "art", "triangles",
vertices and weights (as the InbetweenHeader / InbetweenFrame messages the stream sends), and
compares it with the <path> elements of that frame's SVG (solver/art/art_svg.cpp: one per drawn
layer, in paint order, 9 significant digits): the same layers in the same order, the same paint
(colours exact; opacities, widths, dashes within the SVG's rounding), the same subpaths with the
same point counts and closed flags, every coordinate within rounding. Then frame_art_svg with the
CLI's bounds (every frame's) against the file: the same header lines, and per <path> the same
attributes in the same order and the same commands, numbers within rounding. The same check as
client/web/e2e/art_parity.mjs.

    python3 art_parity.py DIR

Needs the inbetween package installed (tests/e2e/python_client_test.sh installs it in a venv).
Prints one line per frame; exits 1 on the first difference.
"""

import json
import os
import re
import sys

import inbetween
from inbetween.v1 import inbetween_pb2 as pb

CAPS = {"butt": pb.LINE_CAP_BUTT, "round": pb.LINE_CAP_ROUND, "square": pb.LINE_CAP_SQUARE}
JOINS = {"miter": pb.LINE_JOIN_MITER, "round": pb.LINE_JOIN_ROUND, "bevel": pb.LINE_JOIN_BEVEL}


def header_from_json(doc):
    """frames.json's triangles, keys and art (docs/file-formats.md) as an InbetweenHeader."""
    header = pb.InbetweenHeader(frames=len(doc["frames"]), keys=doc["keys"])
    for a, b, c in doc["triangles"]:
        header.triangles.add(a=a, b=b, c=c)
    for k in doc["art"]:
        key_art = header.art.add(key=k["key"])
        for l in k["layers"]:
            layer = key_art.layers.add()
            paint = layer.paint
            paint.id, paint.name, paint.opacity = l.get("id", ""), l.get("name", ""), l["opacity"]
            if l.get("fill"):
                f = l["fill"]
                paint.fill.CopyFrom(pb.FillPaint(rgb=int(f["color"][1:], 16), opacity=f["opacity"],
                                                 even_odd=f["rule"] == "evenodd"))
            if l.get("stroke"):
                s = l["stroke"]
                paint.stroke.CopyFrom(pb.StrokePaint(
                    rgb=int(s["color"][1:], 16), opacity=s["opacity"], width=s["width"],
                    cap=CAPS[s["cap"]], join=JOINS[s["join"]], miter_limit=s["miter_limit"],
                    dashes=s["dashes"], dash_offset=s["dash_offset"]))
            for p in l["paths"]:
                layer.paths.add(triangles=[q[0] for q in p["points"]],
                                barycentric=[b for q in p["points"] for b in q[1:]],
                                closed=p["closed"])
    return header


def frame_from_json(f):
    frame = pb.InbetweenFrame(index=f["index"], time=f["time"], weights=f["weights"])
    for x, y in f["vertices"]:
        frame.vertices.add(x=x, y=y)
    return frame


def svg_paths(svg):
    """The <path> elements: (attribute list, [(commands, [x, y, ...], closed)] per subpath)."""
    out = []
    for attrs in re.findall(r"<path ([^>]*)/>", svg):
        a = re.findall(r'([\w-]+)="([^"]*)"', attrs)
        subpaths = []
        for cmd, x, y, z in re.findall(r"([ML])(\S+) (\S+?)(Z?)(?= |$)", dict(a)["d"]):
            if cmd == "M":
                subpaths.append([[], False])
            subpaths[-1][0] += [float(x), float(y)]
            subpaths[-1][1] = subpaths[-1][1] or z == "Z"
        out.append((a, subpaths))
    return out


def close(actual, expected, what, scale=1.0):
    tol = 1e-8 * max(scale, abs(expected))
    if not abs(actual - expected) <= tol:
        raise AssertionError(f"{what}: art.py {expected}, C++ {actual}")


def equal(actual, expected, what):
    if actual != expected:
        raise AssertionError(f"{what}: art.py {expected!r}, C++ {actual!r}")


def check_layers(name, layers, drawn, extent):
    equal(len(drawn), len(layers), f"{name}: <path> count")
    for l, (layer, (attrs, subpaths)) in enumerate(zip(layers, drawn)):
        a = dict(attrs)
        where = f"{name} layer {l + 1}"

        def num(key, default):
            return float(a[key]) if key in a else default

        equal(a.get("data-layer", ""), layer.name, f"{where} name")
        equal(a["fill"], "#%06x" % layer.fill.rgb if layer.fill else "none", f"{where} fill")
        if layer.fill:
            close(num("fill-opacity", 1), layer.fill.opacity, f"{where} fill-opacity")
            equal(a.get("fill-rule") == "evenodd", layer.fill.even_odd, f"{where} fill-rule")
        equal(a["stroke"], "#%06x" % layer.stroke.rgb if layer.stroke else "none",
              f"{where} stroke")
        if layer.stroke:
            s = layer.stroke
            close(num("stroke-width", None), s.width, f"{where} stroke-width")
            close(num("stroke-opacity", 1), s.opacity, f"{where} stroke-opacity")
            equal(a.get("stroke-linecap", "butt"), s.cap, f"{where} stroke-linecap")
            equal(a.get("stroke-linejoin", "miter"), s.join, f"{where} stroke-linejoin")
            if s.join == "miter":
                close(num("stroke-miterlimit", 4), s.miter_limit, f"{where} stroke-miterlimit")
            dashes = [float(d) for d in a["stroke-dasharray"].split()] \
                if "stroke-dasharray" in a else []
            equal(len(dashes), len(s.dashes), f"{where} dash count")
            for i, d in enumerate(dashes):
                close(d, s.dashes[i], f"{where} dash {i + 1}")
            if s.dashes:
                close(num("stroke-dashoffset", 0), s.dash_offset, f"{where} stroke-dashoffset")
        close(num("opacity", 1), layer.opacity, f"{where} opacity")
        paths = [p for p in layer.paths if p.points]
        equal(len(subpaths), len(paths), f"{where} subpaths")
        for j, (path, (points, closed)) in enumerate(zip(paths, subpaths)):
            equal(closed, path.closed, f"{where} path {j + 1} closed")
            equal(len(points), 2 * len(path.points), f"{where} path {j + 1} coordinate count")
            mine = [c for p in path.points for c in p]
            for i, (v, w) in enumerate(zip(points, mine)):
                close(v, w, f"{where} path {j + 1} coordinate {i}", extent)


def check_svg(name, mine, theirs, extent):
    """frame_art_svg's text against the CLI's: header lines equal, paths alike within rounding."""
    equal(theirs.split("\n")[:2], mine.split("\n")[:2], f"{name}: svg header")
    ours, cli = svg_paths(mine), svg_paths(theirs)
    equal(len(cli), len(ours), f"{name}: frame_art_svg <path> count")
    for l, ((a, p), (b, q)) in enumerate(zip(ours, cli)):
        where = f"{name} frame_art_svg <path> {l + 1}"
        equal([k for k, _ in b], [k for k, _ in a], f"{where} attributes")
        for (key, v), (_, w) in zip(a, b):
            if key == "d":
                continue
            if re.fullmatch(r"[-+0-9.e ]+", v):
                for x, y in zip(w.split(), v.split()):
                    close(float(x), float(y), f"{where} {key}")
            else:
                equal(w, v, f"{where} {key}")
        equal([(len(s[0]), s[1]) for s in q], [(len(s[0]), s[1]) for s in p], f"{where} subpaths")
        for (s, _), (t, _) in zip(p, q):
            for i, (x, y) in enumerate(zip(t, s)):
                close(x, y, f"{where} coordinate {i}", extent)


def main(directory):
    with open(os.path.join(directory, "frames.json"), encoding="utf-8") as source:
        doc = json.load(source)
    if len(doc.get("art", [])) < 2:
        raise AssertionError("frames.json has no art")
    header = header_from_json(doc)
    xs = [x for f in doc["frames"] for x, _ in f["vertices"]]
    ys = [y for f in doc["frames"] for _, y in f["vertices"]]
    bounds = (min(xs), min(ys), max(xs), max(ys))  # the CLI's: every frame's vertices
    morphed = 0
    for f in doc["frames"]:
        frame = frame_from_json(f)
        name = "frame_%04d.svg" % f["index"]
        with open(os.path.join(directory, name), encoding="utf-8") as source:
            theirs = source.read()
        layers = [layer for layer in inbetween.frame_art(header, frame)
                  if (layer.fill or layer.stroke) and any(p.points for p in layer.paths)]
        # Coordinates are compared at the scale of the drawing (the SVG keeps 9 digits).
        extent = max([abs(c) for v in f["vertices"] for c in v] + [1.0])
        check_layers(name, layers, svg_paths(theirs), extent)
        check_svg(name, inbetween.frame_art_svg(header, frame, bounds=bounds), theirs, extent)
        morphed += sum(w > 0 for w in f["weights"]) > 1
        print(f"ok   {name}: {len(layers)} layers, weights "
              + " ".join("%.3f" % w for w in f["weights"]))
    if morphed < 1:
        raise AssertionError("no frame between the keys")
    print(f"art parity: {len(doc['frames'])} frames agree with the C++ rule "
          f"({morphed} between keys)")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python3 art_parity.py DIR")
    try:
        main(sys.argv[1])
    except AssertionError as error:
        sys.exit(f"FAIL {error}")
