#!/usr/bin/env python3
"""Checks a multimesh.json written by `inbetween mesh`.

Usage: check_multimesh.py MULTIMESH_JSON EXPECTED_SHAPES
Asserts: the documented keys, one vertex array per shape with the same length, indices in range,
and every triangle positively oriented in every shape.
"""
import json
import sys


def fail(msg):
    print(f"check_multimesh: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def main():
    doc = json.load(open(sys.argv[1]))
    n_shapes = int(sys.argv[2])
    for key in ("triangles", "shapes", "cohesive_edges"):
        if key not in doc:
            fail(f"missing key {key}")
    shapes, tris = doc["shapes"], doc["triangles"]
    if len(shapes) != n_shapes:
        fail(f"{len(shapes)} shapes, expected {n_shapes}")
    n = len(shapes[0]["vertices"])
    for s, shape in enumerate(shapes):
        v = shape["vertices"]
        if len(v) != n:
            fail(f"shape {s} has {len(v)} vertices, shape 0 has {n}")
        for t, (a, b, c) in enumerate(tris):
            if not all(0 <= i < n for i in (a, b, c)):
                fail(f"triangle {t} index out of range")
            area2 = (v[b][0] - v[a][0]) * (v[c][1] - v[a][1]) - (v[b][1] - v[a][1]) * (v[c][0] - v[a][0])
            if not area2 > 0:
                fail(f"shape {s}: triangle {t} inverted or degenerate")
    print(f"check_multimesh: ok: {n_shapes} shapes, {n} vertices, {len(tris)} triangles")


if __name__ == "__main__":
    main()
