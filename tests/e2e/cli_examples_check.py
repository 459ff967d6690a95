#!/usr/bin/env python3
"""Checks one example's frames.json beyond tests/e2e/lib/check_frames.py: the keys are hit.

Usage: cli_examples_check.py PROJECT_JSON FRAMES_JSON EXPECTED_FRAMES
Asserts: one key per drawing of the project, strictly increasing, first 0 and last the final
frame; at each key frame the example weights are exactly one-hot on that drawing (the frame is
the drawing's shape, not a blend); every frame's weights sum to 1; the drawings' fill colours
("fills") are carried through when the drawings give them. Prints the keys (comma-separated)
for check_frames.py.
"""
import json
import re
import sys


def fail(msg):
    print(f"cli_examples_check: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def main():
    project_path, frames_path, n_frames = sys.argv[1], sys.argv[2], int(sys.argv[3])
    with open(project_path) as f:
        project = json.load(f)
    with open(frames_path) as f:
        doc = json.load(f)
    n_drawings = len(project["drawings"])
    keys, frames = doc["keys"], doc["frames"]
    if len(frames) != n_frames:
        fail(f"{len(frames)} frames, expected {n_frames}")
    if len(keys) != n_drawings:
        fail(f"{len(keys)} keys for {n_drawings} drawings")
    if keys[0] != 0 or keys[-1] != n_frames - 1 or any(b <= a for a, b in zip(keys, keys[1:])):
        fail(f"keys {keys} are not increasing from 0 to {n_frames - 1}")
    for i, fr in enumerate(frames):
        w = fr["weights"]
        if len(w) != n_drawings or abs(sum(w) - 1) > 1e-9:
            fail(f"frame {i}: weights {w} do not sum to 1 over {n_drawings} drawings")
    for d, k in enumerate(keys):
        w = frames[k]["weights"]
        if any(abs(x - (1.0 if j == d else 0.0)) > 1e-12 for j, x in enumerate(w)):
            fail(f"key frame {k} of drawing {d + 1} has weights {w}, not one-hot")
    fills = doc.get("fills")
    if fills is not None:
        if len(fills) != n_drawings or not all(re.fullmatch(r"#[0-9a-f]{6}", c) for c in fills):
            fail(f"fills {fills} are not one #rrggbb per drawing")
    print(",".join(str(k) for k in keys))


if __name__ == "__main__":
    main()
