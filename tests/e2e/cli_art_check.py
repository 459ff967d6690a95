#!/usr/bin/env python3
"""Checks the frames of cli_art_test.sh (the face drawings: yellow #ffd700 face stroked black,
black eyes at y = 38 in key 1 and y = 55 in key 2, x = 35 and 65, radius 7).

Usage: cli_art_check.py OUT_DIR art|silhouette
- art: frame_0000.svg has at least 3 <path>s, with fill #ffd700, stroke #000000 and the eyes'
  fill #000000; frame_0000.png is black at key 1's eyes and yellow between and below them, the
  last frame's PNG black at key 2's eyes; frames.json (when written) has an "art" entry per key.
- silhouette: frame_0000.svg has one filled <path> in one colour and no stroke; the PNG is the
  same colour at the eyes as between them.
The PNG is decoded here (zlib and the five filters) to need no image library.
"""
import json
import os
import re
import struct
import sys
import zlib


def fail(msg):
    print(f"cli_art_check: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def read_png(path):
    """(width, height, rows of RGBA tuples) of an 8-bit RGB or RGBA, non-interlaced PNG."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(f"{path} is not a PNG")
    pos, idat = 8, b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or color not in (2, 6) or interlace:
                fail(f"{path}: unsupported PNG (depth {depth}, colour type {color})")
            channels = 4 if color == 6 else 3
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev, at = [], bytearray(stride), 0
    for _ in range(height):
        kind, line = raw[at], bytearray(raw[at + 1:at + 1 + stride])
        at += 1 + stride
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 0xFF
            elif kind == 2:
                line[i] = (line[i] + b) & 0xFF
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 0xFF
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 0xFF
        rows.append([tuple(line[x * channels:(x + 1) * channels]) + ((255,) if channels == 3 else ())
                     for x in range(width)])
        prev = line
    return width, height, rows


def viewport(frames, width):
    """The renderer's user -> pixel map (client/render/viewport.cpp)."""
    xs = [v[0] for f in frames["frames"] for v in f["vertices"]]
    ys = [v[1] for f in frames["frames"] for v in f["vertices"]]
    extent = max(max(xs) - min(xs), max(ys) - min(ys))
    margin = 0.05 * extent
    scale = width / (max(xs) - min(xs) + 2 * margin)
    return lambda x, y: (int((x - min(xs) + margin) * scale), int((y - min(ys) + margin) * scale))


def near(c, rgb, tol=40):
    return all(abs(a - b) <= tol for a, b in zip(c[:3], rgb))


def main():
    out, mode = sys.argv[1], sys.argv[2]
    frames_json = os.path.join(out, "frames.json")
    if os.path.exists(frames_json):
        frames = json.load(open(frames_json))
    else:  # silhouette runs write no frames.json: the art run's has the same geometry
        frames = json.load(open(os.path.join(os.path.dirname(out) or ".", "art", "frames.json")))
    svg = open(os.path.join(out, "frame_0000.svg")).read()
    paths = re.findall(r"<path[^>]*>", svg)
    pngs = sorted(f for f in os.listdir(out) if re.fullmatch(r"frame_\d{4}\.png", f))
    if not pngs:
        fail(f"{out}: no PNG frames")
    width, _, first = read_png(os.path.join(out, pngs[0]))
    _, _, last = read_png(os.path.join(out, pngs[-1]))
    at = viewport(frames, width)
    px = lambda img, x, y: img[at(x, y)[1]][at(x, y)[0]]
    yellow, black = (0xFF, 0xD7, 0x00), (0, 0, 0)
    if mode == "art":
        if len(paths) < 3:
            fail(f"{out}/frame_0000.svg has {len(paths)} <path>s, expected the 3 layers:\n{svg}")
        for needle in ('fill="#ffd700"', 'stroke="#000000"'):
            if not any(needle in p for p in paths):
                fail(f"{out}/frame_0000.svg has no path with {needle}:\n{svg}")
        if sum('fill="#000000"' in p for p in paths) < 2:
            fail(f"{out}/frame_0000.svg: expected two black-filled eyes:\n{svg}")
        if os.path.exists(frames_json) and len(frames.get("art", [])) != 2:
            fail(f"{frames_json}: expected an art entry per key drawing")
        for x in (35, 65):
            if not near(px(first, x, 38), black):
                fail(f"{out}/{pngs[0]}: not black at key 1's eye ({x}, 38): {px(first, x, 38)}")
            if not near(px(last, x, 55), black):
                fail(f"{out}/{pngs[-1]}: not black at key 2's eye ({x}, 55): {px(last, x, 55)}")
        for img, name in ((first, pngs[0]), (last, pngs[-1])):
            if not near(px(img, 50, 46), yellow) or not near(px(img, 50, 75), yellow):
                fail(f"{out}/{name}: not yellow between/below the eyes")
        if not near(px(first, 35, 55), yellow):
            fail(f"{out}/{pngs[0]}: key 2's eye position is not yellow in key 1")
        if not near(px(first, 50, 10.5), black):
            fail(f"{out}/{pngs[0]}: the face's outline stroke is not black: {px(first, 50, 10.5)}")
    else:
        filled = [p for p in paths if 'fill="none"' not in p]
        if len(filled) != 1 or "#000000" in filled[0]:
            fail(f"{out}/frame_0000.svg: expected one one-colour silhouette path:\n{svg}")
        if px(first, 35, 38) != px(first, 50, 46):
            fail(f"{out}/{pngs[0]}: silhouette has different colours at the eye and between")
    print(f"cli_art_check: ok: {out} ({mode})")


if __name__ == "__main__":
    main()
