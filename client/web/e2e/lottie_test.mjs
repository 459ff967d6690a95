// Plays the CLI's Lottie output (`inbetween animate --format lottie`) in lottie-web, in Debian's
// headless Chromium via playwright-core (run by tests/e2e/lottie_web_test.sh):
//   node e2e/lottie_test.mjs --frames N [--chromium /usr/bin/chromium] A.lottie.json [B ...]
// A tiny page on a node http server on 127.0.0.1:0 loads lottie-web (svg renderer) from
// node_modules and each animation by URL (no CDN: every other request is aborted). Per file:
// lottie-web loads it with no page error and no `data_failed`/`error` event, `totalFrames` is N,
// after `goToAndStop(k, true)` for the first, middle and last frame the rendered <path> `d`
// is non-empty, starts at the frame's first keyframe vertex, differs between those frames, and
// the rendered shape's bounding box is inside the animation's w×h. Then the same checks run on
// corrupted copies of the first file (path keyframes removed, `op` changed, vertices moved out
// of the canvas, truncated JSON) and each must be caught. Prints "N passed, N failed".
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
  },
  allowPositionals: true,
});
const frames = Number(args.frames);
if (!Number.isInteger(frames) || frames < 3) throw new Error("--frames N (N >= 3) is required");
if (files.length === 0) throw new Error("no animation files given");

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
// Shows frame k and returns every rendered path's d and the union of their boxes, in the
// animation's pixels (the svg's client box is mapped onto its viewBox).
window.frameInfo = (k) => {
  window.anim.goToAndStop(k, true);
  const svg = document.querySelector("#c svg");
  const vb = svg.viewBox.baseVal;
  const r = svg.getBoundingClientRect();
  const sx = vb.width / r.width, sy = vb.height / r.height;
  const paths = [...svg.querySelectorAll("path")].filter((p) => !p.closest("defs, clipPath, mask"));
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
           fill: paths.map((p) => p.getAttribute("fill")), box,
           viewBox: [vb.x, vb.y, vb.width, vb.height] };
};
</script></body></html>`;

// Served animations by name (bytes); the page fetches /anim/NAME.
const served = new Map();
const server = createServer((req, res) => {
  const path = new URL(req.url, "http://x").pathname;
  let body = null;
  let type = "application/json";
  if (path === "/") [body, type] = [PAGE, "text/html; charset=utf-8"];
  else if (path === "/lottie.js") [body, type] = [lottieJs, "text/javascript"];
  else if (path.startsWith("/anim/")) body = served.get(decodeURIComponent(path.slice(6))) ?? null;
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

// The first vertex of the first path at frame k as the file gives it: keyframes sit on whole
// frames, so frame k shows the last keyframe with t <= k.
function firstVertex(doc, k) {
  const group = doc.layers[0].shapes.find((s) => s.ty === "gr");
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

  // Corrupted copies of the first file: each must be caught by the checks above.
  const good = readFileSync(files[0]);
  const mutate = (fn) => {
    const doc = JSON.parse(good.toString());
    fn(doc);
    return Buffer.from(JSON.stringify(doc));
  };
  const paths = (doc) => doc.layers[0].shapes.find((s) => s.ty === "gr").it.filter((s) => s.ty === "sh");
  const corrupt = [
    ["path keyframes removed (only frame 0 kept)", /render the same path/,
      mutate((doc) => { for (const sh of paths(doc)) sh.ks.k = sh.ks.k.slice(0, 1); })],
    ["op one frame short", /totalFrames/, mutate((doc) => { doc.op -= 1; doc.layers[0].op -= 1; })],
    ["vertices moved out of the canvas", /not inside/,
      mutate((doc) => { for (const sh of paths(doc)) for (const kf of sh.ks.k) for (const v of kf.s[0].v) v[0] += doc.w; })],
    ["truncated JSON", /lottie-web uncaught error while loading/, good.subarray(0, Math.floor(good.length / 2))],
    ["file missing (HTTP 404)", /lottie-web data_failed/, null],
  ];
  for (const [what, expected, bytes] of corrupt) {
    await step(`corrupted (${what}) is caught`, async () => {
      let err = null;
      try {
        await checkAnimation(`corrupt_${corrupt.findIndex((c) => c[0] === what)}.json`, bytes);
      } catch (e) {
        err = e;
      }
      assert.ok(err, "the corrupted animation passed every check");
      assert.match(err.message, expected);
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
