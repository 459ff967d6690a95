#!/usr/bin/env python3
"""Checks the files `inbetween animate --format svg,json,png,gif,webp,lottie,contact` wrote.

Usage: cli_formats_check.py OUT_DIR FRAMES SCHEMA_JSON
- animation.lottie.json validates against SCHEMA_JSON (needs Debian's python3-jsonschema: run
  with /usr/bin/python3), and a copy without its fill does not (the check can fail);
- animation.gif and animation.webp decode (container level, no image library) to FRAMES frames
  of the PNG frames' size;
- the SVG and PNG frames exist for every frame; frame 0's SVG uses the first drawing's fill.
"""
import copy
import json
import os
import struct
import sys

import jsonschema


def fail(msg):
    print(f"cli_formats_check: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def png_size(path):
    with open(path, "rb") as f:
        data = f.read(24)
    if data[:8] != b"\x89PNG\r\n\x1a\n" or data[12:16] != b"IHDR":
        fail(f"{path} is not a PNG")
    return struct.unpack(">II", data[16:24])


def skip_sub_blocks(data, pos):
    while data[pos] != 0:
        pos += data[pos] + 1
    return pos + 1


def gif_frames(path):
    data = open(path, "rb").read()
    if data[:6] != b"GIF89a":
        fail(f"{path}: not GIF89a")
    width, height, packed = struct.unpack("<HHB", data[6:11])
    pos = 13
    if packed & 0x80:
        pos += 3 * (2 << (packed & 7))
    images = 0
    while True:
        block = data[pos]
        if block == 0x3B:
            break
        if block == 0x21:  # extension: label, then data sub-blocks
            pos = skip_sub_blocks(data, pos + 2)
        elif block == 0x2C:  # image descriptor, optional local table, LZW data
            local = data[pos + 9]
            pos += 10
            if local & 0x80:
                pos += 3 * (2 << (local & 7))
            pos = skip_sub_blocks(data, pos + 1)
            images += 1
        else:
            fail(f"{path}: unexpected block 0x{block:02x} at {pos}")
    return width, height, images


def webp_frames(path):
    data = open(path, "rb").read()
    if data[:4] != b"RIFF" or data[8:12] != b"WEBP":
        fail(f"{path}: not a WebP RIFF")
    pos, size, frames = 12, None, 0
    while pos + 8 <= len(data):
        fourcc, length = data[pos:pos + 4], struct.unpack("<I", data[pos + 4:pos + 8])[0]
        payload = data[pos + 8:pos + 8 + length]
        if fourcc == b"VP8X":
            w = int.from_bytes(payload[4:7], "little") + 1
            h = int.from_bytes(payload[7:10], "little") + 1
            size = (w, h)
        elif fourcc == b"ANMF":
            frames += 1
        pos += 8 + length + (length & 1)
    if size is None:
        fail(f"{path}: no VP8X chunk (not an animation)")
    return size[0], size[1], frames


def main():
    out, n_frames, schema_path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    with open(schema_path) as f:
        schema = json.load(f)
    with open(os.path.join(out, "animation.lottie.json")) as f:
        lottie = json.load(f)
    jsonschema.Draft202012Validator(schema).validate(lottie)
    if lottie["op"] != n_frames:
        fail(f"lottie op {lottie['op']}, expected {n_frames}")
    broken = copy.deepcopy(lottie)
    group = broken["layers"][0]["shapes"][0]["it"]
    group[:] = [item for item in group if item.get("ty") != "fl"]
    if jsonschema.Draft202012Validator(schema).is_valid(broken):
        fail("the schema accepts a Lottie without its fill")

    width, height = png_size(os.path.join(out, "frame_0000.png"))
    for i in range(n_frames):
        for ext in ("svg", "png"):
            if not os.path.isfile(os.path.join(out, f"frame_{i:04d}.{ext}")):
                fail(f"frame_{i:04d}.{ext} missing")
    gif = gif_frames(os.path.join(out, "animation.gif"))
    if gif != (width, height, n_frames):
        fail(f"GIF is {gif}, expected {(width, height, n_frames)}")
    webp = webp_frames(os.path.join(out, "animation.webp"))
    if webp != (width, height, n_frames):
        fail(f"WebP is {webp}, expected {(width, height, n_frames)}")
    if lottie["w"] != width:
        fail(f"Lottie width {lottie['w']} != PNG width {width}")
    png_size(os.path.join(out, "contact_sheet.png"))

    with open(os.path.join(out, "frames.json")) as f:
        frames = json.load(f)
    if "fills" in frames:
        svg = open(os.path.join(out, "frame_0000.svg")).read()
        if f'fill="{frames["fills"][0]}"' not in svg:
            fail(f"frame_0000.svg does not use the first drawing's fill {frames['fills'][0]}")
    print(f"cli_formats_check: ok: {n_frames} frames, {width}x{height}")


if __name__ == "__main__":
    main()
