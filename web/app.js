// The page's driver: loads the wasm module, reports the WebGPU adapter, runs the GPU self-test on
// request, takes a demo object or a dataset, runs the fit and shows the twin. All computation
// happens in the wasm module (web/pkg); these files only move data in and show results.
// `document.body.dataset.state` tells tests where the page is: loading → done | error | panic.
import { $, show, errorText, showBanner, hideBanner, freeQuietly } from "./util.js";
import { setupInput, showDataset } from "./input.js";
import { wireFitButtons, runFit, markFitDone } from "./fit-ui.js";
import { wireResultButtons, showResult, clearResult } from "./result-ui.js";
import { setupBudgets, showPresetBudget, budgetOverrides, shownPreset } from "./budget-ui.js";
import { setPartColours } from "./articulation-ui.js";
import { Eta, estimate, estimateText, photographSeconds } from "./estimate.js";

const params = new URLSearchParams(location.search);
const maxSize = Number(params.get("max") ?? 1000003);

let wasm = null;         // the wasm module's exports (web/pkg/artmesh.js)
let gpuOk = false;       // a WebGPU adapter answered
let busy = false;        // a GPU job (self-test, demo, fit) is running
let broken = false;      // after a panic or a lost device only a reload helps
let currentDataset = null;
let catalogue = { categories: [], presets: [], default: {} };

function updateButtons() {
  const gpu = gpuOk && !broken;
  $("selftest-run").disabled = !gpu || busy;
  $("demo-run").disabled = !gpu || busy;
  $("fit-run").disabled = !gpu || busy || !currentDataset;
}

// --- errors that end the session ----------------------------------------------------------

function wireFatalEvents() {
  window.addEventListener("artmesh-panic", (e) => {
    broken = true;
    document.body.dataset.state = "panic";
    document.body.dataset.error = String(e.detail ?? "panic");
    if (["running", "paused"].includes(document.body.dataset.fit)) document.body.dataset.fit = "error";
    showBanner(`artmesh stopped on an internal error and cannot go on: ${e.detail ?? "unknown"}`,
      { label: "Reload page", run: () => location.reload() });
    updateButtons();
  });
  window.addEventListener("artmesh-device-lost", (e) => {
    // Only the page's current device is announced (src/web/mod.rs), so every event is a real loss.
    const reason = String(e.detail ?? "unknown reason");
    broken = true;
    document.body.dataset.deviceLost = "1";
    showBanner(`The GPU device was lost (${reason}). This happens when the graphics driver resets or the GPU ` +
      `runs out of memory. Restart the page to go on.`, { label: "Restart", run: () => location.reload() });
    updateButtons();
  });
}

// --- 1. the GPU ---------------------------------------------------------------------------

function noGpu(message) {
  gpuOk = false;
  show($("adapter"), message, "fail");
  const note = $("gpu-needed");
  note.hidden = false;
  note.textContent = "Generating and fitting need WebGPU, so those buttons are off. You can still check a dataset.";
  document.body.dataset.selftest = "skipped";
}

async function gpuSection() {
  if (!navigator.gpu) {
    noGpu("This browser has no WebGPU. Use Chrome or Edge 113+ (on Linux start Chromium with " +
      "--enable-unsafe-webgpu), Safari 26+, or Firefox 141+ on Windows.");
    return true;
  }
  let adapter;
  try {
    adapter = JSON.parse(await wasm.adapter_report());
  } catch (e) {
    // The error lists the backends wgpu tried ("noop not requested, vulkan not requested, …"):
    // for the console, not for the visitor.
    console.error("no WebGPU adapter:", errorText(e));
    noGpu("This browser offers WebGPU but gave the page no GPU adapter: it may block WebGPU for this GPU or " +
      "driver, or hardware acceleration may be off.\nTurn hardware acceleration on in the browser's settings, " +
      "or try another browser.");
    document.body.dataset.error = errorText(e);
    return false;
  }
  // The browser's own adapter info names the vendor and architecture even when it hides the description.
  let info = null;
  try { info = (await navigator.gpu.requestAdapter())?.info; } catch { /* optional */ }
  const vendor = [info?.vendor, info?.architecture].filter(Boolean).join(" ");
  const name = vendor ? `${vendor} — ${adapter.name}` : adapter.name;
  document.body.dataset.adapter = name;
  const software = adapter.device_type === "Cpu";
  // A fast fit takes many minutes on a software adapter: start such a visitor at tiny, unless
  // the address asks for a preset.
  const tiny = software && !params.get("preset") && choosePreset("tiny");
  document.body.dataset.software = String(software);
  const limits = `Details: the largest buffer the fit may use is ${(adapter.max_storage_buffer_binding_size / 2 ** 20).toFixed(0)} MiB; ` +
    `up to ${adapter.max_compute_workgroups_per_dimension} workgroups per dimension.`;
  show($("adapter"), software
    ? `No graphics card is available to this page, so the browser emulates one on the processor (${name}). ` +
      `Fits run, but slowly: ${tiny ? "the tiny preset is chosen for you" : "the tiny preset is the one to use"} ` +
      `(a fast fit can take several minutes here).\n${limits}`
    : `The fit runs on your graphics card: ${name}.\n${limits}`, "ok");
  gpuOk = true;
  return true;
}

async function selfTest() {
  if (busy) return;
  busy = true;
  updateButtons();
  delete document.body.dataset.selftest;
  const status = $("selftest-status");
  show(status, "Running prefix sum and radix sort on the GPU…");
  const body = $("selftest-table").querySelector("tbody");
  body.replaceChildren();
  $("selftest-table").hidden = true;
  const t0 = performance.now();
  try {
    const result = JSON.parse(await wasm.gpu_self_test(maxSize));
    const seconds = ((performance.now() - t0) / 1000).toFixed(1);
    for (const c of result.report.checks) {
      const row = body.insertRow();
      for (const v of [c.kernel, c.n.toLocaleString("en"), c.key_bits || "—"]) row.insertCell().textContent = v;
      const verdict = row.insertCell();
      verdict.textContent = c.mismatches === 0 ? "matches CPU" : `${c.mismatches} mismatches (first at ${c.first_mismatch})`;
      verdict.className = c.mismatches === 0 ? "ok" : "fail";
    }
    $("selftest-table").hidden = false;
    const n = result.report.checks.length;
    show(status, result.passed ? `All ${n} checks match the CPU (${seconds} s).`
      : "Some checks differ from the CPU: see the table. Fits on this GPU may be wrong.", result.passed ? "ok" : "fail");
    document.body.dataset.selftest = result.passed ? "pass" : "fail";
  } catch (e) {
    show(status, `The self-test could not run: ${errorText(e)}`, "fail");
    document.body.dataset.selftest = "fail";
  } finally {
    busy = false;
    updateButtons();
  }
}

// --- 2. input -----------------------------------------------------------------------------

function option(select, value, text) {
  const o = document.createElement("option");
  o.value = value;
  o.textContent = text;
  select.append(o);
}

/** Selects preset `name` in both forms (as if chosen by hand); false when there is no such preset. */
function choosePreset(name) {
  if (!catalogue.presets.some((p) => p.name === name)) return false;
  for (const select of [$("demo-preset"), $("fit-preset")]) {
    select.value = name;
    select.dispatchEvent(new Event("change"));
  }
  return true;
}

/** Rewrites both presets' descriptions (their estimates depend on the adapter and past fits). */
const describers = [];
const describePresets = () => describers.forEach((f) => f());

/** What a fit of the current dataset (or, for the demo, of the object it would photograph) with
 *  `preset` costs: `{work, extra}` (extra: seconds photographing first, the demo's), or null. */
function workOf(preset, demo) {
  let budget;
  // (The budget fields' changes, where they show this preset; asking for another would switch them.)
  try { budget = shownPreset() === preset ? budgetOverrides(preset) : undefined; } catch { budget = undefined; }
  const capture = demo ? wasm.demo_capture(preset, budget, Number($("demo-parts").value) || 1) : currentDataset?.capture();
  if (!capture || capture === "null") return null;
  return { work: JSON.parse(wasm.fit_work(preset, budget, capture)), extra: demo ? photographSeconds(JSON.parse(capture)) : 0 };
}

/** The preset line's time estimate; its seconds go to the line's data-estimate-s (settled joints)
 *  and data-estimate-open-s (a joint left open), for tests. */
function timeText(preset, demo) {
  const about = $(demo ? "demo-preset-about" : "fit-preset-about");
  delete about.dataset.estimateS;
  delete about.dataset.estimateOpenS;
  const d = document.body.dataset;
  if (!d.adapter) return "";
  let w;
  try { w = workOf(preset, demo); } catch (e) { console.warn("no estimate:", errorText(e)); return ""; }
  if (!w) return "Time: estimated once a capture is loaded.";
  const e = estimate(d.adapter, d.software === "true", w.work, w.extra);
  if (e) {
    about.dataset.estimateS = e.settled.toFixed(1);
    about.dataset.estimateOpenS = e.open.toFixed(1);
  }
  return estimateText(e, w.work.photometric_always);
}

function fillForms() {
  const d = catalogue.default ?? {};
  const cat = $("demo-category");
  for (const c of catalogue.categories) option(cat, c.name, c.label && c.label !== c.name ? `${c.label} (${c.name})` : c.name);
  if (d.category) cat.value = d.category;
  const names = catalogue.presets.map((p) => p.name);
  const wanted = params.get("preset");
  const preset = names.includes(wanted) ? wanted : (d.preset ?? names[0]);
  for (const [select, about] of [[$("demo-preset"), $("demo-preset-about")], [$("fit-preset"), $("fit-preset-about")]]) {
    for (const p of catalogue.presets) option(select, p.name, p.name);
    select.value = preset;
    const demo = select.id === "demo-preset";
    const describe = () => {
      const p = catalogue.presets.find((p) => p.name === select.value);
      about.textContent = [p?.about ?? "", timeText(select.value, demo)].filter(Boolean).join(". ");
    };
    describers.push(describe);
    select.addEventListener("change", describe);
    // The budgets section follows the preset chosen last.
    select.addEventListener("change", () => showPresetBudget(select.value));
    describe();
  }
  setupBudgets(catalogue.presets, preset, (name, overrides) => JSON.parse(wasm.preset_budget(name, overrides)).about);
  const setRange = (parts) => {
    const c = catalogue.categories.find((c) => c.name === cat.value);
    const [lo, hi] = c?.parts ?? [1, 15];
    const input = $("demo-parts");
    input.min = String(lo);
    input.max = String(hi);
    input.value = String(Math.min(hi, Math.max(lo, parts ?? c?.default_parts ?? lo)));
  };
  cat.addEventListener("change", () => { setRange(null); describePresets(); });
  $("demo-parts").addEventListener("change", describePresets);
  setRange(d.parts);
  $("demo-seed").value = String(d.seed ?? 0);
}

function setDataset(ds) {
  if (currentDataset && currentDataset !== ds) freeQuietly(currentDataset);
  currentDataset = ds;
  showDataset(ds);
  describePresets();
  updateButtons();
}

function readDemoForm() {
  const parts = $("demo-parts");
  let n = Math.round(Number(parts.value));
  if (!Number.isFinite(n)) n = Number(parts.min) || 1;
  n = Math.min(Number(parts.max) || 15, Math.max(Number(parts.min) || 1, n));
  parts.value = String(n);
  let seed = Math.round(Number($("demo-seed").value));
  if (!Number.isFinite(seed) || seed < 0) seed = 0;
  $("demo-seed").value = String(seed);
  return { category: $("demo-category").value, parts: n, preset: $("demo-preset").value, seed,
    sensor: $("demo-sensor").value };
}

async function runDemo() {
  if (busy || broken) return;
  const { category, parts, preset, seed, sensor } = readDemoForm();
  const status = $("demo-status");
  let budget;
  try {
    budget = budgetOverrides(preset);
  } catch (e) {
    status.textContent = `Check the budgets: ${errorText(e)}`;
    showBanner(`Check the budgets (Advanced: budgets): ${errorText(e)}`);
    return;
  }
  busy = true;
  updateButtons();
  hideBanner();
  clearResult();
  const progress = $("demo-progress");
  progress.hidden = false;
  progress.value = 0;
  document.body.dataset.demo = "rendering";
  status.textContent = `Generating a ${category} with ${parts} movable part(s) and photographing both states…`;
  try {
    let ds;
    const t0 = performance.now();
    try {
      ds = await wasm.Dataset.demo(category, parts, preset, seed, (p) => {
        if (!p || !(p.total > 0)) return;
        progress.value = p.done / p.total;
        status.textContent = `Photographing the object: ${p.done} of ${p.total} views rendered.`;
      }, budget, sensor);
    } catch (e) {
      document.body.dataset.demo = "error";
      status.textContent = `The demo object could not be made: ${errorText(e)}`;
      showBanner(`The demo object could not be made: ${errorText(e)}`);
      return;
    }
    progress.value = 1;
    document.body.dataset.photographS = ((performance.now() - t0) / 1000).toFixed(1);
    document.body.dataset.demo = "rendered";
    status.textContent = "Photographed; now fitting (see Fit).";
    setDataset(ds);
    await doFit(ds, preset, budget, `the demo ${category}`);
    status.textContent = document.body.dataset.fit === "done" ? "Done: the twin is under Result."
      : "The fit did not finish: see Fit.";
  } finally {
    busy = false;
    updateButtons();
  }
}

/** Photographs the object in the zipped URDF `bytes` (named `name`) in both states on the GPU, as
 *  the demo does for the fit form's preset; resolves to its Dataset. Throws, for input.js to show
 *  inline, when there is no GPU or it is busy, and with the importer's or the capture's error. */
async function captureObject(name, bytes, onProgress) {
  if (!gpuOk || broken) {
    throw new Error(`${name} holds a URDF, which is photographed on the GPU: ` +
      (broken ? "reload the page first" : "this browser gives the page no WebGPU"));
  }
  if (busy) throw new Error(`${name}: the GPU is busy with a self-test, demo or fit; drop the .zip again when it is done`);
  const preset = $("fit-preset").value;
  let budget;
  try {
    budget = budgetOverrides(preset);
  } catch (e) {
    throw new Error(`check the budgets (Advanced: budgets): ${errorText(e)}`);
  }
  busy = true;
  updateButtons();
  hideBanner();
  try {
    return await wasm.Dataset.from_object_zip(name, bytes, preset, 0, onProgress, budget);
  } finally {
    busy = false;
    updateButtons();
  }
}

// --- 3. + 4. fit and result ---------------------------------------------------------------

/** Fits `ds` with `preset` and `budget` (the budgets' overrides as JSON, or undefined). */
async function doFit(ds, preset, budget, what) {
  clearResult();
  delete window.artmeshLast;
  $("fit").scrollIntoView?.({ behavior: "smooth", block: "start" });
  let handle;
  try {
    handle = ds.share();
  } catch (e) {
    showBanner(`The dataset is no longer available: ${errorText(e)}`);
    document.body.dataset.fit = "error";
    return;
  }
  let eta = null;
  try {
    eta = new Eta(JSON.parse(wasm.fit_work(preset, budget, ds.capture())), document.body.dataset.adapter, performance.now() / 1000);
  } catch (e) {
    console.warn("no time estimate:", errorText(e));
  }
  const r = await runFit(wasm.fit, handle, preset, budget, what, eta);
  describePresets();
  if (!r) {
    $("result-empty").textContent = "No twin: the fit did not finish.";
    return;
  }
  try {
    window.artmeshLast = { joints: r.joints(), report: r.report() };
  } catch (e) {
    console.error("result:", e);
  }
  markFitDone();
  try {
    await showResult(wasm.Viewer, r);
  } catch (e) {
    showBanner(`The result could not be shown: ${errorText(e)}`);
  }
}

async function fitCurrent() {
  if (busy || broken || !currentDataset) return;
  busy = true;
  updateButtons();
  hideBanner();
  try {
    let name = "your dataset";
    try { name = currentDataset.name() || name; } catch { /* unnamed */ }
    const preset = $("fit-preset").value;
    let budget;
    try {
      budget = budgetOverrides(preset);
    } catch (e) {
      showBanner(`Check the budgets (Advanced: budgets): ${errorText(e)}`);
      return;
    }
    await doFit(currentDataset, preset, budget, name);
  } finally {
    busy = false;
    updateButtons();
  }
}

// --- start --------------------------------------------------------------------------------

async function main() {
  wireFatalEvents();
  try {
    try {
      wasm = await import("./pkg/artmesh.js");
    } catch (e) {
      throw new Error(`the wasm module (web/pkg) did not load: ${errorText(e)}; build it with web/build.sh`);
    }
    const missing = ["adapter_report", "gpu_self_test", "catalogue", "preset_budget", "fit_work", "demo_capture", "fit", "Dataset", "Viewer", "part_colours"].filter((n) => !wasm[n]);
    if (missing.length) throw new Error(`web/pkg is out of date (missing ${missing.join(", ")}): rebuild it with web/build.sh`);
    await wasm.default();
    // The articulation's pictures are tinted with the viewer's part colours ("#rrggbb").
    setPartColours(wasm.part_colours().map((hex) => [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16))));
    catalogue = JSON.parse(wasm.catalogue());
    window.artmeshCatalogue = catalogue;
    fillForms();
    setupInput(wasm.Dataset, {
      onDataset: setDataset,
      onProblems: () => {
        freeQuietly(currentDataset);
        currentDataset = null;
        updateButtons();
      },
      captureObject,
    });
    wireFitButtons();
    wireResultButtons();
    $("selftest-run").addEventListener("click", selfTest);
    $("demo-run").addEventListener("click", runDemo);
    $("fit-run").addEventListener("click", fitCurrent);
    const ok = await gpuSection();
    describePresets();
    updateButtons();
    if (document.body.dataset.state !== "panic") document.body.dataset.state = ok ? "done" : "error";
  } catch (e) {
    const message = errorText(e);
    show($("adapter"), `The page could not start: ${message}`, "fail");
    showBanner(`The page could not start: ${message}`, { label: "Reload page", run: () => location.reload() });
    document.body.dataset.state = "error";
    document.body.dataset.error = message;
  }
}

// Offline once loaded: the service worker keeps a copy of every file the page fetched.
if ("serviceWorker" in navigator && window.isSecureContext) {
  navigator.serviceWorker.register("sw.js").catch((e) => console.warn("service worker:", e));
}

main();
