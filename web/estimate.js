// How long a fit will take: before it starts (beside the preset) and while it runs (the ETA).
// The fit's work comes counted from its own config (`fit_work`, src/fit/work.rs); here it becomes
// seconds, stage by stage, with rates measured on a software adapter: headless Chromium on
// SwiftShader, 2-core VM, 2026-12-08, page fits of the demo, habitat's fridge and kitchen counter
// and sektion at tiny and fast; habitat's cabinet and double door were kept aside to check them
// (docs/results.md, "Times that hold on the page").
// A step's cost is a + b × its working-size pixels (a: the dispatches' fixed cost, which
// dominates at 32²). On any adapter a finished fit stores how far each class of work (the GPU's,
// and each kind of CPU work) ran from these rates, and later estimates there use it (localStorage).
const SOFTWARE = {
  warmup: 9,                 // s, once: pipelines compile (start state's 32² optimise 13–16 s, end's 4–6 s)
  surface: [0.054, 2.8e-5],  // per surface step (60 in 4–6 s at 32²; at 64², a fast state whose depth
                             // could not measure a part: 150 in 21–26 s)
  remesh: [0.4, 4.7e-5],     // per state, remeshed mesh to first recovery step: its PSNR, per pixel × view (0.4 s tiny, 2.7 s fast)
  recover: [0.03, 7.3e-5],   // per recovery step (0.105 s at 32², 0.33 s at 64² with 20× the faces)
  evaluate: [0.25, 6e-5],    // per state: PSNR renders, per working pixel × view (0.5 s tiny, 3.2 s fast)
  // The depth measures each movable part's joint: s, and s more up to a part seen in 80k labelled
  // pixels (where its cloud's point cap bites); fitted to the demo 13–17 s, kitchen counter 16–18 s
  // (7 small drawers), fridge 23–28 s, sektion 28–42 s. A part of unknown size counts 60k pixels.
  joints: [1, 10, 80_000, 60_000],
  bakeoff: [1.5, 2.4e-4],    // s, and per movable part per working pixel (its pictures and losses)
  candidates: [0.047, 3.7e-5],
  refine: [0.039, 4.1e-5],   // per render (81 ms at 32², 208 ms at 64²; fast's 40 steps × 24 of them: 200–224 s)
  export: [1.5, 0.5, 7],     // s, per part (base included), and with optimised surfaces: the twin's files,
                             // hulls and scores (fast 2–4 s, tiny 9–16 s for 3–8 parts)
  photograph: 6.2e-7,        // s per captured pixel (colour, depth, part map): the demo's 2.1 M in 1.3 s
};
// Each kind of CPU work is its own class: a remesh running fast says nothing of the measurement.
const CLASS = { remesh: "remesh", joints: "joints", export: "export" };
const CLASSES = ["gpu", ...Object.values(CLASS)];
const KEY = "artmesh.fit-scales.";

const step = ([a, b], pixels) => a + b * pixels;

/** The fit's stages in order: `{key, cls, s}` (predicted seconds on a software adapter). With
 *  `open`, the photometric stages run (a joint the depth maps leave open). */
export function plan(work, open) {
  const px = work.working_pixels, views = work.views, r = SOFTWARE;
  const photometric = open || work.photometric_always;
  const stages = [];
  // fixed: seconds of the stage spent before its first step (the warm-up).
  const add = (key, s, fixed = 0) => stages.push({ key, cls: CLASS[key.split(".").pop()] ?? "gpu", s, fixed });
  for (const state of ["start", "end"]) {
    const warmup = state === "start" ? r.warmup : 0;
    add(`${state}.surface`, warmup + work.surface_steps * step(r.surface, px), warmup);
    add(`${state}.remesh`, step(r.remesh, px * views));
    add(`${state}.recover`, work.recovery_steps * step(r.recover, px) + step(r.evaluate, px * views));
  }
  if (work.depth_pixels > 0) {
    const [a, b, full, unknown] = r.joints;
    const pixels = work.part_pixels.length ? work.part_pixels : Array(work.movable_parts).fill(unknown);
    add("joints", pixels.reduce((t, n) => t + a + b * Math.min(1, n / full), 0));
  }
  if (photometric) add("candidates", work.candidate_steps * step(r.candidates, px));
  add("bakeoff", r.bakeoff[0] + work.movable_parts * r.bakeoff[1] * px);
  // The refinement stops once its objective is flat: as early as its second check, as it mostly does.
  if (photometric) add("refine", work.refine_min_steps * work.refine_renders * step(r.refine, px));
  add("export", r.export[0] + (work.movable_parts + 1) * r.export[1] + (work.surface_steps > 0 ? r.export[2] : 0));
  return stages;
}

/** Seconds the demo spends photographing `capture` (both states, training and 4 held-out views). */
export const photographSeconds = (capture) => 2 * (capture.views + 4) * capture.width * capture.height * SOFTWARE.photograph;

function storedScales(adapter) {
  try { return JSON.parse(localStorage.getItem(KEY + adapter) ?? "null"); } catch { return null; }
}

/** `plan(work, open)` at an adapter's pace: each stage (and its warm-up) times its class's ratio. */
function scaledPlan(work, open, scales) {
  return plan(work, open).map((s) => ({ ...s, s: s.s * (scales?.[s.cls] ?? 1), fixed: s.fixed * (scales?.[s.cls] ?? 1) }));
}

const total = (stages) => stages.reduce((t, s) => t + s.s, 0);

/** Seconds a fit of `work` takes on `adapter`: `{settled, open, own}` (settled: the depth maps
 *  settle every joint; open: they leave one to the photometric stages; own: from this adapter's
 *  last fit), or null where nothing is known (a GPU that has not fitted yet). `extra`: seconds
 *  before the fit (the demo's photographs) at the GPU's scale. */
export function estimate(adapter, software, work, extra = 0) {
  const own = storedScales(adapter);
  if (!own && !software) return null;
  const before = extra * (own?.gpu ?? 1);
  return { settled: before + total(scaledPlan(work, false, own)), open: before + total(scaledPlan(work, true, own)), own: !!own };
}

function fmt(s) {
  if (s < 90) return `${Math.max(5, Math.round(s / 5) * 5)} s`;
  if (s < 90 * 60) return `${Math.round(s / 60)} min`;
  return `${(s / 3600).toFixed(1)} h`;
}

/** The preset line's words for an `estimate`. */
export function estimateText(e, photometricAlways) {
  if (!e) return "Time: not known for this GPU yet; the first fit's time sets the estimate.";
  const where = e.own ? "on this GPU (from its last fit)" : "on a software adapter (measured on a 2-core machine)";
  if (photometricAlways || Math.abs(e.open - e.settled) < 0.1 * e.settled) return `Estimated time: about ${fmt(e.open)} ${where}.`;
  return `Estimated time: about ${fmt(e.settled)} ${where} if the depth maps settle every joint; ` +
    `about ${fmt(e.open)} if they leave one open (the image stages then decide it).`;
}

/** Follows a running fit's progress events and says how long it has left: the stage running
 *  extrapolates its own pace where it reports steps, and the stages to come are predicted, scaled
 *  by how far the finished ones of their class ran from their prediction. */
export class Eta {
  constructor(work, adapter, now) {
    this.work = work;
    this.scales = { ...Object.fromEntries(CLASSES.map((c) => [c, 1])), ...storedScales(adapter) };
    this.stages = scaledPlan(work, false, this.scales);
    this.i = 0;
    this.start = now;
    this.f = 0;
    this.fAt = now;
    this.f0At = null;
    this.stretch = 1;
  }

  /** What each stage was predicted to take and took (s), once finished: "key:predicted/took,…". */
  summary() {
    return this.stages.map((s) => `${s.key}:${s.s.toFixed(1)}/${(s.actual ?? 0).toFixed(1)}`).join(",");
  }

  /** The stage a progress event belongs to (null: none of the plan's). The articulation's closing
   *  "done" comes as the end state's where no image step ran. */
  key(ev) {
    const phase = ev.phase, joints = this.stages.findIndex((s) => s.key === "joints");
    if (phase === "done" && (ev.state === "both" || (joints >= 0 && this.i >= joints))) return "export";
    if (ev.state !== "both") {
      if (phase === "remesh") return `${ev.state}.remesh`;
      if (phase === "recover" || phase === "done") return `${ev.state}.recover`;
      return `${ev.state}.surface`;
    }
    return { measure: "joints", candidates: "candidates", "bake-off": "bakeoff", refine: "refine" }[phase] ?? null;
  }

  /** Closes the running stage (and any skipped before `to`), charging them the time since it began. */
  advance(to, now) {
    if (to <= this.i) return;
    const skipped = this.stages.slice(this.i, to);
    const predicted = skipped.reduce((t, s) => t + s.s, 0) || 1;
    for (const s of skipped) s.actual = (now - this.start) * (s.s / predicted);
    this.i = to;
    this.start = now;
    this.f = 0;
    this.fAt = now;
    this.f0At = null;
    this.stretch = 1;
  }

  /** Plans the stages from the running one on anew, for `work`, with the image stages or not. */
  replan(work, open) {
    this.work = work;
    const rest = scaledPlan(work, open, this.scales).slice(this.i);
    this.stages = [...this.stages.slice(0, this.i), ...rest];
  }

  event(ev, now) {
    const key = this.key(ev);
    const open = this.stages.some((s) => s.key === "candidates");
    if (((ev.phase === "candidates" && ev.iterations > 0) || (ev.phase === "measure" && ev.open > 0)) && !open) {
      // The depth maps left a joint open: the photometric stages join the plan.
      this.replan(this.work, true);
    } else if (ev.phase === "candidates" && ev.iterations === 0 && open && !this.work.photometric_always) {
      // None of the open joints had a surface to train: no image steps after all.
      this.replan(this.work, false);
    }
    let j = this.stages.findIndex((s) => s.key === key);
    // "candidates" with no steps: the joints were measured, the bake-off comes next.
    if (j < 0 && ev.state === "both") j = this.stages.findIndex((s) => s.key === "bakeoff");
    if (j < 0) return;
    this.advance(j, now);
    if (key.endsWith(".surface") && ev.iterations > 0 && this.work.surface_steps === 0 && !this.stages[j].steps) {
      // The depth could not measure every part's surface, so this state optimises its surfaces
      // (the other may not), and that part's joint is left to the image stages.
      if (!this.stages.some((s) => s.key === "candidates")) this.replan(this.work, true);
      const stage = this.stages[j];
      stage.steps = ev.iterations;
      stage.s = stage.fixed + ev.iterations * step(SOFTWARE.surface, this.work.working_pixels) * this.scales.gpu;
    }
    if (ev.iterations > 0) {
      // The refinement may stop at its next check: that is the end to aim at, not its last step.
      const every = this.work.refine_check_every, least = this.work.refine_min_steps;
      // At a check (from the second on) it may stop right there; between checks, at the next.
      const check = ev.iteration >= least && ev.iteration % every === 0;
      const next = check ? ev.iteration : Math.max(least, (Math.floor(ev.iteration / every) + 1) * every);
      const end = key === "refine" ? Math.min(ev.iterations, next) : ev.iterations;
      this.f = Math.min(1, ev.iteration / end);
      this.fAt = now;
      // The pace counts from the stage's first step reported: what came before (pipelines
      // compiling, a measurement's set-up) is no guide to the rest.
      if (this.f0At == null && this.f > 0) [this.f0, this.f0At] = [this.f, now];
      this.stretch = key === "refine" ? end / Math.max(1, least) : 1;
    }
    // A state's reconstruction ends with "done": what follows (the next state, or the joint
    // measurement) starts there.
    if (ev.phase === "done" && key !== "export") this.advance(j + 1, now);
  }

  /** The finished stages' time over their prediction, per class (2 s of prior on each side). */
  scale(cls) {
    const done = this.stages.slice(0, this.i).filter((s) => s.cls === cls);
    const actual = done.reduce((t, s) => t + s.actual, 0), predicted = done.reduce((t, s) => t + s.s, 0);
    return Math.min(100, Math.max(0.01, (actual + 2) / (predicted + 2)));
  }

  remaining(now) {
    if (this.i >= this.stages.length) return 0;
    const k = Object.fromEntries(CLASSES.map((c) => [c, this.scale(c)]));
    const cur = this.stages[this.i];
    const expected = cur.s * k[cur.cls] * this.stretch;
    // Its prediction counted down, and its own pace so far, weighed by how much of it is done
    // (a stage's first steps, or its first part of a few, say little of the rest).
    const scale = expected / Math.max(cur.s, 1e-9), fixed = cur.fixed * scale;
    const warm = this.f > 0 ? 0 : Math.max(0, fixed - (now - this.start));
    const predicted = Math.max(0.05 * expected, warm + (expected - fixed) * (1 - this.f) -
      Math.max(0, now - Math.max(this.fAt, this.start + fixed)));
    const own = this.f0At != null && this.f > this.f0
      ? Math.max(0, (this.fAt - this.f0At) * (1 - this.f) / (this.f - this.f0) - (now - this.fAt)) : predicted;
    const left = this.f * own + (1 - this.f) * predicted;
    return left + this.stages.slice(this.i + 1).reduce((t, s) => t + s.s * k[s.cls], 0);
  }

  /** Closes the last stage and stores how far each class ran from its prediction on `adapter`. */
  finish(adapter, now) {
    this.advance(this.stages.length, now);
    const ratio = (cls) => {
      const done = this.stages.filter((s) => s.cls === cls);
      const predicted = done.reduce((t, s) => t + s.s / this.scales[cls], 0);
      return predicted > 0 ? done.reduce((t, s) => t + s.actual, 0) / predicted : 1;
    };
    if (!adapter) return;
    try { localStorage.setItem(KEY + adapter, JSON.stringify(Object.fromEntries(CLASSES.map((c) => [c, ratio(c)])))); } catch { /* storage off */ }
  }
}
