// The page's frame art (src/page/art.js) against the C++ rule itself: reads the frames.json and
// the frame_NNNN.svg files that `inbetween animate --format svg,json` wrote into DIR, computes
// every frame's art with art.js from frames.json's "art", "triangles", vertices and weights, and
// compares it with the <path> elements of that frame's SVG (solver/art/art_svg.cpp writes one per
// drawn layer, in paint order, numbers with 9 significant digits): the same layers in the same
// order, the same paint (colours exact; opacities, widths, dashes within the SVG's rounding), the
// same subpaths with the same point counts and closed flags, every coordinate within rounding.
//   node e2e/art_parity.mjs DIR
// Run by tests/e2e/web_test.sh. Prints one line per frame; exits 1 on the first difference.
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { join } from "node:path";

import { artForFrame, keysFromProto } from "../src/page/art.js";
import { LineCap, LineJoin } from "../src/gen/inbetween/v1/inbetween_pb.js";

const dir = process.argv[2];
if (!dir) throw new Error("usage: node e2e/art_parity.mjs DIR");
const doc = JSON.parse(readFileSync(join(dir, "frames.json"), "utf8"));
assert.ok(Array.isArray(doc.art) && doc.art.length >= 2, "frames.json has no art");

// frames.json "art" (docs/file-formats.md) as the InbetweenHeader.art messages the page gets.
const rgb = (hex) => parseInt(hex.slice(1), 16);
const header = doc.art.map((k) => ({
  key: k.key,
  layers: k.layers.map((l) => ({
    paint: {
      id: l.id ?? "",
      name: l.name ?? "",
      opacity: l.opacity,
      fill: l.fill && { rgb: rgb(l.fill.color), opacity: l.fill.opacity, evenOdd: l.fill.rule === "evenodd" },
      stroke: l.stroke && {
        rgb: rgb(l.stroke.color),
        opacity: l.stroke.opacity,
        width: l.stroke.width,
        cap: LineCap[l.stroke.cap.toUpperCase()],
        join: LineJoin[l.stroke.join.toUpperCase()],
        miterLimit: l.stroke.miter_limit,
        dashes: l.stroke.dashes,
        dashOffset: l.stroke.dash_offset,
      },
    },
    paths: l.paths.map((p) => ({
      triangles: p.points.map((q) => q[0]),
      barycentric: p.points.flatMap((q) => q.slice(1)),
      closed: p.closed,
    })),
  })),
}));
const keys = keysFromProto(header, Uint32Array.from(doc.triangles.flat()), doc.keys.length);

// The <path> elements of a frame SVG: attributes and subpaths ({ points: [x, y, ...], closed }).
function svgPaths(svg) {
  return [...svg.matchAll(/<path ([^>]*)\/>/g)].map(([, attrs]) => {
    const a = Object.fromEntries([...attrs.matchAll(/([\w-]+)="([^"]*)"/g)].map((m) => [m[1], m[2]]));
    const subpaths = [];
    for (const [, cmd, x, y, z] of a.d.matchAll(/([ML])(\S+) (\S+?)(Z?)(?= |$)/g)) {
      if (cmd === "M") subpaths.push({ points: [], closed: false });
      const last = subpaths[subpaths.length - 1];
      last.points.push(Number(x), Number(y));
      if (z) last.closed = true;
    }
    return { a, subpaths };
  });
}

const num = (v, fallback) => (v === undefined ? fallback : Number(v));
const close = (actual, expected, what, scale = 1) => {
  const tol = 1e-8 * Math.max(scale, Math.abs(expected));
  assert.ok(Math.abs(actual - expected) <= tol, `${what}: art.js ${expected}, C++ ${actual}`);
};
const hex = (v) => `#${v.toString(16).padStart(6, "0")}`;

let morphed = 0;
for (const frame of doc.frames) {
  const name = `frame_${String(frame.index).padStart(4, "0")}.svg`;
  const xy = Float64Array.from(frame.vertices.flat());
  const layers = artForFrame(keys, xy, frame.weights).filter(
    (l) => (l.fill || l.stroke) && l.paths.some((p) => p.points.length > 0));
  const drawn = svgPaths(readFileSync(join(dir, name), "utf8"));
  const where = (l) => `${name} layer ${l + 1}`;
  assert.equal(drawn.length, layers.length, `${name}: ${drawn.length} <path>s, art.js has ${layers.length} layers`);
  // Coordinates are compared at the scale of the drawing (the SVG keeps 9 significant digits).
  const extent = Math.max(...xy.map(Math.abs), 1);
  layers.forEach((layer, l) => {
    const { a, subpaths } = drawn[l];
    assert.equal(a["data-layer"] ?? "", layer.name, `${where(l)} name`);
    assert.equal(a.fill, layer.fill ? hex(layer.fill.rgb) : "none", `${where(l)} fill`);
    if (layer.fill) {
      close(num(a["fill-opacity"], 1), layer.fill.opacity, `${where(l)} fill-opacity`);
      assert.equal(a["fill-rule"] === "evenodd", layer.fill.evenOdd, `${where(l)} fill-rule`);
    }
    assert.equal(a.stroke, layer.stroke ? hex(layer.stroke.rgb) : "none", `${where(l)} stroke`);
    if (layer.stroke) {
      const s = layer.stroke;
      close(num(a["stroke-width"]), s.width, `${where(l)} stroke-width`);
      close(num(a["stroke-opacity"], 1), s.opacity, `${where(l)} stroke-opacity`);
      assert.equal(a["stroke-linecap"] ?? "butt", s.cap, `${where(l)} stroke-linecap`);
      assert.equal(a["stroke-linejoin"] ?? "miter", s.join, `${where(l)} stroke-linejoin`);
      if (s.join === "miter") close(num(a["stroke-miterlimit"], 4), s.miterLimit, `${where(l)} stroke-miterlimit`);
      const dashes = a["stroke-dasharray"]?.split(" ").map(Number) ?? [];
      assert.equal(dashes.length, s.dashes.length, `${where(l)} stroke-dasharray ${a["stroke-dasharray"]}`);
      dashes.forEach((d, i) => close(d, s.dashes[i], `${where(l)} dash ${i + 1}`));
      if (s.dashes.length) close(num(a["stroke-dashoffset"], 0), s.dashOffset, `${where(l)} stroke-dashoffset`);
    }
    close(num(a.opacity, 1), layer.opacity, `${where(l)} opacity`);
    const paths = layer.paths.filter((p) => p.points.length > 0);
    assert.equal(subpaths.length, paths.length, `${where(l)} subpaths`);
    paths.forEach((p, j) => {
      assert.equal(subpaths[j].closed, p.closed, `${where(l)} path ${j + 1} closed`);
      assert.equal(subpaths[j].points.length, p.points.length, `${where(l)} path ${j + 1}: point count`);
      subpaths[j].points.forEach((v, i) => close(v, p.points[i], `${where(l)} path ${j + 1} coordinate ${i}`, extent));
    });
  });
  const active = frame.weights.filter((w) => w > 0).length;
  if (active > 1) morphed++;
  console.log(`ok   ${name}: ${layers.length} layers, weights ${frame.weights.map((w) => w.toFixed(3)).join(" ")}`);
}
assert.ok(morphed >= 1, "no frame between the keys");
console.log(`art parity: ${doc.frames.length} frames agree with the C++ rule (${morphed} between keys)`);
