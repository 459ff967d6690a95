// Browser end-to-end test of the page (run by tests/e2e/web_test.sh against the real
// inbetween-server behind the real gateway), in Debian's headless Chromium via playwright-core:
//   node e2e/browser_test.mjs --url http://127.0.0.1:PORT/ --out DIR --first A.svg --second B.svg
//        --bad BAD.svg --cut X1,Y1,X2,Y2
// Checks: a server error shows next to its control (bad SVG -> on its card; Inbetween before a
// multimesh -> next to the button), the drawn cut comes back with rebuilt boundaries, build
// and optimize fill the energy chart, the player shows different non-blank frames, the mesh
// overlay changes the picture, the GIF download decodes, and the layout fits a phone.
// Screenshots go to --out. Prints "N passed, N failed".
import assert from "node:assert/strict";
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { parseArgs } from "node:util";

import { createClient } from "@connectrpc/connect";
import { createConnectTransport } from "@connectrpc/connect-node";
import { chromium } from "playwright-core";

import { Inbetween } from "../src/gen/inbetween/v1/inbetween_pb.js";

const { values: args } = parseArgs({
  options: {
    url: { type: "string" },
    out: { type: "string" },
    first: { type: "string" },
    second: { type: "string" },
    bad: { type: "string" },
    cut: { type: "string" },
    chromium: { type: "string", default: "/usr/bin/chromium" },
  },
});
for (const k of ["url", "out", "first", "second", "bad", "cut"]) {
  if (!args[k]) throw new Error(`--${k} is required`);
}
const cut = args.cut.split(",").map(Number);

const STEP_MS = 60_000; // bound on any one wait; the whole test is bounded by ctest's timeout
let passed = 0;
let failed = 0;
const problems = [];

async function step(name, fn) {
  const t0 = Date.now();
  try {
    await fn();
    passed++;
    console.log(`ok   ${name} (${Date.now() - t0} ms)`);
  } catch (err) {
    failed++;
    console.log(`FAIL ${name}: ${err.message.split("\n").slice(0, 6).join("\n     ")}`);
    throw err;
  }
}

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

async function scrubTo(page, i) {
  await page.locator("#scrub").evaluate((el, v) => {
    el.value = String(v);
    el.dispatchEvent(new Event("input", { bubbles: true }));
  }, i);
}

const browser = await chromium.launch({
  executablePath: args.chromium,
  // root in containers/CI cannot use Chromium's sandbox; the page only talks to loopback.
  args: [
    "--no-sandbox",
    "--disable-gpu",
    // No network but loopback here: keep Chromium from reaching out on its own.
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-quic",
    "--no-first-run",
  ],
  timeout: STEP_MS,
});
const pageErrors = [];
let exitCode = 1;
try {
  const context = await browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const page = await context.newPage();
  page.setDefaultTimeout(STEP_MS);
  page.on("pageerror", (e) => pageErrors.push(e.message));

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
    await scrubTo(page, 11);
    assert.match(await text(page, "#frame-label"), /^frame 12 \/ 12 · key 2$/);
    const last = await canvasInfo(page);
    await scrubTo(page, 5);
    const middle = await canvasInfo(page);
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
      let blue = 0;
      for (let i = 0; i < d.length; i += 4) if (d[i + 2] > d[i] + 60) blue++;
      return { frames: track.frameCount, width: c.width, blue: blue / (d.length / 4) };
    }, bytes.toString("base64"));
    assert.equal(decoded.frames, 12);
    assert.equal(decoded.width, 320);
    assert.ok(decoded.blue > 0.02, `last GIF frame ${(100 * decoded.blue).toFixed(1)}% fill colour`);
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

  await step("phone layout (390×844): nothing wider than the screen", async () => {
    await page.setViewportSize({ width: 390, height: 844 });
    await page.waitForTimeout(200);
    const overflow = await page.evaluate(() => document.documentElement.scrollWidth);
    assert.ok(overflow <= 390, `page is ${overflow} px wide`);
    await page.evaluate(() => window.dispatchEvent(new Event("resize")));
    await page.screenshot({ path: join(args.out, "phone-390x844.png"), fullPage: true });
  });

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
    const polygons = [
      [[50, 50], [150, 50], [150, 150], [50, 150]],
      [[60, 40], [140, 60], [160, 140], [100, 170], [40, 140]],
    ];
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
    await clickAll([[52, 48]]); // snaps to the corner (50, 50) of drawing 1; then drawing 2
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

  await step("no uncaught errors in the page", async () => {
    assert.deepEqual(pageErrors, []);
  });
  exitCode = 0;
} catch {
  exitCode = 1;
} finally {
  await browser.close();
  console.log(`${passed} passed, ${failed} failed`);
  writeFileSync(join(args.out, "result.txt"), `${passed} passed, ${failed} failed\n`);
}
process.exit(exitCode);
