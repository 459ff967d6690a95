// Lottie (Bodymovin 5.x JSON) from the inbetween frames: one shape layer, one path per boundary
// loop of the mesh (edges used by one triangle), a hold keyframe per frame, one fill colour.
import { addPoint, boundaryLoops, emptyBounds, fitView } from "./geometry.js";

function rgb01(hex) {
  const n = parseInt(hex.slice(1), 16);
  return [((n >> 16) & 255) / 255, ((n >> 8) & 255) / 255, (n & 255) / 255, 1];
}

// frames: array of Float64Array [x0,y0,x1,y1,...]; triangles: Uint32Array.
export function makeLottie({ triangles, frames, fps, width, fill = "#3b7dd8", name = "inbetween" }) {
  const b = emptyBounds();
  for (const f of frames) for (let i = 0; i < f.length; i += 2) addPoint(b, f[i], f[i + 1]);
  const aspect = (b.maxY - b.minY) / Math.max(b.maxX - b.minX, 1e-9);
  const height = Math.max(1, Math.round(width * aspect));
  const view = fitView(b, width, height, Math.round(width * 0.04));
  const r = (v) => Math.round(v * 100) / 100;
  const loops = boundaryLoops(triangles);
  const paths = loops.map((loop, li) => ({
    ty: "sh",
    nm: `boundary ${li + 1}`,
    ks: {
      a: 1,
      k: frames.map((f, t) => {
        const v = loop.map((i) => view.toScreen(f[2 * i], f[2 * i + 1]).map(r));
        const zero = loop.map(() => [0, 0]);
        return { t, s: [{ i: zero, o: zero, v, c: true }], h: 1 };
      }),
    },
  }));
  const still = (k) => ({ a: 0, k });
  return {
    v: "5.7.0",
    fr: fps,
    ip: 0,
    op: frames.length,
    w: width,
    h: height,
    nm: name,
    ddd: 0,
    assets: [],
    layers: [
      {
        ddd: 0,
        ind: 1,
        ty: 4,
        nm: "shape",
        sr: 1,
        ks: {
          o: still(100),
          r: still(0),
          p: still([0, 0, 0]),
          a: still([0, 0, 0]),
          s: still([100, 100, 100]),
        },
        ao: 0,
        shapes: [
          {
            ty: "gr",
            nm: "shape",
            it: [
              ...paths,
              { ty: "fl", c: still(rgb01(fill)), o: still(100), r: 1, nm: "fill" },
              {
                ty: "tr",
                p: still([0, 0]),
                a: still([0, 0]),
                s: still([100, 100]),
                r: still(0),
                o: still(100),
                sk: still(0),
                sa: still(0),
              },
            ],
          },
        ],
        ip: 0,
        op: frames.length,
        st: 0,
        bm: 0,
      },
    ],
  };
}
