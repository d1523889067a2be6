// The Result section: the WebGPU viewer of the twin (orbit, zoom, a slider per joint, a play
// button animating every joint between its states, the part-colour legend, the true parts laid
// over the fit), the metrics table (the joints table is joints-table.js), the report's warnings and
// the downloads.
// Sets `document.body.dataset.result = "ready"` and `document.body.dataset.jointCount`.
import { $, errorText, fmtNum, freeQuietly, row } from "./util.js";
import { fillJoints } from "./joints-table.js";

let viewer = null;
let result = null;
let canvas = null;
let resizeObserver = null;
let drawPending = false;

/** Forgets the shown result (before a new fit starts). */
export function clearResult() {
  stopPlaying();
  delete document.body.dataset.result;
  delete document.body.dataset.jointCount;
  resizeObserver?.disconnect();
  resizeObserver = null;
  freeQuietly(viewer);
  freeQuietly(result);
  viewer = null;
  result = null;
  $("result-body").hidden = true;
  $("result-empty").hidden = false;
  $("result-empty").textContent = "The twin appears here when the fit finishes.";
}

// --- drawing ------------------------------------------------------------------------------

function flushDraw() {
  if (!drawPending || !viewer) return;
  drawPending = false;
  // Resolves once the frame is on the canvas; draws asked for meanwhile are folded into one.
  Promise.resolve()
    .then(() => viewer?.draw())
    .catch((e) => console.error("viewer draw:", e));
}

function requestDraw() {
  if (drawPending) return;
  drawPending = true;
  requestAnimationFrame(flushDraw);
  setTimeout(flushDraw, 100); // when frames are throttled (background tab), draw anyway
}

function resize() {
  if (!viewer || !canvas) return;
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.clientWidth === 0 || canvas.clientHeight === 0) return;
  if (canvas.width !== w || canvas.height !== h || !canvas.dataset.sized) {
    canvas.width = w;
    canvas.height = h;
    canvas.dataset.sized = "1";
    try { viewer.resize(w, h); } catch (e) { console.error("viewer resize:", e); }
  }
  requestDraw();
}

function wireCamera(el) {
  const pointers = new Map();
  let pinch = 0;
  const spread = () => {
    const [a, b] = [...pointers.values()];
    return Math.hypot(a.x - b.x, a.y - b.y);
  };
  el.addEventListener("pointerdown", (e) => {
    el.setPointerCapture?.(e.pointerId);
    pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
    if (pointers.size === 2) pinch = spread();
    e.preventDefault();
  });
  el.addEventListener("pointermove", (e) => {
    const p = pointers.get(e.pointerId);
    if (!p || !viewer) return;
    const dx = e.clientX - p.x, dy = e.clientY - p.y;
    p.x = e.clientX; p.y = e.clientY;
    if (pointers.size === 1) {
      viewer.orbit(dx, dy);
    } else if (pointers.size === 2) {
      const d = spread();
      if (pinch > 0 && d > 0) viewer.zoom(d / pinch);
      pinch = d;
    }
    requestDraw();
  });
  const end = (e) => {
    pointers.delete(e.pointerId);
    pinch = pointers.size === 2 ? spread() : 0;
  };
  el.addEventListener("pointerup", end);
  el.addEventListener("pointercancel", end);
  el.addEventListener("wheel", (e) => {
    e.preventDefault();
    if (!viewer) return;
    const delta = e.deltaMode === 1 ? e.deltaY * 16 : e.deltaY;
    viewer.zoom(Math.exp(-delta * 0.0015));
    requestDraw();
  }, { passive: false });
  el.addEventListener("keydown", (e) => {
    if (!viewer) return;
    const step = 20;
    const moves = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, -step], ArrowDown: [0, step] };
    if (moves[e.key]) viewer.orbit(...moves[e.key]);
    else if (e.key === "+" || e.key === "=") viewer.zoom(1.1);
    else if (e.key === "-") viewer.zoom(1 / 1.1);
    else return;
    e.preventDefault();
    requestDraw();
  });
}

// --- play ---------------------------------------------------------------------------------

/** One start → end → start cycle of the play button (ms): slow enough to follow a part. */
const PLAY_PERIOD_MS = 4000;
let playing = false;
let playFrame = 0;
/** Where in the cycle (ms) the motion was paused, so play resumes from there. */
let playElapsed = 0;
let playOrigin = 0;

function setPlayButton(on) {
  $("play").setAttribute("aria-pressed", String(on));
}

function playTick(now) {
  if (!playing || !viewer) return;
  playElapsed = now - playOrigin;
  // Eased both ways (a cosine), so each state is held a moment and the turn is gentle.
  const t = (1 - Math.cos((2 * Math.PI * playElapsed) / PLAY_PERIOD_MS)) / 2;
  try { viewer.set_phase(t); } catch (e) { console.error("set_phase:", e); stopPlaying(); return; }
  syncSliders(sliders);
  requestDraw();
  playFrame = requestAnimationFrame(playTick);
}

function startPlaying() {
  if (playing || !viewer) return;
  playing = true;
  setPlayButton(true);
  playOrigin = performance.now() - playElapsed;
  playFrame = requestAnimationFrame(playTick);
}

/** Pauses the motion; `reset` (a slider moved, a state picked) starts the next play afresh. */
function stopPlaying(reset = true) {
  playing = false;
  cancelAnimationFrame(playFrame);
  if (reset) playElapsed = 0;
  if ($("play")) setPlayButton(false);
}

/** Plays on its own only where motion is welcome and cheap: not for a visitor who asked for
 * reduced motion, nor on a software adapter, where every frame costs a second of CPU. */
function autoplayWanted() {
  const reduced = window.matchMedia?.("(prefers-reduced-motion: reduce)").matches ?? false;
  return !reduced && document.body.dataset.software !== "true";
}

// --- legend -------------------------------------------------------------------------------

/** The part-colour legend from the viewer (its colours are the renderer's palette). */
function buildLegend() {
  const list = $("part-legend");
  list.replaceChildren();
  let entries = [];
  try { entries = JSON.parse(viewer.legend()); } catch (e) { console.error("legend:", e); }
  for (const e of entries) {
    const li = document.createElement("li");
    li.dataset.part = String(e.part);
    li.dataset.colour = e.colour;
    li.title = e.link ? `link ${e.link}` : "";
    const swatch = document.createElement("span");
    swatch.className = "swatch";
    swatch.style.backgroundColor = e.colour;
    swatch.setAttribute("aria-hidden", "true");
    li.append(swatch, document.createTextNode(e.name));
    list.append(li);
  }
  showLegend();
}

function showLegend() {
  $("part-legend").hidden = !$("colour-by-part").checked || $("part-legend").childElementCount === 0;
}

// --- sliders ------------------------------------------------------------------------------

/** A joint value as the joints table gives it: millimetres for a slide, degrees for a hinge. */
function fmtValue(v, unit) {
  return unit === "m" ? `${(Number(v) * 1000).toFixed(1)} mm` : `${Number(v).toFixed(1)}°`;
}

function buildSliders(joints) {
  const box = $("sliders");
  box.replaceChildren();
  const labels = [];
  joints.forEach((j, i) => {
    const row = document.createElement("div");
    row.className = "slider-row";
    const label = document.createElement("label");
    label.htmlFor = `joint-${i}`;
    const input = document.createElement("input");
    input.type = "range";
    input.id = `joint-${i}`;
    input.className = "joint-slider";
    let lo = Number(j.lower), hi = Number(j.upper);
    if (!(Number.isFinite(lo) && Number.isFinite(hi))) { lo = Math.min(j.start ?? 0, j.end ?? 0); hi = Math.max(j.start ?? 0, j.end ?? 1); }
    if (lo > hi) [lo, hi] = [hi, lo];
    if (lo === hi) { lo -= j.unit === "m" ? 0.01 : 1; hi += j.unit === "m" ? 0.01 : 1; }
    input.min = String(lo);
    input.max = String(hi);
    // Any value (so both states are reachable); the keys step by a unit a reader thinks in: 1° or
    // 1 mm, ten of them with Page Up/Down.
    input.step = "any";
    input.value = String(j.start ?? lo);
    const unitStep = j.unit === "m" ? 0.001 : 1;
    const keySteps = { ArrowRight: 1, ArrowUp: 1, ArrowLeft: -1, ArrowDown: -1, PageUp: 10, PageDown: -10 };
    input.addEventListener("keydown", (e) => {
      const k = keySteps[e.key];
      if (k == null) return;
      e.preventDefault();
      input.value = String(Math.min(hi, Math.max(lo, Number(input.value) + k * unitStep)));
      input.dispatchEvent(new Event("input", { bubbles: true }));
    });
    const name = `${j.name ?? `joint ${i}`} (${j.type ?? "?"}, part ${j.part ?? i + 1})`;
    const setLabel = (v) => { label.textContent = `${name}: ${fmtValue(v, j.unit)}`; };
    setLabel(input.value);
    input.addEventListener("input", () => {
      stopPlaying();
      const v = Number(input.value);
      setLabel(v);
      if (!viewer) return;
      try { viewer.set_joint(i, v); } catch (e) { console.error("set_joint:", e); }
      requestDraw();
    });
    labels.push({ input, setLabel });
    row.append(label, input);
    box.append(row);
  });
  return labels;
}

function syncSliders(sliders) {
  let values = [];
  try { values = Array.from(viewer.values()); } catch (e) { console.error("values:", e); return; }
  sliders.forEach(({ input, setLabel }, i) => {
    if (values[i] == null) return;
    input.value = String(values[i]);
    setLabel(values[i]);
  });
}

// --- tables -------------------------------------------------------------------------------

function chamfer(c) {
  if (!c) return "—";
  const mm = c.cd_mm != null ? ` (${fmtNum(c.cd_mm, 1)} mm)` : "";
  return `${fmtNum(c.cd_peer, 3)}${mm}`;
}

/** One summary row: the metric's name, its value and what it measures (shown, so it also reads on touch). */
function metricRow(tbody, name, value, what) {
  const tr = row(tbody, [name, value, what]);
  tr.cells[0].title = what;
  return tr;
}

const scaled = (v, k) => (v == null ? null : v * k);

function fillMetrics(m) {
  const box = $("metrics-box");
  const tbody = $("metrics").querySelector("tbody");
  tbody.replaceChildren();
  if (!m) { box.hidden = true; return; }
  const n = Array.isArray(m.joints) ? m.joints.length : null;
  let types = "—";
  if (n != null && m.type_errors != null) types = `${n - m.type_errors} of ${n}`;
  else if (m.type_accuracy != null) types = `${(m.type_accuracy * 100).toFixed(0)} %`;
  metricRow(tbody, "Axis Ang (°)", fmtNum(m.axis_ang, 3),
    "angle between each fitted axis and the true one, mean over the joints");
  metricRow(tbody, "Axis Pos (mm)", fmtNum(scaled(m.axis_pos, 100), 2),
    "distance between each fitted hinge line and the true one (hinges only), mean");
  metricRow(tbody, "Part Motion, hinges (°)", fmtNum(m.part_motion_revolute, 3),
    "the angle between each fitted and true rotation (so it counts the axis error too), mean over hinges");
  metricRow(tbody, "Part Motion, slides (mm)", fmtNum(scaled(m.part_motion_prismatic, 1000), 2),
    "the distance between each fitted and true displacement (so it counts the axis error too), mean over slides");
  metricRow(tbody, "CD-s (mm)", m.cd_s?.cd_mm != null ? fmtNum(m.cd_s.cd_mm, 1) : "—",
    "Chamfer distance between the fitted and the true static part: mean distance from each surface to the other");
  metricRow(tbody, "CD-m (mm)", m.cd_m?.cd_mm != null ? fmtNum(m.cd_m.cd_mm, 1) : "—",
    "the same for the movable parts, mean over parts");
  metricRow(tbody, "Joint types right", types, "hinge or slide, as the truth has it");
  box.hidden = false;
}

function fillWarnings(warnings) {
  const list = $("warnings");
  list.replaceChildren();
  const items = Array.isArray(warnings) ? warnings : [];
  for (const w of items) {
    const li = document.createElement("li");
    li.textContent = typeof w === "string" ? w : JSON.stringify(w);
    list.append(li);
  }
  $("warnings-box").hidden = items.length === 0;
}

// --- downloads ----------------------------------------------------------------------------

const DOWNLOADS = {
  "download-glb": ["twin.glb", "model/gltf-binary"],
  "download-zip": ["twin.zip", "application/zip"],
  "download-joints": ["joints.json", "application/json"],
  "download-report": ["report.json", "application/json"],
  "download-preview": ["preview.png", "image/png"],
};

let previewUrl = null;

/** Shows `preview.png` of the result (hidden when there is none). */
function showPreview(fitResult) {
  if (previewUrl) URL.revokeObjectURL(previewUrl);
  previewUrl = null;
  try {
    previewUrl = URL.createObjectURL(new Blob([fitResult.file("preview.png")], { type: "image/png" }));
    $("preview").src = previewUrl;
  } catch (e) { console.error("preview:", e); }
  $("preview-box").hidden = previewUrl === null;
}

function download(name, type) {
  if (!result) return;
  let bytes;
  try { bytes = result.file(name); } catch (e) { console.error(`file ${name}:`, e); return; }
  const url = URL.createObjectURL(new Blob([bytes], { type }));
  const a = document.createElement("a");
  a.href = url;
  a.download = name;
  a.hidden = true;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 30_000);
}

let sliders = [];

export function wireResultButtons() {
  for (const state of ["start", "end"]) {
    $(`state-${state}`).addEventListener("click", () => {
      stopPlaying();
      if (!viewer) return;
      try { viewer.set_state(state); } catch (e) { console.error("set_state:", e); }
      syncSliders(sliders);
      requestDraw();
    });
  }
  window.addEventListener("resize", () => resize());
  for (const [id, [name, type]] of Object.entries(DOWNLOADS)) $(id).addEventListener("click", () => download(name, type));
  $("play").addEventListener("click", () => {
    if (playing) stopPlaying(false); else startPlaying();
  });
  $("colour-by-part").addEventListener("change", (e) => {
    showLegend();
    if (!viewer) return;
    try { viewer.colour_by_part(e.target.checked); } catch (err) { console.error(err); }
    requestDraw();
  });
  $("show-truth-parts").addEventListener("change", (e) => {
    if (!viewer) return;
    try { viewer.show_truth_parts(e.target.checked); } catch (err) { console.error(err); }
    requestDraw();
  });
  $("show-truth").addEventListener("change", (e) => {
    if (!viewer) return;
    try { viewer.show_truth(e.target.checked); } catch (err) { console.error(err); }
    requestDraw();
  });
  $("show-axes").addEventListener("change", (e) => {
    if (!viewer) return;
    try { viewer.show_axes(e.target.checked); } catch (err) { console.error(err); }
    requestDraw();
  });
}

/**
 * Shows a FitResult (kept; its handle is freed by the next clearResult). `ViewerClass` is the wasm
 * Viewer. Throws when the viewer cannot be created (the tables are still filled).
 */
export async function showResult(ViewerClass, fitResult) {
  result = fitResult;
  const report = JSON.parse(fitResult.report());
  const joints = JSON.parse(fitResult.joints());
  let names = [];
  try { names = Array.from(fitResult.file_names()); } catch { /* all offered */ }
  for (const [id, [name]] of Object.entries(DOWNLOADS)) $(id).disabled = names.length > 0 && !names.includes(name);

  $("result-empty").hidden = true;
  $("result-body").hidden = false;
  fillMetrics(report.metrics ?? null);
  fillJoints(joints, report.truth ?? null, report.metrics?.joints ?? null);
  fillWarnings(report.warnings);
  showPreview(fitResult);

  // A fresh canvas per result: a canvas keeps the context it was first configured with.
  const fresh = document.createElement("canvas");
  fresh.id = "viewer";
  fresh.tabIndex = 0;
  fresh.setAttribute("aria-label", "3D view of the fitted twin");
  $("viewer").replaceWith(fresh);
  canvas = fresh;
  wireCamera(canvas);
  const dpr = window.devicePixelRatio || 1;
  canvas.width = Math.max(1, Math.round(canvas.clientWidth * dpr));
  canvas.height = Math.max(1, Math.round(canvas.clientHeight * dpr));

  try {
    viewer = await ViewerClass.create(canvas, fitResult.share());
  } catch (e) {
    viewer = null;
    throw new Error(`the 3D viewer could not start: ${errorText(e)}`);
  }
  let vj = [];
  try { vj = JSON.parse(viewer.joints()); } catch (e) { console.error("viewer joints:", e); }
  sliders = buildSliders(vj);
  syncSliders(sliders);
  try {
    viewer.colour_by_part($("colour-by-part").checked);
    viewer.show_axes($("show-axes").checked);
    const truth = viewer.has_truth();
    $("show-truth-label").hidden = !truth;
    viewer.show_truth(truth && $("show-truth").checked);
    const parts = viewer.has_truth_parts();
    $("show-truth-parts-label").hidden = !parts;
    viewer.show_truth_parts(parts && $("show-truth-parts").checked);
    const view = JSON.parse(viewer.opening_view());
    canvas.dataset.openingScore = String(view.score);
    canvas.dataset.openingOldScore = String(view.old_score);
    canvas.dataset.openingMs = String(view.ms);
  } catch (e) { console.error(e); }
  buildLegend();
  delete canvas.dataset.sized;
  resize();
  resizeObserver = new ResizeObserver(() => resize());
  resizeObserver.observe(canvas);
  flushDraw();
  document.body.dataset.jointCount = String(vj.length);
  document.body.dataset.result = "ready";
  // Wide pages put the result under the fit once it is ready (style.css): bring it into view.
  $("result").scrollIntoView?.({ behavior: "smooth", block: "start" });
  playElapsed = 0;
  if (autoplayWanted() && vj.length > 0) startPlaying();
  return { report, joints };
}
