// Gateway unit tests: a stand-in upstream (a Connect gRPC server on loopback implementing a few
// Inbetween methods and recording what reached it) behind the real gateway handler, called the
// way the page calls it (Connect protocol over HTTP/1.1). The browser e2e test
// (tests/e2e/web_test.sh) runs the gateway against the real inbetween-server.
import assert from "node:assert/strict";
import { once } from "node:events";
import { mkdtemp, mkdir, rm, writeFile } from "node:fs/promises";
import { createServer } from "node:http";
import { createServer as createHttp2Server } from "node:http2";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { after, before, test } from "node:test";

import { create } from "@bufbuild/protobuf";
import { Code, ConnectError, createClient } from "@connectrpc/connect";
import { connectNodeAdapter, createConnectTransport } from "@connectrpc/connect-node";

import { createGatewayHandler } from "../src/gateway/gateway.mjs";
import {
  ElementKind,
  Inbetween,
  SessionSchema,
  TopologyStateSchema,
} from "../src/gen/inbetween/v1/inbetween_pb.js";
import { Gateway } from "../src/gen/inbetween/web/v1/gateway_pb.js";

const seen = []; // { method, headers: {authorization, x-session-id, x-other} , edits? }
function record(method, ctx, extra = {}) {
  const h = (n) => ctx.requestHeader.get(n);
  seen.push({
    method,
    authorization: h("authorization"),
    sessionId: h("x-session-id"),
    other: h("x-not-forwarded"),
    ...extra,
  });
}

const upstreamImpl = {
  async createSession(req, ctx) {
    record("createSession", ctx);
    ctx.responseHeader.set("x-request-id", "req-42");
    return { session: create(SessionSchema, { id: "s1", version: 1n, displayName: req.displayName }) };
  },
  async getSession(req, ctx) {
    record("getSession", ctx);
    const meta = new Headers({ "retry-after-ms": "250", "x-secret-internal": "no" });
    throw new ConnectError(`session ${req.sessionId} is busy`, Code.ResourceExhausted, meta);
  },
  async *buildMultimesh(req, ctx) {
    record("buildMultimesh", ctx);
    for (const fraction of [0.25, 0.5, 1]) {
      yield { event: { case: "progress", value: { stage: "map", fraction } } };
    }
    yield { event: { case: "result", value: { session: { id: req.sessionId, version: 5n } } } };
  },
  async *inbetween(req, ctx) {
    record("inbetween", ctx);
    yield { event: { case: "header", value: { frames: 2 } } };
    throw new ConnectError("Inbetween needs BuildMultimesh first", Code.FailedPrecondition);
  },
  async *editTopology(edits, ctx) {
    const got = [];
    for await (const edit of edits) {
      got.push(edit);
      if (edit.expectedVersion !== 7n) {
        record("editTopology", ctx, { edits: got });
        throw new ConnectError("expected_version 3, session is at 7", Code.Aborted);
      }
      yield create(TopologyStateSchema, {
        version: edit.expectedVersion + 1n,
        drawingId: edit.drawingId,
        elements: [{ id: 2, kind: edit.edit.value.kind, polyline: edit.edit.value.polyline }],
      });
    }
    record("editTopology", ctx, { edits: got });
  },
};

let upstream, gateway, gatewayHandler, staticDir, baseUrl;
const upstreamSessions = new Set();

before(async () => {
  upstream = createHttp2Server(
    connectNodeAdapter({ routes: (r) => r.service(Inbetween, upstreamImpl) }),
  );
  upstream.on("session", (s) => {
    upstreamSessions.add(s);
    s.on("close", () => upstreamSessions.delete(s));
  });
  upstream.listen(0, "127.0.0.1");
  await once(upstream, "listening");
  staticDir = await mkdtemp(join(tmpdir(), "gateway-test-"));
  await mkdir(join(staticDir, "sub"));
  await writeFile(join(staticDir, "index.html"), "<!doctype html><title>page</title>");
  await writeFile(join(staticDir, "app.js"), "console.log(1)");
  await writeFile(join(tmpdir(), "gateway-test-outside.txt"), "secret");
  gatewayHandler = createGatewayHandler({
    upstream: `http://127.0.0.1:${upstream.address().port}`,
    staticDir,
  });
  gateway = createServer(gatewayHandler);
  gateway.listen(0, "127.0.0.1");
  await once(gateway, "listening");
  baseUrl = `http://127.0.0.1:${gateway.address().port}`;
});

after(async () => {
  gateway.closeAllConnections();
  gateway.close();
  gatewayHandler.close();
  for (const s of upstreamSessions) s.destroy();
  upstream.close();
  await rm(staticDir, { recursive: true, force: true });
  await rm(join(tmpdir(), "gateway-test-outside.txt"), { force: true });
});

function clients() {
  const transport = createConnectTransport({ baseUrl, httpVersion: "1.1" });
  return { api: createClient(Inbetween, transport), gw: createClient(Gateway, transport) };
}

const headers = {
  authorization: "Bearer tok-1",
  "x-session-id": "s1",
  "x-not-forwarded": "x",
};

test("unary call is forwarded with token and session id, nothing else", async () => {
  const { api } = clients();
  let requestId = null;
  const res = await api.createSession(
    { displayName: "walk" },
    { headers, onHeader: (h) => (requestId = h.get("x-request-id")) },
  );
  assert.equal(res.session.id, "s1");
  assert.equal(res.session.displayName, "walk");
  assert.equal(requestId, "req-42");
  const call = seen.findLast((s) => s.method === "createSession");
  assert.equal(call.authorization, "Bearer tok-1");
  assert.equal(call.sessionId, "s1");
  assert.equal(call.other, null);
});

test("server error comes back with its code, message and retry-after-ms only", async () => {
  const { api } = clients();
  await assert.rejects(api.getSession({ sessionId: "s9" }, { headers }), (err) => {
    assert.ok(err instanceof ConnectError);
    assert.equal(err.code, Code.ResourceExhausted);
    assert.equal(err.rawMessage, "session s9 is busy");
    assert.equal(err.metadata.get("retry-after-ms"), "250");
    assert.equal(err.metadata.get("x-secret-internal"), null);
    return true;
  });
});

test("server stream is relayed in order to an HTTP/1.1 client", async () => {
  const { api } = clients();
  const events = [];
  for await (const m of api.buildMultimesh({ sessionId: "s1", expectedVersion: 4n }, { headers })) {
    events.push(m.event.case === "progress" ? m.event.value.fraction : m.event.case);
  }
  assert.deepEqual(events, [0.25, 0.5, 1, "result"]);
  assert.equal(seen.findLast((s) => s.method === "buildMultimesh").authorization, "Bearer tok-1");
});

test("error in the middle of a stream ends the stream with that error", async () => {
  const { api } = clients();
  const events = [];
  await assert.rejects(
    (async () => {
      for await (const m of api.inbetween({ sessionId: "s1" }, { headers })) events.push(m.event.case);
    })(),
    (err) => err.code === Code.FailedPrecondition && /BuildMultimesh first/.test(err.rawMessage),
  );
  assert.deepEqual(events, ["header"]);
});

test("EditTopologyOnce sends exactly one edit on the bidi stream and relays the state", async () => {
  const { gw } = clients();
  const polyline = { points: [{ x: 1, y: 2 }, { x: 3, y: 4 }] };
  const state = await gw.editTopologyOnce(
    {
      sessionId: "s1",
      expectedVersion: 7n,
      drawingId: 1,
      edit: { case: "add", value: { kind: ElementKind.CUT, polyline } },
    },
    { headers },
  );
  assert.equal(state.version, 8n);
  assert.equal(state.elements[0].kind, ElementKind.CUT);
  assert.deepEqual(
    state.elements[0].polyline.points.map((p) => [p.x, p.y]),
    [
      [1, 2],
      [3, 4],
    ],
  );
  const call = seen.findLast((s) => s.method === "editTopology");
  assert.equal(call.edits.length, 1);
  assert.equal(call.authorization, "Bearer tok-1");
  assert.equal(call.sessionId, "s1");
});

test("EditTopologyOnce with a stale version is ABORTED", async () => {
  const { gw } = clients();
  await assert.rejects(
    gw.editTopologyOnce(
      { sessionId: "s1", expectedVersion: 3n, drawingId: 1, edit: { case: "deleteElement", value: 2 } },
      { headers },
    ),
    (err) => err.code === Code.Aborted && /expected_version/.test(err.rawMessage),
  );
});

test("unreachable upstream is UNAVAILABLE, not a hang", async () => {
  const deadHandler = createGatewayHandler({ upstream: "http://127.0.0.1:1" });
  const dead = createServer(deadHandler);
  dead.listen(0, "127.0.0.1");
  await once(dead, "listening");
  try {
    const transport = createConnectTransport({
      baseUrl: `http://127.0.0.1:${dead.address().port}`,
      httpVersion: "1.1",
    });
    await assert.rejects(
      createClient(Inbetween, transport).createSession({}),
      (err) => err.code === Code.Unavailable,
    );
  } finally {
    dead.closeAllConnections();
    dead.close();
    deadHandler.close();
  }
});

test("static page: files under the directory, 404 outside it and for unknown paths", async () => {
  const index = await fetch(`${baseUrl}/`);
  assert.equal(index.status, 200);
  assert.match(index.headers.get("content-type"), /text\/html/);
  assert.match(await index.text(), /<title>page<\/title>/);
  const js = await fetch(`${baseUrl}/app.js`);
  assert.match(js.headers.get("content-type"), /javascript/);
  assert.equal((await fetch(`${baseUrl}/missing.js`)).status, 404);
  assert.equal((await fetch(`${baseUrl}/sub`)).status, 404);
  assert.equal((await fetch(`${baseUrl}/..%2fgateway-test-outside.txt`)).status, 404);
  assert.equal((await fetch(`${baseUrl}/%2e%2e/gateway-test-outside.txt`)).status, 404);
  assert.equal((await fetch(`${baseUrl}/index.html`, { method: "DELETE" })).status, 404);
});
