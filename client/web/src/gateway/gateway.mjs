// The Inbetween web gateway: a Connect server for browsers in front of the C++ gRPC server.
//
// - inbetween.v1.Inbetween is forwarded method by method to the upstream server over the
//   Connect gRPC transport (HTTP/2): unary calls, server streams (progress, iterations,
//   frames) and, for HTTP/2 Connect clients, the EditTopology bidi stream.
// - inbetween.web.v1.Gateway/EditTopologyOnce is the browser's way to edit topology: one
//   unary call opens the server's EditTopology stream, sends the one edit, half-closes and
//   relays the one reply (or the server's status, e.g. ABORTED on a stale expected_version).
// - Anything else that is a GET is a file of the built page (dist/).
//
// The gateway checks nothing itself: the bearer token (authorization), the session id
// (x-session-id) and the request id are passed through, and the server's status, message and
// retry-after-ms come back unchanged. Cancellation (the tab goes away) cancels upstream.
import { readFile, stat } from "node:fs/promises";
import { extname, join, normalize, sep } from "node:path";

import { Code, ConnectError, createClient } from "@connectrpc/connect";
import {
  Http2SessionManager,
  connectNodeAdapter,
  createGrpcTransport,
} from "@connectrpc/connect-node";

import { Inbetween } from "../gen/inbetween/v1/inbetween_pb.js";
import { Gateway } from "../gen/inbetween/web/v1/gateway_pb.js";

// Request headers the server reads; nothing else is forwarded.
export const FORWARDED_REQUEST_HEADERS = ["authorization", "x-session-id", "x-request-id"];
// Response metadata the server sends that a page can use.
export const FORWARDED_RESPONSE_HEADERS = ["x-request-id", "retry-after-ms"];

// Largest message in either direction (a multimesh or a long SVG); the server has its own limit.
export const DEFAULT_MAX_BYTES = 64 * 1024 * 1024;

function forwardedHeaders(ctx) {
  const headers = new Headers();
  for (const name of FORWARDED_REQUEST_HEADERS) {
    const value = ctx.requestHeader.get(name);
    if (value !== null) headers.set(name, value);
  }
  return headers;
}

function copyHeaders(from, to) {
  for (const name of FORWARDED_RESPONSE_HEADERS) {
    const value = from.get(name);
    if (value !== null) to.set(name, value);
  }
}

// Options for one upstream call on behalf of the handler context `ctx`.
function callOptions(ctx) {
  return {
    headers: forwardedHeaders(ctx),
    signal: ctx.signal,
    timeoutMs: ctx.timeoutMs(),
    onHeader: (h) => copyHeaders(h, ctx.responseHeader),
    onTrailer: (t) => copyHeaders(t, ctx.responseTrailer),
  };
}

// Re-throws an upstream error with its code and message and only the metadata listed above.
function relayError(err) {
  const e = ConnectError.from(err);
  const metadata = new Headers();
  copyHeaders(e.metadata, metadata);
  return new ConnectError(e.rawMessage, e.code, metadata);
}

// A handler for every method of inbetween.v1.Inbetween that forwards to `client`.
export function forwardingImplementation(client) {
  const impl = {};
  for (const method of Inbetween.methods) {
    const call = client[method.localName];
    switch (method.methodKind) {
      case "unary":
        impl[method.localName] = async (req, ctx) => {
          try {
            return await call(req, callOptions(ctx));
          } catch (err) {
            throw relayError(err);
          }
        };
        break;
      case "server_streaming":
      case "bidi_streaming":
      case "client_streaming":
        impl[method.localName] = async function* (input, ctx) {
          try {
            yield* call(input, callOptions(ctx));
          } catch (err) {
            throw relayError(err);
          }
        };
        break;
      default:
        throw new Error(`unknown method kind ${method.methodKind}`);
    }
  }
  return impl;
}

// inbetween.web.v1.Gateway: one topology edit as a unary call over the server's bidi stream.
export function gatewayImplementation(client) {
  return {
    async editTopologyOnce(edit, ctx) {
      async function* one() {
        yield edit;
      }
      const replies = [];
      try {
        for await (const state of client.editTopology(one(), callOptions(ctx))) replies.push(state);
      } catch (err) {
        throw relayError(err);
      }
      if (replies.length !== 1) {
        // The server answers every edit exactly once (proto); anything else is a server bug.
        throw new ConnectError(
          `EditTopology answered one edit with ${replies.length} replies`,
          Code.Internal,
        );
      }
      return replies[0];
    },
  };
}

const CONTENT_TYPES = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".css": "text/css; charset=utf-8",
  ".svg": "image/svg+xml",
  ".png": "image/png",
  ".json": "application/json",
  ".map": "application/json",
};

// Serves GET/HEAD requests for files under `root` (the built page); 404 for anything else.
export function staticFiles(root) {
  const base = normalize(root + sep);
  return async (req, res) => {
    const url = new URL(req.url ?? "/", "http://gateway");
    let path;
    try {
      path = decodeURIComponent(url.pathname);
    } catch {
      path = "";
    }
    if (path.endsWith("/")) path += "index.html";
    const file = normalize(join(base, path));
    const ok = (req.method === "GET" || req.method === "HEAD") && file.startsWith(base);
    let body = null;
    if (ok) {
      try {
        if ((await stat(file)).isFile()) body = await readFile(file);
      } catch {
        body = null;
      }
    }
    if (body === null) {
      res.writeHead(404, { "content-type": "text/plain; charset=utf-8" });
      res.end("not found\n");
      return;
    }
    res.writeHead(200, {
      "content-type": CONTENT_TYPES[extname(file)] ?? "application/octet-stream",
      "content-length": body.length,
      "cache-control": "no-cache",
      "x-content-type-options": "nosniff",
    });
    res.end(req.method === "HEAD" ? undefined : body);
  };
}

// The request handler for node:http / node:http2: Connect routes, then the static page.
//   upstream:  "http://127.0.0.1:50051" (the inbetween-server, plaintext HTTP/2)
//   staticDir: directory of the built page, or null for API only
// handler.close() drops the upstream HTTP/2 connection (it is otherwise kept while idle).
export function createGatewayHandler({ upstream, staticDir = null, maxBytes = DEFAULT_MAX_BYTES }) {
  const sessionManager = new Http2SessionManager(upstream);
  const transport = createGrpcTransport({
    baseUrl: upstream,
    httpVersion: "2",
    sessionManager,
    readMaxBytes: maxBytes,
    writeMaxBytes: maxBytes,
  });
  const client = createClient(Inbetween, transport);
  const handler = connectNodeAdapter({
    readMaxBytes: maxBytes,
    writeMaxBytes: maxBytes,
    routes(router) {
      router.service(Inbetween, forwardingImplementation(client));
      router.service(Gateway, gatewayImplementation(client));
    },
    fallback: staticDir ? staticFiles(staticDir) : undefined,
  });
  handler.close = () => sessionManager.abort();
  return handler;
}
