// The Inbetween page: key drawings -> topology edits and marks -> multimesh (build, optimize,
// energy chart) -> inbetweens (timeline, parameters) -> player (canvas: each frame's art by
// art.js, the same rule as the CLI's renderers, or the one-colour silhouette; mesh overlay) ->
// downloads. Talks Connect to the gateway on the same origin (inbetween.v1.Inbetween, plus
// inbetween.web.v1.Gateway/EditTopologyOnce for topology edits). Every server error is shown
// in the error line of the control that caused it.
import { Code, ConnectError, createClient } from "@connectrpc/connect";
import { createConnectTransport } from "@connectrpc/connect-web";

import {
  ElementKind,
  Inbetween,
  Method,
  Stage,
  TimingCurve,
} from "../gen/inbetween/v1/inbetween_pb.js";
import { Gateway } from "../gen/inbetween/web/v1/gateway_pb.js";
import { appendArtChunk, artForFrame, hasArt, keysFromProto, paintArt } from "./art.js";
import { addPoint, emptyBounds, fitView, isEmpty, nearestOnPolylines, signedArea2 } from "./geometry.js";
import { encodeGif } from "./gif.js";
import { makeLottie } from "./lottie.js";

const $ = (id) => document.getElementById(id);
const transport = createConnectTransport({ baseUrl: location.origin, useBinaryFormat: true });
const api = createClient(Inbetween, transport);
const gateway = createClient(Gateway, transport);

const FILL = "#3b7dd8";
const COLORS = { outline: "#3b7dd8", cut: "#d6336c", opening: "#f08c00", boundary: "#2b8a3e" };

const state = {
  session: null,
  fileNames: new Map(), // drawing id -> uploaded file name (for the project file)
  polygonSvgs: new Map(), // drawing id -> SVG text of a drawing made with the mouse
  classes: new Map(), // drawing id -> EquivalenceClass
  topology: new Map(), // drawing id -> { boundaries, cohesiveEdges }
  failedUploads: [], // { name, error }
  drawingErrors: new Map(), // drawing id -> message
  selected: 0, // drawing id shown in the editor
  stroke: [], // points of the element being drawn
  marks: [], // [[{x,y} per drawing], ...]
  pendingMark: [],
  editorView: null,
  multimesh: null,
  chart: { map: [], mesh: [] },
  triangles: null,
  frames: [], // Float64Array per frame
  frameStats: [],
  frameWeights: [], // Float64Array per frame: its example weights, one per drawing
  drawingCount: 0, // drawings of the Inbetween run (InbetweenHeader.keys)
  artProto: [], // InbetweenHeader.art, with the InbetweenResponse.art messages appended
  artExpected: 0, // InbetweenHeader.art_messages
  artReceived: 0,
  art: null, // art.js keys once the header's art is complete, or null (no art: silhouette)
  frameArt: [], // per frame: its art layers (computed when first drawn)
  artError: "", // why the art cannot be drawn (the silhouette is drawn instead)
  keys: [],
  totalFrames: 0,
  frameBounds: emptyBounds(),
  current: 0,
  playing: false,
  heavy: null, // AbortController of the running stream
  keyTimes: null, // user-set key times (null = evenly spaced)
  ease: [],
};

// ------------------------------------------------------------------------------------------
// Calls and errors

function callOptions(signal) {
  const headers = {};
  const token = $("token").value.trim();
  if (token) headers.authorization = `Bearer ${token}`;
  if (state.session) headers["x-session-id"] = state.session.id;
  return { headers, signal };
}

function codeName(code) {
  return (Code[code] ?? String(code)).replace(/([a-z])([A-Z])/g, "$1_$2").toUpperCase();
}

function describe(err) {
  const e = ConnectError.from(err);
  return `${codeName(e.code)}: ${e.rawMessage}`;
}

function showError(slot, err) {
  const el = typeof slot === "string" ? $(slot) : slot;
  el.textContent = err ? (typeof err === "string" ? err : describe(err)) : "";
}

// Runs a mutating call; ABORTED (stale version) reloads the session and says so in `slot`.
async function mutate(slot, fn) {
  showError(slot, null);
  try {
    return await fn();
  } catch (err) {
    const e = ConnectError.from(err);
    if (e.code === Code.Aborted) {
      await reloadSession();
      showError(slot, `${describe(e)}\nThe session changed elsewhere: reloaded it, try again.`);
    } else if (e.code !== Code.Canceled) {
      showError(slot, e);
    } else {
      showError(slot, "cancelled");
    }
    return undefined;
  }
}

const version = () => state.session.version;
const sid = () => state.session.id;
const drawings = () => state.session?.drawings ?? [];

// ------------------------------------------------------------------------------------------
// Session

function applySession(session) {
  state.session = session;
  if (!drawings().some((d) => d.id === state.selected)) state.selected = drawings()[0]?.id ?? 0;
  const stage = session.stage === Stage.UNSPECIFIED ? "empty" : (Stage[session.stage] ?? "?");
  $("session-info").textContent =
    `session ${session.id} · v${session.version} · ${drawings().length} drawings · ${stage.toLowerCase()}`;
  $("session-info").dataset.version = String(session.version);
  $("session-info").dataset.sessionId = session.id;
  if (session.multimeshStats && session.stage >= Stage.MULTIMESH) showStats(session.multimeshStats);
  renderDrawings();
  renderEditor();
  renderTimeline();
}

async function newSession() {
  showError("error-session", null);
  try {
    const res = await api.createSession({ displayName: "web" }, callOptions());
    resetProject();
    applySession(res.session);
  } catch (err) {
    showError("error-session", err);
  }
}

async function reloadSession() {
  try {
    const res = await api.getSession({ sessionId: sid() }, callOptions());
    applySession(res.session);
  } catch (err) {
    showError("error-session", err);
  }
}

function resetProject() {
  for (const m of [state.fileNames, state.polygonSvgs, state.classes, state.topology]) m.clear();
  state.drawingErrors.clear();
  state.failedUploads = [];
  state.marks = [];
  state.pendingMark = [];
  state.stroke = [];
  state.multimesh = null;
  state.chart = { map: [], mesh: [] };
  state.keyTimes = null;
  resetFrames();
  renderChart();
}

// ------------------------------------------------------------------------------------------
// Drawings

async function uploadFiles(files) {
  showError("error-upload", null);
  for (const file of files) {
    const svg = await file.text();
    await putDrawing({ name: file.name, source: { case: "svg", value: svg } }, file.name);
  }
}

async function putDrawing(drawing, name, svgText = null) {
  try {
    const res = await api.putDrawing(
      { sessionId: sid(), expectedVersion: version(), drawing },
      callOptions(),
    );
    state.classes.set(res.drawing.id, res.equivalenceClass);
    if (svgText) state.polygonSvgs.set(res.drawing.id, svgText);
    else state.fileNames.set(res.drawing.id, name);
    state.selected = res.drawing.id;
    invalidateMesh();
    applySession(res.session);
    return true;
  } catch (err) {
    state.failedUploads.push({ name, error: describe(err) });
    if (ConnectError.from(err).code === Code.Aborted) await reloadSession();
    renderDrawings();
    return false;
  }
}

async function removeDrawing(id) {
  state.drawingErrors.delete(id);
  try {
    const res = await api.removeDrawing(
      { sessionId: sid(), expectedVersion: version(), drawingId: id },
      callOptions(),
    );
    state.topology.delete(id);
    state.classes.delete(id);
    state.marks = [];
    state.pendingMark = [];
    state.keyTimes = null;
    invalidateMesh();
    applySession(res.session);
  } catch (err) {
    state.drawingErrors.set(id, describe(err));
    if (ConnectError.from(err).code === Code.Aborted) await reloadSession();
    renderDrawings();
  }
}

function elementPolylines(d) {
  return d.elements.map((e) => ({
    kind: e.kind,
    id: e.id,
    points: e.polyline?.points ?? [],
    closed: e.kind === ElementKind.OUTLINE,
  }));
}

function drawingBounds(d) {
  const b = emptyBounds();
  for (const e of d.elements) for (const p of e.polyline?.points ?? []) addPoint(b, p.x, p.y);
  return b;
}

function kindName(kind) {
  return { [ElementKind.OUTLINE]: "outline", [ElementKind.CUT]: "cut", [ElementKind.OPENING]: "opening" }[kind] ?? "?";
}

function strokePolyline(ctx, view, points, closed) {
  ctx.beginPath();
  points.forEach((p, i) => {
    const [x, y] = view.toScreen(p.x, p.y);
    if (i === 0) ctx.moveTo(x, y);
    else ctx.lineTo(x, y);
  });
  if (closed) ctx.closePath();
}

// Draws a drawing's elements, rebuilt boundaries and marks into `ctx` with `view`.
function paintDrawing(ctx, view, d, index, detailed) {
  const outlines = elementPolylines(d).filter((e) => e.closed);
  ctx.beginPath();
  for (const e of outlines) {
    e.points.forEach((p, i) => {
      const [x, y] = view.toScreen(p.x, p.y);
      if (i === 0) ctx.moveTo(x, y);
      else ctx.lineTo(x, y);
    });
    ctx.closePath();
  }
  ctx.fillStyle = "rgba(59,125,216,0.25)";
  ctx.fill("evenodd");
  for (const e of elementPolylines(d)) {
    strokePolyline(ctx, view, e.points, e.closed);
    ctx.strokeStyle = COLORS[kindName(e.kind)] ?? "#000";
    ctx.lineWidth = e.closed ? 1.5 : 2.5;
    ctx.stroke();
  }
  const topo = state.topology.get(d.id);
  if (topo && detailed) {
    // Rebuilt boundaries: each region bounded by a positive loop gets its own tint, so a cut
    // that separates the shape shows as two colours; every loop is dashed on top.
    topo.boundaries.forEach((b, i) => {
      if (signedArea2(b.points) <= 0) return;
      strokePolyline(ctx, view, b.points, true);
      ctx.fillStyle = `hsla(${(i * 137) % 360}, 70%, 55%, 0.25)`;
      ctx.fill();
    });
    ctx.setLineDash([5, 4]);
    ctx.strokeStyle = COLORS.boundary;
    ctx.lineWidth = 1.5;
    for (const b of topo.boundaries) {
      strokePolyline(ctx, view, b.points, true);
      ctx.stroke();
    }
    ctx.setLineDash([]);
    ctx.strokeStyle = "#7048e8";
    ctx.lineWidth = 3;
    for (const e of topo.cohesiveEdges) {
      strokePolyline(ctx, view, [e.a, e.b], false);
      ctx.stroke();
    }
  }
  const marks = [...state.marks, state.pendingMark];
  marks.forEach((mark, mi) => {
    const p = mark[index];
    if (!p) return;
    const [x, y] = view.toScreen(p.x, p.y);
    ctx.fillStyle = mi === state.marks.length ? "#f08c00" : "#222";
    ctx.beginPath();
    ctx.arc(x, y, detailed ? 5 : 3, 0, 2 * Math.PI);
    ctx.fill();
    if (detailed) {
      ctx.font = "12px system-ui";
      ctx.fillText(String(mi + 1), x + 6, y - 6);
    }
  });
}

// Sizes a canvas's backing store to its CSS size; returns [ctx, width, height] in CSS px.
function prepareCanvas(canvas) {
  const dpr = window.devicePixelRatio || 1;
  const w = canvas.clientWidth || canvas.width;
  const h = canvas.clientHeight || canvas.height;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
  }
  const ctx = canvas.getContext("2d");
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.fillStyle = "#fff";
  ctx.fillRect(0, 0, w, h);
  return [ctx, w, h];
}

function classText(c) {
  if (!c) return "";
  return `${c.components} comp. · ${c.holes} hole${c.holes === 1 ? "" : "s"}`;
}

function renderDrawings() {
  const list = $("drawing-list");
  list.textContent = "";
  drawings().forEach((d, index) => {
    const li = document.createElement("li");
    li.dataset.drawingId = String(d.id);
    li.className = d.id === state.selected ? "selected" : "";
    const canvas = document.createElement("canvas");
    canvas.title = "Edit this drawing";
    canvas.addEventListener("click", () => {
      state.selected = d.id;
      state.stroke = [];
      renderDrawings();
      renderEditor();
    });
    const name = document.createElement("div");
    name.className = "name";
    name.textContent = `${index + 1}. ${d.name}`;
    name.title = d.name;
    const info = document.createElement("div");
    info.className = "muted class";
    info.textContent = classText(state.classes.get(d.id));
    const remove = document.createElement("button");
    remove.type = "button";
    remove.textContent = "Remove";
    remove.addEventListener("click", () => removeDrawing(d.id));
    const error = document.createElement("p");
    error.className = "error";
    error.setAttribute("role", "alert");
    error.textContent = state.drawingErrors.get(d.id) ?? "";
    li.append(canvas, name, info, remove, error);
    list.append(li);
    const [ctx, w, h] = prepareCanvas(canvas);
    paintDrawing(ctx, fitView(drawingBounds(d), w, h, 6), d, index, false);
  });
  state.failedUploads.forEach((f, i) => {
    const li = document.createElement("li");
    li.className = "failed";
    li.dataset.failedUpload = f.name;
    const name = document.createElement("div");
    name.className = "name";
    name.textContent = f.name;
    const error = document.createElement("p");
    error.className = "error";
    error.setAttribute("role", "alert");
    error.textContent = f.error;
    const dismiss = document.createElement("button");
    dismiss.type = "button";
    dismiss.textContent = "Dismiss";
    dismiss.addEventListener("click", () => {
      state.failedUploads.splice(i, 1);
      renderDrawings();
    });
    li.append(name, error, dismiss);
    list.append(li);
  });
}

// ------------------------------------------------------------------------------------------
// Editor: cuts, openings, marks, new polygons

const tool = () => document.querySelector('input[name="tool"]:checked').value;

function selectedDrawing() {
  const i = drawings().findIndex((d) => d.id === state.selected);
  return i < 0 ? [null, -1] : [drawings()[i], i];
}

function renderEditor() {
  const canvas = $("editor");
  const [ctx, w, h] = prepareCanvas(canvas);
  const [d, index] = selectedDrawing();
  // The view fits the drawing, and stays put while a stroke is being drawn.
  const old = state.editorView;
  let view = old;
  if (!(state.stroke.length && old && old.w === w && old.h === h)) {
    const b = d ? drawingBounds(d) : emptyBounds();
    if (isEmpty(b) || Math.max(b.maxX - b.minX, b.maxY - b.minY) < 1e-6) {
      addPoint(addPoint(b, 0, 0), 200, 200);
    }
    // Room around the drawing: cuts and openings start and end outside the outline.
    const margin = 0.2 * Math.max(b.maxX - b.minX, b.maxY - b.minY);
    addPoint(addPoint(b, b.minX - margin, b.minY - margin), b.maxX + margin, b.maxY + margin);
    view = { ...fitView(b, w, h, 8), w, h };
  }
  state.editorView = view;
  canvas.dataset.scale = String(view.scale);
  canvas.dataset.ox = String(view.ox);
  canvas.dataset.oy = String(view.oy);
  if (d) paintDrawing(ctx, view, d, index, true);
  if (state.stroke.length) {
    strokePolyline(ctx, view, state.stroke, tool() === "polygon" && state.stroke.length > 2);
    ctx.strokeStyle = tool() === "polygon" ? "#222" : COLORS[tool()] ?? "#222";
    ctx.lineWidth = 2;
    ctx.stroke();
    for (const p of state.stroke) {
      const [x, y] = view.toScreen(p.x, p.y);
      ctx.fillStyle = "#222";
      ctx.fillRect(x - 2.5, y - 2.5, 5, 5);
    }
  }
  const list = $("element-list");
  list.textContent = "";
  for (const e of d?.elements ?? []) {
    if (e.kind === ElementKind.OUTLINE) continue;
    const li = document.createElement("li");
    li.textContent = `${kindName(e.kind)} #${e.id} (${e.polyline?.points.length ?? 0} points) `;
    const del = document.createElement("button");
    del.type = "button";
    del.textContent = "Delete";
    del.addEventListener("click", () => editTopology(d.id, { case: "deleteElement", value: e.id }));
    li.append(del);
    list.append(li);
  }
  const topo = d && state.topology.get(d.id);
  $("topology-info").textContent = topo
    ? `rebuilt: ${topo.boundaries.length} boundar${topo.boundaries.length === 1 ? "y" : "ies"} · ` +
      `${topo.cohesiveEdges.length} cohesive edge${topo.cohesiveEdges.length === 1 ? "" : "s"}`
    : "";
  $("warnings").textContent = "";
  for (const w of topo?.warnings ?? []) {
    const li = document.createElement("li");
    li.textContent = w;
    $("warnings").append(li);
  }
  $("marks-info").textContent = state.marks.length
    ? `${state.marks.length} mark(s)${state.pendingMark.length ? `, placing mark ${state.marks.length + 1}` : ""}`
    : state.pendingMark.length
      ? `placing mark 1: ${state.pendingMark.length}/${drawings().length} drawings`
      : "marks: automatic";
}

function editorPoint(ev) {
  const r = $("editor").getBoundingClientRect();
  const [x, y] = state.editorView.toWorld(ev.clientX - r.left, ev.clientY - r.top);
  return { x, y };
}

function onEditorClick(ev) {
  if (!state.session) return;
  const p = editorPoint(ev);
  if (tool() === "mark") return placeMark(p);
  state.stroke.push(p);
  renderEditor();
}

function placeMark(p) {
  const [d, index] = selectedDrawing();
  if (!d) return;
  if (index !== state.pendingMark.length) {
    showError("error-marks", `Place mark ${state.marks.length + 1} on drawing ${state.pendingMark.length + 1} next.`);
    return;
  }
  showError("error-marks", null);
  const snapped = nearestOnPolylines(
    [...elementPolylines(d).filter((e) => e.closed), ...(state.topology.get(d.id)?.boundaries ?? []).map((b) => ({ points: b.points, closed: true }))],
    p.x,
    p.y,
  );
  state.pendingMark.push(snapped ?? p);
  if (state.pendingMark.length === drawings().length) {
    state.marks.push(state.pendingMark);
    state.pendingMark = [];
    state.selected = drawings()[0].id;
  } else {
    state.selected = drawings()[state.pendingMark.length].id;
  }
  renderDrawings();
  renderEditor();
}

async function finishStroke() {
  const points = state.stroke;
  const t = tool();
  if (t === "polygon") {
    if (points.length < 3) return showError("error-edit", "A polygon needs at least 3 points.");
    const outline = signedArea2(points) < 0 ? [...points].reverse() : [...points];
    const n = drawings().length + 1;
    const svg = polygonSvg(outline);
    state.stroke = [];
    showError("error-edit", null);
    await putDrawing(
      {
        name: `polygon_${n}.svg`,
        source: {
          case: "polylines",
          value: { elements: [{ kind: ElementKind.OUTLINE, polyline: { points: outline } }] },
        },
      },
      `polygon_${n}.svg`,
      svg,
    );
    return;
  }
  if (t === "mark") return;
  const [d] = selectedDrawing();
  if (!d) return showError("error-edit", "Upload or draw a drawing first.");
  if (points.length < 2) return showError("error-edit", `A ${t} needs at least 2 points.`);
  const kind = t === "cut" ? ElementKind.CUT : ElementKind.OPENING;
  const ok = await editTopology(d.id, { case: "add", value: { kind, polyline: { points } } });
  if (ok) state.stroke = [];
  renderEditor();
}

async function editTopology(drawingId, edit) {
  const res = await mutate("error-edit", () =>
    gateway.editTopologyOnce(
      { sessionId: sid(), expectedVersion: version(), drawingId, edit },
      callOptions(),
    ),
  );
  if (!res) return false;
  state.session.version = res.version;
  const d = drawings().find((x) => x.id === res.drawingId);
  if (d) d.elements = res.elements;
  state.topology.set(res.drawingId, {
    boundaries: res.boundaries.map((b) => ({ points: b.points })),
    cohesiveEdges: res.cohesiveEdges,
    warnings: res.warnings,
  });
  drawings().forEach((dd, i) => res.classes[i] && state.classes.set(dd.id, res.classes[i]));
  invalidateMesh();
  applySession(state.session);
  return true;
}

function polygonSvg(points) {
  const b = emptyBounds();
  for (const p of points) addPoint(b, p.x, p.y);
  const d = points.map((p, i) => `${i ? "L" : "M"} ${p.x.toFixed(3)} ${p.y.toFixed(3)}`).join(" ");
  return (
    `<svg xmlns="http://www.w3.org/2000/svg" viewBox="${b.minX - 10} ${b.minY - 10} ` +
    `${b.maxX - b.minX + 20} ${b.maxY - b.minY + 20}">\n  <path fill="${FILL}" d="${d} Z"/>\n</svg>\n`
  );
}

async function sendMarks() {
  const res = await mutate("error-marks", () =>
    api.setCorrespondences(
      { sessionId: sid(), expectedVersion: version(), correspondences: state.marks.map((m) => ({ points: m })) },
      callOptions(),
    ),
  );
  if (res) {
    invalidateMesh();
    applySession(res.session);
  }
}

// ------------------------------------------------------------------------------------------
// Multimesh: build, optimize, chart

function invalidateMesh() {
  state.multimesh = null;
}

function setBusy(busy) {
  for (const id of ["build", "optimize", "inbetween"]) $(id).disabled = busy;
  $("cancel-heavy").disabled = !busy;
}

function setProgress(p) {
  $("progress").value = p.fraction;
  $("progress-text").textContent = `${p.stage} ${(100 * p.fraction).toFixed(0)}% ${p.detail}`;
}

function showStats(s) {
  $("mesh-stats").textContent =
    `${s.vertices} vertices · ${s.triangles} triangles · ${s.shapes} shapes · ` +
    `map energy ${s.mapEnergy.toFixed(4)} · mesh energy ${s.meshEnergy.toPrecision(4)} · ` +
    `worst triangle quality ${s.worstQuality.toFixed(3)}`;
}

async function heavy(slot, run) {
  const ac = new AbortController();
  state.heavy = ac;
  setBusy(true);
  try {
    return await mutate(slot, () => run(ac.signal));
  } finally {
    state.heavy = null;
    setBusy(false);
  }
}

async function build() {
  showError("error-build", null);
  await heavy("error-build", async (signal) => {
    for await (const m of api.buildMultimesh(
      { sessionId: sid(), expectedVersion: version() },
      callOptions(signal),
    )) {
      if (m.event.case === "progress") setProgress(m.event.value);
      if (m.event.case === "result") {
        const r = m.event.value;
        state.multimesh = r.multimesh;
        state.chart = { map: [r.stats.mapEnergy], mesh: [r.stats.meshEnergy] };
        renderChart();
        applySession(r.session);
        showStats(r.stats);
      }
    }
    return true;
  });
}

async function optimize() {
  await heavy("error-build", async (signal) => {
    const comesh = { mapWeight: Number($("map-weight").value) };
    // Unset: the server's default (outline sliding at 25 degrees); 0 turns it off.
    if (!$("slide-outline").checked) comesh.outlineCornerDegrees = 0;
    for await (const m of api.optimizeComesh(
      { sessionId: sid(), expectedVersion: version(), comesh },
      callOptions(signal),
    )) {
      const ev = m.event;
      if (ev.case === "progress") setProgress(ev.value);
      if (ev.case === "iteration") {
        state.chart.map.push(ev.value.mapEnergy);
        state.chart.mesh.push(ev.value.meshEnergy);
        $("progress-text").textContent =
          `optimize: outer ${ev.value.outer}, inner ${ev.value.inner}, ${ev.value.vertices} vertices`;
        renderChart();
      }
      if (ev.case === "result") {
        const r = ev.value;
        state.multimesh = r.multimesh;
        applySession(r.session);
        showStats(r.stats);
        $("progress").value = 1;
        $("progress-text").textContent =
          `optimized: ${r.outerIterations} outer / ${r.innerIterations} inner iterations in ${r.seconds.toFixed(2)} s`;
      }
    }
    return true;
  });
}

function renderChart() {
  const svg = $("chart");
  const W = 600;
  const H = 200;
  const pad = 8;
  const n = Math.max(state.chart.map.length, 2);
  let html = "";
  for (const [name, series] of Object.entries(state.chart)) {
    if (!series.length) continue;
    // Each series on its own scale (map energy ~2, mesh energy in squared user units).
    const lo = Math.min(...series);
    const hi = Math.max(...series);
    const span = hi - lo || 1;
    const pts = series.map((v, i) => {
      const x = pad + ((W - 2 * pad) * i) / (n - 1);
      const y = H - pad - ((H - 2 * pad) * (v - lo)) / span;
      return `${x.toFixed(1)},${y.toFixed(1)}`;
    });
    html += `<polyline class="${name}" fill="none" stroke-width="2" vector-effect="non-scaling-stroke" points="${pts.join(" ")}"/>`;
  }
  svg.innerHTML = html;
  svg.dataset.points = String(state.chart.map.length);
  const last = (s) => (s.length ? s[s.length - 1].toPrecision(5) : "–");
  $("chart-info").textContent = state.chart.map.length
    ? `${state.chart.map.length} points · map ${last(state.chart.map)} · mesh ${last(state.chart.mesh)}`
    : "";
}

// ------------------------------------------------------------------------------------------
// Timeline and parameters

function renderTimeline() {
  const tl = $("timeline");
  tl.textContent = "";
  const ds = drawings();
  if (ds.length < 2) return;
  const times = state.keyTimes ?? ds.map((_, i) => i / (ds.length - 1));
  ds.forEach((d, i) => {
    const row = document.createElement("div");
    row.className = "track";
    const label = document.createElement("span");
    label.textContent = `key ${i + 1} time`;
    const input = document.createElement("input");
    input.type = "range";
    input.min = "0";
    input.max = "1";
    input.step = "0.01";
    input.value = String(times[i]);
    input.disabled = i === 0 || i === ds.length - 1;
    input.setAttribute("aria-label", `key time of drawing ${i + 1}`);
    const out = document.createElement("output");
    out.textContent = times[i].toFixed(2);
    input.addEventListener("input", () => {
      state.keyTimes = state.keyTimes ?? [...times];
      state.keyTimes[i] = Number(input.value);
      out.textContent = Number(input.value).toFixed(2);
    });
    row.append(label, input, out);
    tl.append(row);
  });
  if (Number($("timing").value) === TimingCurve.EASE_IN_OUT) {
    for (let s = 0; s + 1 < ds.length; s++) {
      const row = document.createElement("div");
      row.className = "track";
      const label = document.createElement("span");
      label.textContent = `ease ${s + 1}→${s + 2}`;
      const input = document.createElement("input");
      input.type = "range";
      input.min = "0";
      input.max = "1";
      input.step = "0.05";
      input.value = String(state.ease[s] ?? 1);
      input.setAttribute("aria-label", `ease of segment ${s + 1}`);
      const out = document.createElement("output");
      out.textContent = Number(input.value).toFixed(2);
      input.addEventListener("input", () => {
        state.ease[s] = Number(input.value);
        out.textContent = Number(input.value).toFixed(2);
      });
      row.append(label, input, out);
      tl.append(row);
    }
  }
}

function inbetweenParameters() {
  const ds = drawings();
  const params = {
    method: Number($("method").value),
    frames: Number($("frames").value),
    timing: Number($("timing").value),
    tau: Number($("tau").value),
    alpha: Number($("alpha").value),
    epsilon: Number($("epsilon").value),
  };
  if (params.timing === TimingCurve.EASE_IN_OUT) {
    params.ease = ds.slice(1).map((_, s) => state.ease[s] ?? 1);
  }
  if (state.keyTimes && state.keyTimes.length === ds.length) params.keyTimes = state.keyTimes;
  const kappa = 10 ** Number($("kappa").value);
  if (Math.abs(kappa - 1) > 1e-9 && ds.length) {
    // One region over all of drawing 1 (its bounds, padded): the whole shape gets kappa.
    const b = drawingBounds(ds[0]);
    const pad = 1 + 0.01 * (b.maxX - b.minX + b.maxY - b.minY);
    const polygon = {
      points: [
        { x: b.minX - pad, y: b.minY - pad },
        { x: b.maxX + pad, y: b.minY - pad },
        { x: b.maxX + pad, y: b.maxY + pad },
        { x: b.minX - pad, y: b.maxY + pad },
      ],
    };
    params.stiffness = [{ polygon, kappa }];
  }
  return params;
}

// ------------------------------------------------------------------------------------------
// Inbetweens and the player

function resetFrames() {
  stop();
  state.triangles = null;
  state.frames = [];
  state.frameStats = [];
  state.frameWeights = [];
  state.drawingCount = 0;
  state.artProto = [];
  state.artExpected = 0;
  state.artReceived = 0;
  state.art = null;
  state.frameArt = [];
  state.artError = "";
  state.keys = [];
  state.totalFrames = 0;
  state.frameBounds = emptyBounds();
  state.current = 0;
  updatePlayerControls();
  drawFrame(0);
}

async function inbetween() {
  resetFrames();
  await heavy("error-inbetween", async (signal) => {
    const parameters = inbetweenParameters();
    for await (const m of api.inbetween({ sessionId: sid(), parameters }, callOptions(signal))) {
      const ev = m.event;
      if (ev.case === "progress") setProgress(ev.value);
      if (ev.case === "header") {
        const h = ev.value;
        state.triangles = Uint32Array.from(h.triangles.flatMap((t) => [t.a, t.b, t.c]));
        state.keys = h.keys;
        state.totalFrames = h.frames;
        state.drawingCount = h.keys.length;
        state.artProto = h.art;
        state.artExpected = h.artMessages;
        if (h.artMessages === 0) finishArt();
      }
      if (ev.case === "art") receiveArt(ev.value);
      if (ev.case === "frame") {
        const f = ev.value;
        if (state.artReceived < state.artExpected) {
          artFailed(`Inbetween stream sent a frame after ${state.artReceived} of ${state.artExpected} art messages`);
        }
        const xy = new Float64Array(f.vertices.length * 2);
        f.vertices.forEach((p, i) => {
          xy[2 * i] = p.x;
          xy[2 * i + 1] = p.y;
          addPoint(state.frameBounds, p.x, p.y);
        });
        state.frames[f.index] = xy;
        state.frameStats[f.index] = f.stats;
        state.frameWeights[f.index] = Float64Array.from(f.weights);
        $("progress").value = (f.index + 1) / state.totalFrames;
        $("progress-text").textContent = `frame ${f.index + 1} of ${state.totalFrames}`;
        updatePlayerControls();
        if (f.index === 0 || !state.playing) drawFrame(state.current);
      }
    }
    return true;
  });
  updatePlayerControls();
  if (state.frames.length) play();
}

function updatePlayerControls() {
  const n = state.frames.length;
  $("play").disabled = n === 0;
  $("scrub").disabled = n === 0;
  $("scrub").max = String(Math.max(0, n - 1));
  const done = n > 0 && n === state.totalFrames;
  $("download-gif").disabled = !done;
  $("download-lottie").disabled = !done;
  $("silhouette").disabled = !state.art;
  $("silhouette").parentElement.title = state.art
    ? "draw the frames in one colour instead of the drawings' art"
    : "the drawings have no art: the frames are drawn in one colour";
}

// The header's art is complete (InbetweenHeader.art plus its art_messages): ready to draw.
function finishArt() {
  if (state.artError) return;
  try {
    const keys = keysFromProto(state.artProto, state.triangles, state.drawingCount);
    state.art = hasArt(keys) ? keys : null;
    state.artProto = []; // converted: the messages are not needed any more
  } catch (err) {
    artFailed(err.message);
  }
  updatePlayerControls();
}

// An InbetweenResponse.art message: the rest of a key's layers.
function receiveArt(chunk) {
  if (state.artError) return;
  if (state.artReceived >= state.artExpected) {
    artFailed(`Inbetween stream sent more art messages than the ${state.artExpected} its header announced`);
    return;
  }
  try {
    appendArtChunk(state.artProto, chunk);
  } catch (err) {
    artFailed(err.message);
    return;
  }
  if (++state.artReceived === state.artExpected) finishArt();
}

// The frames are drawn as the silhouette from now on; says why under the Inbetween button.
function artFailed(message) {
  if (state.artError) return;
  state.artError = message;
  state.art = null;
  state.frameArt = [];
  showError("error-inbetween", `the art cannot be drawn (${message}); showing the silhouette`);
  updatePlayerControls();
}

// Frame i's art layers (art.js artForFrame), or null when the silhouette is to be drawn.
function frameArt(i) {
  if (!state.art || $("silhouette").checked || !state.frames[i] || !state.frameWeights[i]) return null;
  if (!state.frameArt[i]) {
    try {
      state.frameArt[i] = artForFrame(state.art, state.frames[i], state.frameWeights[i]);
    } catch (err) {
      artFailed(`frame ${i + 1}: ${err.message}`);
      return null;
    }
  }
  return state.frameArt[i];
}

function trianglesPath(ctx, view, xy) {
  const t = state.triangles;
  ctx.beginPath();
  for (let k = 0; k < t.length; k += 3) {
    const [ax, ay] = view.toScreen(xy[2 * t[k]], xy[2 * t[k] + 1]);
    const [bx, by] = view.toScreen(xy[2 * t[k + 1]], xy[2 * t[k + 1] + 1]);
    const [cx, cy] = view.toScreen(xy[2 * t[k + 2]], xy[2 * t[k + 2] + 1]);
    ctx.moveTo(ax, ay);
    ctx.lineTo(bx, by);
    ctx.lineTo(cx, cy);
    ctx.closePath();
  }
}

// Paints frame i into ctx (w×h CSS px): its art, or the silhouette; the same routine feeds the
// GIF encoder. Returns what it drew: "art", "silhouette" or "" (no frame).
function paintFrame(ctx, w, h, i, overlay) {
  const xy = state.frames[i];
  if (!xy || !state.triangles) return "";
  const view = fitView(state.frameBounds, w, h, 12);
  const art = frameArt(i);
  if (art) {
    paintArt(ctx, art, view);
  } else {
    trianglesPath(ctx, view, xy);
    ctx.fillStyle = FILL;
    ctx.fill("nonzero");
  }
  if (overlay) {
    trianglesPath(ctx, view, xy);
    ctx.strokeStyle = art ? "rgba(0,0,0,0.35)" : "rgba(255,255,255,0.8)";
    ctx.lineWidth = 0.75;
    ctx.stroke();
  }
  return art ? "art" : "silhouette";
}

function drawFrame(i) {
  const [ctx, w, h] = prepareCanvas($("player"));
  const n = state.frames.length;
  if (!n) {
    $("player").dataset.render = "";
    $("frame-label").textContent = "no frames";
    $("frame-stats").textContent = "";
    return;
  }
  i = Math.min(i, n - 1);
  state.current = i;
  // What the canvas shows, for tests and tools: "art" or "silhouette", and the frame's weights.
  $("player").dataset.render = paintFrame(ctx, w, h, i, $("overlay").checked);
  $("player").dataset.weights = JSON.stringify([...(state.frameWeights[i] ?? [])]);
  const key = state.keys.indexOf(i);
  $("frame-label").textContent =
    `frame ${i + 1} / ${state.totalFrames}${key >= 0 ? ` · key ${key + 1}` : ""}`;
  $("scrub").value = String(i);
  const s = state.frameStats[i];
  if (s) {
    $("frame-stats").textContent =
      `${s.iterations} iterations · energy ${s.energy.toPrecision(4)} · ` +
      `${s.invertedTriangles} inverted triangles · ${(s.seconds * 1000).toFixed(1)} ms`;
  }
}

let timer = null;
function play() {
  stop();
  state.playing = true;
  $("play").textContent = "Pause";
  const tick = () => {
    const n = state.frames.length;
    if (!n) return stop();
    drawFrame((state.current + 1) % n);
    timer = setTimeout(tick, 1000 / Math.max(1, Number($("fps").value) || 24));
  };
  timer = setTimeout(tick, 0);
}

function stop() {
  clearTimeout(timer);
  timer = null;
  state.playing = false;
  $("play").textContent = "Play";
}

// ------------------------------------------------------------------------------------------
// Downloads

function download(blob, name) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

function downloadGif() {
  const width = 320;
  const b = state.frameBounds;
  const height = Math.max(16, Math.round((width * (b.maxY - b.minY)) / Math.max(b.maxX - b.minX, 1e-9)) + 24);
  const canvas = document.createElement("canvas");
  canvas.width = width;
  canvas.height = height;
  const ctx = canvas.getContext("2d", { willReadFrequently: true });
  const rgba = state.frames.map((_, i) => {
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, width, height);
    paintFrame(ctx, width, height, i, $("overlay").checked);
    return ctx.getImageData(0, 0, width, height).data;
  });
  const fps = Math.max(1, Number($("fps").value) || 24);
  download(encodeGif(width, height, rgba, 1000 / fps), "animation.gif");
}

function downloadLottie() {
  const fps = Math.max(1, Number($("fps").value) || 24);
  const json = makeLottie({ triangles: state.triangles, frames: state.frames, fps, width: 512, fill: FILL });
  download(new Blob([JSON.stringify(json)], { type: "application/json" }), "animation.lottie.json");
}

const METHOD_NAMES = { [Method.LINEAR]: "linear", [Method.ALEXA]: "alexa", [Method.ZHU17]: "zhu17" };
const TIMING_NAMES = {
  [TimingCurve.LINEAR]: "linear",
  [TimingCurve.CATMULL_ROM]: "catmull_rom",
  [TimingCurve.EASE_IN_OUT]: "ease_in_out",
};

// docs/project-file.md; drawings made with the mouse are downloaded as SVG files beside it.
function downloadProject() {
  const ds = drawings();
  const p = inbetweenParameters();
  const pts = (line) => line.points.map((q) => [q.x, q.y]);
  const project = {
    version: 1,
    drawings: ds.map((d, i) => {
      const entry = { file: state.fileNames.get(d.id) ?? `polygon_${i + 1}.svg` };
      if (state.keyTimes) entry.key_time = state.keyTimes[i];
      const cuts = d.elements.filter((e) => e.kind === ElementKind.CUT).map((e) => pts(e.polyline));
      const openings = d.elements.filter((e) => e.kind === ElementKind.OPENING).map((e) => pts(e.polyline));
      if (cuts.length) entry.cuts = cuts;
      if (openings.length) entry.openings = openings;
      return entry;
    }),
    comesh: { map_weight: Number($("map-weight").value) },
    inbetween: {
      method: METHOD_NAMES[p.method],
      frames: p.frames,
      timing: TIMING_NAMES[p.timing],
      tau: p.tau,
      alpha: p.alpha,
      epsilon: p.epsilon,
    },
    output: { formats: ["svg", "json", "gif"], fps: Number($("fps").value) || 24, fill: FILL, mesh_overlay: $("overlay").checked },
  };
  if (!$("slide-outline").checked) project.comesh.outline_corner_degrees = 0;
  if (state.marks.length) project.correspondences = state.marks.map((m) => m.map((q) => [q.x, q.y]));
  if (p.ease) project.inbetween.ease = p.ease;
  if (p.stiffness) project.inbetween.stiffness = p.stiffness.map((r) => ({ polygon: pts(r.polygon), kappa: r.kappa }));
  download(new Blob([JSON.stringify(project, null, 2) + "\n"], { type: "application/json" }), "project.json");
  ds.forEach((d, i) => {
    const svg = state.polygonSvgs.get(d.id);
    if (svg) download(new Blob([svg], { type: "image/svg+xml" }), `polygon_${i + 1}.svg`);
  });
}

async function downloadArchive() {
  showError("error-download", null);
  try {
    const res = await api.exportSession({ sessionId: sid() }, callOptions());
    download(new Blob([res.data], { type: "application/octet-stream" }), `${sid()}.inbetween`);
  } catch (err) {
    showError("error-download", err);
  }
}

async function openArchive(file) {
  showError("error-session", null);
  try {
    const data = new Uint8Array(await file.arrayBuffer());
    const res = await api.importSession({ data }, callOptions());
    resetProject();
    applySession(res.session);
  } catch (err) {
    showError("error-session", err);
  }
}

// ------------------------------------------------------------------------------------------
// Wiring

function wire() {
  $("token").value = sessionStorage.getItem("inbetween-token") ?? "";
  $("token").addEventListener("change", () => sessionStorage.setItem("inbetween-token", $("token").value));
  $("new-session").addEventListener("click", newSession);
  $("open-archive").addEventListener("change", (e) => e.target.files[0] && openArchive(e.target.files[0]));
  $("upload").addEventListener("change", async (e) => {
    const files = [...e.target.files];
    e.target.value = "";
    await uploadFiles(files);
  });
  $("editor").addEventListener("click", onEditorClick);
  $("editor").addEventListener("dblclick", (e) => {
    e.preventDefault();
    state.stroke.pop(); // the second click of the double-click added a duplicate point
    finishStroke();
  });
  $("finish-stroke").addEventListener("click", finishStroke);
  $("cancel-stroke").addEventListener("click", () => {
    state.stroke = [];
    renderEditor();
  });
  for (const r of document.querySelectorAll('input[name="tool"]')) {
    r.addEventListener("change", () => {
      state.stroke = [];
      renderEditor();
    });
  }
  $("send-marks").addEventListener("click", sendMarks);
  $("clear-marks").addEventListener("click", () => {
    state.marks = [];
    state.pendingMark = [];
    renderDrawings();
    renderEditor();
  });
  $("build").addEventListener("click", build);
  $("optimize").addEventListener("click", optimize);
  $("cancel-heavy").addEventListener("click", () => state.heavy?.abort());
  $("inbetween").addEventListener("click", inbetween);
  $("timing").addEventListener("change", renderTimeline);
  for (const id of ["map-weight", "tau", "alpha", "epsilon", "kappa"]) {
    const input = $(id);
    const out = document.querySelector(`output[for="${id}"]`);
    const show = () => {
      out.textContent = id === "kappa" ? (10 ** Number(input.value)).toPrecision(3) : input.value;
    };
    input.addEventListener("input", show);
    show();
  }
  $("play").addEventListener("click", () => (state.playing ? stop() : play()));
  $("scrub").addEventListener("input", () => {
    stop();
    drawFrame(Number($("scrub").value));
  });
  $("overlay").addEventListener("change", () => drawFrame(state.current));
  $("silhouette").addEventListener("change", () => drawFrame(state.current));
  $("download-gif").addEventListener("click", downloadGif);
  $("download-lottie").addEventListener("click", downloadLottie);
  $("download-project").addEventListener("click", downloadProject);
  $("download-archive").addEventListener("click", downloadArchive);
  window.addEventListener("resize", () => {
    renderEditor();
    drawFrame(state.current);
  });
}

wire();
renderChart();
drawFrame(0);
newSession();
