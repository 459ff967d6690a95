// A frame's art for the page: the drawings' layered paint, placed from the Inbetween header's
// art (KeyArt: every art point as a triangle and barycentric coordinates) at a frame's vertices,
// combined by the frame's example weights, and painted on a canvas. A port of the C++ rule, kept
// to the same arithmetic and tie-breaks so that the page draws what the CLI's renderers draw:
//  - placement: solver/art/art_embedding.h (PlacePath, PlaceArt);
//  - resampling, alignment of closed paths and blending of corresponding paths:
//    solver/art/blend_paths.h;
//  - which layers morph and which cross-fade, paint blending, draw order: solver/art/frame_art.h
//    (ArtForFrame), whose header states the rule this file follows line by line;
//  - painting: client/render/art_painter.h (cairo), here with the canvas 2D context.
//
// Points are packed: a placed path's points are a Float64Array [x0, y0, x1, y1, ...], and frame
// vertices the same (the player keeps each frame so). A layer is
//   { id, name, opacity, fill: null | { rgb, opacity, evenOdd },
//     stroke: null | { rgb, opacity, width, cap, join, miterLimit, dashes, dashOffset },
//     paths: [{ points, closed }] }
// with rgb = 0xRRGGBB, cap "butt" | "round" | "square" and join "miter" | "round" | "bevel" (the
// canvas's own names), as solver/core/art.h's ArtLayer.
import { LineCap, LineJoin } from "../gen/inbetween/v1/inbetween_pb.js";

// FrameArtOptions (frame_art.h), with the same defaults.
export const DEFAULT_OPTIONS = Object.freeze({
  matchByName: true, // layers with equal non-empty names correspond
  matchByOrder: true, // unnamed layers aligned in paint order correspond
  maxAlignmentCells: 4e6, // above it, unnamed layers align index to index (equal counts)
  mergeFraction: 1e-9, // arc-length samples closer than this are one
});

// ------------------------------------------------------------------------------------------
// The header's art

function paintFromProto(p) {
  const out = {
    id: p?.id ?? "",
    name: p?.name ?? "",
    opacity: p?.opacity ?? 0,
    fill: null,
    stroke: null,
  };
  if (p?.fill) out.fill = { rgb: p.fill.rgb >>> 0, opacity: p.fill.opacity, evenOdd: p.fill.evenOdd };
  if (p?.stroke) {
    const s = p.stroke;
    out.stroke = {
      rgb: s.rgb >>> 0,
      opacity: s.opacity,
      width: s.width,
      // UNSPECIFIED (and any value this page does not know) = butt / miter, as the C++ reads it.
      cap: s.cap === LineCap.ROUND ? "round" : s.cap === LineCap.SQUARE ? "square" : "butt",
      join: s.join === LineJoin.ROUND ? "round" : s.join === LineJoin.BEVEL ? "bevel" : "miter",
      miterLimit: s.miterLimit,
      dashes: [...s.dashes],
      dashOffset: s.dashOffset,
    };
  }
  return out;
}

// Appends an InbetweenResponse.art message (a KeyArt continuing its key's layers) to the
// header's art (`art`: InbetweenHeader.art, changed in place), as InbetweenHeader.art_messages
// says. Throws when the header has no KeyArt with that key.
export function appendArtChunk(art, chunk) {
  let target = null;
  for (const k of art) if (k.key === chunk.key) target = k;
  if (!target) throw new Error(`Inbetween stream sent art for key ${chunk.key}, not in its header`);
  target.layers.push(...chunk.layers);
  return art;
}

// The header's art (InbetweenHeader.art, every chunk appended) as the keys that artForFrame
// takes: one per drawing, index = KeyArt.key (a drawing missing from the header has no layers),
// each path's triangle indices resolved to vertex indices with `triangles` (flat [a0, b0, c0,
// a1, ...], InbetweenHeader.triangles). Throws on a triangle index out of range or a barycentric
// list that is not 3 per point.
export function keysFromProto(art, triangles, drawings = 0) {
  const count = Math.max(drawings, ...art.map((k) => k.key + 1));
  const keys = Array.from({ length: count }, (_, key) => ({ key, layers: [] }));
  const numTriangles = Math.floor(triangles.length / 3);
  for (const k of art) {
    keys[k.key].layers = k.layers.map((layer, l) => ({
      paint: paintFromProto(layer.paint),
      paths: layer.paths.map((path, p) => {
        const where = `art of drawing ${k.key + 1}, layer ${l + 1}, path ${p + 1}`;
        const n = path.triangles.length;
        if (path.barycentric.length !== 3 * n) {
          throw new Error(`${where}: ${path.barycentric.length} barycentric coordinates for ${n} points`);
        }
        const corners = new Uint32Array(3 * n);
        for (let i = 0; i < n; i++) {
          const t = path.triangles[i];
          if (!(t < numTriangles)) throw new Error(`${where}: triangle ${t} of ${numTriangles}`);
          corners[3 * i] = triangles[3 * t];
          corners[3 * i + 1] = triangles[3 * t + 1];
          corners[3 * i + 2] = triangles[3 * t + 2];
        }
        return { corners, barycentric: Float64Array.from(path.barycentric), closed: path.closed };
      }),
    }));
  }
  return keys;
}

// True when some key has a layer: the frames have art to draw.
export function hasArt(keys) {
  return keys.some((k) => k.layers.length > 0);
}

// ------------------------------------------------------------------------------------------
// Placement (art_embedding.h)

// The path's points in geometry `xy`: b0 v[a] + b1 v[b] + b2 v[c] per point.
export function placePath(path, xy) {
  const { corners: c, barycentric: b } = path;
  const n = c.length / 3;
  const out = new Float64Array(2 * n);
  for (let i = 0; i < n; i++) {
    const a = 2 * c[3 * i];
    const e = 2 * c[3 * i + 1];
    const f = 2 * c[3 * i + 2];
    const b0 = b[3 * i];
    const b1 = b[3 * i + 1];
    const b2 = b[3 * i + 2];
    out[2 * i] = b0 * xy[a] + b1 * xy[e] + b2 * xy[f];
    out[2 * i + 1] = b0 * xy[a + 1] + b1 * xy[e + 1] + b2 * xy[f + 1];
  }
  return out;
}

function copyPaint(paint) {
  return {
    id: paint.id,
    name: paint.name,
    opacity: paint.opacity,
    fill: paint.fill ? { ...paint.fill } : null,
    stroke: paint.stroke ? { ...paint.stroke, dashes: [...paint.stroke.dashes] } : null,
  };
}

// Throws unless every point of `keys` refers to a vertex of `xy` (frame_art.h: art embedded in a
// mesh of another vertex count is an error).
function checkVertices(keys, xy) {
  const nv = xy.length / 2;
  for (const k of keys) {
    for (const layer of k.layers) {
      for (const path of layer.paths) {
        for (const v of path.corners) {
          if (!(v < nv)) {
            throw new Error(`frame art: drawing ${k.key + 1}'s art uses vertex ${v}, the frame has ${nv}`);
          }
        }
      }
    }
  }
}

// A key's art in geometry `xy`: paint as embedded, every path placed (PlaceArt).
export function placeArt(key, xy) {
  checkVertices([key], xy);
  return key.layers.map((layer) => ({
    ...copyPaint(layer.paint),
    paths: layer.paths.map((path) => ({ points: placePath(path, xy), closed: path.closed })),
  }));
}

// ------------------------------------------------------------------------------------------
// Morph of corresponding paths (blend_paths.h)

// Normalized arc-length parameter of every vertex of packed `path`: 0 at the first, 1 at the last
// of an open path; a closed path's closing segment counts. All 0 for a path of zero length.
export function arcLengthParameters(path, closed) {
  const n = path.length / 2;
  const params = new Float64Array(n);
  for (let i = 1; i < n; i++) {
    const dx = path[2 * i] - path[2 * i - 2];
    const dy = path[2 * i + 1] - path[2 * i - 1];
    params[i] = params[i - 1] + Math.sqrt(dx * dx + dy * dy);
  }
  let total = 0;
  if (n > 0) {
    const dx = path[0] - path[2 * n - 2];
    const dy = path[1] - path[2 * n - 1];
    total = params[n - 1] + (closed ? Math.sqrt(dx * dx + dy * dy) : 0);
  }
  if (!(total > 0)) return new Float64Array(n);
  for (let i = 0; i < n; i++) params[i] /= total;
  if (!closed) params[n - 1] = 1; // exactly, whatever the rounding of the sum
  return params;
}

// First index of `params` (ascending) whose value is > u (std::upper_bound).
function upperBound(params, u) {
  let lo = 0;
  let hi = params.length;
  while (lo < hi) {
    const mid = (lo + hi) >>> 1;
    if (params[mid] > u) hi = mid;
    else lo = mid + 1;
  }
  return lo;
}

// The point [x, y] at normalized arc length u of packed `path` (`params` from
// arcLengthParameters); the first point for a path of zero length.
export function pointAtParameter(path, closed, params, u) {
  const n = path.length / 2;
  if (n === 1 || params[n - 1] === 0) return [path[0], path[1]];
  const i = upperBound(params, u);
  const a = i === 0 ? 0 : i - 1;
  if (a + 1 === n && !closed) return [path[2 * n - 2], path[2 * n - 1]];
  const b = (a + 1) % n;
  const end = a + 1 === n ? 1 : params[b];
  const span = end - params[a];
  const t = span > 0 ? Math.min(Math.max((u - params[a]) / span, 0), 1) : 0;
  if (t === 0) return [path[2 * a], path[2 * a + 1]];
  return [path[2 * a] + t * (path[2 * b] - path[2 * a]), path[2 * a + 1] + t * (path[2 * b + 1] - path[2 * a + 1])];
}

// Twice the signed area of the closed packed polygon: the sum of cross(p_i, p_{i+1}) in index
// order, cross(a, b) = a.x * b.y - a.y * b.x (solver/geometry/primitives.h PolygonSignedArea2).
export function polygonSignedArea2(path) {
  const n = path.length / 2;
  let sum = 0;
  for (let i = 0; i < n; i++) {
    const j = (i + 1) % n;
    sum += path[2 * i] * path[2 * j + 1] - path[2 * i + 1] * path[2 * j];
  }
  return sum;
}

const ALIGN_SAMPLES = 64;

// Samples of the closed packed `path` at arc-length offsets (i / ALIGN_SAMPLES + shift) mod 1,
// packed.
function uniformSamples(path, params, shift) {
  const out = new Float64Array(2 * ALIGN_SAMPLES);
  for (let i = 0; i < ALIGN_SAMPLES; i++) {
    let u = i / ALIGN_SAMPLES + shift;
    u -= Math.floor(u);
    const [x, y] = pointAtParameter(path, true, params, u);
    out[2 * i] = x;
    out[2 * i + 1] = y;
  }
  return out;
}

// The sum over points of |a_i - b_i|^2 (packed, same length).
function squaredDistances(a, b) {
  let sum = 0;
  for (let i = 0; i < a.length; i += 2) {
    const dx = a[i] - b[i];
    const dy = a[i + 1] - b[i + 1];
    sum += dx * dx + dy * dy;
  }
  return sum;
}

// Closed packed `path` started at arc-length offset u in (0, 1) (params from
// arcLengthParameters): a first vertex there unless u falls on a vertex.
function restartAt(path, params, u) {
  const n = path.length / 2;
  const a = upperBound(params, u) - 1;
  const [sx, sy] = pointAtParameter(path, true, params, u);
  const out = [sx, sy];
  for (let k = 1; k <= n; k++) {
    const q = (a + k) % n;
    const px = path[2 * q];
    const py = path[2 * q + 1];
    const atStart = px === sx && py === sy;
    if (k === n && atStart) break; // the offset fell on vertex a
    if (k === 1 && atStart) continue; // or on vertex a + 1
    out.push(px, py);
  }
  return Float64Array.from(out);
}

// Closed packed `path` restarted and, when needed, reversed so that it runs along `reference`
// (closed, packed, in the same space): the same direction (the sign of the enclosed area), and
// the start at the arc-length offset whose 64 uniform samples lie closest to the reference's
// (every offset of the sample grid, then a golden-section search between its neighbours). A new
// first vertex is inserted at that offset unless it falls on a vertex. Returned as is when either
// path has fewer than 3 points or no length (blend_paths.h AlignClosedPath).
export function alignClosedPath(reference, path) {
  if (reference.length / 2 < 3 || path.length / 2 < 3) return path;
  let p = path;
  if (polygonSignedArea2(reference) * polygonSignedArea2(p) < 0) {
    // The other direction, from the same first point.
    const n = path.length / 2;
    p = new Float64Array(path.length);
    p[0] = path[0];
    p[1] = path[1];
    for (let k = 1; k < n; k++) {
      p[2 * k] = path[2 * (n - k)];
      p[2 * k + 1] = path[2 * (n - k) + 1];
    }
  }
  const refParams = arcLengthParameters(reference, true);
  const params = arcLengthParameters(p, true);
  if (refParams[refParams.length - 1] === 0 || params[params.length - 1] === 0) return p;
  const ref = uniformSamples(reference, refParams, 0);
  const grid = uniformSamples(p, params, 0);
  // Every offset of the sample grid: sample i of the reference against sample i + k of the path.
  let best = 0;
  let bestCost = 0;
  for (let k = 0; k < ALIGN_SAMPLES; k++) {
    let cost = 0;
    for (let i = 0; i < ALIGN_SAMPLES; i++) {
      const j = (i + k) % ALIGN_SAMPLES;
      const dx = ref[2 * i] - grid[2 * j];
      const dy = ref[2 * i + 1] - grid[2 * j + 1];
      cost += dx * dx + dy * dy;
    }
    if (k === 0 || cost < bestCost) {
      best = k;
      bestCost = cost;
    }
  }
  // Refined between the neighbouring grid offsets (golden-section search on the sampled cost).
  const costAt = (shift) => squaredDistances(ref, uniformSamples(p, params, shift));
  const step = 1 / ALIGN_SAMPLES;
  const ratio = (Math.sqrt(5) - 1) / 2;
  let lo = (best - 1) * step;
  let hi = (best + 1) * step;
  let x1 = hi - ratio * (hi - lo);
  let x2 = lo + ratio * (hi - lo);
  let f1 = costAt(x1);
  let f2 = costAt(x2);
  for (let it = 0; it < 40; it++) {
    if (f1 <= f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - ratio * (hi - lo);
      f1 = costAt(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + ratio * (hi - lo);
      f2 = costAt(x2);
    }
  }
  let shift = f1 <= f2 ? x1 : x2;
  const least = f2 < f1 ? f2 : f1; // std::min(f1, f2)
  if (least >= costAt(0)) return p; // the drawn start is as good
  shift -= Math.floor(shift);
  // An offset within a hair of a vertex is that vertex (no near-duplicate first point).
  for (const v of params) {
    if (Math.abs(v - shift) < 1e-9) shift = v;
  }
  if (shift >= 1 - 1e-9 || shift === 0) return p;
  return restartAt(p, params, shift);
}

// Mean squared distance between 64 uniform arc-length samples of two closed packed paths, sample
// i of one against sample i of the other (so: after alignClosedPath). Infinity when either has
// fewer than 3 points or no length (blend_paths.h MeanSquaredDistance).
export function meanSquaredDistance(a, b) {
  if (a.length / 2 < 3 || b.length / 2 < 3) return Infinity;
  const pa = arcLengthParameters(a, true);
  const pb = arcLengthParameters(b, true);
  if (pa[pa.length - 1] === 0 || pb[pb.length - 1] === 0) return Infinity;
  return squaredDistances(uniformSamples(a, pa, 0), uniformSamples(b, pb, 0)) / ALIGN_SAMPLES;
}

// sum_k weights[k] paths[k](u) / sum_k weights[k], sampled at the union of every path's own
// vertex parameters (those within `mergeFraction` of a kept one merged into it). Every path has
// at least one point; one path is returned as is.
export function blendPaths(paths, closed, weights, mergeFraction) {
  if (paths.length === 1) return paths[0];
  const params = [];
  const all = [];
  let totalWeight = 0;
  for (let k = 0; k < paths.length; k++) {
    params.push(arcLengthParameters(paths[k], closed));
    for (const u of params[k]) all.push(u);
    totalWeight += weights[k];
  }
  all.sort((x, y) => x - y);
  const samples = [];
  for (const u of all) {
    if (samples.length === 0 || u - samples[samples.length - 1] > mergeFraction) samples.push(u);
  }
  if (!closed) samples[samples.length - 1] = 1; // the ends stay the ends
  const out = new Float64Array(2 * samples.length);
  samples.forEach((u, s) => {
    let x = 0;
    let y = 0;
    for (let k = 0; k < paths.length; k++) {
      const [px, py] = pointAtParameter(paths[k], closed, params[k], u);
      x += weights[k] * px;
      y += weights[k] * py;
    }
    out[2 * s] = x / totalWeight;
    out[2 * s + 1] = y / totalWeight;
  });
  return out;
}

// ------------------------------------------------------------------------------------------
// Which layers correspond (frame_art.cpp)

// A group member: one layer of one key, with that key's weight normalized over the active keys.
// A group has one member per active key, in key order.

const sameKind = (a, b) => (a.fill !== null) === (b.fill !== null) && (a.stroke !== null) === (b.stroke !== null);

// Closed, non-empty paths only: layers of such paths morph even when their path counts differ
// (a face that gains a mouth hole, one cell that becomes two), see morphLayer.
function allClosedAndDrawn(layer) {
  if (layer.paths.length === 0) return false;
  for (const path of layer.paths) if (!path.closed || path.corners.length === 0) return false;
  return true;
}

// Same path count, and each path closed (and empty) in all members or in none; or closed,
// non-empty paths in every member, in any count.
function sameGeometry(keys, group) {
  const first = keys[group[0].key].layers[group[0].layer];
  if (group.every((m) => allClosedAndDrawn(keys[m.key].layers[m.layer]))) return true;
  for (const m of group) {
    const layer = keys[m.key].layers[m.layer];
    if (layer.paths.length !== first.paths.length) return false;
    for (let j = 0; j < layer.paths.length; j++) {
      if (layer.paths[j].closed !== first.paths[j].closed ||
          (layer.paths[j].corners.length === 0) !== (first.paths[j].corners.length === 0)) {
        return false;
      }
    }
  }
  return true;
}

// Same kind of paint and the same path structure (path count, each closed in both or neither),
// or closed non-empty paths in both.
function compatible(a, b) {
  if (!sameKind(a.paint, b.paint)) return false;
  if (allClosedAndDrawn(a) && allClosedAndDrawn(b)) return true;
  if (a.paths.length !== b.paths.length) return false;
  for (let j = 0; j < a.paths.length; j++) if (a.paths[j].closed !== b.paths[j].closed) return false;
  return true;
}

// The mean of the layer's points placed in the frame.
function centroid(layer, xy) {
  let sx = 0;
  let sy = 0;
  let count = 0;
  for (const path of layer.paths) {
    const p = placePath(path, xy);
    for (let i = 0; i < p.length; i += 2) {
      sx += p[i];
      sy += p[i + 1];
      count++;
    }
  }
  return count > 0 ? [sx / count, sy / count] : [sx, sy];
}

// The paint-order alignment of b's unnamed layers to a's (an index into b per layer of a, or -1):
// the order-preserving matching of compatible layers with the largest score (frame_art.cpp's
// AlignLayers: 2 for equal colours, else 1, plus 1 / (1 + d / size) for centroids d apart in a
// frame of diagonal size; the first of equal choices wins: pair, then skip a, then skip b).
function alignLayers(a, b, xy, named, maxCells) {
  const n = a.length;
  const m = b.length;
  const match = new Array(n).fill(-1);
  const ok = (i, j) => !named(a[i]) && !named(b[j]) && compatible(a[i], b[j]);
  if (n * m > maxCells) {
    if (n === m) for (let i = 0; i < n; i++) match[i] = ok(i, i) ? i : -1;
    return match;
  }
  let minX = Infinity;
  let minY = Infinity;
  let maxX = -Infinity;
  let maxY = -Infinity;
  for (let i = 0; i < xy.length; i += 2) {
    minX = Math.min(minX, xy[i]);
    minY = Math.min(minY, xy[i + 1]);
    maxX = Math.max(maxX, xy[i]);
    maxY = Math.max(maxY, xy[i + 1]);
  }
  const dx = maxX - minX;
  const dy = maxY - minY;
  const size = Math.max(xy.length === 0 ? 0 : Math.sqrt(dx * dx + dy * dy), 1e-300);
  const ca = a.map((l) => centroid(l, xy));
  const cb = b.map((l) => centroid(l, xy));
  const score = (i, j) => {
    if (!ok(i, j)) return 0;
    const p = a[i].paint;
    const q = b[j].paint;
    const same = (!p.fill || p.fill.rgb === q.fill.rgb) && (!p.stroke || p.stroke.rgb === q.stroke.rgb);
    const ex = ca[i][0] - cb[j][0];
    const ey = ca[i][1] - cb[j][1];
    return (same ? 2 : 1) + 1 / (1 + Math.sqrt(ex * ex + ey * ey) / size);
  };
  // best[i][j]: the best score aligning a[i..] with b[j..]; step: 0 pair, 1 skip a[i], 2 skip b[j].
  const w = m + 1;
  const best = new Float64Array((n + 1) * w);
  const step = new Uint8Array((n + 1) * w).fill(1);
  for (let i = n - 1; i >= 0; i--) {
    for (let j = m - 1; j >= 0; j--) {
      const s = score(i, j);
      const at = i * w + j;
      best[at] = s > 0 ? s + best[at + w + 1] : -1;
      step[at] = 0;
      if (best[at + w] > best[at]) {
        best[at] = best[at + w];
        step[at] = 1;
      }
      if (best[at + 1] > best[at]) {
        best[at] = best[at + 1];
        step[at] = 2;
      }
    }
  }
  for (let i = 0, j = 0; i < n && j < m;) {
    const s = step[i * w + j];
    if (s === 0) match[i++] = j++;
    else if (s === 1) i++;
    else j++;
  }
  return match;
}

// The morphing groups among `active` (key indices ascending, weights normalized), ordered by
// their layer in the first active key (the backbone).
function matchLayers(keys, active, xy, options) {
  let groups = [];
  const named = (l) => options.matchByName && l.paint.name !== "";
  if (options.matchByName) {
    const byName = new Map(); // name -> occurrence -> group
    for (const a of active) {
      const seen = new Map();
      keys[a.key].layers.forEach((layer, l) => {
        if (!named(layer)) return;
        const name = layer.paint.name;
        const occurrence = seen.get(name) ?? 0;
        seen.set(name, occurrence + 1);
        if (!byName.has(name)) byName.set(name, new Map());
        const groupsOfName = byName.get(name);
        if (!groupsOfName.has(occurrence)) groupsOfName.set(occurrence, []);
        groupsOfName.get(occurrence).push({ key: a.key, layer: l, weight: a.weight });
      });
    }
    for (const groupsOfName of byName.values()) {
      for (const group of groupsOfName.values()) if (group.length === active.length) groups.push(group);
    }
  }
  if (options.matchByOrder) {
    const backbone = keys[active[0].key].layers;
    const byLayer = backbone.map((layer, l) =>
      named(layer) ? [] : [{ key: active[0].key, layer: l, weight: active[0].weight }]);
    for (let k = 1; k < active.length; k++) {
      const match = alignLayers(backbone, keys[active[k].key].layers, xy, named, options.maxAlignmentCells);
      for (let l = 0; l < backbone.length; l++) {
        if (match[l] >= 0) byLayer[l].push({ key: active[k].key, layer: match[l], weight: active[k].weight });
      }
    }
    for (const group of byLayer) if (group.length === active.length) groups.push(group);
  }
  groups = groups.filter((g) => sameGeometry(keys, g));
  // Each backbone layer is in one group at most: the order is the backbone's paint order.
  groups.sort((g, h) => g[0].layer - h[0].layer);
  return groups;
}

// ------------------------------------------------------------------------------------------
// Morph of a group's paint (frame_art.cpp's Morph)

// Per 8-bit channel, the weighted mean over [rgb, weight] pairs, rounded (half away from zero).
export function blendRgb(colours) {
  let total = 0;
  for (const [, w] of colours) total += w;
  let out = 0;
  for (const shift of [16, 8, 0]) {
    let v = 0;
    for (const [rgb, w] of colours) v += w * ((rgb >>> shift) & 0xff);
    out |= Math.min(Math.max(Math.round(v / total), 0), 255) << shift;
  }
  return out >>> 0;
}

// The heaviest member for which `has` holds (ties: the lower key); members are in key order.
function heaviest(group, has) {
  let best = null;
  for (const m of group) if (has(m) && (best === null || m.weight > best.weight)) best = m;
  return best;
}

// A key's layer cross-faded: its paint at `weight` times its opacity, placed in the frame.
function fadedLayer(layer, weight, xy) {
  const faded = copyPaint(layer.paint);
  faded.opacity *= weight;
  faded.paths = layer.paths.map((path) => ({ points: placePath(path, xy), closed: path.closed }));
  return faded;
}

// The length of a closed packed polyline.
function pathLength(path) {
  const n = path.length / 2;
  let length = 0;
  for (let i = 0; i < n; i++) {
    const j = (i + 1) % n;
    const dx = path[2 * j] - path[2 * i];
    const dy = path[2 * j + 1] - path[2 * i + 1];
    length += Math.sqrt(dx * dx + dy * dy);
  }
  return length;
}

// The group's morphed layer, or null when its closed paths come in different counts and do not
// pair up closely (see morphUnequalCounts): then its layers cross-fade.
function morphLayer(keys, group, xy, options) {
  const layerOf = (m) => keys[m.key].layers[m.layer];
  const top = heaviest(group, () => true);
  const out = copyPaint(layerOf(top).paint);
  out.opacity = 0;
  for (const m of group) out.opacity += m.weight * layerOf(m).paint.opacity;
  out.fill = morphFill(group, layerOf);
  out.stroke = morphStroke(group, layerOf);
  const weights = group.map((m) => m.weight);
  // The first member with the most paths (std::max_element).
  let most = 0;
  for (let m = 1; m < group.length; m++) {
    if (layerOf(group[most]).paths.length < layerOf(group[m]).paths.length) most = m;
  }
  if (group.some((m) => layerOf(m).paths.length !== layerOf(group[most]).paths.length)) {
    const paths = morphUnequalCounts(group, layerOf, xy, weights, most, options);
    if (paths === null) return null;
    out.paths = paths;
    return out;
  }
  out.paths = layerOf(top).paths.map((path, j) => {
    const placed = group.map((m) => placePath(layerOf(m).paths[j], xy));
    const closed = path.closed;
    // Closed paths drawn from other points or in the other direction in different keys: each
    // runs from the point nearest the first member's start, in its direction, in this frame.
    if (closed && placed[0].length > 0) {
      for (let m = 1; m < placed.length; m++) placed[m] = alignClosedPath(placed[0], placed[m]);
    }
    return {
      points: placed[0].length === 0 ? new Float64Array(0) : blendPaths(placed, closed, weights, options.mergeFraction),
      closed,
    };
  });
  return out;
}

// polygon.h PolygonContains: even-odd crossing test of (qx, qy) against a flat polygon.
function polygonContains(polygon, qx, qy) {
  let inside = false;
  const n = polygon.length / 2;
  for (let i = 0, j = n - 1; i < n; j = i++) {
    const ax = polygon[2 * i], ay = polygon[2 * i + 1];
    const bx = polygon[2 * j], by = polygon[2 * j + 1];
    if ((ay > qy) !== (by > qy)) {
      const x = ax + ((qy - ay) * (bx - ax)) / (by - ay);
      if (qx < x) inside = !inside;
    }
  }
  return inside;
}

// Closed paths in different counts (a face that gains a mouth hole, one cell that becomes two):
// each path of the member with the most (group[most]) morphs with the path of every other member
// that pairs with it, nearest first (mean squared distance of their aligned placements in this
// frame), and a member without a partner for it lends that path's own placement (the mesh
// carries it). Pairs must lie close (root mean squared distance under PAIR_DISTANCE of the
// path's length), else null: the layers cross-fade (frame_art.cpp's MorphUnequalCounts).
function morphUnequalCounts(group, layerOf, xy, weights, most, options) {
  const PAIR_DISTANCE = 0.02;
  const place = (m) => layerOf(m).paths.map((path) => placePath(path, xy));
  const full = place(group[most]);
  // partner[m][j]: member m's path (aligned) that morphs with full[j], or null.
  const partner = [];
  for (let m = 0; m < group.length; m++) {
    partner.push(new Array(full.length).fill(null));
    if (m === most) {
      for (let j = 0; j < full.length; j++) partner[m][j] = full[j];
      continue;
    }
    const own = place(group[m]);
    const pairs = [];
    for (let i = 0; i < own.length; i++) {
      for (let j = 0; j < full.length; j++) {
        const aligned = alignClosedPath(full[j], own[i]);
        pairs.push({ cost: meanSquaredDistance(full[j], aligned), i, j, aligned });
      }
    }
    // Stable (as std::stable_sort with a.cost < b.cost).
    pairs.sort((a, b) => (a.cost < b.cost ? -1 : b.cost < a.cost ? 1 : 0));
    const used = new Array(own.length).fill(false);
    for (const pair of pairs) {
      if (used[pair.i] || partner[m][pair.j] !== null) continue;
      const length = pathLength(full[pair.j]);
      if (!(pair.cost <= PAIR_DISTANCE * PAIR_DISTANCE * length * length)) return null;
      used[pair.i] = true;
      partner[m][pair.j] = pair.aligned;
    }
    // A path this member lacks is carried only if it lies inside one it has (a hole); a separate
    // region it lacks (a second eye) would appear at once, so the layers cross-fade instead.
    for (let j = 0; j < full.length; j++) {
      if (partner[m][j] !== null) continue;
      let inside = false;
      for (let k = 0; k < full.length && !inside; k++) {
        inside = k !== j && partner[m][k] !== null && polygonContains(full[k], full[j][0], full[j][1]);
      }
      if (!inside) return null;
    }
  }
  return full.map((path, j) => ({
    points: blendPaths(group.map((_, m) => partner[m][j] ?? path), true, weights, options.mergeFraction),
    closed: true,
  }));
}

// Present in some member: colour blended among those that have it, opacity among all (a member
// without it counts as opacity 0, so it fades in).
function morphFill(group, layerOf) {
  const top = heaviest(group, (m) => layerOf(m).paint.fill !== null);
  if (top === null) return null;
  const fill = { ...layerOf(top).paint.fill };
  const colours = [];
  fill.opacity = 0;
  for (const m of group) {
    const f = layerOf(m).paint.fill;
    if (!f) continue;
    colours.push([f.rgb, m.weight]);
    fill.opacity += m.weight * f.opacity;
  }
  fill.rgb = blendRgb(colours);
  return fill;
}

function morphStroke(group, layerOf) {
  const has = (m) => layerOf(m).paint.stroke !== null;
  const top = heaviest(group, has);
  if (top === null) return null;
  const stroke = { ...layerOf(top).paint.stroke };
  stroke.dashes = [...stroke.dashes];
  const dashes = stroke.dashes.length;
  let sameDashes = true;
  let present = 0;
  for (const m of group) {
    if (!has(m)) continue;
    present += m.weight;
    sameDashes = sameDashes && layerOf(m).paint.stroke.dashes.length === dashes;
  }
  const colours = [];
  stroke.opacity = 0;
  stroke.width = 0;
  stroke.miterLimit = 0;
  if (sameDashes) {
    stroke.dashes.fill(0);
    stroke.dashOffset = 0;
  }
  for (const m of group) {
    if (!has(m)) continue;
    const s = layerOf(m).paint.stroke;
    const w = m.weight / present; // among the members that stroke
    colours.push([s.rgb, m.weight]);
    stroke.opacity += m.weight * s.opacity;
    stroke.width += w * s.width;
    stroke.miterLimit += w * s.miterLimit;
    if (!sameDashes) continue;
    for (let d = 0; d < dashes; d++) stroke.dashes[d] += w * s.dashes[d];
    stroke.dashOffset += w * s.dashOffset;
  }
  stroke.rgb = blendRgb(colours);
  return stroke;
}

// ------------------------------------------------------------------------------------------
// The frame's art (ArtForFrame)

// The frame's layers in paint order, from `keys` (keysFromProto), the frame's vertices `xy`
// (packed) and its example weights (weights[k] goes with keys[k]). Throws (with the C++ rule's
// messages) on weights and keys of different counts, a non-finite weight, no weight > 0, or art
// that refers to a vertex the frame does not have.
export function artForFrame(keys, xy, weights, options = {}) {
  const opts = { ...DEFAULT_OPTIONS, ...options };
  if (weights.length !== keys.length) {
    throw new Error(`frame art: ${weights.length} weights for the art of ${keys.length} keys`);
  }
  let total = 0;
  for (let k = 0; k < keys.length; k++) {
    if (!Number.isFinite(weights[k])) throw new Error(`frame art: weight ${k + 1} is not finite`);
    if (weights[k] > 0) total += weights[k];
  }
  checkVertices(keys, xy);
  if (!(total > 0)) throw new Error("frame art: no key has a weight > 0");
  const active = [];
  const groupOf = keys.map((k) => new Int32Array(k.layers.length).fill(-1)); // [key][layer] -> group
  for (let k = 0; k < keys.length; k++) {
    // w / total is exactly 1 for a key frame's only active key: its art comes out unchanged.
    if (weights[k] > 0) active.push({ key: k, layer: -1, weight: weights[k] / total });
  }
  const groups = matchLayers(keys, active, xy, opts);
  groups.forEach((group, g) => {
    for (const m of group) groupOf[m.key][m.layer] = g;
  });
  // slots[g + 1]: cross-faded layers drawn right after group g (slots[0]: before every group).
  const slots = Array.from({ length: groups.length + 1 }, () => []);
  for (const a of active) {
    let last = -1;
    keys[a.key].layers.forEach((layer, l) => {
      if (groupOf[a.key][l] >= 0) {
        last = groupOf[a.key][l];
        return;
      }
      slots[last + 1].push(fadedLayer(layer, a.weight, xy));
    });
  }
  const out = slots[0];
  groups.forEach((group, g) => {
    const morphed = morphLayer(keys, group, xy, opts);
    if (morphed !== null) {
      out.push(morphed);
    } else {
      // Not morphable in this frame: its members cross-fade where the group stands.
      for (const m of group) out.push(fadedLayer(keys[m.key].layers[m.layer], m.weight, xy));
    }
    out.push(...slots[g + 1]);
  });
  return out;
}

// ------------------------------------------------------------------------------------------
// Painting (art_painter.h)

export function cssColor(rgb) {
  return `#${(rgb & 0xffffff).toString(16).padStart(6, "0")}`;
}

// A canvas ignores an alpha outside [0, 1] (keeping the previous one): clamp the rounding.
const alpha01 = (a) => (a > 0 ? Math.min(a, 1) : 0);

// Every subpath of the layer as one canvas path, so that the fill rule sees them together.
function appendPath(ctx, layer, view) {
  for (const path of layer.paths) {
    const p = path.points;
    for (let i = 0; i < p.length; i += 2) {
      const [x, y] = view.toScreen(p[i], p[i + 1]);
      if (i === 0) ctx.moveTo(x, y);
      else ctx.lineTo(x, y);
    }
    if (path.closed && p.length > 0) ctx.closePath();
  }
}

function setStroke(ctx, s, scale) {
  ctx.lineWidth = s.width * scale;
  ctx.lineCap = s.cap;
  ctx.lineJoin = s.join;
  // SVG's stroke-miterlimit and the canvas's miterLimit are the same ratio (miter / width).
  if (s.miterLimit > 0) ctx.miterLimit = s.miterLimit;
  // A dash array of zero total length draws a solid line (as in SVG).
  const total = s.dashes.reduce((sum, d) => sum + d, 0);
  if (total > 0) {
    ctx.setLineDash(s.dashes.map((d) => d * scale));
    ctx.lineDashOffset = s.dashOffset * scale;
  } else {
    ctx.setLineDash([]);
  }
}

function paintLayer(ctx, layer, view, alpha) {
  ctx.save();
  ctx.beginPath();
  appendPath(ctx, layer, view);
  if (layer.fill) {
    ctx.globalAlpha = alpha01(layer.fill.opacity * alpha);
    ctx.fillStyle = cssColor(layer.fill.rgb);
    ctx.fill(layer.fill.evenOdd ? "evenodd" : "nonzero");
  }
  if (layer.stroke && layer.stroke.width > 0) {
    setStroke(ctx, layer.stroke, view.scale);
    ctx.globalAlpha = alpha01(layer.stroke.opacity * alpha);
    ctx.strokeStyle = cssColor(layer.stroke.rgb);
    ctx.stroke();
  }
  ctx.restore();
}

// A canvas of ctx's size for a layer drawn as a group (one per context, reused).
const scratch = new WeakMap();
function groupContext(ctx) {
  const { width, height } = ctx.canvas;
  let g = scratch.get(ctx);
  if (!g || g.canvas.width !== width || g.canvas.height !== height) {
    const canvas = typeof OffscreenCanvas === "function"
      ? new OffscreenCanvas(width, height)
      : Object.assign(document.createElement("canvas"), { width, height });
    g = canvas.getContext("2d");
    scratch.set(ctx, g);
  }
  g.setTransform(1, 0, 0, 1, 0, 0);
  g.clearRect(0, 0, width, height);
  g.setTransform(ctx.getTransform());
  return g;
}

// Paints `layers` (artForFrame) onto `ctx` through `view` (geometry.js fitView: toScreen, and
// scale for stroke widths and dashes), in paint order: fills with their rule and opacity, then
// strokes with width, cap, join, miter limit and dashes. A layer with a fill, a stroke and
// opacity < 1 is drawn into a group painted with that opacity, as SVG composites an element's
// opacity (where its stroke covers its fill the fill does not show through); every other layer
// multiplies its opacity into its paint's alpha. Leaves the context's state as it found it.
export function paintArt(ctx, layers, view) {
  for (const layer of layers) {
    if ((!layer.fill && !layer.stroke) || layer.paths.length === 0 || !(layer.opacity > 0)) continue;
    const group = layer.fill && layer.stroke && layer.opacity < 1;
    if (!group) {
      paintLayer(ctx, layer, view, layer.opacity);
      continue;
    }
    const g = groupContext(ctx);
    paintLayer(g, layer, view, 1);
    ctx.save();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.globalAlpha = alpha01(layer.opacity);
    ctx.drawImage(g.canvas, 0, 0);
    ctx.restore();
  }
}
