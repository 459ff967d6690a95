// Generates the protobuf-es code (src/gen/) from proto/inbetween/v1 and the gateway proto with
// Debian's protoc and @bufbuild/protoc-gen-es. Generated code is not committed.
import { execFileSync } from "node:child_process";
import { mkdirSync, rmSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const web = join(dirname(fileURLToPath(import.meta.url)), "..");
const repoProto = join(web, "..", "..", "proto");
const out = join(web, "src", "gen");
rmSync(out, { recursive: true, force: true });
mkdirSync(out, { recursive: true });
execFileSync(
  "protoc",
  [
    `--plugin=protoc-gen-es=${join(web, "node_modules", ".bin", "protoc-gen-es")}`,
    `--es_out=${out}`,
    "--es_opt=target=js,import_extension=js",
    `-I${repoProto}`,
    `-I${join(web, "proto")}`,
    "inbetween/v1/inbetween.proto",
    "inbetween/web/v1/gateway.proto",
  ],
  { stdio: "inherit" },
);
console.log(`gen: wrote ${out}`);
