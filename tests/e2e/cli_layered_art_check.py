#!/usr/bin/env python3
"""Checks the art targets of tests/e2e/cli_layered_art_test.sh on `inbetween animate` output.

Usage (Debian's python3 with python3-numpy and python3-pil; rsvg-convert from librsvg2-bin):
  cli_layered_art_check.py keys OUT RESULTS NAME DRAWING...
      "keys reproduced": each key frame's PNG (OUT/frame_NNNN.png at the frames.json keys, written
      by `animate --format png,json --transparent`) against the key's drawing rendered by an
      independent renderer (rsvg-convert) in the same viewport; appends one JSON line per key to
      RESULTS.
  cli_layered_art_check.py inside OUT RESULTS NAME
      "no art leaves its shape": every point of the art drawn in every frame (OUT/frame_NNNN.svg,
      written by `animate --format svg`) lies inside the frame's shape (the union of its
      triangles in frames.json) or within the gap tolerance of it; appends one JSON line.
  cli_layered_art_check.py summary RESULTS MIN_IOU MAX_COLOR_ERROR_PERCENT
      prints a table of every result and exits 1 when a key is below MIN_IOU or above the colour
      error, or when art leaves its shape.

Measures (per key frame):
- the reference: the drawing without what is not paint (elements with class "cut" or "opening",
  correspondence marks data-corr: docs/svg-convention.md), its root given the CLI's viewport as
  viewBox (client/render/viewport.cpp: the union of every frame's vertices plus 5% of the larger
  extent, scaled to the PNG's width) and preserveAspectRatio="none", rendered by rsvg-convert at
  the PNG's size, transparent;
- painted pixels: alpha >= 128 in each image; IoU = |both| / |either|;
- colour error: the mean absolute difference of R, G, B (each image over white) over the pixels
  painted in both, in percent of 255.
Per frame (inside): every vertex of every art path drawn in the frame SVG; a point is inside when
the frame's boundary edges (edges of one triangle; both sides of a cut) wind round it an odd
number of times, else its distance to the nearest boundary edge counts; the gap tolerance is
0.002 (the import's default gap_tolerance) times the diagonal of the frame's bounding box.
"""
import json
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
from PIL import Image

SVG_NS = "http://www.w3.org/2000/svg"
GAP_TOLERANCE = 0.002


def fail(msg):
    print(f"cli_layered_art_check: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def append(results, record):
    with open(results, "a") as f:
        f.write(json.dumps(record) + "\n")


# ------------------------------------------------------------------------------ keys reproduced


def viewport(frames, width):
    """(origin_x, origin_y, scale, height) of the CLI's raster viewport (viewport.cpp)."""
    v = np.array([p for fr in frames["frames"] for p in fr["vertices"]], dtype=float)
    lo, hi = v.min(axis=0), v.max(axis=0)
    extent = max(hi - lo)
    margin = 0.05 * extent
    scale = width / (hi[0] - lo[0] + 2 * margin)
    height = max(1, int(np.floor((hi[1] - lo[1] + 2 * margin) * scale + 0.5)))
    return lo[0] - margin, lo[1] - margin, scale, height


def classes(el):
    return (el.get("class") or "").split()


def strip_non_paint(el):
    """Removes cuts, openings and correspondence marks below `el` (they are never paint)."""
    for child in list(el):
        if "cut" in classes(child) or "opening" in classes(child) or \
                child.get("data-corr") is not None:
            el.remove(child)
        else:
            strip_non_paint(child)


def render_reference(drawing, view, width, out_png):
    ox, oy, scale, height = view
    ET.register_namespace("", SVG_NS)
    ET.register_namespace("xlink", "http://www.w3.org/1999/xlink")
    tree = ET.parse(drawing)
    root = tree.getroot()
    strip_non_paint(root)
    root.set("viewBox", "%.17g %.17g %.17g %.17g" % (ox, oy, width / scale, height / scale))
    root.set("width", str(width))
    root.set("height", str(height))
    root.set("preserveAspectRatio", "none")
    svg = out_png[:-4] + ".svg"
    tree.write(svg, xml_declaration=True, encoding="utf-8")
    subprocess.run(["rsvg-convert", "-w", str(width), "-h", str(height), "-f", "png", "-o",
                    out_png, svg], check=True)


def rgba(path):
    return np.asarray(Image.open(path).convert("RGBA"), dtype=float)


def compare(cli_png, ref_png):
    a, b = rgba(cli_png), rgba(ref_png)
    if a.shape != b.shape:
        fail(f"{cli_png} is {a.shape[1]}x{a.shape[0]}, the reference {b.shape[1]}x{b.shape[0]}")
    pa, pb = a[..., 3] >= 128, b[..., 3] >= 128
    either, both = np.count_nonzero(pa | pb), np.count_nonzero(pa & pb)
    iou = both / either if either else 1.0

    def over_white(img):
        alpha = img[..., 3:4] / 255
        return img[..., :3] * alpha + 255 * (1 - alpha)

    diff = np.abs(over_white(a) - over_white(b))[pa & pb]
    color = float(diff.mean() / 255 * 100) if both else 0.0
    return iou, color, int(np.count_nonzero(pa)), int(np.count_nonzero(pb))


def check_keys(out, results, name, drawings):
    frames = json.load(open(os.path.join(out, "frames.json")))
    keys = frames["keys"]
    if len(keys) != len(drawings):
        fail(f"{out}: {len(keys)} keys for {len(drawings)} drawings")
    for k, (key, drawing) in enumerate(zip(keys, drawings)):
        cli_png = os.path.join(out, "frame_%04d.png" % frames["frames"][key]["index"])
        if not os.path.exists(cli_png):
            fail(f"{cli_png}: missing (animate --format png)")
        width = Image.open(cli_png).size[0]
        view = viewport(frames, width)
        ref_png = os.path.join(out, "reference_%d.png" % (k + 1))
        render_reference(drawing, view, width, ref_png)
        iou, color, cli_px, ref_px = compare(cli_png, ref_png)
        record = {"kind": "key", "name": name, "key": k + 1,
                  "drawing": os.path.basename(drawing), "iou": iou, "color_error": color,
                  "cli_pixels": cli_px, "reference_pixels": ref_px, "width": width}
        append(results, record)
        print("%-28s key %2d %-22s IoU %.4f  colour error %5.2f %%" %
              (name, k + 1, os.path.basename(drawing), iou, color))


# ------------------------------------------------------------------------- art inside its shape

NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def svg_art_points(path):
    """Every vertex of every <path> in a frame SVG (the art: flattened, M/L/Z only)."""
    text = open(path).read()
    points = []
    for d in re.findall(r'<path[^>]*\sd="([^"]*)"', text):
        if re.search(r"[^MLZmlz0-9eE+\-., ]", d):
            fail(f"{path}: art path with commands other than M, L, Z: {d[:80]}")
        if re.search(r"[mlz]", d):
            fail(f"{path}: art path with relative commands: {d[:80]}")
        nums = [float(x) for x in re.findall(NUMBER, d)]
        points.extend(zip(nums[0::2], nums[1::2]))
    return np.array(points, dtype=float).reshape(-1, 2)


def boundary_edges(triangles):
    count = {}
    for t in triangles:
        for i in range(3):
            a, b = t[i], t[(i + 1) % 3]
            key = (min(a, b), max(a, b))
            count[key] = count.get(key, 0) + 1
    return np.array([e for e, c in count.items() if c == 1], dtype=int)


def outside_distance(points, a, b):
    """Per point: 0 inside the region the segments a->b bound (odd crossings of a ray to +x),
    else the distance to the nearest segment."""
    out = np.zeros(len(points))
    for s in range(0, len(points), 1024):
        p = points[s:s + 1024, None, :]
        ax, ay, bx, by = a[None, :, 0], a[None, :, 1], b[None, :, 0], b[None, :, 1]
        px, py = p[..., 0], p[..., 1]
        straddle = (ay > py) != (by > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            xcross = ax + (py - ay) * (bx - ax) / (by - ay)
        inside = (np.count_nonzero(straddle & (xcross > px), axis=1) % 2) == 1
        ab = b - a
        t = np.clip(((p - a[None]) * ab[None]).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300),
                    0, 1)
        nearest = a[None] + t[..., None] * ab[None]
        dist = np.sqrt(((p - nearest) ** 2).sum(-1)).min(axis=1)
        out[s:s + 1024] = np.where(inside, 0.0, dist)
    return out


def check_inside(out, results, name):
    frames = json.load(open(os.path.join(out, "frames.json")))
    edges = boundary_edges(frames["triangles"])
    worst = {"distance": 0.0, "ratio": 0.0, "frame": None, "point": None}
    frames_outside, points, points_outside = 0, 0, 0
    for fr in frames["frames"]:
        v = np.array(fr["vertices"], dtype=float)
        art = svg_art_points(os.path.join(out, "frame_%04d.svg" % fr["index"]))
        if len(art) == 0:
            fail(f"{out}/frame_{fr['index']:04d}.svg has no art")
        tolerance = GAP_TOLERANCE * np.linalg.norm(v.max(axis=0) - v.min(axis=0))
        dist = outside_distance(art, v[edges[:, 0]], v[edges[:, 1]])
        points += len(art)
        beyond = dist > tolerance
        points_outside += int(np.count_nonzero(beyond))
        frames_outside += bool(beyond.any())
        i = int(np.argmax(dist))
        if dist[i] / tolerance > worst["ratio"]:
            worst = {"distance": float(dist[i]), "ratio": float(dist[i] / tolerance),
                     "frame": fr["index"], "point": [float(art[i, 0]), float(art[i, 1])]}
    record = {"kind": "inside", "name": name, "frames": len(frames["frames"]),
              "frames_outside": frames_outside, "points": points,
              "points_outside": points_outside, "worst": worst}
    append(results, record)
    print("%-28s %d frames, %d art points: %d beyond the gap tolerance (in %d frames); farthest "
          "%.3g user units outside (%.2f x tolerance, frame %s)" %
          (name, len(frames["frames"]), points, points_outside, frames_outside,
           worst["distance"], worst["ratio"], worst["frame"]))


# ------------------------------------------------------------------------------------- summary


def summary(results, min_iou, max_color):
    records = [json.loads(line) for line in open(results)]
    keys = [r for r in records if r["kind"] == "key"]
    inside = [r for r in records if r["kind"] == "inside"]
    refused = [r for r in records if r["kind"] == "refused"]
    bad = []
    print("\nkeys reproduced (IoU >= %.3f, colour error <= %.1f %%):" % (min_iou, max_color))
    print("%-28s %4s %-22s %8s %8s" % ("example / pair", "key", "drawing", "IoU", "colour %"))
    for r in keys:
        ok = r["iou"] >= min_iou and r["color_error"] <= max_color
        print("%-28s %4d %-22s %8.4f %8.2f%s" % (r["name"], r["key"], r["drawing"], r["iou"],
                                                  r["color_error"], "" if ok else "  FAIL"))
        if not ok:
            bad.append(f"{r['name']} key {r['key']} ({r['drawing']}): IoU {r['iou']:.4f}, "
                       f"colour error {r['color_error']:.2f} %")
    for group, members in (("examples", [r for r in keys if not r["name"].startswith("openmoji")]),
                           ("openmoji", [r for r in keys if r["name"].startswith("openmoji")])):
        if members:
            ious = sorted(r["iou"] for r in members)
            colors = sorted(r["color_error"] for r in members)
            passed = sum(r["iou"] >= min_iou and r["color_error"] <= max_color for r in members)
            print("%s: %d key drawings, %d pass; IoU min %.4f median %.4f; colour error median "
                  "%.2f %% max %.2f %%" % (group, len(members), passed, ious[0],
                                          ious[len(ious) // 2], colors[len(colors) // 2],
                                          colors[-1]))
    if refused:
        print("openmoji pairs refused by the service (not measured): %d: %s" %
              (len(refused), " ".join(r["name"] for r in refused)))
    print("\nno art leaves its shape (gap tolerance %g of the frame's diagonal):" % GAP_TOLERANCE)
    for r in inside:
        w = r["worst"]
        print("%-28s %3d frames %7d points: %d outside in %d frames; farthest %.3g (%.2f x "
              "tolerance, frame %s, at %s)" % (r["name"], r["frames"], r["points"],
                                               r["points_outside"], r["frames_outside"],
                                               w["distance"], w["ratio"], w["frame"], w["point"]))
        if r["points_outside"]:
            bad.append(f"{r['name']}: {r['points_outside']} art points outside the shape in "
                       f"{r['frames_outside']} frames")
    if bad:
        print("\nFAIL:\n  " + "\n  ".join(bad), file=sys.stderr)
        sys.exit(1)
    print("ok")


def main():
    cmd = sys.argv[1] if len(sys.argv) > 1 else ""
    if cmd == "keys" and len(sys.argv) >= 6:
        check_keys(sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5:])
    elif cmd == "inside" and len(sys.argv) == 5:
        check_inside(sys.argv[2], sys.argv[3], sys.argv[4])
    elif cmd == "summary" and len(sys.argv) == 5:
        summary(sys.argv[2], float(sys.argv[3]), float(sys.argv[4]))
    else:
        fail(__doc__)


if __name__ == "__main__":
    main()
