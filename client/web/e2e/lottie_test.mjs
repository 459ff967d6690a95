// Plays the CLI's Lottie output (`inbetween animate --format lottie`) in lottie-web, in Debian's
// headless Chromium via playwright-core (run by tests/e2e/lottie_web_test.sh):
//   node e2e/lottie_test.mjs --frames N [--chromium /usr/bin/chromium] A.lottie.json [B ...]
//     [--layered L.lottie.json --expect '{"K": {"paths": n, "faded": n, "fill": ["#rrggbb", ...],
//                                                "stroke": [...]}, ...}' [--reference DIR]]
// A tiny page on a node http server on 127.0.0.1:0 loads lottie-web (svg renderer) from
// node_modules and each animation by URL (no CDN: every other request is aborted). Per file:
// lottie-web loads it with no page error and no `data_failed`/`error` event, `totalFrames` is N,
// after `goToAndStop(k, true)` for the first, middle and last frame the visible <path>s (not
// display:none, opacity > 0) have a non-empty `d`, the first starts at the first vertex of the
// bottom layer shown at that frame, they differ between those frames, and their bounding box is
// inside the animation's w×h. The layered file (art: a Lottie layer per art layer) also gets
// these checks, then per frame K of --expect: `paths` visible <path>s (lottie-web draws a layer's
// fill and stroke as two), `faded` of them under a layer opacity strictly between 0 and 1 (a
// cross-fade), the visible fills' and strokes' colours the given sets (±1 per channel), and each
// stroke drawn after the fill of the same path; with --reference, the page's pixels at frame K
// match DIR/frame_000K.png, the CLI's PNG frame of the same export (white background, same
// width): at most 1 % of the pixels differ by more than 64 in a channel and the mean difference
// is at most 2 (of 255). Then the same checks run on corrupted copies of
// the first file (path keyframes removed, `op` changed, vertices moved out of the canvas,
// truncated JSON) and of the layered one (every layer spanning every frame; with --reference,
// the layers in reverse paint order) and each must be caught. Prints "N passed, N failed".
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { createServer } from "node:http";
import { basename, dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { parseArgs } from "node:util";

import { launchChromium, stepRunner } from "./harness.mjs";

const { values: args, positionals: files } = parseArgs({
  options: {
    frames: { type: "string" },
    chromium: { type: "string", default: "/usr/bin/chromium" },
    layered: { type: "string" },
    expect: { type: "string" },
    reference: { type: "string" },
  },
  allowPositionals: true,
});
const frames = Number(args.frames);
if (!Number.isInteger(frames) || frames < 3) throw new Error("--frames N (N >= 3) is required");
if (files.length === 0) throw new Error("no animation files given");
if (!args.layered !== !args.expect) throw new Error("--layered and --expect go together");
const expected = args.expect ? JSON.parse(args.expect) : null;

const STEP_MS = 30_000; // bound on any one wait
const watchdog = setTimeout(() => {
  console.log("FAIL: lottie_test did not finish within 120 s");
  process.exit(1);
}, 120_000);
watchdog.unref();

const web = join(dirname(fileURLToPath(import.meta.url)), "..");
const lottieJs = readFileSync(join(web, "node_modules", "lottie-web", "build", "player", "lottie.min.js"));
const lottieVersion = JSON.parse(readFileSync(join(web, "node_modules", "lottie-web", "package.json"))).version;

const PAGE = `<!doctype html><html><head><meta charset="utf-8"><title>lottie test</title>
<style>html,body{margin:0;padding:0;background:#fff}#c{position:absolute;left:0;top:0}</style>
<script>
// lottie-web parses a \`path\` answer in an XHR callback and, for a 200 answer that is not JSON,
// only throws there (no data_failed): an uncaught error fails the load in progress.
window.onLoadError = null;
window.addEventListener("error", (e) => window.onLoadError && window.onLoadError(e.message));
</script>
<script src="/lottie.js"></script></head><body><div id="c"></div><script>
// Loads /anim/NAME into a container of w×h CSS pixels; resolves with totalFrames and the
// animation's size once lottie-web has built the DOM, rejects on data_failed / error.
window.loadAnim = (name, w, h) => new Promise((resolve, reject) => {
  if (window.anim) { window.anim.destroy(); window.anim = null; }
  const c = document.getElementById("c");
  c.innerHTML = "";
  c.style.width = w + "px";
  c.style.height = h + "px";
  const anim = lottie.loadAnimation({ container: c, renderer: "svg", loop: false, autoplay: false,
                                      path: "/anim/" + name });
  window.anim = anim;
  const timer = setTimeout(() => reject(new Error("lottie-web did not load it within 15 s")), 15000);
  const fail = (what) => (e) => {
    clearTimeout(timer);
    reject(new Error("lottie-web " + what + ": " + String(e && (e.nativeError || e.message || e.type) || "")));
  };
  anim.addEventListener("data_failed", fail("data_failed"));
  anim.addEventListener("error", fail("error"));
  window.onLoadError = (message) => fail("uncaught error while loading")({ message });
  anim.addEventListener("DOMLoaded", () => {
    clearTimeout(timer);
    resolve({ totalFrames: anim.totalFrames });
  });
});
// How far two same-sized images (/img/A, /img/B) differ: the fraction of pixels with a channel
// more than 64 apart and the mean channel difference (0..255).
window.compareImages = async (a, b) => {
  const pixels = async (name) => {
    const img = new Image();
    img.src = "/img/" + name;
    await img.decode();
    const c = document.createElement("canvas");
    [c.width, c.height] = [img.naturalWidth, img.naturalHeight];
    const ctx = c.getContext("2d");
    ctx.drawImage(img, 0, 0);
    return ctx.getImageData(0, 0, c.width, c.height);
  };
  const [p, q] = [await pixels(a), await pixels(b)];
  if (p.width !== q.width || p.height !== q.height) return { size: [p.width, p.height, q.width, q.height] };
  let far = 0, sum = 0;
  for (let i = 0; i < p.data.length; i += 4) {
    let most = 0;
    for (let c = 0; c < 3; c++) {
      const d = Math.abs(p.data[i + c] - q.data[i + c]);
      sum += d;
      most = Math.max(most, d);
    }
    if (most > 64) far++;
  }
  const n = p.width * p.height;
  return { far: far / n, mean: sum / (3 * n) };
};
// Shows frame k and returns every visible path (in document order: bottom first) with its d,
// paint (a stroke when it has a stroke colour, else a fill), colour and the opacity of the layers
// above it, and the union of their boxes, in the animation's pixels (the svg's client box is
// mapped onto its viewBox). Visible: no ancestor display:none, opacity and paint opacity > 0.
window.frameInfo = (k) => {
  window.anim.goToAndStop(k, true);
  const svg = document.querySelector("#c svg");
  const vb = svg.viewBox.baseVal;
  const r = svg.getBoundingClientRect();
  const sx = vb.width / r.width, sy = vb.height / r.height;
  const shown = [];
  for (const p of svg.querySelectorAll("path")) {
    if (p.closest("defs, clipPath, mask")) continue;
    let opacity = 1, hidden = false;
    for (let e = p; e && e !== svg; e = e.parentElement) {
      const cs = getComputedStyle(e);
      if (cs.display === "none" || cs.visibility === "hidden") hidden = true;
      opacity *= Number(cs.opacity);
    }
    const stroke = p.getAttribute("stroke");
    const kind = stroke && stroke !== "none" ? "stroke" : "fill";
    const paint = Number(getComputedStyle(p)[kind === "stroke" ? "strokeOpacity" : "fillOpacity"]);
    if (hidden || !(opacity > 0) || !(paint > 0)) continue;
    shown.push({ p, kind, color: p.getAttribute(kind), opacity });
  }
  const paths = shown.map((s) => s.p);
  let box = null;
  for (const p of paths) {
    const b = p.getBoundingClientRect();
    if (b.width === 0 && b.height === 0) continue;
    const q = { x0: (b.left - r.left) * sx + vb.x, y0: (b.top - r.top) * sy + vb.y,
                x1: (b.right - r.left) * sx + vb.x, y1: (b.bottom - r.top) * sy + vb.y };
    box = box ? { x0: Math.min(box.x0, q.x0), y0: Math.min(box.y0, q.y0),
                  x1: Math.max(box.x1, q.x1), y1: Math.max(box.y1, q.y1) } : q;
  }
  return { currentFrame: window.anim.currentFrame, d: paths.map((p) => p.getAttribute("d") || ""),
           kind: shown.map((s) => s.kind), color: shown.map((s) => s.color),
           opacity: shown.map((s) => s.opacity), box, viewBox: [vb.x, vb.y, vb.width, vb.height] };
};
</script></body></html>`;

// Served animations by name (bytes); the page fetches /anim/NAME (and images to compare as
// /img/NAME).
const served = new Map();
const server = createServer((req, res) => {
  const path = new URL(req.url, "http://x").pathname;
  let body = null;
  let type = "application/json";
  if (path === "/") [body, type] = [PAGE, "text/html; charset=utf-8"];
  else if (path === "/lottie.js") [body, type] = [lottieJs, "text/javascript"];
  else if (path.startsWith("/anim/")) body = served.get(decodeURIComponent(path.slice(6))) ?? null;
  else if (path.startsWith("/img/")) [body, type] = [served.get(decodeURIComponent(path.slice(5))) ?? null, "image/png"];
  if (body === null) {
    res.writeHead(404).end();
    return;
  }
  res.writeHead(200, { "content-type": type, "cache-control": "no-store" }).end(body);
});
await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
const base = `http://127.0.0.1:${server.address().port}`;

// Every step runs: one broken file does not hide the others.
const { step, counts } = stepRunner({ stopOnFailure: false });

// The first vertex of the first path of the bottom layer shown at frame k (ip <= k < op; Lottie
// draws the last layer at the bottom) as the file gives it: keyframes sit on whole frames, so
// frame k shows the last keyframe with t <= k.
function firstVertex(doc, k) {
  const layer = doc.layers.findLast((l) => l.ip <= k && k < l.op);
  if (!layer) return null;
  const group = layer.shapes.find((s) => s.ty === "gr");
  const sh = group.it.find((s) => s.ty === "sh");
  const key = sh.ks.a ? sh.ks.k.findLast((kf) => kf.t <= k) : { s: [sh.ks.k] };
  return key ? key.s[0].v[0] : null;
}

const TOL = 0.05; // lottie-web writes path coordinates rounded to 1/100
const pageErrors = [];
let page;

// Every check on one animation; throws on the first that fails.
async function checkAnimation(name, bytes) {
  if (bytes) served.set(name, bytes);
  pageErrors.length = 0;
  let doc = null;
  try {
    doc = JSON.parse(bytes?.toString());
  } catch {} // still given to lottie-web, which must report it (data_failed)
  const { w, h } = doc ?? { w: 100, h: 100 };
  await page.setViewportSize({ width: Math.ceil(w) + 20, height: Math.ceil(h) + 20 });
  const loaded = await page.evaluate(([n, ww, hh]) => window.loadAnim(n, ww, hh), [name, w, h]);
  assert.deepEqual(pageErrors, [], "page errors while loading");
  assert.ok(doc, "lottie-web loaded a file that is not JSON");
  assert.equal(loaded.totalFrames, frames, `anim.totalFrames ${loaded.totalFrames}, expected ${frames}`);
  const ks = [0, Math.floor(frames / 2), frames - 1];
  const infos = [];
  for (const k of ks) {
    const info = await page.evaluate((kk) => window.frameInfo(kk), k);
    assert.deepEqual(info.viewBox, [0, 0, w, h], "svg viewBox is the animation's 0 0 w h");
    assert.equal(info.currentFrame, k, `currentFrame after goToAndStop(${k}, true)`);
    assert.ok(info.d.length > 0, `frame ${k}: no <path> rendered`);
    for (const d of info.d) assert.match(d, /^\s*M\s*-?[\d.]+[ ,]-?[\d.]+.*\S/s, `frame ${k}: path d "${d.slice(0, 40)}"`);
    const start = info.d[0].match(/M\s*(-?[\d.e+-]+)[ ,](-?[\d.e+-]+)/).slice(1).map(Number);
    const v = firstVertex(doc, k);
    assert.ok(v, `frame ${k}: no keyframe in the file`);
    assert.ok(Math.abs(start[0] - v[0]) <= TOL && Math.abs(start[1] - v[1]) <= TOL,
      `frame ${k}: rendered path starts at ${start}, the file's keyframe at ${v}`);
    assert.ok(info.box, `frame ${k}: the rendered shape has an empty bounding box`);
    const { x0, y0, x1, y1 } = info.box;
    assert.ok(x0 >= -0.5 && y0 >= -0.5 && x1 <= w + 0.5 && y1 <= h + 0.5 && x1 - x0 > 1 && y1 - y0 > 1,
      `frame ${k}: rendered box [${[x0, y0, x1, y1].map((x) => x.toFixed(1))}] not inside 0 0 ${w} ${h}`);
    infos.push({ k, ...info });
  }
  for (let i = 1; i < infos.length; i++) {
    assert.notDeepEqual(infos[i].d, infos[i - 1].d,
      `frames ${infos[i - 1].k} and ${infos[i].k} render the same path`);
  }
  assert.deepEqual(pageErrors, [], "page errors while playing");
  return infos;
}

// "#rrggbb" or lottie-web's "rgb(r,g,b)" as [r, g, b].
function rgb(color) {
  const hex = /^#([0-9a-f]{2})([0-9a-f]{2})([0-9a-f]{2})$/i.exec(color ?? "");
  if (hex) return hex.slice(1).map((h) => parseInt(h, 16));
  const css = /^rgb\((\d+),\s*(\d+),\s*(\d+)\)$/.exec(color ?? "");
  return css ? css.slice(1).map(Number) : null;
}

// The layered checks at frame k of --expect (see the header), on frameInfo's answer.
function checkLayers(info, k, want) {
  assert.equal(info.d.length, want.paths, `frame ${k}: ${info.d.length} visible paths, expected ${want.paths}`);
  const faded = info.opacity.filter((o) => o > 0.001 && o < 0.999).length;
  assert.equal(faded, want.faded, `frame ${k}: ${faded} paths under a cross-fading layer, expected ${want.faded}`);
  for (const kind of ["fill", "stroke"]) {
    const got = info.color.filter((_, i) => info.kind[i] === kind).map(rgb);
    assert.ok(got.every((c) => c), `frame ${k}: a ${kind} colour lottie-web wrote is not rgb(): ${info.color}`);
    const same = (a, b) => a.every((x, i) => Math.abs(x - b[i]) <= 1);
    const wanted = want[kind].map(rgb);
    const missing = wanted.filter((w) => !got.some((c) => same(c, w)));
    const extra = got.filter((c) => !wanted.some((w) => same(c, w)));
    assert.ok(missing.length === 0 && extra.length === 0,
      `frame ${k}: ${kind} colours [${got.map((c) => c.join(","))}], expected ${want[kind]}`);
  }
  // A layer's stroke is listed before its fill in the file, so it lies over it on the page.
  info.d.forEach((d, i) => {
    if (info.kind[i] !== "stroke") return;
    const fill = info.d.findIndex((e, j) => e === d && info.kind[j] === "fill");
    assert.ok(fill < i, `frame ${k}: a stroke is drawn under its own fill`);
  });
}

// The page showing frame k against the CLI's PNG of that frame (see the header).
// Every image gets a new name: a page reuses an image it loaded by URL whatever the cache headers.
let shots = 0;
async function checkPixels(k, w, h) {
  const reference = `frame_${String(k).padStart(4, "0")}.png`;
  const [ref, shot] = [`ref_${++shots}.png`, `shot_${shots}.png`];
  served.set(ref, readFileSync(join(args.reference, reference)));
  served.set(shot, await page.screenshot({ clip: { x: 0, y: 0, width: w, height: h } }));
  const d = await page.evaluate(([a, b]) => window.compareImages(a, b), [shot, ref]);
  assert.ok(!d.size, `frame ${k}: the page is ${d.size?.slice(0, 2)}, ${reference} ${d.size?.slice(2)}`);
  assert.ok(d.far <= 0.01 && d.mean <= 2,
    `frame ${k}: ${(100 * d.far).toFixed(2)} % of the pixels differ from ${reference} (mean ${d.mean.toFixed(2)})`);
  return d;
}

async function checkLayered(name, bytes) {
  await checkAnimation(name, bytes);
  const { w, h } = JSON.parse(bytes.toString());
  const summary = [];
  for (const [k, want] of Object.entries(expected)) {
    const info = await page.evaluate((kk) => window.frameInfo(kk), Number(k));
    checkLayers(info, Number(k), want);
    let line = `${k}: ${info.d.length} paths (${info.opacity.filter((o) => o < 0.999).length} fading)`;
    if (args.reference) {
      const d = await checkPixels(Number(k), w, h);
      line += `, ${(100 * d.far).toFixed(2)} % off the PNG (mean ${d.mean.toFixed(2)})`;
    }
    summary.push(line);
  }
  return summary;
}

const browser = await launchChromium(args.chromium, STEP_MS);
const offsite = [];
try {
  const context = await browser.newContext();
  await context.route("**/*", (route) => {
    const u = new URL(route.request().url());
    if (u.origin === base) return route.continue();
    offsite.push(u.href);
    return route.abort();
  });
  page = await context.newPage();
  page.setDefaultTimeout(STEP_MS);
  page.on("pageerror", (e) => pageErrors.push(e.message));
  page.on("console", (m) => { if (m.type() === "error") pageErrors.push(`console: ${m.text()}`); });
  await page.goto(base + "/");
  await step(`lottie-web ${lottieVersion} loads from node_modules`, async () => {
    assert.equal(await page.evaluate(() => typeof lottie?.loadAnimation), "function");
    assert.equal(await page.evaluate(() => lottie.version), lottieVersion);
  });

  for (const [i, file] of files.entries()) {
    await step(`${file}: plays in lottie-web (${frames} frames, frames differ, inside w×h)`, async () => {
      const infos = await checkAnimation(`${i}_${basename(file)}`, readFileSync(file));
      console.log(`     frame ${infos.map((f) => `${f.k}: box [${[f.box.x0, f.box.y0, f.box.x1, f.box.y1].map((x) => x.toFixed(1))}]`).join(", ")}`);
    });
  }
  if (args.layered) {
    await step(`${args.layered}: art layers play in lottie-web (visible paths, cross-fades, colours per frame)`, async () => {
      const summary = await checkLayered(`layered_${basename(args.layered)}`, readFileSync(args.layered));
      console.log(`     frame ${summary.join(", ")}`);
    });
  }

  // Corrupted copies of the first file: each must be caught by the checks above.
  const good = readFileSync(files[0]);
  const mutate = (fn) => {
    const doc = JSON.parse(good.toString());
    fn(doc);
    return Buffer.from(JSON.stringify(doc));
  };
  const paths = (doc) => doc.layers.flatMap((l) => l.shapes.find((s) => s.ty === "gr").it.filter((s) => s.ty === "sh"));
  const corrupt = [
    ["path keyframes removed (only frame 0 kept)", /render the same path/,
      mutate((doc) => { for (const sh of paths(doc)) sh.ks.k = sh.ks.k.slice(0, 1); })],
    ["op one frame short", /totalFrames/, mutate((doc) => { doc.op -= 1; doc.layers[0].op -= 1; })],
    ["vertices moved out of the canvas", /not inside/,
      mutate((doc) => { for (const sh of paths(doc)) for (const kf of sh.ks.k) for (const v of kf.s[0].v) v[0] += doc.w; })],
    ["truncated JSON", /lottie-web uncaught error while loading/, good.subarray(0, Math.floor(good.length / 2))],
    ["file missing (HTTP 404)", /lottie-web data_failed/, null],
  ];
  if (args.layered) {
    const layered = JSON.parse(readFileSync(args.layered).toString());
    for (const layer of layered.layers) [layer.ip, layer.op] = [0, layered.op];
    corrupt.push(["layered: every layer spanning every frame", /visible paths/,
      Buffer.from(JSON.stringify(layered)), checkLayered]);
    if (args.reference) {
      const upsideDown = JSON.parse(readFileSync(args.layered).toString());
      upsideDown.layers.reverse();
      corrupt.push(["layered: paint order upside down", /pixels differ from frame_0000\.png/,
        Buffer.from(JSON.stringify(upsideDown)), checkLayered]);
    }
  }
  for (const [what, expectedError, bytes, check = checkAnimation] of corrupt) {
    await step(`corrupted (${what}) is caught`, async () => {
      let err = null;
      try {
        await check(`corrupt_${corrupt.findIndex((c) => c[0] === what)}.json`, bytes);
      } catch (e) {
        err = e;
      }
      assert.ok(err, "the corrupted animation passed every check");
      assert.match(err.message, expectedError);
      console.log(`     caught: ${err.message.split("\n")[0]}`);
    });
  }
  await step("no request left loopback", async () => assert.deepEqual(offsite, []));
} finally {
  await browser.close();
  server.close();
}
console.log(`${counts.passed} passed, ${counts.failed} failed`);
process.exit(counts.failed === 0 ? 0 : 1);
