// The Result section: the WebGPU viewer of the twin (orbit, zoom, a slider per joint), the
// metrics and joints tables, the report's warnings and the downloads.
// Sets `document.body.dataset.result = "ready"` and `document.body.dataset.jointCount`.
import { $, errorText, fmtNum, freeQuietly } from "./util.js";

let viewer = null;
let result = null;
let canvas = null;
let resizeObserver = null;
let drawPending = false;

/** Forgets the shown result (before a new fit starts). */
export function clearResult() {
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

// --- sliders ------------------------------------------------------------------------------

function fmtValue(v, unit) {
  return unit === "m" ? `${Number(v).toFixed(3)} m` : `${Number(v).toFixed(1)}°`;
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
    input.step = String((hi - lo) / 500);
    input.value = String(j.start ?? lo);
    const name = `${j.name ?? `joint ${i}`} (${j.type ?? "?"}, part ${j.part ?? i + 1})`;
    const setLabel = (v) => { label.textContent = `${name}: ${fmtValue(v, j.unit)}`; };
    setLabel(input.value);
    input.addEventListener("input", () => {
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

function row(tbody, cells) {
  const tr = tbody.insertRow();
  for (const c of cells) tr.insertCell().textContent = c;
  return tr;
}

const vec = (v) => (Array.isArray(v) ? `(${v.map((x) => fmtNum(x, 3)).join(", ")})` : "—");

function chamfer(c) {
  if (!c) return "—";
  const mm = c.cd_mm != null ? ` (${fmtNum(c.cd_mm, 1)} mm)` : "";
  return `${fmtNum(c.cd_peer, 3)}${mm}`;
}

function fillMetrics(m) {
  const box = $("metrics-box");
  const tbody = $("metrics").querySelector("tbody");
  tbody.replaceChildren();
  if (!m) { box.hidden = true; return; }
  const n = Array.isArray(m.joints) ? m.joints.length : null;
  let types = "—";
  if (n != null && m.type_errors != null) types = `${n - m.type_errors} of ${n}`;
  else if (m.type_accuracy != null) types = `${(m.type_accuracy * 100).toFixed(0)} %`;
  row(tbody, ["Axis Ang (°)", fmtNum(m.axis_ang, 3)]);
  row(tbody, ["Axis Pos (0.1 m)", fmtNum(m.axis_pos, 3)]);
  row(tbody, ["Part Motion (° or m)", fmtNum(m.part_motion, 3)]);
  row(tbody, ["CD-s (static part)", chamfer(m.cd_s)]);
  row(tbody, ["CD-m (movable parts)", chamfer(m.cd_m)]);
  row(tbody, ["Joint types right", types]);
  box.hidden = false;
}

function fillJoints(joints) {
  const tbody = $("joints-table").querySelector("tbody");
  tbody.replaceChildren();
  for (const j of joints) {
    const motion = j.type === "prismatic" ? `${fmtNum(j.motion * 100, 1)} cm` : `${fmtNum(j.motion, 1)}°`;
    row(tbody, [String(j.part), j.type, vec(j.direction), j.type === "prismatic" ? "—" : vec(j.origin), motion]);
  }
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
      if (!viewer) return;
      try { viewer.set_state(state); } catch (e) { console.error("set_state:", e); }
      syncSliders(sliders);
      requestDraw();
    });
  }
  window.addEventListener("resize", () => resize());
  for (const [id, [name, type]] of Object.entries(DOWNLOADS)) $(id).addEventListener("click", () => download(name, type));
  $("colour-by-part").addEventListener("change", (e) => {
    if (!viewer) return;
    try { viewer.colour_by_part(e.target.checked); } catch (err) { console.error(err); }
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
  fillJoints(joints);
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
  } catch (e) { console.error(e); }
  delete canvas.dataset.sized;
  resize();
  resizeObserver = new ResizeObserver(() => resize());
  resizeObserver.observe(canvas);
  flushDraw();
  document.body.dataset.jointCount = String(vj.length);
  document.body.dataset.result = "ready";
  return { report, joints };
}
