#!/usr/bin/env python3
"""Checks a frames.json written by `inbetween animate`.

Usage: check_frames.py FRAMES_JSON EXPECTED_FRAMES EXPECTED_KEYS(comma-separated) [MAX_OVERLAPS]
Asserts: frame count and order, keys, one vertex per mesh vertex in every frame, finite
coordinates, and zero inverted (non-positive signed area) triangles in every frame; each frame's
"valid" stats (written by the service) report no inverted triangle, no boundary overlap and a
positive smallest area ratio. MAX_OVERLAPS (default 0) is the most boundary overlaps a frame
may report (only for the known cases the caller names).
"""
import json
import math
import sys


class FramesError(Exception):
    pass


def fail(msg):
    raise FramesError(msg)


def check_frames(doc, n_frames, keys, max_overlaps=0):
    """Checks a parsed frames.json (the assertions above); returns a one-line summary, raises
    FramesError naming the first problem. Also imported by tests/e2e/cli_openmoji_check.py."""
    tris, frames = doc["triangles"], doc["frames"]
    if len(frames) != n_frames:
        fail(f"{len(frames)} frames, expected {n_frames}")
    if doc["keys"] != keys:
        fail(f"keys {doc['keys']}, expected {keys}")
    if not tris:
        fail("no triangles")
    n_vertices = len(frames[0]["vertices"])
    for i, fr in enumerate(frames):
        if fr["index"] != i:
            fail(f"frame {i} has index {fr['index']}")
        v = fr["vertices"]
        if len(v) != n_vertices:
            fail(f"frame {i} has {len(v)} vertices, frame 0 has {n_vertices}")
        if not all(math.isfinite(c) for p in v for c in p):
            fail(f"frame {i} has a non-finite coordinate")
        for t, (a, b, c) in enumerate(tris):
            area2 = (v[b][0] - v[a][0]) * (v[c][1] - v[a][1]) - (v[b][1] - v[a][1]) * (v[c][0] - v[a][0])
            if not area2 > 0:
                fail(f"frame {i}: triangle {t} is inverted or degenerate (2*area={area2})")
        valid = fr.get("valid")
        if valid is None:
            fail(f"frame {i} has no 'valid' stats")
        if valid["inverted_triangles"] != 0 or valid["boundary_overlaps"] > max_overlaps:
            fail(f"frame {i}: valid reports {valid['inverted_triangles']} inverted triangles, "
                 f"{valid['boundary_overlaps']} boundary overlaps")
        if not 0.0 < valid["min_area_ratio"] <= valid["max_area_ratio"]:
            fail(f"frame {i}: area ratios {valid['min_area_ratio']} .. {valid['max_area_ratio']}")
    if not 0.0 <= frames[0]["time"] < frames[-1]["time"] <= 1.0:
        fail("frame times are not increasing within [0, 1]")
    return f"{len(frames)} frames, {len(tris)} triangles, {n_vertices} vertices"


def main():
    path, n_frames, keys = sys.argv[1], int(sys.argv[2]), [int(k) for k in sys.argv[3].split(",")]
    max_overlaps = int(sys.argv[4]) if len(sys.argv) > 4 else 0
    with open(path) as f:
        doc = json.load(f)
    try:
        summary = check_frames(doc, n_frames, keys, max_overlaps)
    except FramesError as e:
        print(f"check_frames: FAIL: {e}", file=sys.stderr)
        sys.exit(1)
    print(f"check_frames: ok: {summary}")


if __name__ == "__main__":
    main()
