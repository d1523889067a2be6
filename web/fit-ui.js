// The Fit section: runs `fit` with pause/cancel control, shows its progress (throttled to 10
// updates a second) on a timeline of the method's phases, the loss curves (reconstruction and
// articulation apart) and the latest render beside its photo; the articulation's pictures go to
// articulation-ui.js.
// `document.body.dataset.fit` is "running" | "paused" | "done" | "cancelled" | "error";
// `document.body.dataset.preview` becomes "1" once a preview has been drawn.
import { $, show, errorText, drawRgba, fmtDuration, showBanner } from "./util.js";
import { drawLogPlot } from "./plot.js";
import { addBakeOff, resetArticulation, showMoved } from "./articulation-ui.js";

const PHASES = {
  initialise: "setting up",
  optimise: "optimising the mesh",
  densify: "adding detail where the error is high",
  remesh: "rebuilding the triangles",
  recover: "optimising again after remeshing",
  measure: "measuring the joints from the depth maps",
  candidates: "trying joint candidates",
  "bake-off": "comparing hinge and slide",
  refine: "refining the chosen joint",
  done: "finished",
};
const SERIES = [
  { key: "start", label: "start state", colour: "#1f5fbf" },
  { key: "end", label: "end state", colour: "#d9730d" },
];
const ARTICULATION_SERIES = [
  { key: "hinge", label: "hinge candidates", colour: "#d9730d" },
  { key: "slide", label: "slide candidates", colour: "#1f5fbf" },
  { key: "refine", label: "refinement (the winners)", colour: "#1b8a4a" },
];
// The timeline's entry of each phase (a state's reconstruction ends with "done" too).
const TIMELINE = {
  initialise: "reconstruction", optimise: "reconstruction", densify: "reconstruction",
  remesh: "remeshing", recover: "remeshing",
  measure: "measurement", candidates: "candidates", "bake-off": "bake-off", refine: "refinement",
};
const MAX_POINTS = 4000;

let control = "run";
let running = false;
let latest = null;          // last progress event
let latestPreview = null;   // last preview event
let dirty = false;
let timer = null;
let lastUpdate = 0;
let points = {};
let marks = [];             // where each stage began: {x: seconds into the fit, label, articulation}
let timeline = {};          // seconds spent per timeline entry, and the one running
let lastEntry = null, lastTime = 0;
let eta = null;             // the running fit's Eta (estimate.js), or null
let etaTimer = null;        // counts the ETA down between events

function setFit(state) {
  document.body.dataset.fit = state;
}

/** The plot point of a progress event: its series and x (seconds into the fit), or null. The
 *  hinge and slide candidates train on alternate steps, each its own series. */
function plotPoint(ev) {
  const x = Number(ev.elapsed_s) || 0;
  if (ev.state !== "both") return [ev.state === "end" ? "end" : "start", x];
  if (ev.phase === "candidates" && ev.candidate) return [ev.candidate, x];
  if (ev.phase === "refine") return ["refine", x];
  return null;
}

/** A mark on the plots where a stage (or a state's reconstruction) begins. */
function markStage(ev, entry) {
  const label = entry === "reconstruction" ? `${ev.state} state` : entry;
  const last = marks[marks.length - 1];
  if (last?.label === label) return;
  marks.push({ x: Number(ev.elapsed_s) || 0, label, articulation: ev.state === "both" });
}

/** Charges the time since the last event to the timeline entry that was running. */
function tick(ev) {
  const now = performance.now() / 1000;
  if (lastEntry) timeline[lastEntry] = (timeline[lastEntry] ?? 0) + now - lastTime;
  lastTime = now;
  lastEntry = TIMELINE[ev.phase] ?? (ev.state === "both" ? null : lastEntry);
  if (lastEntry) {
    timeline[lastEntry] ??= 0;
    markStage(ev, lastEntry);
  }
  if (ev.phase === "candidates" && ev.iterations === 0) timeline.noSteps = true;
}

function onEvent(ev) {
  if (!ev || typeof ev !== "object") return;
  if (ev.kind === "progress") {
    latest = ev;
    tick(ev);
    eta?.event(ev, performance.now() / 1000);
    const loss = Number(ev.loss);
    const at = plotPoint(ev);
    if (at && ev.loss != null && loss > 0 && Number.isFinite(loss)) {
      const [key, x] = at;
      const list = points[key] ??= [];
      list.push([x, loss]);
      if (list.length > MAX_POINTS) points[key] = list.filter((_, i) => i % 2 === 0);
    }
  } else if (ev.kind === "preview") {
    latestPreview = ev;
    showMoved(ev);
  } else if (ev.kind === "bake-off") {
    addBakeOff(ev);
  }
  schedule();
}

/** The timeline's entries: done ones with their seconds, the running one highlighted. */
function drawTimeline() {
  for (const li of $("stages").children) {
    const key = li.dataset.stage, s = timeline[key];
    const current = running && key === lastEntry;
    li.classList.toggle("current", current);
    li.classList.toggle("done", s != null && !current);
    let when = "";
    if (current) when = `running, ${fmtDuration(s)} so far`;
    else if (s != null) when = `took ${fmtDuration(s)}`;
    if (s != null && timeline.noSteps && (key === "candidates" || key === "refinement")) {
      when += " (no image steps: the depth maps settled every joint)";
    }
    const span = li.querySelector(".when");
    if (span.textContent !== when) span.textContent = when;
  }
}

function schedule() {
  dirty = true;
  if (timer !== null) return;
  const wait = Math.max(0, 100 - (performance.now() - lastUpdate));
  timer = setTimeout(() => { timer = null; update(); }, wait);
}

function text(id, value) {
  const el = $(id);
  if (el.textContent !== value) el.textContent = value;
}

/** The time left, from the running fit's Eta (its seconds in `data-remaining-s`, for tests). */
function showEta() {
  if (!eta || !running) return;
  const left = eta.remaining(performance.now() / 1000);
  text("fit-eta", `about ${fmtDuration(left)}`);
  $("fit-eta").dataset.remainingS = left.toFixed(1);
  $("fit-eta").dataset.elapsedS = (performance.now() / 1000 - etaStart).toFixed(1);
}
let etaStart = 0;

/** The fraction of the fit done, as the ETA sees it (elapsed over elapsed + left), or null. */
function etaFraction() {
  if (!eta || !running) return null;
  const elapsed = performance.now() / 1000 - etaStart;
  return elapsed / Math.max(1e-3, elapsed + eta.remaining(performance.now() / 1000));
}

function update() {
  if (!dirty) return;
  dirty = false;
  lastUpdate = performance.now();
  showEta();
  const ev = latest;
  if (ev) {
    text("fit-stage", ev.stage ?? "—");
    text("fit-phase", ev.phase ? `${ev.phase} (${PHASES[ev.phase] ?? ev.phase})` : "—");
    text("fit-state", ev.state ?? "—");
    text("fit-iter", ev.iterations ? `${ev.iteration} / ${ev.iterations}` : String(ev.iteration ?? "—"));
    text("fit-elapsed", fmtDuration(running ? performance.now() / 1000 - etaStart : ev.elapsed_s));
    text("fit-faces", ev.faces != null ? Number(ev.faces).toLocaleString("en") : "—");
    text("fit-vertices", ev.vertices != null ? Number(ev.vertices).toLocaleString("en") : "—");
    const fraction = Math.min(1, Math.max(0, etaFraction() ?? (Number(ev.fraction) || 0)));
    $("fit-progress").value = fraction;
    if (running && control === "run") {
      const loss = ev.loss != null ? `, loss ${Number(ev.loss).toPrecision(4)}` : "";
      show($("fit-status"), `Running: ${(fraction * 100).toFixed(0)} % — ${ev.stage ?? ""}, ${PHASES[ev.phase] ?? ev.phase ?? ""}${loss}`);
    }
  }
  drawTimeline();
  const xLabel = "seconds into the fit";
  drawLogPlot($("loss-plot"), SERIES.map((s) => ({ ...s, points: points[s.key] ?? [] })),
    { xLabel, marks: marks.filter((m) => !m.articulation) });
  const articulated = ARTICULATION_SERIES.map((s) => ({ ...s, points: points[s.key] ?? [] }));
  // What the plots hold, for tests and assistive tools: each series' point count and the marks.
  document.body.dataset.plotSeries = [...SERIES, ...ARTICULATION_SERIES]
    .map((s) => `${s.key}:${points[s.key]?.length ?? 0}`).join(",");
  document.body.dataset.plotMarks = marks.map((m) => m.label).join(",");
  $("articulation-plot").hidden = !articulated.some((s) => s.points.length > 0);
  if (!$("articulation-plot").hidden) {
    drawLogPlot($("articulation-plot"), articulated, { xLabel, marks: marks.filter((m) => m.articulation) });
  }
  const p = latestPreview;
  if (p) {
    latestPreview = null;
    const a = drawRgba($("preview-render"), p.width, p.height, p.render);
    const b = drawRgba($("preview-target"), p.width, p.height, p.target);
    if (a && b) {
      text("preview-caption", p.moved_by
        ? `${p.stage}: the start state's mesh moved by the ${p.moved_by}, beside end-state view ${p.view}`
        : `${p.stage}: ${p.state} state, iteration ${p.iteration}`);
      document.body.dataset.preview = "1";
    }
  }
}

function resetPanel() {
  latest = null; latestPreview = null; points = {};
  marks = []; timeline = {}; lastEntry = null; lastTime = performance.now() / 1000;
  resetArticulation();
  for (const id of ["fit-stage", "fit-phase", "fit-state", "fit-iter", "fit-elapsed", "fit-eta", "fit-faces", "fit-vertices"]) text(id, "—");
  text("preview-caption", "");
  delete $("fit-eta").dataset.remainingS;
  delete $("fit-eta").dataset.elapsedS;
  $("fit-progress").value = 0;
  for (const c of [$("preview-render"), $("preview-target")]) { c.width = 1; c.height = 1; }
  delete document.body.dataset.preview;
  $("fit-panel").hidden = false;
  dirty = true;
  update();
}

export function wireFitButtons() {
  $("pause").addEventListener("click", () => {
    if (!running || control === "cancel") return;
    if (control === "run") {
      control = "pause";
      $("pause").textContent = "Resume";
      setFit("paused");
      show($("fit-status"), "Paused. The GPU finishes its current step, then waits; press Resume to go on.");
    } else {
      control = "run";
      $("pause").textContent = "Pause";
      setFit("running");
      show($("fit-status"), "Resuming…");
    }
  });
  $("cancel").addEventListener("click", () => {
    if (!running) return;
    control = "cancel";
    $("cancel").disabled = true;
    $("pause").disabled = true;
    show($("fit-status"), "Cancelling at the next checkpoint…");
  });
  $("pause").disabled = true;
  $("cancel").disabled = true;
}

export const fitRunning = () => running;

/** Resolves to the hint shown after a fit error (or ""). */
function hintFor(message) {
  return /memory|limit|binding|too many/i.test(message)
    ? "\nTry a smaller preset (tiny or fast) or smaller budgets (Advanced: budgets)." : "";
}

/**
 * Runs `fitFn(datasetHandle, preset, onEvent, control, budget)`; the handle is consumed. `budget`
 * is the budgets' overrides as JSON (undefined: the preset's own); `fitEta` (an Eta of
 * estimate.js) says the time left, and learns this adapter's pace once the fit is done.
 * Resolves to the FitResult, or null when cancelled or failed (the panel says which).
 */
export async function runFit(fitFn, datasetHandle, preset, budget, what, fitEta = null) {
  running = true;
  eta = fitEta;
  etaStart = performance.now() / 1000;
  clearInterval(etaTimer);
  etaTimer = setInterval(schedule, 1000); // the ETA and the bar move between events too
  control = "run";
  resetPanel();
  $("pause").textContent = "Pause";
  $("pause").disabled = false;
  $("cancel").disabled = false;
  setFit("running");
  const changes = budget ? Object.entries(JSON.parse(budget)).map(([k, v]) => `${k} ${v}`).join(", ") : "";
  show($("fit-status"), `Starting the fit of ${what} (preset ${preset}${changes ? `; ${changes}` : ""})…`);
  const t0 = performance.now();
  try {
    const result = await fitFn(datasetHandle, preset, onEvent, () => control, budget);
    running = false;
    dirty = true;
    update();
    $("fit-progress").value = 1;
    const seconds = (performance.now() - t0) / 1000;
    document.body.dataset.fitSeconds = seconds.toFixed(1);
    // The last progress event's elapsed time and estimate are stale once the fit returns: the
    // panel's elapsed time is the one "Done in" gives, and nothing remains.
    text("fit-elapsed", fmtDuration(seconds));
    text("fit-eta", "none (done)");
    if (eta) {
      eta.finish(document.body.dataset.adapter, performance.now() / 1000);
      // What each stage was predicted to take and took, for tests and the curious.
      document.body.dataset.etaStages = eta.summary();
    }
    show($("fit-status"), `Done in ${fmtDuration(seconds)}.`, "ok");
    drawTimeline();
    return result;
  } catch (e) {
    running = false;
    dirty = true;
    update();
    const message = errorText(e);
    if (control === "cancel" || /^cancelled/i.test(message)) {
      show($("fit-status"), "Cancelled.");
      setFit("cancelled");
    } else {
      show($("fit-status"), `The fit failed: ${message}${hintFor(message)}`, "fail");
      setFit("error");
      document.body.dataset.fitError = message;
      showBanner(`The fit failed: ${message}${hintFor(message)}`);
    }
    return null;
  } finally {
    running = false;
    eta = null;
    clearInterval(etaTimer);
    $("pause").disabled = true;
    $("cancel").disabled = true;
    $("pause").textContent = "Pause";
  }
}

/** Marks the fit done (called by the app once the result is stored). The panel said the last
 * progress event's stage, which is often the reconstruction's: joints the depth maps settle send none. */
export function markFitDone() {
  setFit("done");
  text("fit-stage", "finished: every stage ran");
  text("fit-phase", "done (both phases finished)");
  text("fit-state", "both");
  drawTimeline();
}
