// Builds the static page into dist/: bundles src/page/app.js (with the generated code and the
// Connect web client) with esbuild and copies index.html and app.css. Needs `npm run gen` first.
import { copyFileSync, mkdirSync, rmSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

import { build } from "esbuild";

const web = join(dirname(fileURLToPath(import.meta.url)), "..");
const page = join(web, "src", "page");
const out = join(web, "dist");
rmSync(out, { recursive: true, force: true });
mkdirSync(out, { recursive: true });
await build({
  entryPoints: [join(page, "app.js")],
  bundle: true,
  format: "esm",
  target: ["chrome110", "firefox110", "safari16"],
  minify: true,
  sourcemap: true,
  outfile: join(out, "app.js"),
  logLevel: "warning",
});
for (const f of ["index.html", "app.css"]) copyFileSync(join(page, f), join(out, f));
console.log(`build-page: wrote ${out}`);
