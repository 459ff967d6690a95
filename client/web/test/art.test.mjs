// The page's frame art (src/page/art.js), the port of solver/art/frame_art.h: key frames give
// the key's placed art exactly, corresponding layers morph (midway positions and paint),
// the others cross-fade with opacity × weight in key order, named layers correspond across paint
// orders, an added layer leaves the others morphing, art chunks are appended to their key, and
// the painter draws fills, strokes and groups as client/render/art_painter.cpp does. The art is
// embedded here by a small point-location helper (the server's embedding adds edge crossings,
// which the rule does not care about); tests/e2e/web_test.sh checks the port against the CLI's
// own frames (client/web/e2e/art_parity.mjs).
import assert from "node:assert/strict";
import { test } from "node:test";

import { create } from "@bufbuild/protobuf";

import {
  alignClosedPath,
  appendArtChunk,
  arcLengthParameters,
  artForFrame,
  blendPaths,
  blendRgb,
  keysFromProto,
  meanSquaredDistance,
  paintArt,
  placeArt,
  placePath,
  pointAtParameter,
  polygonSignedArea2,
} from "../src/page/art.js";
import { KeyArtSchema, LineCap, LineJoin } from "../src/gen/inbetween/v1/inbetween_pb.js";

// ------------------------------------------------------------------------------------------
// A multimesh: an nx × ny grid of squares (two triangles each), jittered; more shapes by
// mapping its vertices.

function grid(nx, ny, jitter) {
  const xy = [];
  let seed = 12345;
  const rand = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648) - 0.5;
  for (let j = 0; j <= ny; j++) {
    for (let i = 0; i <= nx; i++) {
      const inner = i > 0 && i < nx && j > 0 && j < ny;
      xy.push(i + (inner ? jitter * rand() : 0), j + (inner ? jitter * rand() : 0));
    }
  }
  const triangles = [];
  const v = (i, j) => j * (nx + 1) + i;
  for (let j = 0; j < ny; j++) {
    for (let i = 0; i < nx; i++) {
      triangles.push(v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j), v(i + 1, j + 1), v(i, j + 1));
    }
  }
  return { xy: Float64Array.from(xy), triangles: Uint32Array.from(triangles) };
}

function mapped(xy, f) {
  const out = new Float64Array(xy.length);
  for (let i = 0; i < xy.length; i += 2) [out[i], out[i + 1]] = f(xy[i], xy[i + 1]);
  return out;
}

const rotatedStretched = (x, y) => {
  const c = Math.cos(0.4);
  const s = Math.sin(0.4);
  const dx = x - 4;
  const dy = y - 3;
  return [1.5 * (4 + c * dx - s * dy), 3 + s * dx + c * dy];
};

// Triangle and barycentric coordinates of (x, y) in geometry `xy`: the containing triangle.
function locate(mesh, xy, x, y) {
  const t = mesh.triangles;
  for (let k = 0; k < t.length / 3; k++) {
    const [ax, ay, bx, by, cx, cy] = [0, 1, 2].flatMap((c) => [xy[2 * t[3 * k + c]], xy[2 * t[3 * k + c] + 1]]);
    const det = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
    const b1 = ((x - ax) * (cy - ay) - (cx - ax) * (y - ay)) / det;
    const b2 = ((bx - ax) * (y - ay) - (x - ax) * (by - ay)) / det;
    const b0 = 1 - b1 - b2;
    if (b0 >= -1e-12 && b1 >= -1e-12 && b2 >= -1e-12) return [k, b0, b1, b2];
  }
  throw new Error(`(${x}, ${y}) is outside the mesh`);
}

// Drawn layers: { paint (ArtLayer init), paths: [{ points: [[x, y], ...], closed }] }.
function fillLayer(points, rgb, extra = {}) {
  return { paint: { fill: { rgb, opacity: 1 }, opacity: 1, ...extra }, paths: [{ points, closed: true }] };
}
function strokeLayer(points, rgb, width, extra = {}) {
  return {
    paint: {
      stroke: { rgb, opacity: 1, width, cap: LineCap.ROUND, join: LineJoin.BEVEL, miterLimit: 4 },
      opacity: 1,
      ...extra,
    },
    paths: [{ points, closed: false }],
  };
}

// A KeyArt (the protobuf message, as the page receives it) of `layers`, given in the mesh's
// first shape (for the shapes here, affine images of it, the same as drawing their image there).
function keyArt(mesh, key, layers) {
  const xy = mesh.xy;
  return create(KeyArtSchema, {
    key,
    layers: layers.map((l) => ({
      paint: l.paint,
      paths: l.paths.map((p) => {
        const located = p.points.map(([x, y]) => locate(mesh, xy, x, y));
        return { triangles: located.map((q) => q[0]), barycentric: located.flatMap((q) => q.slice(1)), closed: p.closed };
      }),
    })),
  });
}

const shifted = (points, [dx, dy]) => points.map(([x, y]) => [x + dx, y + dy]);
const quad = [[1, 1], [6, 1.2], [6.5, 4.5], [1.2, 4.8]];
const zigzag = [[0.5, 0.5], [7.5, 5.5], [3, 5.5]];
// A head (fill) with a stroke across it, as in the C++ test.
function head(shift, fill, width) {
  return [fillLayer(shifted(quad, shift), fill, { id: "head" }), strokeLayer(shifted(zigzag, shift), 0x000000, width)];
}
const triangleAt = ([x, y], r = 0.4) => [[x - r, y - r], [x + r, y - r], [x, y + r]];

const pts = (points) => [...points];
function nearAll(actual, expected, tol, what) {
  assert.equal(actual.length, expected.length, `${what}: ${actual.length} vs ${expected.length} coordinates`);
  for (let i = 0; i < actual.length; i++) {
    assert.ok(Math.abs(actual[i] - expected[i]) <= tol, `${what}[${i}]: ${actual[i]} vs ${expected[i]}`);
  }
}

// The distance from (x, y) to the packed polyline `path` (closed: with its closing segment).
function distanceToPolyline(path, closed, [x, y]) {
  const n = path.length / 2;
  let best = Math.hypot(path[0] - x, path[1] - y);
  const segments = closed ? n : n - 1;
  for (let i = 0; i < segments; i++) {
    const j = (i + 1) % n;
    const [ax, ay, bx, by] = [path[2 * i], path[2 * i + 1], path[2 * j], path[2 * j + 1]];
    const dx = bx - ax;
    const dy = by - ay;
    const d2 = dx * dx + dy * dy;
    const t = d2 === 0 ? 0 : Math.min(Math.max(((x - ax) * dx + (y - ay) * dy) / d2, 0), 1);
    best = Math.min(best, Math.hypot(ax + t * dx - x, ay + t * dy - y));
  }
  return best;
}
const pairsOf = (flat) => Array.from({ length: flat.length / 2 }, (_, i) => [flat[2 * i], flat[2 * i + 1]]);

function twoShapes() {
  const mesh = grid(8, 6, 0.25);
  return { mesh, shapes: [mesh.xy, mapped(mesh.xy, rotatedStretched)] };
}

// ------------------------------------------------------------------------------------------

test("a key frame gives that key's placed art exactly, whatever the other keys hold", () => {
  const { mesh, shapes } = twoShapes();
  const art0 = [...head([0, 0], 0x204060, 1), fillLayer(triangleAt([2.5, 2.5]), 0xff0000, { name: "eye" })];
  const art1 = [...head([0.3, 0.2], 0x60a020, 3), strokeLayer([[2, 2], [3, 3]], 0x00ff00, 0.5)];
  const keys = keysFromProto([keyArt(mesh, 0, art0), keyArt(mesh, 1, art1)], mesh.triangles);
  // Placed in its own shape, a key's art is what was drawn.
  const placed0 = placeArt(keys[0], shapes[0]);
  placed0.forEach((layer, l) => nearAll(pts(layer.paths[0].points), art0[l].paths[0].points.flat(), 1e-12, `layer ${l}`));
  assert.deepEqual(artForFrame(keys, shapes[0], [1, 0]), placed0);
  assert.deepEqual(artForFrame(keys, shapes[1], [0, 1]), placeArt(keys[1], shapes[1]));
  // The paint comes through as drawn.
  const [headLayer, stroke, eye] = placed0;
  assert.deepEqual({ id: headLayer.id, fill: headLayer.fill, stroke: headLayer.stroke, opacity: headLayer.opacity },
    { id: "head", fill: { rgb: 0x204060, opacity: 1, evenOdd: false }, stroke: null, opacity: 1 });
  assert.deepEqual(stroke.stroke, {
    rgb: 0, opacity: 1, width: 1, cap: "round", join: "bevel", miterLimit: 4, dashes: [], dashOffset: 0,
  });
  assert.equal(eye.name, "eye");
  // Weights need not sum to 1: only the active keys count.
  assert.deepEqual(artForFrame(keys, shapes[1], [0, 2.5]), placeArt(keys[1], shapes[1]));
});

test("two keys with the same layers morph: midway positions and blended paint", () => {
  const mesh = grid(8, 6, 0.25);
  const xy = mesh.xy; // one geometry: the art's own motion is all there is
  const a = head([0, 0], 0x204060, 1);
  const b = head([0.5, 0.25], 0x60a020, 3);
  a[0].paint.fill.opacity = 0.2;
  b[0].paint.fill.opacity = 0.6;
  b[0].paint.opacity = 0.5;
  b[1].paint.stroke.cap = LineCap.SQUARE;
  const keys = keysFromProto([keyArt(mesh, 0, a), keyArt(mesh, 1, b)], mesh.triangles);
  const mid = artForFrame(keys, xy, [0.5, 0.5]);
  assert.equal(mid.length, 2);
  const [fill, stroke] = mid;
  // Positions: the same parametrization in both keys, so each point is the midpoint.
  nearAll(pts(fill.paths[0].points), shifted(quad, [0.25, 0.125]).flat(), 1e-12, "fill path");
  nearAll(pts(stroke.paths[0].points), shifted(zigzag, [0.25, 0.125]).flat(), 1e-12, "stroke path");
  assert.equal(fill.paths[0].closed, true);
  assert.equal(stroke.paths[0].closed, false);
  assert.equal(fill.fill.rgb, 0x407040);
  assert.ok(Math.abs(fill.fill.opacity - 0.4) < 1e-15);
  assert.equal(fill.opacity, 0.75);
  assert.equal(stroke.stroke.width, 2);
  // Ties go to the lower key: its cap.
  assert.equal(stroke.stroke.cap, "round");
  // A quarter of the way: colours per channel, rounded; discrete paint from the heavier key.
  const quarter = artForFrame(keys, xy, [0.25, 0.75]);
  assert.equal(quarter[0].fill.rgb, 0x508830);
  assert.equal(quarter[1].stroke.width, 2.5);
  assert.equal(quarter[1].stroke.cap, "square");
  nearAll(pts(quarter[0].paths[0].points), shifted(quad, [0.375, 0.1875]).flat(), 1e-12, "quarter");
});

test("layers without a counterpart cross-fade with opacity × weight, outgoing under incoming", () => {
  const { mesh, shapes } = twoShapes();
  const eyeA = fillLayer(triangleAt([3, 2.5]), 0xff0000, { opacity: 0.8 }); // a filled eye
  const eyeB = strokeLayer([[2.5, 2.5], [3.5, 2.5]], 0x0000ff, 0.3); // a stroke: another kind
  const back = strokeLayer([[0.2, 0.2], [7.8, 0.2]], 0x888888, 0.2); // drawn first, key 2 only
  const art0 = [...head([0, 0], 0x204060, 1).slice(0, 1), eyeA];
  const art1 = [back, ...head([0, 0], 0x204060, 1).slice(0, 1), eyeB];
  const keys = keysFromProto([keyArt(mesh, 0, art0), keyArt(mesh, 1, art1)], mesh.triangles);
  const xy = mapped(shapes[0], (x, y) => [x + 0.1, y]);
  const frame = artForFrame(keys, xy, [0.3, 0.7]);
  // The head morphs; the background stroke comes before every morphed layer, as in key 2; both
  // eyes come right after the head, key 1's under key 2's.
  assert.deepEqual(frame.map((l) => [l.fill?.rgb, l.stroke?.rgb]), [
    [undefined, 0x888888],
    [0x204060, undefined],
    [0xff0000, undefined],
    [undefined, 0x0000ff],
  ]);
  assert.equal(frame[0].opacity, 0.7);
  assert.equal(frame[2].opacity, 0.8 * 0.3);
  assert.equal(frame[3].opacity, 0.7);
  // A cross-faded layer is its key's layer placed in the frame.
  assert.deepEqual(frame[2].paths, placeArt(keys[0], xy)[1].paths);
  assert.deepEqual(frame[3].paths, placeArt(keys[1], xy)[2].paths);
  // Whatever the weights, the order stays (keys by index, not by weight).
  const other = artForFrame(keys, xy, [0.9, 0.1]);
  assert.deepEqual(other.map((l) => l.opacity), [0.1, 1, 0.8 * 0.9, 0.1]);

  // Same name, one closed path vs two far from it: no pairing, both cross-fade.
  const one = fillLayer(triangleAt([3, 3]), 0xff0000, { name: "eyes" });
  const two = fillLayer(triangleAt([2, 3]), 0x00ff00, { name: "eyes" });
  two.paths.push({ points: triangleAt([4, 3]), closed: true });
  const named = keysFromProto([keyArt(mesh, 0, [one]), keyArt(mesh, 1, [two])], mesh.triangles);
  const faded = artForFrame(named, xy, [0.5, 0.5]);
  assert.deepEqual(faded.map((l) => [l.fill.rgb, l.opacity, l.paths.length]), [[0xff0000, 0.5, 1], [0x00ff00, 0.5, 2]]);
});

test("named layers correspond across paint orders; the first key's order is kept", () => {
  const { mesh, shapes } = twoShapes();
  const x = (rgb, at) => fillLayer(triangleAt(at), rgb, { name: "x" });
  const y = (rgb, at) => fillLayer(triangleAt(at), rgb, { name: "y" });
  const keys = keysFromProto([
    keyArt(mesh, 0, [x(0x100000, [2, 2]), y(0x001000, [5, 4])]),
    keyArt(mesh, 1, [y(0x003000, [5, 2]), x(0x300000, [3, 4])]),
  ], mesh.triangles);
  const frame = artForFrame(keys, shapes[0], [0.5, 0.5]);
  assert.deepEqual(frame.map((l) => [l.name, l.fill.rgb, l.opacity]), [["x", 0x200000, 1], ["y", 0x002000, 1]]);
  // Only key 2 active: its own order.
  assert.deepEqual(artForFrame(keys, shapes[1], [0, 1]).map((l) => l.name), ["y", "x"]);
  // Without name matching the layers align in paint order (y with x: both fills).
  const byOrder = artForFrame(keys, shapes[0], [0.5, 0.5], { matchByName: false });
  assert.deepEqual(byOrder.map((l) => [l.name, l.fill.rgb]), [["x", 0x081800], ["y", 0x180800]]);
  // Neither: everything cross-fades.
  assert.equal(artForFrame(keys, shapes[0], [0.5, 0.5], { matchByName: false, matchByOrder: false }).length, 4);
});

test("a key that adds a layer keeps the others morphing (paint-order alignment)", () => {
  const { mesh, shapes } = twoShapes();
  const face = (rgb) => fillLayer([[0.5, 0.5], [7.5, 0.5], [7.5, 5.5], [0.5, 5.5]], rgb);
  const eye = (at, rgb) => fillLayer(triangleAt(at, 0.3), rgb);
  const mouth = (y) => strokeLayer([[2, y], [4, y + 0.3], [6, y]], 0x000000, 0.2);
  const nose = fillLayer(triangleAt([4, 3.2], 0.3), 0xff66cc);
  const art0 = [face(0xfcea2b), eye([2.5, 2], 0xc81e1e), eye([5.5, 2], 0xc81e1e), mouth(4.5)];
  const art1 = [face(0xfcea2b), eye([2.6, 2.2], 0x1e8c1e), eye([5.4, 2.2], 0x1e8c1e), nose, mouth(4.6)];
  const keys = keysFromProto([keyArt(mesh, 0, art0), keyArt(mesh, 1, art1)], mesh.triangles);
  const frame = artForFrame(keys, shapes[0], [0.5, 0.5]);
  assert.deepEqual(frame.map((l) => [l.fill?.rgb ?? l.stroke.rgb, l.opacity]), [
    [0xfcea2b, 1],
    [blendRgb([[0xc81e1e, 0.5], [0x1e8c1e, 0.5]]), 1],
    [blendRgb([[0xc81e1e, 0.5], [0x1e8c1e, 0.5]]), 1],
    [0xff66cc, 0.5], // the nose fades in right after the eye it follows in key 2
    [0x000000, 1],
  ]);
  // Each eye morphs with the eye on its own side.
  const left = frame[1].paths[0].points;
  assert.ok(left[0] < 3 && frame[2].paths[0].points[0] > 4.5);
});

test("three active keys: one group per layer, paint blended over all three", () => {
  const { mesh, shapes } = twoShapes();
  const keys = keysFromProto([0x300000, 0x003000, 0x000030].map((rgb, k) =>
    keyArt(mesh, k, [fillLayer(triangleAt([3 + k * 0.5, 3]), rgb), strokeLayer([[1, 1], [2 + k, 2]], rgb, 1 + k)])),
  mesh.triangles);
  const frame = artForFrame(keys, shapes[0], [0.5, 0.25, 0.25]);
  assert.deepEqual(frame.map((l) => [l.fill?.rgb ?? l.stroke.rgb, l.opacity]), [[0x180c0c, 1], [0x180c0c, 1]]);
  assert.equal(frame[1].stroke.width, 0.5 * 1 + 0.25 * 2 + 0.25 * 3);
  nearAll(pts(frame[0].paths[0].points), triangleAt([3 + 0.25 * 0.5 + 0.25 * 1, 3]).flat(), 1e-12, "triangle");
  // Key 3 draws its stroke first: order-preserving, one pair can stay (of equals the stroke:
  // skipping the backbone's fill wins). The fills cross-fade, keys 1 and 2's before the stroke,
  // key 3's after it, as in each key's paint order.
  const swapped = keysFromProto([...[0, 1].map((k) => keyArt(mesh, k, [fillLayer(triangleAt([3, 3]), 0x300000),
    strokeLayer([[1, 1], [2, 2]], 0, 1)])), keyArt(mesh, 2, [strokeLayer([[1, 1], [2, 2]], 0, 1),
    fillLayer(triangleAt([3, 3]), 0x300000)])], mesh.triangles);
  const order = artForFrame(swapped, shapes[0], [1, 1, 1]);
  assert.deepEqual(order.map((l) => [l.fill !== null, l.opacity]), [[true, 1 / 3], [true, 1 / 3], [false, 1], [true, 1 / 3]]);
});

test("in paint-order alignment equal colours outweigh lying close", () => {
  const { mesh, shapes } = twoShapes();
  const red = strokeLayer([[2, 2], [3, 2]], 0xff0000, 0.2); // where key 2's stroke is
  const black = strokeLayer([[5, 4], [6, 4]], 0x000000, 0.2); // its colour, further away
  const keys = keysFromProto([keyArt(mesh, 0, [red, black]), keyArt(mesh, 1, [strokeLayer([[2, 2.2], [3, 2.2]], 0, 0.2)])],
    mesh.triangles);
  const frame = artForFrame(keys, shapes[0], [0.5, 0.5]);
  assert.deepEqual(frame.map((l) => [l.stroke.rgb, l.opacity]), [[0xff0000, 0.5], [0x000000, 1]]);
  nearAll(pts(frame[1].paths[0].points), [3.5, 3.1, 4.5, 3.1], 1e-12, "black morphs with black");
});

test("alignment ties go to the earliest pairing", () => {
  const { mesh, shapes } = twoShapes();
  const dot = (id) => fillLayer(triangleAt([4, 3]), 0x123456, { id });
  const keys = keysFromProto([keyArt(mesh, 0, [dot("a")]), keyArt(mesh, 1, [dot("b1"), dot("b2")])], mesh.triangles);
  // Key 2's first dot pairs (its second fades in after the pair); key 1, the heavier, names it.
  assert.deepEqual(artForFrame(keys, shapes[0], [0.6, 0.4]).map((l) => [l.id, l.opacity]), [["a", 1], ["b2", 0.4]]);
  const reversed = keysFromProto([keyArt(mesh, 0, [dot("b1"), dot("b2")]), keyArt(mesh, 1, [dot("a")])], mesh.triangles);
  assert.deepEqual(artForFrame(reversed, shapes[0], [0.4, 0.6]).map((l) => [l.id, l.opacity]), [["a", 1], ["b2", 0.4]]);
});

test("art chunks are appended to their key's layers in order", () => {
  const { mesh, shapes } = twoShapes();
  const layers0 = [0, 1, 2, 3].map((i) => fillLayer(triangleAt([1 + i, 2]), 0x101010 * (i + 1), { id: `a${i}` }));
  const layers1 = [0, 1].map((i) => fillLayer(triangleAt([2 + i, 4]), 0x0f0f0f * (i + 1), { id: `b${i}` }));
  const whole = [keyArt(mesh, 0, layers0), keyArt(mesh, 1, layers1)];
  // The header holds each key's first layer; then chunks for key 0, key 1, key 0.
  const header = [keyArt(mesh, 0, layers0.slice(0, 1)), keyArt(mesh, 1, layers1.slice(0, 1))];
  const chunks = [
    keyArt(mesh, 0, layers0.slice(1, 3)),
    keyArt(mesh, 1, layers1.slice(1)),
    keyArt(mesh, 0, layers0.slice(3)),
  ];
  for (const c of chunks) appendArtChunk(header, c);
  assert.deepEqual(header.map((k) => k.layers.map((l) => l.paint.id)), [["a0", "a1", "a2", "a3"], ["b0", "b1"]]);
  assert.deepEqual(keysFromProto(header, mesh.triangles), keysFromProto(whole, mesh.triangles));
  assert.throws(() => appendArtChunk(header, keyArt(mesh, 2, layers0)), /art for key 2, not in its header/);
  // A drawing the header has no art for has no layers; so has every drawing past the last.
  const keys = keysFromProto([whole[1]], mesh.triangles, 3);
  assert.deepEqual(keys.map((k) => [k.key, k.layers.length]), [[0, 0], [1, 2], [2, 0]]);
});

test("errors: weights, vertices and triangle indices", () => {
  const { mesh, shapes } = twoShapes();
  const art = [keyArt(mesh, 0, head([0, 0], 1, 1)), keyArt(mesh, 1, head([0, 0], 2, 1))];
  const keys = keysFromProto(art, mesh.triangles);
  assert.throws(() => artForFrame(keys, shapes[0], [1]), /1 weights for the art of 2 keys/);
  assert.throws(() => artForFrame(keys, shapes[0], [NaN, 1]), /weight 1 is not finite/);
  assert.throws(() => artForFrame(keys, shapes[0], [0, 0]), /no key has a weight > 0/);
  assert.throws(() => artForFrame(keys, shapes[0].subarray(0, 20), [1, 0]), /the frame has 10/);
  assert.throws(() => keysFromProto(art, mesh.triangles.subarray(0, 9)), /triangle \d+ of 3/);
});

test("blend_paths: arc-length parameters, corners kept, ends kept", () => {
  const square = Float64Array.from([0, 0, 2, 0, 2, 2, 0, 2]);
  assert.deepEqual([...arcLengthParameters(square, true)], [0, 0.25, 0.5, 0.75]);
  assert.deepEqual([...arcLengthParameters(square, false)], [0, 1 / 3, 2 / 3, 1]);
  assert.deepEqual([...arcLengthParameters(Float64Array.from([1, 1, 1, 1]), false)], [0, 0]);
  const params = arcLengthParameters(square, true);
  assert.deepEqual(pointAtParameter(square, true, params, 0.875), [0, 1]); // on the closing side
  assert.deepEqual(pointAtParameter(square, false, arcLengthParameters(square, false), 1), [0, 2]);
  // A line of 2 points with a bent line of 3: the blend has the corner's parameter too.
  const line = Float64Array.from([0, 0, 4, 0]);
  const bent = Float64Array.from([0, 0, 2, 2, 4, 0]);
  const mid = blendPaths([line, bent], false, [0.5, 0.5], 1e-9);
  nearAll([...mid], [0, 0, 2, 1, 4, 0], 1e-12, "blend");
  assert.equal(blendPaths([bent], false, [1], 1e-9), bent);
  // Weights 1 and 0: the first path, at the union of both paths' parameters.
  nearAll([...blendPaths([bent, line], false, [1, 0], 1e-9)], [...bent], 1e-12, "weight 1");
  // Samples merged into the end of an open path: the end stays the end.
  const late = Float64Array.from([0, 0, 9, 0, 10, 0]);
  nearAll([...blendPaths([late, line], false, [0.5, 0.5], 0.3)], [0, 0, 7, 0], 1e-12, "merged end");
  // Rounding: per channel, half away from zero.
  assert.equal(blendRgb([[0x000001, 0.5], [0x000002, 0.5]]), 0x000002);
  assert.equal(blendRgb([[0xffffff, 1]]), 0xffffff);
});

test("blend_paths: closed paths are aligned to the reference's start and direction", () => {
  const flat = (points) => Float64Array.from(points.flat());
  const square = flat([[0, 0], [4, 0], [4, 4], [0, 4]]);
  // Started at the third corner; drawn the other way; started half-way along a side.
  assert.deepEqual([...alignClosedPath(square, flat([[4, 4], [0, 4], [0, 0], [4, 0]]))], [...square]);
  assert.deepEqual([...alignClosedPath(square, flat([[0, 0], [0, 4], [4, 4], [4, 0]]))], [...square]);
  const octagonLike = flat([[2, 0], [4, 0], [4, 4], [0, 4], [0, 0]]);
  assert.deepEqual([...alignClosedPath(square, octagonLike)], [0, 0, 2, 0, 4, 0, 4, 4, 0, 4]);
  // A start between the path's own vertices gets a vertex there: same point set.
  const shiftedSquare = flat([[1, 1], [5, 1], [5, 5], [1, 5]]);
  const diamond = [[3, 0], [6, 3], [3, 6], [0, 3]];
  const aligned = pairsOf(alignClosedPath(shiftedSquare, flat(diamond)));
  assert.equal(aligned.length, 5);
  for (const p of diamond) assert.ok(aligned.some((q) => q[0] === p[0] && q[1] === p[1]), `${p} kept`);
  assert.ok(Math.hypot(aligned[0][0] - 1.5, aligned[0][1] - 1.5) < 0.2, `starts at ${aligned[0]}`);
  // Too short to align: as given.
  assert.deepEqual([...alignClosedPath(square, flat([[0, 0], [1, 1]]))], [0, 0, 1, 1]);
  // Twice the signed area, positive counter-clockwise in y-up axes; the mean squared distance of
  // aligned samples.
  assert.equal(polygonSignedArea2(square), 32);
  assert.equal(polygonSignedArea2(flat([[0, 0], [0, 4], [4, 4], [4, 0]])), -32);
  assert.equal(meanSquaredDistance(square, square), 0);
  assert.ok(Math.abs(meanSquaredDistance(square, flat([[1, 0], [5, 0], [5, 4], [1, 4]])) - 1) < 1e-12);
  assert.equal(meanSquaredDistance(square, flat([[0, 0], [1, 1]])), Infinity);
});

// A closed path drawn from another corner, or the other way round, in the other key still morphs
// in place: the same square in both keys (one geometry) stays that square midway.
test("closed paths drawn from other starts morph in place", () => {
  const mesh = grid(8, 6, 0.25);
  const xy = mesh.xy;
  const square = [[1, 1], [6, 1], [6, 5], [1, 5]];
  const fromThird = [[6, 5], [1, 5], [1, 1], [6, 1]];
  const reversed = [[6, 1], [1, 1], [1, 5], [6, 5]];
  const flatSquare = square.flat();
  for (const other of [fromThird, reversed]) {
    const keys = keysFromProto([keyArt(mesh, 0, [fillLayer(square, 0x204060)]), keyArt(mesh, 1, [fillLayer(other, 0x204060)])],
      mesh.triangles);
    for (const s of [0.25, 0.5, 0.75]) {
      const out = artForFrame(keys, xy, [1 - s, s]);
      assert.equal(out.length, 1);
      const got = out[0].paths[0].points;
      for (const p of pairsOf(got)) assert.ok(distanceToPolyline(flatSquare, true, p) < 1e-9, `${s}: ${p} on the square`);
      for (const corner of square) assert.ok(distanceToPolyline(got, true, corner) < 1e-9, `${s}: corner ${corner} kept`);
    }
  }
});

// A fill that gains a hole (a mouth that opens) morphs instead of fading: its outline pairs with
// the other key's outline, and the hole, which the other key lacks, is carried by the mesh. A
// fill whose outline would pair only with a far path (one cell that becomes two) cross-fades.
test("fills that gain a hole morph; cells that split cross-fade", () => {
  const mesh = grid(8, 6, 0.25);
  const xy = mesh.xy;
  const face = [[1, 1], [7, 1], [7, 5], [1, 5]];
  const open = fillLayer(face, 0x204060);
  open.paths.push({ points: [[3, 2], [5, 2], [5, 3], [3, 3]], closed: true });
  const keys = keysFromProto([keyArt(mesh, 0, [fillLayer(face, 0x204060)]), keyArt(mesh, 1, [open])], mesh.triangles);
  const out = artForFrame(keys, xy, [0.5, 0.5]);
  assert.equal(out.length, 1);
  assert.equal(out[0].opacity, 1);
  assert.equal(out[0].paths.length, 2);
  for (const p of pairsOf(out[0].paths[0].points)) assert.ok(distanceToPolyline(face.flat(), true, p) < 1e-9, `${p} on the face`);
  assert.deepEqual(out[0].paths[1], { points: placePath(keys[1].layers[0].paths[1], xy), closed: true });

  const two = fillLayer([[0.5, 1], [3, 1], [3, 5], [0.5, 5]], 0x204060);
  two.paths.push({ points: [[5, 1], [7.5, 1], [7.5, 5], [5, 5]], closed: true });
  const split = keysFromProto([keyArt(mesh, 0, [fillLayer(face, 0x204060)]), keyArt(mesh, 1, [two])], mesh.triangles);
  const faded = artForFrame(split, xy, [0.25, 0.75]);
  assert.equal(faded.length, 2);
  assert.equal(faded[0].opacity, 0.25);
  assert.equal(faded[1].opacity, 0.75);
  assert.equal(faded[1].paths.length, 2);
  // Each is its key's layer placed in the frame.
  assert.deepEqual(faded[0].paths, placeArt(split[0], xy)[0].paths);
  assert.deepEqual(faded[1].paths, placeArt(split[1], xy)[0].paths);
});

// ------------------------------------------------------------------------------------------
// The painter, against a context that records what it is asked to do.

function recordingContext(width = 100, height = 80, log = []) {
  const state = { globalAlpha: 1, fillStyle: "#000", strokeStyle: "#000", lineWidth: 1, lineCap: "butt",
    lineJoin: "miter", miterLimit: 10, lineDashOffset: 0 };
  const stack = [];
  let dash = [];
  let transform = { a: 1, b: 0, c: 0, d: 1, e: 0, f: 0 };
  const ctx = {
    canvas: { width, height },
    log,
    save: () => stack.push({ state: { ...state }, dash, transform }),
    restore: () => {
      const saved = stack.pop();
      Object.assign(state, saved.state);
      dash = saved.dash;
      transform = saved.transform;
    },
    beginPath: () => log.push(["beginPath"]),
    moveTo: (x, y) => log.push(["moveTo", x, y]),
    lineTo: (x, y) => log.push(["lineTo", x, y]),
    closePath: () => log.push(["closePath"]),
    setLineDash: (d) => (dash = d),
    getTransform: () => transform,
    setTransform: (...m) => (transform = m.length === 1 ? m[0] : { a: m[0], b: m[1], c: m[2], d: m[3], e: m[4], f: m[5] }),
    clearRect: () => log.push(["clearRect"]),
    fill: (rule) => log.push(["fill", rule, state.fillStyle, state.globalAlpha]),
    stroke: () => log.push(["stroke", state.strokeStyle, state.globalAlpha, state.lineWidth, state.lineCap,
      state.lineJoin, state.miterLimit, [...dash], state.lineDashOffset]),
    drawImage: (img) => log.push(["drawImage", img.id, state.globalAlpha]),
  };
  return new Proxy(ctx, {
    get: (t, k) => (k in t ? t[k] : state[k]),
    set: (t, k, v) => ((k in t ? (t[k] = v) : (state[k] = v)), true),
  });
}

test("paintArt: fill rules, stroke paint, dashes, opacity, groups, in paint order", () => {
  const view = { scale: 2, toScreen: (x, y) => [10 + 2 * x, 20 + 2 * y] };
  const square = { points: Float64Array.from([0, 0, 1, 0, 1, 1]), closed: true };
  const layers = [
    { opacity: 0.5, fill: { rgb: 0x112233, opacity: 0.8, evenOdd: true }, stroke: null, paths: [square] },
    {
      opacity: 1, fill: null, paths: [{ points: Float64Array.from([0, 0, 3, 0]), closed: false }],
      stroke: { rgb: 0xff0000, opacity: 0.5, width: 1.5, cap: "round", join: "bevel", miterLimit: 3, dashes: [1, 2], dashOffset: 0.5 },
    },
    { opacity: 1, fill: null, paths: [square],
      stroke: { rgb: 0xabcdef, opacity: 1, width: 1, cap: "butt", join: "miter", miterLimit: 4, dashes: [0, 0], dashOffset: 0 } },
    { opacity: 0, fill: { rgb: 0, opacity: 1, evenOdd: false }, stroke: null, paths: [square] }, // invisible
    { opacity: 1, fill: null, stroke: null, paths: [square] }, // no paint
  ];
  const ctx = recordingContext();
  paintArt(ctx, layers, view);
  const paint = ctx.log.filter((e) => e[0] === "fill" || e[0] === "stroke");
  assert.deepEqual(paint, [
    ["fill", "evenodd", "#112233", 0.4],
    ["stroke", "#ff0000", 0.5, 3, "round", "bevel", 3, [2, 4], 1],
    ["stroke", "#abcdef", 1, 2, "butt", "miter", 4, [], 0], // zero-length dashes: solid
  ]);
  assert.deepEqual(ctx.log.slice(0, 5), [["beginPath"], ["moveTo", 10, 20], ["lineTo", 12, 20], ["lineTo", 12, 22], ["closePath"]]);

  // A fill and a stroke with opacity < 1: drawn at full alpha into a group, painted at 0.6.
  const made = [];
  globalThis.OffscreenCanvas = class {
    constructor(width, height) {
      Object.assign(this, { width, height, id: `group${made.length}` });
      made.push(this);
    }
    getContext() {
      const g = recordingContext(this.width, this.height);
      g.canvas = this;
      this.ctx = g;
      return g;
    }
  };
  try {
    const both = { opacity: 0.6, fill: { rgb: 0x00ff00, opacity: 1, evenOdd: false }, paths: [square],
      stroke: { rgb: 0x0000ff, opacity: 0.9, width: 1, cap: "butt", join: "miter", miterLimit: 4, dashes: [], dashOffset: 0 } };
    const main = recordingContext();
    paintArt(main, [both, both], view);
    assert.equal(made.length, 1, "one group canvas, reused");
    assert.deepEqual(main.log.filter((e) => e[0] === "drawImage"), [["drawImage", "group0", 0.6], ["drawImage", "group0", 0.6]]);
    assert.deepEqual(made[0].ctx.log.filter((e) => e[0] === "fill" || e[0] === "stroke").map((e) => e.slice(0, 3)),
      [["fill", "nonzero", "#00ff00"], ["stroke", "#0000ff", 0.9], ["fill", "nonzero", "#00ff00"], ["stroke", "#0000ff", 0.9]]);
    assert.equal(made[0].ctx.log.filter((e) => e[0] === "clearRect").length, 2);
  } finally {
    delete globalThis.OffscreenCanvas;
  }
});
