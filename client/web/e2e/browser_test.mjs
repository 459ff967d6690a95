// Browser end-to-end test of the page (run by tests/e2e/web_test.sh against the real
// inbetween-server behind the real gateway), in Debian's headless Chromium via playwright-core:
//   node e2e/browser_test.mjs --url http://127.0.0.1:PORT/ --out DIR --first A.svg --second B.svg
//        --bad BAD.svg --cut X1,Y1,X2,Y2 --art-first FACE1.svg --art-second FACE2.svg
// Checks: a server error shows next to its control (bad SVG -> on its card; Inbetween before a
// multimesh -> next to the button), the drawn cut comes back with rebuilt boundaries, build
// and optimize fill the energy chart, the player shows different non-blank frames in the
// drawings' colour (their art), the mesh overlay changes the picture, the GIF download decodes
// with the art's colour, the κ/τ/α/ε sliders reach the
// Inbetween request (decoded from what the page sends) and ε > 0 changes the frames, the
// project file download is docs/project-file.md's format with the cut and the slider values
// (and, for drawings made with the mouse, comes with their SVGs), the layout fits a phone, and
// two layered drawings (--art-first/--art-second: client/web/e2e/data/face_*.svg) play as their
// art: each key frame in its own paint (eye colours, the nose only key 2 has), the middle frame
// with the eyes' colours blended and the nose faded in at half opacity, the silhouette toggle
// back to one colour. Screenshots go to --out. Prints "N passed, N failed".
import assert from "node:assert/strict";
import { readFileSync, writeFileSync } from "node:fs";
import { basename, join } from "node:path";
import { parseArgs } from "node:util";

import { fromBinary } from "@bufbuild/protobuf";
import { createClient } from "@connectrpc/connect";
import { createConnectTransport } from "@connectrpc/connect-node";

import { Inbetween, InbetweenRequestSchema } from "../src/gen/inbetween/v1/inbetween_pb.js";
import { launchChromium, stepRunner } from "./harness.mjs";

const { values: args } = parseArgs({
  options: {
    url: { type: "string" },
    out: { type: "string" },
    first: { type: "string" },
    second: { type: "string" },
    bad: { type: "string" },
    cut: { type: "string" },
    "art-first": { type: "string" },
    "art-second": { type: "string" },
    chromium: { type: "string", default: "/usr/bin/chromium" },
  },
});
for (const k of ["url", "out", "first", "second", "bad", "cut", "art-first", "art-second"]) {
  if (!args[k]) throw new Error(`--${k} is required`);
}
const cut = args.cut.split(",").map(Number);

const STEP_MS = 60_000; // bound on any one wait; the whole test is bounded by ctest's timeout
const problems = [];
// A failed step ends the run: the later steps build on the earlier ones.
const { step, counts } = stepRunner({ stopOnFailure: true });

const text = (page, sel) => page.locator(sel).textContent();

// Fraction of canvas pixels that differ from white, and a digest of the picture.
async function canvasInfo(page) {
  return page.evaluate(() => {
    const c = document.getElementById("player");
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let inked = 0;
    let hash = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (d[i] < 250 || d[i + 1] < 250 || d[i + 2] < 250) inked++;
      hash = (hash * 31 + d[i] + 3 * d[i + 1] + 7 * d[i + 2]) | 0;
    }
    return { inked: inked / (d.length / 4), hash };
  });
}

// How many player pixels are each of `colours` (0xRRGGBB, each channel within `tol`).
async function colourCounts(page, colours, tol = 2) {
  return page.evaluate(([targets, t]) => {
    const c = document.getElementById("player");
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    const counts = targets.map(() => 0);
    for (let i = 0; i < d.length; i += 4) {
      targets.forEach((rgb, k) => {
        if (Math.abs(d[i] - ((rgb >> 16) & 255)) <= t && Math.abs(d[i + 1] - ((rgb >> 8) & 255)) <= t &&
            Math.abs(d[i + 2] - (rgb & 255)) <= t) counts[k]++;
      });
    }
    return counts;
  }, [colours, tol]);
}

// The InbetweenRequest in the body of a Connect server-stream call made with the binary format:
// one envelope (flags byte, big-endian 32-bit length, protobuf message).
function decodeInbetweenRequest({ contentType, body }) {
  assert.equal(contentType, "application/connect+proto");
  assert.ok(body && body.length >= 5, `request body of ${body?.length} bytes`);
  assert.equal(body[0], 0, "envelope flags (compressed or end-of-stream)");
  const length = body.readUInt32BE(1);
  assert.equal(body.length, 5 + length, "one envelope");
  return fromBinary(InbetweenRequestSchema, body.subarray(5));
}

const near = (a, b, tol = 1e-9) => Math.abs(a - b) <= tol;

async function scrubTo(page, i) {
  await page.locator("#scrub").evaluate((el, v) => {
    el.value = String(v);
    el.dispatchEvent(new Event("input", { bubbles: true }));
  }, i);
}

const browser = await launchChromium(args.chromium, STEP_MS);
const pageErrors = [];
let exitCode = 1;
try {
  const context = await browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const page = await context.newPage();
  page.setDefaultTimeout(STEP_MS);
  page.on("pageerror", (e) => pageErrors.push(e.message));
  // Every Inbetween call the page makes, as sent (content type and body).
  const inbetweenCalls = [];
  page.on("request", (r) => {
    if (new URL(r.url()).pathname === "/inbetween.v1.Inbetween/Inbetween") {
      inbetweenCalls.push({ contentType: r.headers()["content-type"], body: r.postDataBuffer() });
    }
  });

  await step("page loads and creates a session", async () => {
    await page.goto(args.url);
    await page.waitForFunction(() => /^session \S+ · v1 /.test(document.getElementById("session-info").textContent));
  });

  await step("Inbetween before a multimesh: the server's error shows next to the button", async () => {
    await page.click("#inbetween");
    await page.waitForFunction(() => document.getElementById("error-inbetween").textContent !== "");
    const msg = await text(page, "#error-inbetween");
    assert.match(msg, /^FAILED_PRECONDITION: /, msg);
  });

  await step("a bad SVG is refused and the error shows on its card", async () => {
    await page.setInputFiles("#upload", [args.bad]);
    const card = page.locator("#drawing-list li.failed");
    await card.waitFor();
    const msg = await card.locator(".error").textContent();
    assert.match(msg, /^INVALID_ARGUMENT: \S/, msg);
    assert.equal(await page.locator("#drawing-list li[data-drawing-id]").count(), 0);
    await card.locator("button").click();
  });

  await step("two SVGs upload as drawings 1 and 2", async () => {
    await page.setInputFiles("#upload", [args.first, args.second]);
    await page.locator("#drawing-list li[data-drawing-id]").nth(1).waitFor();
    assert.equal(await page.locator("#drawing-list li.failed").count(), 0);
    assert.match(await text(page, "#session-info"), / 2 drawings /);
  });

  await step("a cut drawn with the mouse comes back with rebuilt boundaries", async () => {
    await page.locator("#drawing-list li[data-drawing-id] canvas").first().click();
    await page.check('input[name="tool"][value="cut"]');
    const editor = page.locator("#editor");
    const box = await editor.boundingBox();
    const view = await editor.evaluate((c) => ({
      scale: Number(c.dataset.scale),
      ox: Number(c.dataset.ox),
      oy: Number(c.dataset.oy),
    }));
    const at = (x, y) => ({ x: view.ox + view.scale * x, y: view.oy + view.scale * y });
    for (const p of [at(cut[0], cut[1]), at(cut[2], cut[3])]) {
      assert.ok(p.x > 0 && p.y > 0 && p.x < box.width && p.y < box.height,
        `cut point ${JSON.stringify(p)} outside the ${box.width}×${box.height} editor`);
      await editor.click({ position: p });
    }
    const before = Number(await page.locator("#session-info").getAttribute("data-version"));
    await page.click("#finish-stroke");
    await page.locator("#element-list li").first().waitFor();
    assert.equal(await text(page, "#error-edit"), "");
    assert.match(await text(page, "#element-list"), /cut #\d+ \(2 points\)/);
    // The cut splits the cell: two closed boundaries, joined by cohesive edges along the cut.
    assert.match(await text(page, "#topology-info"), /^rebuilt: 2 boundaries · [1-9]\d* cohesive edges?$/);
    const classes = await page.locator("#drawing-list li[data-drawing-id] .class").allTextContents();
    assert.deepEqual(classes, ["2 comp. · 0 holes", "2 comp. · 0 holes"]);
    const after = Number(await page.locator("#session-info").getAttribute("data-version"));
    assert.equal(after, before + 1);
    await page.screenshot({ path: join(args.out, "cut.png") });
  });

  await step("a change made elsewhere: the page's stale call is ABORTED and it reloads", async () => {
    // Another client (Connect over HTTP/1.1 through the same gateway) changes the session.
    const info = page.locator("#session-info");
    const sessionId = await info.getAttribute("data-session-id");
    const other = createClient(
      Inbetween,
      createConnectTransport({ baseUrl: args.url, httpVersion: "1.1" }),
    );
    const { session } = await other.getSession({ sessionId }, { headers: { "x-session-id": sessionId } });
    assert.equal(String(session.version), await info.getAttribute("data-version"));
    const res = await other.setCorrespondences(
      { sessionId, expectedVersion: session.version, correspondences: [] },
      { headers: { "x-session-id": sessionId } },
    );
    assert.equal(res.session.version, session.version + 1n);
    await page.click("#send-marks");
    await page.waitForFunction(() => document.getElementById("error-marks").textContent !== "");
    const msg = await text(page, "#error-marks");
    assert.match(msg, /^ABORTED: /, msg);
    assert.match(msg, /reloaded/);
    assert.equal(await info.getAttribute("data-version"), String(res.session.version));
    await page.click("#send-marks"); // now with the reloaded version
    await page.waitForFunction(
      (v) => document.getElementById("session-info").dataset.version === v,
      String(res.session.version + 1n),
    );
    assert.equal(await text(page, "#error-marks"), "");
  });

  await step("build the multimesh: stats and a first chart point", async () => {
    await page.click("#build");
    await page.waitForFunction(
      () => document.getElementById("mesh-stats").textContent.includes("vertices") ||
        document.getElementById("error-build").textContent !== "",
    );
    assert.equal(await text(page, "#error-build"), "");
    assert.match(await text(page, "#mesh-stats"), /^\d+ vertices · \d+ triangles · 2 shapes/);
    assert.match(await text(page, "#session-info"), / multimesh$/);
    assert.equal(await page.locator("#chart").getAttribute("data-points"), "1");
  });

  await step("optimize: the energy chart gets one point per iteration", async () => {
    await page.click("#optimize");
    await page.waitForFunction(
      () => document.getElementById("progress-text").textContent.startsWith("optimized") ||
        document.getElementById("error-build").textContent !== "",
    );
    assert.equal(await text(page, "#error-build"), "");
    const points = Number(await page.locator("#chart").getAttribute("data-points"));
    assert.ok(points >= 2, `chart has ${points} points`);
    assert.equal(await page.locator("#chart polyline").count(), 2);
    assert.match(await text(page, "#session-info"), / optimized$/);
    // The optimized multimesh's worst triangle quality (MultimeshStats.worst_quality), in (0, 1].
    const quality = /worst triangle quality (\d\.\d{3})$/.exec(await text(page, "#mesh-stats"));
    assert.ok(quality && Number(quality[1]) > 0 && Number(quality[1]) <= 1,
      await text(page, "#mesh-stats"));
  });

  await step("inbetweens stream in and play", async () => {
    await page.fill("#frames", "12");
    await page.click("#inbetween");
    await page.waitForFunction(() => !document.getElementById("download-gif").disabled ||
      document.getElementById("error-inbetween").textContent !== "");
    assert.equal(await text(page, "#error-inbetween"), "");
    assert.match(await text(page, "#frame-label"), /^frame \d+ \/ 12/);
    await page.waitForFunction(() => document.getElementById("play").textContent === "Pause");
    await page.screenshot({ path: join(args.out, "desktop-1280x800.png"), fullPage: true });
  });

  await step("the canvas shows different non-blank frames; the mesh overlay changes it", async () => {
    await page.click("#play"); // pause
    await scrubTo(page, 0);
    assert.match(await text(page, "#frame-label"), /^frame 1 \/ 12 · key 1$/);
    const first = await canvasInfo(page);
    // The drawings have art (the cell's green, #6aa84f): the key frames show it exactly, and no
    // frame the silhouette's blue. (In between, the one cell and the two cells are layers of
    // different path counts: they cross-fade, lighter where only one of them is.)
    const [green1, blue1] = await colourCounts(page, [0x6aa84f, 0x3b7dd8]);
    await scrubTo(page, 11);
    assert.match(await text(page, "#frame-label"), /^frame 12 \/ 12 · key 2$/);
    const last = await canvasInfo(page);
    const [green2, blue2] = await colourCounts(page, [0x6aa84f, 0x3b7dd8]);
    await scrubTo(page, 5);
    const middle = await canvasInfo(page);
    const [, blueMiddle] = await colourCounts(page, [0x6aa84f, 0x3b7dd8]);
    assert.equal(await page.locator("#player").getAttribute("data-render"), "art");
    assert.ok(green1 > 1000 && green2 > 1000 && blue1 + blue2 + blueMiddle === 0,
      `green px ${green1}, ${green2} in the key frames; blue px ${blue1}, ${blue2}, ${blueMiddle}`);
    for (const [name, c] of Object.entries({ first, middle, last })) {
      assert.ok(c.inked > 0.02 && c.inked < 0.95, `${name} frame: ${(100 * c.inked).toFixed(1)}% inked`);
    }
    assert.notEqual(first.hash, last.hash);
    assert.notEqual(first.hash, middle.hash);
    assert.notEqual(middle.hash, last.hash);
    await page.check("#overlay");
    const overlaid = await canvasInfo(page);
    assert.notEqual(overlaid.hash, middle.hash);
    assert.match(await text(page, "#frame-stats"), /^\d+ iterations · energy \S+ · 0 inverted triangles/);
  });

  await step("the GIF download is a GIF Chromium decodes, one frame per inbetween", async () => {
    const [dl] = await Promise.all([page.waitForEvent("download"), page.click("#download-gif")]);
    const path = join(args.out, "animation.gif");
    await dl.saveAs(path);
    const bytes = readFileSync(path);
    assert.equal(bytes.subarray(0, 6).toString("latin1"), "GIF89a");
    assert.equal(bytes[bytes.length - 1], 0x3b);
    // Decode what the page produced with the browser's own GIF decoder.
    const decoded = await page.evaluate(async (b64) => {
      const blob = await (await fetch(`data:image/gif;base64,${b64}`)).blob();
      const decoder = new ImageDecoder({ data: blob.stream(), type: "image/gif" });
      await decoder.tracks.ready;
      await decoder.completed;
      const track = decoder.tracks.selectedTrack;
      const last = await decoder.decode({ frameIndex: track.frameCount - 1 });
      const c = new OffscreenCanvas(last.image.displayWidth, last.image.displayHeight);
      const ctx = c.getContext("2d");
      ctx.drawImage(last.image, 0, 0);
      const d = ctx.getImageData(0, 0, c.width, c.height).data;
      // The art's green (#6aa84f, (102, 170, 102) in the GIF's palette), not the silhouette blue.
      let green = 0;
      for (let i = 0; i < d.length; i += 4) if (d[i + 1] > d[i] + 40 && d[i + 1] > d[i + 2] + 40) green++;
      return { frames: track.frameCount, width: c.width, green: green / (d.length / 4) };
    }, bytes.toString("base64"));
    assert.equal(decoded.frames, 12);
    assert.equal(decoded.width, 320);
    assert.ok(decoded.green > 0.02, `last GIF frame ${(100 * decoded.green).toFixed(1)}% art colour`);
  });

  await step("the Lottie download has one hold keyframe per frame", async () => {
    const [dl] = await Promise.all([page.waitForEvent("download"), page.click("#download-lottie")]);
    const path = join(args.out, "animation.lottie.json");
    await dl.saveAs(path);
    const lottie = JSON.parse(readFileSync(path, "utf8"));
    assert.equal(lottie.op, 12);
    const paths = lottie.layers[0].shapes[0].it.filter((s) => s.ty === "sh");
    assert.ok(paths.length >= 1);
    for (const p of paths) assert.equal(p.ks.k.length, 12);
  });

  // A digest of every frame as the player draws it (paused, scrubbed to each frame in turn).
  const allFrames = async () => {
    if (await page.locator("#play").textContent() === "Pause") await page.click("#play");
    const n = Number(await page.locator("#scrub").getAttribute("max")) + 1;
    const hashes = [];
    for (let i = 0; i < n; i++) {
      await scrubTo(page, i);
      hashes.push((await canvasInfo(page)).hash);
    }
    return hashes;
  };
  // Clicks "Make inbetweens", waits for the stream to end; returns the request the page sent.
  const makeInbetweens = async () => {
    const calls = inbetweenCalls.length;
    await page.click("#inbetween");
    await page.waitForFunction(() => !document.getElementById("inbetween").disabled);
    assert.equal(await text(page, "#error-inbetween"), "");
    assert.match(await text(page, "#frame-label"), /^frame \d+ \/ 12/);
    assert.equal(inbetweenCalls.length, calls + 1, "one Inbetween call per click");
    return decodeInbetweenRequest(inbetweenCalls[calls]).parameters;
  };
  const slider = async (id) => ({
    value: Number(await page.locator(`#${id}`).inputValue()),
    shown: await page.locator(`output[for="${id}"]`).textContent(),
  });
  // What the sliders were set to (kappa as sent: 10^slider).
  const set = {};

  await step("the κ, τ, α sliders reach the Inbetween request; then ε > 0 changes the frames", async () => {
    // The run played above was made with the sliders untouched: the defaults went out.
    const first = decodeInbetweenRequest(inbetweenCalls.at(-1)).parameters;
    assert.equal(first.frames, 12);
    assert.ok(near(first.tau, 0.1) && near(first.alpha, 0.5) && first.epsilon === 0 && first.stiffness.length === 0,
      `default parameters sent: ${JSON.stringify({ tau: first.tau, alpha: first.alpha, epsilon: first.epsilon, stiffness: first.stiffness.length })}`);
    await page.uncheck("#overlay");
    const before = await allFrames();
    assert.equal(before.length, 12);

    // Real input events: keyboard arrows on τ and κ, fill (input + change) on α.
    await page.focus("#tau");
    for (let i = 0; i < 5; i++) await page.keyboard.press("ArrowRight"); // 0.1 + 5 × 0.01
    await page.focus("#kappa");
    for (let i = 0; i < 10; i++) await page.keyboard.press("ArrowRight"); // 0 + 10 × 0.1: κ = 10
    await page.locator("#alpha").fill("0.8");
    const tau = await slider("tau");
    const kappa = await slider("kappa");
    const alpha = await slider("alpha");
    assert.ok(near(tau.value, 0.15, 1e-12), `τ slider at ${tau.value}`);
    assert.ok(near(kappa.value, 1, 1e-12), `κ slider at ${kappa.value}`);
    assert.equal(alpha.value, 0.8);
    assert.deepEqual([tau.shown, kappa.shown, alpha.shown], ["0.15", "10.0", "0.8"]);
    Object.assign(set, { tau: tau.value, alpha: alpha.value, kappa: 10 ** kappa.value });

    const sent = await makeInbetweens();
    assert.ok(near(sent.tau, set.tau), `tau sent ${sent.tau}`);
    assert.ok(near(sent.alpha, set.alpha), `alpha sent ${sent.alpha}`);
    assert.equal(sent.epsilon, 0);
    // κ: one region around all of drawing 1 (examples/split: x 10..110, y 30..70).
    assert.equal(sent.stiffness.length, 1);
    assert.ok(near(sent.stiffness[0].kappa, set.kappa), `kappa sent ${sent.stiffness[0].kappa}`);
    const xs = sent.stiffness[0].polygon.points.map((q) => q.x);
    const ys = sent.stiffness[0].polygon.points.map((q) => q.y);
    assert.ok(xs.length >= 3 && Math.min(...xs) < 10 && Math.max(...xs) > 110 && Math.min(...ys) < 30 &&
      Math.max(...ys) > 70, `stiffness region ${JSON.stringify(sent.stiffness[0].polygon.points)}`);
    const noDynamics = await allFrames();
    // The solver is deterministic: the same request draws the same frames (so that the
    // comparison below shows what ε does, not noise).
    const again = await makeInbetweens();
    assert.ok(near(again.tau, set.tau) && again.epsilon === 0);
    assert.deepEqual(await allFrames(), noDynamics, "same parameters, different frames");

    // ε from 0 to 2: the same request otherwise, and the inbetweens move differently.
    await page.locator("#epsilon").fill("2");
    const epsilon = await slider("epsilon");
    assert.deepEqual(epsilon, { value: 2, shown: "2" });
    set.epsilon = 2;
    const sentDyn = await makeInbetweens();
    assert.equal(sentDyn.epsilon, 2);
    assert.ok(near(sentDyn.tau, set.tau) && near(sentDyn.alpha, set.alpha) && near(sentDyn.stiffness[0]?.kappa, set.kappa));
    const dynamics = await allFrames();
    assert.equal(dynamics.length, 12);
    const changed = dynamics.filter((h, i) => h !== noDynamics[i]).length;
    assert.ok(changed >= 1, `ε = 2 drew the same 12 frames as ε = 0`);
    console.log(`     frames changed: ${before.filter((h, i) => h !== noDynamics[i]).length}/12 by κ, τ, α; ` +
      `${changed}/12 by ε`);
    await scrubTo(page, 5);
    await page.screenshot({ path: join(args.out, "sliders-epsilon-2.png") });
  });

  await step("the project file download: version 1, both drawings, the cut, the slider values", async () => {
    // Outline sliding off is written as outline_corner_degrees 0; on (the default) leaves it out.
    await page.uncheck("#slide-outline");
    const [off] = await Promise.all([page.waitForEvent("download"), page.click("#download-project")]);
    const offPath = join(args.out, "project-no-outline-sliding.json");
    await off.saveAs(offPath);
    assert.equal(JSON.parse(readFileSync(offPath, "utf8")).comesh.outline_corner_degrees, 0);
    await page.check("#slide-outline");
    const [dl] = await Promise.all([page.waitForEvent("download"), page.click("#download-project")]);
    assert.equal(dl.suggestedFilename(), "project.json");
    const path = join(args.out, "project.json");
    await dl.saveAs(path);
    const project = JSON.parse(readFileSync(path, "utf8"));
    // Only fields docs/project-file.md defines (the CLI refuses unknown ones).
    const allowed = {
      "": ["version", "drawings", "correspondences", "meshing", "comesh", "inbetween", "output"],
      comesh: ["map_weight", "max_outer_iterations", "max_inner_iterations", "tolerance",
        "outer_tolerance", "outline_corner_degrees"],
      inbetween: ["method", "frames", "timing", "ease", "stiffness", "lambda", "tau", "alpha", "epsilon",
        "rho", "timestep", "max_iterations"],
      output: ["formats", "width", "fps", "fill", "mesh_overlay"],
    };
    for (const [section, keys] of Object.entries(allowed)) {
      const obj = section ? project[section] : project;
      for (const k of Object.keys(obj ?? {})) assert.ok(keys.includes(k), `unknown field ${section}.${k}`);
    }
    assert.equal(project.version, 1);
    assert.equal(project.drawings.length, 2);
    const [d1, d2] = project.drawings;
    assert.equal(d1.file, basename(args.first));
    assert.equal(d2.file, basename(args.second));
    for (const d of project.drawings) {
      for (const k of Object.keys(d)) assert.ok(["file", "key_time", "cuts", "openings"].includes(k), `drawings[].${k}`);
    }
    // The cut drawn with the mouse, in drawing 1's coordinates (within 2 editor pixels of --cut).
    assert.equal(d1.cuts?.length, 1, JSON.stringify(d1));
    assert.equal(d1.cuts[0].length, 2);
    const pxUnits = 2 / Number(await page.locator("#editor").getAttribute("data-scale"));
    d1.cuts[0].flat().forEach((v, i) => assert.ok(near(v, cut[i], pxUnits), `cut ${JSON.stringify(d1.cuts[0])} vs ${cut}`));
    assert.equal(d1.openings, undefined);
    assert.equal(d2.cuts, undefined);
    assert.equal(project.correspondences, undefined); // marks were sent empty
    const ib = project.inbetween;
    assert.deepEqual({ method: ib.method, frames: ib.frames, timing: ib.timing },
      { method: "zhu17", frames: 12, timing: "linear" });
    assert.ok(near(ib.tau, set.tau), `tau ${ib.tau}`);
    assert.ok(near(ib.alpha, set.alpha), `alpha ${ib.alpha}`);
    assert.equal(ib.epsilon, set.epsilon);
    assert.equal(ib.stiffness?.length, 1);
    assert.ok(near(ib.stiffness[0].kappa, set.kappa), `kappa ${ib.stiffness[0].kappa}`);
    assert.ok(ib.stiffness[0].polygon.length >= 3 && ib.stiffness[0].polygon.every((q) => q.length === 2));
    assert.equal(project.comesh.map_weight, 0.5);
    assert.equal(project.comesh.outline_corner_degrees, undefined);
    assert.deepEqual({ fps: project.output.fps, fill: project.output.fill, overlay: project.output.mesh_overlay },
      { fps: 24, fill: "#3b7dd8", overlay: false });
  });

  await step("phone layout (390×844): nothing wider than the screen", async () => {
    await page.setViewportSize({ width: 390, height: 844 });
    await page.waitForTimeout(200);
    const overflow = await page.evaluate(() => document.documentElement.scrollWidth);
    assert.ok(overflow <= 390, `page is ${overflow} px wide`);
    await page.evaluate(() => window.dispatchEvent(new Event("resize")));
    await page.screenshot({ path: join(args.out, "phone-390x844.png"), fullPage: true });
  });

  const polygons = [
    [[50, 50], [150, 50], [150, 150], [50, 150]],
    [[60, 40], [140, 60], [160, 140], [100, 170], [40, 140]],
  ];
  await step("new session: two polygons drawn with the mouse, one mark, build, inbetween", async () => {
    await page.setViewportSize({ width: 1280, height: 800 });
    await page.click("#server-settings summary");
    await page.click("#new-session");
    await page.waitForFunction(() => document.getElementById("session-info").dataset.version === "1");
    assert.equal(await page.locator("#drawing-list li").count(), 0);
    const editor = page.locator("#editor");
    const clickAll = async (points) => {
      const v = await editor.evaluate((c) => [c.dataset.scale, c.dataset.ox, c.dataset.oy].map(Number));
      for (const [x, y] of points) await editor.click({ position: { x: v[1] + v[0] * x, y: v[2] + v[0] * y } });
    };
    for (const [i, polygon] of polygons.entries()) {
      await page.check('input[name="tool"][value="polygon"]');
      await clickAll(polygon);
      await page.click("#finish-stroke");
      await page.locator("#drawing-list li[data-drawing-id]").nth(i).waitFor();
      assert.equal(await text(page, "#error-edit"), "");
    }
    assert.deepEqual(await page.locator("#drawing-list .name").allTextContents(), [
      "1. polygon_1.svg",
      "2. polygon_2.svg",
    ]);
    await page.check('input[name="tool"][value="mark"]');
    await page.locator("#drawing-list li[data-drawing-id] canvas").first().click();
    await clickAll([[52, 48]]); // snaps onto drawing 1's top edge; then drawing 2
    await clickAll([[60, 40]]);
    assert.equal(await text(page, "#marks-info"), "1 mark(s)");
    const v = Number(await page.locator("#session-info").getAttribute("data-version"));
    await page.click("#send-marks");
    await page.waitForFunction((want) => document.getElementById("session-info").dataset.version === want, String(v + 1));
    assert.equal(await text(page, "#error-marks"), "");
    await page.click("#build");
    await page.waitForFunction(() => !document.getElementById("build").disabled);
    assert.equal(await text(page, "#error-build"), "");
    assert.match(await text(page, "#mesh-stats"), /^\d+ vertices · \d+ triangles · 2 shapes/);
    await page.fill("#frames", "6");
    await page.selectOption("#timing", "3"); // ease in/out: the timeline gets an ease slider
    const ease = page.locator('#timeline input[aria-label="ease of segment 1"]');
    await ease.fill("0.5");
    assert.equal(await page.locator("#timeline .track output").last().textContent(), "0.50");
    await page.click("#inbetween");
    await page.waitForFunction(() => !document.getElementById("inbetween").disabled);
    assert.equal(await text(page, "#error-inbetween"), "");
    assert.match(await text(page, "#frame-label"), /^frame \d+ \/ 6/);
    await page.screenshot({ path: join(args.out, "polygons.png") });
  });

  await step("the project of drawn polygons downloads with polygon_1.svg and polygon_2.svg", async () => {
    const downloads = [];
    const onDownload = (d) => downloads.push(d);
    page.on("download", onDownload);
    await page.click("#download-project");
    for (const t0 = Date.now(); downloads.length < 3 && Date.now() - t0 < STEP_MS;) await page.waitForTimeout(50);
    page.off("download", onDownload);
    const files = {};
    for (const d of downloads) {
      const path = join(args.out, `polygons-${d.suggestedFilename()}`);
      await d.saveAs(path);
      files[d.suggestedFilename()] = readFileSync(path, "utf8");
    }
    assert.deepEqual(Object.keys(files).sort(), ["polygon_1.svg", "polygon_2.svg", "project.json"]);
    const project = JSON.parse(files["project.json"]);
    assert.equal(project.version, 1);
    assert.deepEqual(project.drawings, [{ file: "polygon_1.svg" }, { file: "polygon_2.svg" }]);
    assert.deepEqual({ frames: project.inbetween.frames, timing: project.inbetween.timing, ease: project.inbetween.ease },
      { frames: 6, timing: "ease_in_out", ease: [0.5] });
    // Each SVG is the polygon clicked (within 2 editor pixels), filled.
    const units = 2 / Number(await page.locator("#editor").getAttribute("data-scale"));
    const outlines = [];
    for (const [i, polygon] of polygons.entries()) {
      const svg = files[`polygon_${i + 1}.svg`];
      assert.match(svg, /^<svg xmlns="http:\/\/www\.w3\.org\/2000\/svg" viewBox="[-\d. ]+">\n  <path fill="#3b7dd8" d="M [^"]+ Z"\/>\n<\/svg>\n$/);
      const xy = svg.match(/ d="M ([^"]+) Z"/)[1].split(/ (?:L )?/).map(Number);
      const outline = polygon.map((_, k) => [xy[2 * k], xy[2 * k + 1]]);
      assert.equal(xy.length, 2 * polygon.length, svg);
      outline.forEach((q, k) => assert.ok(near(q[0], polygon[k][0], units) && near(q[1], polygon[k][1], units),
        `polygon_${i + 1}.svg point ${q} vs ${polygon[k]}`));
      outlines.push(outline);
    }
    // The one mark: a point on each drawing's outline, near where it was clicked.
    assert.equal(project.correspondences?.length, 1);
    const mark = project.correspondences[0];
    assert.equal(mark.length, 2);
    const onOutline = ([x, y], outline) => outline.some(([ax, ay], k) => {
      const [bx, by] = outline[(k + 1) % outline.length];
      const cross = (bx - ax) * (y - ay) - (by - ay) * (x - ax);
      const dot = (x - ax) * (bx - ax) + (y - ay) * (by - ay);
      const len2 = (bx - ax) ** 2 + (by - ay) ** 2;
      return Math.abs(cross) / Math.sqrt(len2) < 1e-3 && dot >= 0 && dot <= len2; // SVG: 3 decimals
    });
    [[52, 48], [60, 40]].forEach((clicked, i) => {
      assert.ok(onOutline(mark[i], outlines[i]), `mark ${mark[i]} not on outline ${i + 1}`);
      assert.ok(Math.hypot(mark[i][0] - clicked[0], mark[i][1] - clicked[1]) < 3 + units, `mark ${mark[i]}`);
    });
  });

  // client/web/e2e/data/face_*.svg: a yellow face (#fcea2b) with eyes, red (#c81e1e) in key 1 and
  // green (#1e8c1e) in key 2, a pink nose (#ff66cc) only key 2 has, a mouth and an outline.
  const FACE = { yellow: 0xfcea2b, red: 0xc81e1e, green: 0x1e8c1e, pink: 0xff66cc, silhouette: 0x3b7dd8 };
  const blend = (a, b, w) => [16, 8, 0].reduce(
    (rgb, s) => rgb | (Math.round(w[0] * ((a >> s) & 255) + w[1] * ((b >> s) & 255)) << s), 0);
  let artMiddle = null;
  await step("layered drawings play as their art: key frames as drawn, eyes morph, the nose fades in", async () => {
    await page.evaluate(() => { document.getElementById("server-settings").open = true; });
    await page.click("#new-session");
    await page.waitForFunction(() => document.getElementById("session-info").dataset.version === "1");
    await page.setInputFiles("#upload", [args["art-first"], args["art-second"]]);
    await page.locator("#drawing-list li[data-drawing-id]").nth(1).waitFor();
    assert.equal(await page.locator("#drawing-list li.failed").count(), 0);
    assert.deepEqual(await page.locator("#drawing-list li[data-drawing-id] .class").allTextContents(),
      ["1 comp. · 0 holes", "1 comp. · 0 holes"]);
    await page.click("#build");
    await page.waitForFunction(() => !document.getElementById("build").disabled);
    assert.equal(await text(page, "#error-build"), "");
    await page.fill("#frames", "3");
    await page.selectOption("#timing", "1"); // linear: the middle frame is halfway
    await page.locator("#epsilon").fill("0");
    await page.uncheck("#overlay");
    await page.click("#inbetween");
    await page.waitForFunction(() => !document.getElementById("inbetween").disabled);
    assert.equal(await text(page, "#error-inbetween"), "");
    if (await page.locator("#play").textContent() === "Pause") await page.click("#play");
    assert.equal(await page.locator("#silhouette").isDisabled(), false, "the silhouette toggle is enabled");
    assert.equal(await page.locator("#silhouette").isChecked(), false, "art is the default");
    const counts = async () => {
      const c = await colourCounts(page, Object.values(FACE));
      return Object.fromEntries(Object.keys(FACE).map((k, i) => [k, c[i]]));
    };
    await scrubTo(page, 0);
    assert.equal(await page.locator("#player").getAttribute("data-render"), "art");
    const first = await counts();
    assert.ok(first.red > 300 && first.yellow > 5000, `key 1: ${JSON.stringify(first)}`);
    assert.ok(first.green < 20 && first.pink < 20 && first.silhouette === 0, `key 1: ${JSON.stringify(first)}`);
    await page.screenshot({ path: join(args.out, "art-key1.png") });
    await scrubTo(page, 2);
    const last = await counts();
    assert.ok(last.green > 300 && last.pink > 100 && last.yellow > 5000, `key 2: ${JSON.stringify(last)}`);
    assert.ok(last.red < 20 && last.silhouette === 0, `key 2: ${JSON.stringify(last)}`);
    await scrubTo(page, 1);
    const weights = JSON.parse(await page.locator("#player").getAttribute("data-weights"));
    assert.equal(weights.length, 2);
    assert.ok(weights[0] > 0.3 && weights[1] > 0.3, `middle frame weights ${weights}`);
    // Eyes correspond (paint order): one pair of eyes in the blended colour, neither key's own.
    // The nose has no counterpart: key 2's nose at half its opacity over the face.
    const eyes = blend(FACE.red, FACE.green, weights);
    const nose = blend(FACE.yellow, FACE.pink, weights); // yellow under pink at opacity weights[1]
    const [eyePx, nosePx] = await colourCounts(page, [eyes, nose], 3);
    const middle = await counts();
    assert.ok(eyePx > 300, `middle frame: ${eyePx} px of the blended eye colour #${eyes.toString(16)}`);
    assert.ok(nosePx > 50, `middle frame: ${nosePx} px of the half-faded nose #${nose.toString(16)}`);
    assert.ok(middle.red < 20 && middle.green < 20 && middle.pink < 20 && middle.silhouette === 0,
      `middle frame: ${JSON.stringify(middle)}`);
    artMiddle = (await canvasInfo(page)).hash;
    await page.screenshot({ path: join(args.out, "art-middle.png") });
  });

  await step("the silhouette toggle draws the frames in one colour, and back", async () => {
    await page.check("#silhouette");
    assert.equal(await page.locator("#player").getAttribute("data-render"), "silhouette");
    const [silhouette, yellow, red, green] = await colourCounts(page, [FACE.silhouette, FACE.yellow, FACE.red, FACE.green]);
    assert.ok(silhouette > 5000 && yellow === 0 && red === 0 && green === 0,
      `silhouette: ${JSON.stringify({ silhouette, yellow, red, green })}`);
    await page.screenshot({ path: join(args.out, "art-silhouette.png") });
    await page.uncheck("#silhouette");
    assert.equal(await page.locator("#player").getAttribute("data-render"), "art");
    assert.equal((await canvasInfo(page)).hash, artMiddle, "back to the same art");
  });


  await step("no uncaught errors in the page", async () => {
    assert.deepEqual(pageErrors, []);
  });
  exitCode = 0;
} catch {
  exitCode = 1;
} finally {
  await browser.close();
  const summary = `${counts.passed} passed, ${counts.failed} failed`;
  console.log(summary);
  writeFileSync(join(args.out, "result.txt"), `${summary}\n`);
}
process.exit(exitCode);
