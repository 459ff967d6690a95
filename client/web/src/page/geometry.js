// Small 2D helpers for the page: bounds, a fit-to-canvas view, orientation, boundary loops of a
// triangle mesh, nearest point on polylines. Coordinates are the drawings' user units, y down.

export function emptyBounds() {
  return { minX: Infinity, minY: Infinity, maxX: -Infinity, maxY: -Infinity };
}

export function addPoint(b, x, y) {
  if (x < b.minX) b.minX = x;
  if (y < b.minY) b.minY = y;
  if (x > b.maxX) b.maxX = x;
  if (y > b.maxY) b.maxY = y;
  return b;
}

export function isEmpty(b) {
  return !(b.maxX >= b.minX && b.maxY >= b.minY);
}

// A view that fits bounds `b` into a w×h pixel box with `pad` pixels around, aspect kept.
export function fitView(b, w, h, pad = 12) {
  if (isEmpty(b)) b = { minX: 0, minY: 0, maxX: 200, maxY: 200 };
  const bw = Math.max(b.maxX - b.minX, 1e-9);
  const bh = Math.max(b.maxY - b.minY, 1e-9);
  const scale = Math.min((w - 2 * pad) / bw, (h - 2 * pad) / bh);
  const ox = (w - scale * bw) / 2 - scale * b.minX;
  const oy = (h - scale * bh) / 2 - scale * b.minY;
  return {
    scale,
    ox,
    oy,
    toScreen: (x, y) => [ox + scale * x, oy + scale * y],
    toWorld: (sx, sy) => [(sx - ox) / scale, (sy - oy) / scale],
  };
}

// Twice the signed area with y down; > 0 = clockwise on screen = the proto's "inside" outline.
export function signedArea2(points) {
  let a = 0;
  for (let i = 0; i < points.length; i++) {
    const p = points[i];
    const q = points[(i + 1) % points.length];
    a += p.x * q.y - q.x * p.y;
  }
  return a;
}

// Closed loops of the edges that belong to exactly one triangle, each following its triangle's
// orientation (so outer loops and holes come out with opposite orientation).
// triangles: flat Uint32Array [a0,b0,c0,a1,...]; returns arrays of vertex indices.
export function boundaryLoops(triangles) {
  const count = new Map();
  const key = (a, b) => (a < b ? `${a},${b}` : `${b},${a}`);
  for (let t = 0; t < triangles.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const e = key(triangles[t + k], triangles[t + ((k + 1) % 3)]);
      count.set(e, (count.get(e) ?? 0) + 1);
    }
  }
  const next = new Map();
  for (let t = 0; t < triangles.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const a = triangles[t + k];
      const b = triangles[t + ((k + 1) % 3)];
      if (count.get(key(a, b)) === 1) next.set(a, b);
    }
  }
  const loops = [];
  const used = new Set();
  for (const start of next.keys()) {
    if (used.has(start)) continue;
    const loop = [];
    let v = start;
    while (v !== undefined && !used.has(v)) {
      used.add(v);
      loop.push(v);
      v = next.get(v);
    }
    if (loop.length >= 3) loops.push(loop);
  }
  return loops;
}

// Nearest point to (x, y) on any of the polylines (arrays of {x, y}); closed ones wrap.
export function nearestOnPolylines(polylines, x, y) {
  let best = null;
  let bestD = Infinity;
  for (const { points, closed } of polylines) {
    const n = points.length;
    const segs = closed ? n : n - 1;
    for (let i = 0; i < segs; i++) {
      const p = points[i];
      const q = points[(i + 1) % n];
      const dx = q.x - p.x;
      const dy = q.y - p.y;
      const len2 = dx * dx + dy * dy;
      const t = len2 > 0 ? Math.max(0, Math.min(1, ((x - p.x) * dx + (y - p.y) * dy) / len2)) : 0;
      const cx = p.x + t * dx;
      const cy = p.y + t * dy;
      const d = (cx - x) ** 2 + (cy - y) ** 2;
      if (d < bestD) {
        bestD = d;
        best = { x: cx, y: cy };
      }
    }
  }
  return best;
}
