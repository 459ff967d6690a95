#!/usr/bin/env python3
"""Selects and judges the OpenMoji corpus runs of tests/e2e/cli_openmoji_test.sh.

Usage:
  cli_openmoji_check.py drawings PACKAGE EVERY      the drawings to import, one hexcode a line
  cli_openmoji_check.py pairs PACKAGE EVERY         the related pairs to animate, "HEX1 HEX2" a line
  cli_openmoji_check.py report PACKAGE RUNS FRAMES MIN_IMPORT MIN_ANIMATE SUMMARY_JSON
                                                    judges the runs (the minimums in percent)
PACKAGE is node_modules/openmoji (data/openmoji.csv, color/svg/HEX.svg). RUNS holds, per run,
ID.cmd (the command line), ID.code (exit status), ID.out, ID.err and for pairs ID.dir (the --out
directory); ID is "d-HEX" for a drawing, "p-HEX1_HEX2" for a pair (hexcodes have dashes).

Selection (rows of data/openmoji.csv in the file's order, the package's own order; rows with a
non-empty skintone column, the skin-tone variants, are left out everywhere):
- drawings: groups smileys-emotion, people-body, animals-nature, food-drink, travel-places,
  objects (so no flags, symbols, extras), drawings with at least MIN_LAYERS painted elements
  (a filled element of non-zero area, as cli_icons_check.read_svg reads fills, or a stroked
  element: each is a layer painted over the ones before); of those the 1st, (EVERY+1)th, ...
- pairs of related drawings: a face and the same face with another expression (each two rows
  next to each other in the csv within one of the face subgroups PAIR_SUBGROUPS), and an animal
  and its variant (within one animal-* subgroup, rows whose annotations end in the same noun,
  "face" aside: dog / guide dog / service dog, bear / polar bear, fish / tropical fish; each
  such row with the previous one of its noun); of those pairs the 1st, (EVERY+1)th, ...

Outcomes:
- a drawing (`inbetween validate SVG SVG`: the drawing against itself, as the CLI takes 2 to 16
  drawings): imported (exit 0, "ok"), imported but not built (exit 3, only "build: REASON"
  problems: the two copies did not mesh and map; counted as imported, and apart), refused
  (exit 3, the problem lines name the drawing and one reason), else failed; the import's
  warnings (validate's "drawing 1 (F): warning: ..." lines) are counted by cause;
- a pair (`inbetween animate A B --frames F --format json`): animated (exit 0 and frames.json
  passes tests/e2e/lib/check_frames.py's check: F frames, keys 0 and F-1, every frame's "valid"
  stats with 0 inverted triangles and 0 boundary overlaps, every triangle positive), refused
  (exit 3, an "error:" line, nothing written to --out but --auto-topology's project.json), else
  failed (a crash, a timeout, another exit code, broken frames).
A refusal's cause is its message with the file names, numbers and places taken out
(cause_key). `report` prints the failures and a summary table, writes SUMMARY_JSON and exits 1
when anything failed or a rate is below its minimum.
"""
import csv
import json
import os
import re
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
import cli_icons_check as icons  # noqa: E402  (the SVG reader of the icon corpus test)
from check_frames import FramesError, check_frames  # noqa: E402

DRAWING_GROUPS = ("smileys-emotion", "people-body", "animals-nature", "food-drink",
                  "travel-places", "objects")
PAIR_SUBGROUPS = ("face-smiling", "face-affection", "face-tongue", "face-hand",
                  "face-neutral-skeptical", "face-sleepy", "face-unwell", "face-concerned",
                  "face-negative", "face-costume", "cat-face", "monkey-face")
MIN_LAYERS = 3
SHAPES = ("path", "circle", "ellipse", "rect", "polygon", "polyline", "line")


def rows(package):
    """The csv rows without skin-tone variants whose colour SVG exists, in the file's order."""
    with open(os.path.join(package, "data", "openmoji.csv"), newline="", encoding="utf-8") as f:
        for row in csv.DictReader(f):
            if row["skintone"]:
                continue
            if os.path.isfile(svg_path(package, row["hexcode"])):
                yield row


def svg_path(package, hexcode):
    return os.path.join(package, "color", "svg", hexcode + ".svg")


def stroked_elements(path):
    """Elements with a stroke (inherited from their groups as SVG does)."""
    count = 0

    def walk(el, stroke):
        nonlocal count
        tag = el.tag.replace(icons.SVG_NS, "")
        stroke = icons.style_of(el).get("stroke", el.get("stroke", stroke))
        if tag in ("svg", "g"):
            for child in el:
                walk(child, stroke)
        elif tag in SHAPES and stroke not in (None, "none"):
            count += 1

    walk(ET.parse(path).getroot(), None)
    return count


def layers(path):
    return len(icons.read_svg(path)) + stroked_elements(path)


def every_kth(items, every):
    return [x for i, x in enumerate(items) if i % every == 0]


def select_drawings(package, every):
    chosen = [r["hexcode"] for r in rows(package) if r["group"] in DRAWING_GROUPS and
              layers(svg_path(package, r["hexcode"])) >= MIN_LAYERS]
    return every_kth(chosen, every)


def animal_noun(r):
    """The animal a row draws, for pairing variants: its annotation's last word."""
    words = r["annotation"].lower().split()
    return words[-1] if words and words[-1] != "face" else None


def select_pairs(package, every):
    pairs, last, last_of_noun = [], None, {}
    for r in rows(package):
        if r["subgroups"] in PAIR_SUBGROUPS:
            if last is not None and last["subgroups"] == r["subgroups"]:
                pairs.append((last["hexcode"], r["hexcode"]))
        elif r["subgroups"].startswith("animal-") and animal_noun(r):
            key = (r["subgroups"], animal_noun(r))
            if key in last_of_noun:
                pairs.append((last_of_noun[key]["hexcode"], r["hexcode"]))
            last_of_noun[key] = r
        last = r
    return every_kth(pairs, every)


# ---------------------------------------------------------------------------- judging runs

PLACE_RE = re.compile(r"\(\s*-?[0-9.eE+-]+\s*,\s*-?[0-9.eE+-]+\s*\)")
NUMBER_RE = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
DRAWING_RE = re.compile(r"^drawing ([0-9]+) \(([^)]*)\): (.*)$")


def cause_key(message):
    """A refusal message without what differs between drawings: the file names, numbers,
    places, and the advice and details after " — ", "; " or " (", e.g. "import: outline N and
    outline N touch or cross at (x, y)"."""
    text = message
    if "must have the same topology" in text:
        return "build multimesh: the drawings have different topology"
    text = re.sub(r"drawing ([0-9]+) \([^)]*\)", r"drawing \1", text)  # "drawing 2 (F.svg)"
    text = re.sub(r"\S+\.svg\b:?\s*", "", text)  # the service's "drawing.svg element[3] ..."
    text = PLACE_RE.sub("(x, y)", text)
    text = NUMBER_RE.sub("N", text).replace(" (line N)", "")
    text = re.split(r" — |; | \((?!x, y\))", text)[0]  # the advice and the details
    return text.strip()[:160]


LOG_RE = re.compile(r"^\[\d{4}-\d\d-\d\d [\d:.]+\] \[\w+\] ")  # spdlog lines ("shutting down")


def read(path):
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            return f.read()
    except FileNotFoundError:
        return ""


def read_lines(path):
    """A run's output without the embedded service's log lines."""
    return [line for line in read(path).splitlines() if not LOG_RE.match(line)]


def judge_drawing(base):
    """(outcome, cause, detail, warnings) of `inbetween validate SVG SVG` (the drawing against
    itself: the CLI takes 2 to 16 drawings). Its stdout: per drawing imported, what the import
    did ("drawing 1 (F): silhouette ...", "drawing 1 (F): warning: ..."; builds before the
    layered import print none), then the problems, one a line (as many as stderr's "error: N
    problem(s) found" says: "drawing K (F): REASON" for an import, "build: REASON" for the two
    copies built together), then "ok" when there are none."""
    code = int(read(base + ".code").strip() or -1)
    out, err = read_lines(base + ".out"), read_lines(base + ".err")
    counts = [re.match(r"^error: ([0-9]+) problem\(s\) found$", line) for line in err]
    counts = [int(m.group(1)) for m in counts if m]
    n = counts[-1] if counts and code == 3 else 0
    problems, report = (out[len(out) - n:], out[:len(out) - n]) if n else ([], out)
    warnings = [m.group(3)[len("warning: "):] for m in (DRAWING_RE.match(line) for line in report)
                if m and m.group(1) == "1" and m.group(3).startswith("warning: ")]
    if code == 0:
        if out and out[-1].strip() == "ok":
            return "imported", "", "", warnings
        return "failed", "", f"exit 0 without 'ok': {(out or ['(no output)'])[-1]}", warnings
    if code == 3 and n and len(problems) == n:
        imports = [DRAWING_RE.match(line) for line in problems]
        builds = [line for line in problems if line.startswith("build: ")]
        if imports[0] and all(m is None or m.group(3) == imports[0].group(3) for m in imports) \
                and all(m or line in builds for m, line in zip(imports, problems)):
            reason = imports[0].group(3)  # both copies give the same reason
            return "refused", cause_key(reason), reason, warnings
        if builds and len(builds) == n:
            reason = builds[0]
            return "not built", cause_key(reason), reason, warnings
    return "failed", "", describe_failure(code, out + err), warnings


def judge_pair(base, n_frames):
    """(outcome, cause, detail) of `inbetween animate A B --frames N --format json --out DIR`."""
    code = int(read(base + ".code").strip() or -1)
    out_dir = read(base + ".dir").strip()
    err = read_lines(base + ".err")
    frames = os.path.join(out_dir, "frames.json")
    if code == 0:
        if not os.path.isfile(frames):
            return "failed", "", "exit 0 without frames.json"
        try:
            with open(frames) as f:
                doc = json.load(f)
            summary = check_frames(doc, n_frames, [0, n_frames - 1])
        except (FramesError, ValueError, KeyError, TypeError, IndexError) as e:
            return "failed", "", f"broken frames.json: {e.__class__.__name__}: {e}"
        return "animated", "", summary
    errors = [line[len("error: "):] for line in err if line.startswith("error: ")]
    if code == 3 and errors:
        # --auto-topology writes its proposal (OUT/project.json, docs/cli.md) before the build.
        written = sorted(set(os.listdir(out_dir)) - {"project.json"}) \
            if os.path.isdir(out_dir) else []
        if written:
            return "failed", "", f"refused (exit 3) but wrote {', '.join(written)} into {out_dir}"
        reason = errors[-1]
        return "refused", cause_key(reason), reason
    return "failed", "", describe_failure(code, read_lines(base + ".out") + err)


def describe_failure(code, lines):
    what = {124: " (timeout)", 137: " (killed after the timeout)"}.get(code, "")
    if not what and code > 128:
        what = f" (signal {code - 128})"
    tail = " | ".join(line for line in lines[-3:] if line.strip())
    return f"exit {code}{what}" + (f": {tail}" if tail else "")


def percent(n, total):
    return round(100.0 * n / total, 1) if total else 0.0


def count_by(keys):
    counts = {}
    for k in keys:
        counts[k] = counts.get(k, 0) + 1
    return dict(sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])))


def tally(results, good):
    """Counts of a stage; `good` outcomes are what the rate counts ("imported" includes drawings
    imported but not built against themselves, also counted apart)."""
    n = len(results)
    ok = sum(r["outcome"] in good for r in results)
    refused = [r for r in results if r["outcome"] == "refused"]
    t = {"tried": n, good[0]: ok, f"{good[0]}_percent": percent(ok, n),
         "refused": len(refused), "refused_percent": percent(len(refused), n),
         "failed": sum(r["outcome"] == "failed" for r in results),
         "refused_by_cause": count_by(r["cause"] for r in refused)}
    if "not built" in good:
        not_built = [r for r in results if r["outcome"] == "not built"]
        t["not_built"] = len(not_built)
        t["not_built_by_cause"] = count_by(r["cause"] for r in not_built)
        t["with_warnings"] = sum(bool(r["warnings"]) for r in results)
        t["warnings_by_cause"] = count_by(cause_key(w) for r in results for w in r["warnings"])
    return t


def family(subgroup):
    """Pairs are counted apart for faces (face-*, cat-face, monkey-face) and animals."""
    return "animals" if subgroup.startswith("animal-") else "faces"


def report(package, runs, n_frames, min_import, min_animate, summary_json):
    subgroup = {r["hexcode"]: r["subgroups"] for r in rows(package)}
    drawings, pairs = [], []
    for name in sorted(os.listdir(runs)):
        if not name.endswith(".code"):
            continue
        run_id = name[:-len(".code")]
        base = os.path.join(runs, run_id)
        if run_id.startswith("d-"):
            outcome, cause, detail, warnings = judge_drawing(base)
            drawings.append({"drawing": run_id[2:], "outcome": outcome, "cause": cause,
                             "detail": detail, "warnings": warnings})
        else:
            a, b = run_id[2:].split("_", 1)
            outcome, cause, detail = judge_pair(base, n_frames)
            pairs.append({"pair": [a, b], "subgroup": subgroup.get(a, ""), "outcome": outcome,
                          "cause": cause, "detail": detail})
    for r in drawings + pairs:
        if r["outcome"] == "failed":
            what = r.get("drawing") or " + ".join(r["pair"])
            print(f"FAIL {what}: {r['detail']}")
            print(f"  command: {read(os.path.join(runs, run_key(r)) + '.cmd').strip()}")
    d = tally(drawings, ("imported", "not built"))
    p = tally(pairs, ("animated",))
    p["by_family"] = {f: tally([r for r in pairs if family(r["subgroup"]) == f], ("animated",))
                      for f in sorted({family(r["subgroup"]) for r in pairs})}
    lines = ["", "| stage | tried | ok | refused | failed |", "|---|---|---|---|---|",
             f"| import (`validate SVG SVG`) | {d['tried']} | {d['imported']} imported"
             f" ({d['imported_percent']}%, min {min_import:g}%; {d['not_built']} of them not built"
             f" with themselves) | {d['refused']} ({d['refused_percent']}%) | {d['failed']} |",
             f"| pairs (`animate A B`) | {p['tried']} | {p['animated']} animated"
             f" ({p['animated_percent']}%, min {min_animate:g}%) | {p['refused']}"
             f" ({p['refused_percent']}%) | {p['failed']} |"]
    for f, t in p["by_family"].items():
        lines.append(f"| pairs: {f} | {t['tried']} | {t['animated']} ({t['animated_percent']}%)"
                     f" | {t['refused']} ({t['refused_percent']}%) | {t['failed']} |")
    for title, counts in (("drawings refused, by cause", d["refused_by_cause"]),
                          ("drawings imported but not built with themselves, by cause",
                           d["not_built_by_cause"]),
                          (f"import warnings ({d['with_warnings']} drawings), by cause",
                           d["warnings_by_cause"]),
                          ("pairs refused, by cause", p["refused_by_cause"])):
        lines.append(f"{title}:")
        lines += [f"  {n:4d}  {cause}" for cause, n in counts.items()] or ["  none"]
    print("\n".join(lines))
    verdicts = []
    if d["failed"] or p["failed"]:
        verdicts.append(f"{d['failed']} drawings and {p['failed']} pairs failed")
    if d["tried"] and d["imported_percent"] < min_import:
        verdicts.append(f"imported {d['imported_percent']}% < MIN_IMPORT_PERCENT {min_import:g}%")
    if p["tried"] and p["animated_percent"] < min_animate:
        verdicts.append(f"animated {p['animated_percent']}% < MIN_ANIMATE_PERCENT "
                        f"{min_animate:g}%")
    summary = {"corpus": "openmoji@17.0.0 (CC BY-SA 4.0)", "drawings": d, "pairs": p,
               "min_import_percent": min_import, "min_animate_percent": min_animate,
               "verdict": "; ".join(verdicts) or "ok",
               "drawing_results": drawings, "pair_results": pairs}
    with open(summary_json, "w") as f:
        json.dump(summary, f, indent=1, ensure_ascii=False)
        f.write("\n")
    for v in verdicts:
        print(f"FAIL: {v}")
    return 1 if verdicts else 0


def run_key(r):
    return f"d-{r['drawing']}" if "drawing" in r else f"p-{r['pair'][0]}_{r['pair'][1]}"


def main():
    command = sys.argv[1]
    if command == "drawings":
        print("\n".join(select_drawings(sys.argv[2], int(sys.argv[3]))))
    elif command == "pairs":
        print("\n".join(f"{a} {b}" for a, b in select_pairs(sys.argv[2], int(sys.argv[3]))))
    elif command == "report":
        sys.exit(report(sys.argv[2], sys.argv[3], int(sys.argv[4]), float(sys.argv[5]),
                        float(sys.argv[6]), sys.argv[7]))
    else:
        sys.exit(f"cli_openmoji_check: unknown command {command}")


if __name__ == "__main__":
    main()
