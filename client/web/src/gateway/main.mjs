#!/usr/bin/env node
// inbetween-gateway: serves the built page and the Connect API on HTTP/1.1 (browsers) and
// forwards to inbetween-server over gRPC.
//   node src/gateway/main.mjs --upstream 127.0.0.1:50051 [--listen 127.0.0.1:8080] [--static DIR]
// --listen with port 0 picks a free port; the bound address is printed as
// "inbetween-gateway listening on http://HOST:PORT/".
import { createServer } from "node:http";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { parseArgs } from "node:util";

import { createGatewayHandler } from "./gateway.mjs";

const usage =
  "usage: main.mjs --upstream HOST:PORT [--listen HOST:PORT] [--static DIR | --no-static]";

function fail(message) {
  console.error(`inbetween-gateway: ${message}\n${usage}`);
  process.exit(2);
}

let values;
try {
  ({ values } = parseArgs({
    options: {
      upstream: { type: "string" },
      listen: { type: "string", default: "127.0.0.1:8080" },
      static: { type: "string" },
      "no-static": { type: "boolean", default: false },
      help: { type: "boolean", default: false },
    },
  }));
} catch (err) {
  fail(err.message);
}
if (values.help) {
  console.log(usage);
  process.exit(0);
}
if (!values.upstream) fail("--upstream is required");

function splitHostPort(text, flag) {
  const m = /^(\[[^\]]+\]|[^:]+):(\d+)$/.exec(text);
  if (!m || Number(m[2]) > 65535) fail(`${flag}: expected HOST:PORT, got "${text}"`);
  return { host: m[1].replace(/^\[|\]$/g, ""), port: Number(m[2]) };
}

const up = /^https?:\/\//.test(values.upstream) ? values.upstream : `http://${values.upstream}`;
const listen = splitHostPort(values.listen, "--listen");
const here = dirname(fileURLToPath(import.meta.url));
const staticDir = values["no-static"] ? null : (values.static ?? join(here, "..", "..", "dist"));

const handler = createGatewayHandler({ upstream: up, staticDir });
const server = createServer(handler);
server.on("error", (err) => {
  console.error(`inbetween-gateway: ${err.message}`);
  process.exit(1);
});
server.listen(listen.port, listen.host, () => {
  const addr = server.address();
  const host = addr.family === "IPv6" ? `[${addr.address}]` : addr.address;
  console.log(`inbetween-gateway listening on http://${host}:${addr.port}/ (upstream ${up})`);
});

function stop() {
  server.close(() => process.exit(0));
  server.closeAllConnections();
  handler.close();
}
process.on("SIGTERM", stop);
process.on("SIGINT", stop);
