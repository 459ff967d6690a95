// Shared by the browser tests (browser_test.mjs, lottie_test.mjs): Debian's Chromium launched
// the way this machine allows, and a step runner that prints one "ok"/"FAIL" line per step and
// counts them.
import { chromium } from "playwright-core";

// Headless Debian Chromium for pages on loopback. The launch gets at least 90 s whatever the
// step timeout: on a loaded 2-core CI machine a cold Chromium start once took over 30 s
// (lottie_web_test: 'browserType.launch: Timeout 30000ms exceeded').
const LAUNCH_MS = 90000;
export function launchChromium(executablePath, timeout) {
  return chromium.launch({
    executablePath,
    headless: true,
    // root in containers/CI cannot use Chromium's sandbox; the page only talks to loopback.
    args: [
      "--no-sandbox",
      "--disable-gpu",
      "--disable-quic",
      "--no-first-run",
      // No network but loopback here: keep Chromium from reaching out on its own.
      "--disable-background-networking",
      "--disable-component-update",
      "--disable-sync",
    ],
    timeout: Math.max(timeout, LAUNCH_MS),
  });
}

// step(name, fn) runs fn, prints its line and counts it in `counts`; with stopOnFailure a failed
// step also rethrows (the steps after it depend on it).
export function stepRunner({ stopOnFailure }) {
  const counts = { passed: 0, failed: 0 };
  async function step(name, fn) {
    const t0 = Date.now();
    try {
      await fn();
      counts.passed++;
      console.log(`ok   ${name} (${Date.now() - t0} ms)`);
    } catch (err) {
      counts.failed++;
      console.log(`FAIL ${name}: ${err.message.split("\n").slice(0, 6).join("\n     ")}`);
      if (stopOnFailure) throw err;
    }
  }
  return { step, counts };
}
