// End-to-end test of the page in headless Chromium with WebGPU (SwiftShader where there is no GPU):
//  1. adapter report and the GPU self-test (button);
//  2. a dataset written by the native `artmesh demo` fitted in the page, joints compared with the native fit;
//  3. the page's own demo (2 parts; tiny, or ARTMESH_DEMO_PRESET=fast), scored and timed against native;
//  4. a joint slider changes the viewer's picture;
//  5. downloads: the GLB passes the glTF validator, the zip holds <folder>/twin.urdf with joint limits;
//  6. a malformed dataset, as a folder and as a dropped .zip, is reported by file name;
//     budgets: a zip bomb is refused, a folder beside a 4 GB file loads without reading it;
//     zipped URDFs: three objects from ../shared/objects fitted at the demo's preset and scored;
//  7. no request leaves the page's origin.
// Screenshots go to artefacts/ (repository root). Exit code 0 = pass. Needs web/pkg built (web/build.sh)
// and the native CLI (ARTMESH_BIN, default target/debug/artmesh).
import { chromium } from "playwright-core";
import validator from "gltf-validator";
import { mkdir, mkdtemp, writeFile, cp, readFile, truncate } from "node:fs/promises";
import { execFileSync } from "node:child_process";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { fileURLToPath } from "node:url";
import { serve } from "../serve.mjs";
import { checkSharedObjectFit, checkUrdfZip } from "./urdf.mjs";
import {
  checkDemoScore, checkFinishedPanel, checkJointsTable, checkNoWarnings, checkResultViewer, checkResultWidth,
  checkSliderKeys,
} from "./result.mjs";
import { changed, snapshot } from "./canvas.mjs";
import { checkMobileAndTouch } from "./touch.mjs";
import { checkTimes, readEstimate, sampleEta } from "./timing.mjs";

// The parity fit's preset: tiny in CI; ARTMESH_PARITY_PRESET=fast (64 px, 12 views; ~25–32 min in
// the browser) asserts the issue's 0.5° / 5 mm (docs/results.md, "Browser vs native").
const parityPreset = process.env.ARTMESH_PARITY_PRESET ?? "tiny";
const parityMinutes = parityPreset === "tiny" ? 10 : 50;
// The page demo's and the shared objects' preset: tiny (a software adapter's) in CI; fast (a hardware
// adapter's) takes SwiftShader minutes per fit. At both the demo must type both joints right with every
// axis within 2° (issue 46), and the shared objects meet urdf.mjs's bounds (issue 47).
const demoPreset = process.env.ARTMESH_DEMO_PRESET ?? "tiny";
const demoMinutes = demoPreset === "tiny" ? 10 : 50;
const TOTAL_MINUTES = parityMinutes + demoMinutes + 5; // the whole run's limit: those fits' and 5 min more
let failed = 0, passed = 0;
const check = (ok, what) => {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (ok) passed++; else failed++;
  return ok;
};
const note = (what) => console.log(`note ${what}`);
const guard = setTimeout(() => {
  check(false, `total time limit of ${TOTAL_MINUTES} min reached`);
  console.log(`page: ${passed} passed, ${failed} failed`);
  process.exit(1);
}, TOTAL_MINUTES * 60_000);
guard.unref();

const bin = process.env.ARTMESH_BIN ?? fileURLToPath(new URL("../../target/debug/artmesh", import.meta.url));
const artefacts = fileURLToPath(new URL("../../artefacts/", import.meta.url));
await mkdir(artefacts, { recursive: true });
const work = await mkdtemp(join(tmpdir(), "artmesh-page-"));
console.log(`work folder: ${work}`);

/** Runs the native CLI (stderr shown, stdout dropped); returns wall seconds. */
function native(args) {
  const t0 = performance.now();
  execFileSync(bin, args, { stdio: ["ignore", "ignore", "inherit"] });
  return (performance.now() - t0) / 1000;
}

// ARTMESH_PAGE_STEPS: only these steps (comma-separated names, so none has a comma; the GPU self-test, which opens the page, always runs).
const onlySteps = process.env.ARTMESH_PAGE_STEPS?.split(",").map((s) => s.trim());
const timings = [];
async function step(name, fn) {
  if (onlySteps && name !== "GPU self-test" && !onlySteps.includes(name)) return;
  console.log(`--- ${name}`);
  const t0 = performance.now();
  try {
    await fn();
  } catch (e) {
    check(false, `${name}: ${String(e?.message ?? e).split("\n").slice(0, 3).join(" | ")}`);
  }
  const s = (performance.now() - t0) / 1000;
  timings.push([name, s]);
  console.log(`step ${name}: ${s.toFixed(1)} s`);
}

// --- small vector maths for the joint comparison ------------------------------------------
const sub = (a, b) => a.map((x, i) => x - b[i]);
const dot = (a, b) => a.reduce((s, x, i) => s + x * b[i], 0);
const len = (a) => Math.sqrt(dot(a, a));
const unit = (a) => a.map((x) => x / len(a));
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const parse = (v) => (typeof v === "string" ? JSON.parse(v) : v);

// ARTMESH_WEB_ROOT: test a folder `web/build.sh --dist` wrote (CI does) instead of web/ itself.
const webRoot = process.env.ARTMESH_WEB_ROOT ?? fileURLToPath(new URL("..", import.meta.url));
const server = await serve(0, webRoot);
const url = `http://127.0.0.1:${server.address().port}/`;
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: ["--no-sandbox", "--enable-unsafe-webgpu", "--disable-background-networking", "--disable-component-update",
    "--disable-sync", "--no-first-run", "--disable-quic"],
});
const requests = [];
const pageErrors = [];
let nativeLaptopS = null;

try {
  const context = await browser.newContext({ viewport: { width: 1000, height: 1100 }, acceptDownloads: true });
  const page = await context.newPage();
  page.setDefaultTimeout(60_000);
  page.on("request", (r) => requests.push(r.url()));
  page.on("console", (m) => m.type() === "error" && console.log("page console:", m.text()));
  page.on("pageerror", (e) => { pageErrors.push(e.message); console.log("page error:", e.message); });
  const body = () => page.evaluate(() => ({ ...document.body.dataset }));
  // axe-core's serious and critical violations on the page as it is now. Its source is evaluated through
  // the DevTools protocol: no request, and the page's script policy (no inline scripts) stays as it is.
  const axeSource = await readFile(fileURLToPath(new URL("../node_modules/axe-core/axe.min.js", import.meta.url)), "utf8");
  const accessibility = async (label) => {
    if (!(await page.evaluate(() => "axe" in window))) await page.evaluate(axeSource);
    const found = await page.evaluate(async () => {
      const r = await window.axe.run(document, { resultTypes: ["violations"] });
      return r.violations.filter((v) => ["serious", "critical"].includes(v.impact))
        .map((v) => `${v.id} (${v.impact}, ${v.nodes.length}×, e.g. ${v.nodes[0]?.target?.join(" ")})`);
    });
    check(found.length === 0, `axe-core: ${found.length} serious or critical violations on ${label}` +
      (found.length ? ": " + found.join("; ") : ""));
  };
  const clearFlags = (...names) => page.evaluate((names) => { for (const n of names) delete document.body.dataset[n]; }, names);

  // 1. GPU ---------------------------------------------------------------------------------
  await step("GPU self-test", async () => {
    await page.goto(url + "?max=65537");
    await page.waitForFunction(() => document.body.dataset.state !== "loading", null, { timeout: 300_000 });
    const state = await body();
    check(state.state === "done", `page started (state=${state.state}${state.error ? ", error: " + state.error : ""})`);
    check(Boolean(state.adapter), `adapter reported: ${state.adapter}`);
    if (state.software === "true") {
      const presets = [await page.inputValue("#demo-preset"), await page.inputValue("#fit-preset")];
      check(presets.every((p) => p === "tiny"), `a software adapter starts at the tiny preset (${presets.join(", ")})`);
      const about = await page.locator("#demo-preset-about").textContent();
      check(/Estimated time: about \d+ s/.test(about), `the time a tiny fit takes is shown before it starts: ${about}`);
    }
    await page.click("#selftest-run");
    await page.waitForFunction(() => ["pass", "fail"].includes(document.body.dataset.selftest) ||
      document.body.dataset.state === "panic", null,
      { timeout: 300_000, polling: 500 });
    check((await body()).selftest === "pass", `GPU self-test passed (selftest=${(await body()).selftest})`);
    const rows = await page.locator("#selftest-table tbody tr").count();
    check(rows >= 20, `self-test table shows ${rows} checks`);
    await page.screenshot({ path: artefacts + "web-selftest.png", fullPage: true });
    await accessibility("the landing page");
  });

  // 1b. the README's web command: the page `web/build.sh --serve` serves (scripts/test.sh starts it)
  await step("web/build.sh --serve", async () => {
    const served = process.env.ARTMESH_SERVE_URL;
    if (!served) { note("ARTMESH_SERVE_URL not set: web/build.sh --serve is checked by scripts/test.sh"); return; }
    let up = false;
    for (let i = 0; i < 240 && !up; i++) {
      up = await fetch(served).then((r) => r.ok, () => false);
      if (!up) await new Promise((r) => setTimeout(r, 500));
    }
    if (!check(up, `web/build.sh --serve answers at ${served}`)) return;
    const other = await context.newPage();
    try {
      await other.goto(served);
      await other.waitForFunction(() => document.body.dataset.state !== "loading", null, { timeout: 300_000 });
      const state = await other.evaluate(() => ({ ...document.body.dataset }));
      check(state.state === "done" && Boolean(state.adapter),
        `the page web/build.sh --serve serves starts (state=${state.state}, adapter ${state.adapter})`);
    } finally {
      await other.close();
    }
  });

  // 2. a native demo's dataset fitted in the page ------------------------------------------
  await step("fit a native dataset", async () => {
    // ARTMESH_PARITY_NATIVE: a folder that same `artmesh demo` already wrote (saves minutes at fast).
    const out = process.env.ARTMESH_PARITY_NATIVE ?? join(work, "native");
    if (!process.env.ARTMESH_PARITY_NATIVE) {
      nativeLaptopS = native(["demo", "--preset", parityPreset, "--category", "laptop", "--parts", "1", "--seed", "3", "--out", out]);
      console.log(`native demo (laptop, 1 part, ${parityPreset}): ${nativeLaptopS.toFixed(1)} s`);
    }

    await clearFlags("dataset");
    await page.setInputFiles("#folder", join(out, "dataset"));
    await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 120_000 });
    const text = await page.locator("#dataset-result").textContent();
    check((await body()).dataset === "ok", `native dataset accepted: ${text.split("\n")[0]}`);
    const thumbs = await page.locator("#thumbs canvas").count();
    check(thumbs >= 2, `dataset thumbnails shown (${thumbs})`);

    await page.selectOption("#fit-preset", parityPreset);
    await clearFlags("fit", "preview", "result");
    const t0 = performance.now();
    await page.click("#fit-run");
    const first = await (await page.waitForFunction(() => {
      const d = document.body.dataset;
      if (d.state === "panic") return "panic";
      if (d.fit === "running" && d.preview === "1") return "running";
      return ["done", "error", "cancelled"].includes(d.fit) ? d.fit : false;
    }, null, { timeout: parityMinutes * 60_000, polling: 250 })).jsonValue();
    await page.screenshot({ path: artefacts + "web-fit-progress.png", fullPage: true });
    await page.locator("#fit").screenshot({ path: artefacts + "web-fit-section.png" });
    if (first === "running") check(true, "fit progress with a preview shown (artefacts/web-fit-progress.png)");
    else note(`the fit ended (${first}) before the first preview; screenshot taken after it`);
    const left = Math.max(1000, parityMinutes * 60_000 - (performance.now() - t0));
    await page.waitForFunction(() => ["done", "error", "cancelled"].includes(document.body.dataset.fit) ||
      document.body.dataset.state === "panic", null, { timeout: left, polling: 500 });
    const fitS = (performance.now() - t0) / 1000;
    const state = await body();
    if (!check(state.fit === "done", `page fit finished in ${fitS.toFixed(1)} s (fit=${state.fit}` +
      `${state.fitError ? ": " + state.fitError : ""}${state.state === "panic" ? ", panic: " + state.error : ""})`)) return;
    if (first !== "running") check(state.preview === "1" || fitS < 5, `a preview arrived during the fit (preview=${state.preview})`);
    await page.waitForFunction(() => document.body.dataset.result === "ready", null, { timeout: 120_000 });
    check(true, `result shown with ${(await body()).jointCount} joint slider(s)`);

    const last = await page.evaluate(() => window.artmeshLast ?? null);
    const pj = parse(last.joints).slice().sort((a, b) => a.part - b.part);
    const nj = JSON.parse(await readFile(join(out, "fit", "joints.json"), "utf8")).sort((a, b) => a.part - b.part);
    // Both reports kept, and where the two fits part ways printed: the first stage whose
    // numbers differ (densify counts and PSNRs compared to 4 digits, remeshed face counts exact).
    const nativeReport = await readFile(join(out, "fit", "report.json"), "utf8");
    await writeFile(artefacts + "parity-page-report.json", last.report);
    await writeFile(artefacts + "parity-native-report.json", nativeReport);
    const [ps, ns] = [parse(last.report), JSON.parse(nativeReport)].map((r) => r.reconstruction.states);
    const parting = ps.flatMap((p, i) => [
      ["faces split", p.faces_split, ns[i].faces_split],
      ["faces pruned", p.faces_pruned, ns[i].faces_pruned],
      ["PSNR optimised", p.psnr_optimised.toFixed(4), ns[i].psnr_optimised.toFixed(4)],
      ["remeshed faces", p.remesh.faces_built, ns[i].remesh.faces_built],
    ].map(([what, a, b]) => ({ what: `${p.state} state ${what}`, a, b }))).find((d) => d.a !== d.b);
    console.log(parting ? `note the fits part ways at the ${parting.what}: page ${parting.a}, native ${parting.b}`
      : "note the reconstructions agree in every reported count");
    const types = (js) => js.map((j) => j.type).join(",");
    if (!check(pj.length === nj.length && types(pj) === types(nj),
      `page joints match native in number and type (page ${types(pj)}; native ${types(nj)})`)) return;
    // The issue asks for 0.5° / 5 mm. Both fits repeat to the digit, but SwiftShader and lavapipe
    // round differently (PSNRs agree to ~1e-4 dB after optimisation) and remeshing turns that into
    // a few faces' difference. At fast the joints stay within the target (0.18°, 0.46 mm and,
    // since the axis registration, 0.28° of motion on 2026-12-02; 0.84° before it), asserted here;
    // at tiny (32 px, 4 views) they do not (natively, a 1e-6 change of the reconstruction's SSIM
    // weight moves the tiny axis up to 2.3°), so tiny asserts its accuracy bound against the
    // ground truth (< 10°, tests/native/articulation.rs) and prints the gap against the target.
    const [angleTol, mmTol, motionTol] = parityPreset === "tiny" ? [10, 0.02, [10, 0.02]] : [0.5, 0.005, [0.5, 0.005]];
    for (let i = 0; i < nj.length; i++) {
      const a = nj[i], b = pj[i];
      const da = unit(a.direction), db = unit(b.direction);
      const c = dot(da, db);
      const angle = (Math.acos(Math.min(1, Math.abs(c))) * 180) / Math.PI;
      check(angle <= angleTol, `part ${a.part} (${a.type}): axis directions differ by ${angle.toFixed(4)}° ` +
        `(asserted ≤ ${angleTol}°; target 0.5°: ${angle <= 0.5 ? "met" : "NOT met"})`);
      if (a.type === "revolute") {
        const distance = len(cross(sub(a.origin, b.origin), db));
        check(distance <= mmTol, `part ${a.part}: axis lines ${(distance * 1000).toFixed(2)} mm apart ` +
          `(asserted ≤ ${mmTol * 1000} mm; target 5 mm: ${distance <= 0.005 ? "met" : "NOT met"})`);
      }
      const motion = Math.abs(a.motion - (c < 0 ? -b.motion : b.motion));
      const [tol, target, u, scale] = a.type === "revolute" ? [motionTol[0], 0.5, "°", 1] : [motionTol[1], 0.005, " mm", 1000];
      check(motion <= tol, `part ${a.part}: motion differs by ${(motion * scale).toFixed(3)}${u} ` +
        `(native ${a.motion.toFixed(4)}, page ${b.motion.toFixed(4)}; target ${target * scale}${u}: ` +
        `${motion <= target ? "met" : "NOT met"})`);
    }
  });

  // Screenshots mid-fit: the reconstruction at its first preview; the articulation paused at its first
  // picture (the start mesh moved by the joint seeds), then resumed.
  const midFit = async () => {
    await page.waitForFunction(() => document.body.dataset.preview === "1", null, { timeout: 300_000, polling: 100 });
    await page.locator("#fit").screenshot({ path: artefacts + "web-mid-reconstruction.png" });
    await page.waitForFunction(() => (document.body.dataset.moved ?? "").includes("joint seeds") ||
      document.body.dataset.result === "ready", null, { timeout: 600_000, polling: "raf" });
    await page.click("#pause");
    await page.waitForFunction(() => ["paused", "done", "error"].includes(document.body.dataset.fit));
    const during = await body();
    note(`paused ${during.moved?.includes("fitted") ? "after" : "during"} the articulation (moved: ${during.moved})`);
    await page.locator("#fit").screenshot({ path: artefacts + "web-mid-articulation.png" });
    if (during.fit === "paused") await page.click("#pause");
  };
  // The articulation's pictures: the start mesh moved by the seeds and by the fitted joints differ, and
  // every movable part's bake-off shows two candidates that move it differently, one the winner.
  const articulationPictures = async () => {
    const shots = await page.evaluate(() => {
      const data = (c) => Array.from(c.getContext("2d").getImageData(0, 0, c.width, c.height).data);
      const differ = (a, b) => a.length === b.length && a.some((v, i) => Math.abs(v - b[i]) > 24);
      const rows = [...document.querySelectorAll("#bake-off-table tbody tr")].map((tr) => {
        const [rot, trans] = [...tr.querySelectorAll("td.candidate canvas")].map(data);
        return { part: tr.dataset.part, differ: rot && trans ? differ(rot, trans) : false,
          winners: tr.querySelectorAll("td.winner").length, text: tr.textContent };
      });
      const [seeds, fitted] = ["moved-seeds", "moved-fitted"].map((id) => document.getElementById(id));
      // Pixels of the axis colours (orange hinge, blue slide) drawn over the fitted joints' picture.
      const px = data(fitted), near = (i, c) => c.every((v, k) => Math.abs(px[i + k] - v) < 30);
      let axisPixels = 0;
      for (let i = 0; i < px.length; i += 4) axisPixels += near(i, [0xe8, 0x71, 0x0a]) || near(i, [0x1a, 0x73, 0xe8]);
      return { rows, axisPixels, axes: document.body.dataset.movedAxes,
        moved: seeds.width > 1 && fitted.width > 1 && differ(data(seeds), data(fitted)),
        timeline: [...document.querySelectorAll("#stages li")].map((li) => `${li.dataset.stage}: ${li.querySelector(".when").textContent}`) };
    });
    check(shots.moved, "the articulation preview changes: the start mesh moved by the seeds, then by the fitted joints");
    check(shots.axes === "2" && shots.axisPixels > 50,
      `the fitted joints' picture draws both moved parts' axes (${shots.axes} axes, ${shots.axisPixels} axis-coloured pixels)`);
    check(shots.rows.length === 2, `the bake-off panel has a row per movable part (${shots.rows.length} of 2)`);
    for (const r of shots.rows) {
      check(r.differ && r.winners === 1, `part ${r.part}'s bake-off: two candidates that differ, one winner (${r.text.trim()})`);
    }
    check(shots.timeline.every((t) => /took/.test(t)), `every phase on the timeline says how long it took (${shots.timeline.join("; ")})`);
  };

  // 3. the page's demo ---------------------------------------------------------------------
  await step("browser demo", async () => {
    // At 1280 px, the width the README's screenshots (mid-articulation, result) are taken at.
    await page.setViewportSize({ width: 1280, height: 1100 });
    const def = await page.evaluate(() => window.artmeshCatalogue?.default ?? null);
    const category = def?.category ?? (await page.inputValue("#demo-category"));
    const nativeS = native(["demo", "--preset", demoPreset, "--category", category, "--parts", "2", "--seed", "0",
      "--out", join(work, "native-demo")]);
    console.log(`native demo (${category}, 2 parts, ${demoPreset}): ${nativeS.toFixed(1)} s`);

    await page.selectOption("#demo-category", category);
    await page.fill("#demo-parts", "2");
    await page.selectOption("#demo-preset", demoPreset);
    await page.fill("#demo-seed", "0");
    await clearFlags("result", "fit", "preview", "demo", "moved", "bakeOffs");
    const estimate = await readEstimate(page, true);
    const t0 = performance.now();
    await page.click("#demo-run");
    const stopEta = sampleEta(page);
    await midFit();
    await page.waitForFunction(() => {
      const d = document.body.dataset;
      return d.result === "ready" || d.demo === "error" || ["error", "cancelled"].includes(d.fit) || d.state === "panic";
    }, null, { timeout: demoMinutes * 60_000, polling: 500 });
    const browserS = (performance.now() - t0) / 1000;
    const state = await body();
    if (!check(state.result === "ready", `browser demo finished (result=${state.result}, fit=${state.fit}, demo=${state.demo}` +
      `${state.fitError ? ", " + state.fitError : ""})`)) return;
    console.log(`browser demo (${demoPreset}): ${browserS.toFixed(1)} s`);
    console.log(`demo timing: native ${nativeS.toFixed(1)} s, browser ${browserS.toFixed(1)} s` +
      ` (${category}, 2 parts, seed 0, ${demoPreset}; native laptop 1 part: ${nativeLaptopS?.toFixed(1) ?? "—"} s)`);
    await checkTimes({ page, check, name: `the ${demoPreset} demo`, estimate, samples: await stopEta() });
    await checkDemoScore({ page, check, preset: demoPreset });
    const visible = await page.locator("#metrics").isVisible();
    const rows = await page.locator("#metrics tbody tr").count();
    check(visible && rows >= 3, `metrics table shown with ${rows} rows`);
    await checkFinishedPanel({ page, check });
    await checkNoWarnings({ page, check, what: `the ${demoPreset} demo` });
    await checkResultWidth({ page, check });
    await articulationPictures();
    await accessibility("the result view");
    await page.screenshot({ path: artefacts + "web-result.png", fullPage: true });
    await page.locator("#result").screenshot({ path: artefacts + "web-result-section.png" });
    await page.setViewportSize({ width: 1000, height: 1100 });
  });

  // 4. a slider moves a part ---------------------------------------------------------------
  await step("joint slider", async () => {
    const viewer = page.locator("#viewer");
    await viewer.scrollIntoViewIfNeeded();
    await page.waitForTimeout(500);
    const a = await viewer.screenshot();
    const moved = await page.evaluate(() => {
      const el = document.getElementById("joint-0");
      if (!el) return null;
      const from = Number(el.value);
      // The end of the range farther from the current value (its max unless it already sits there).
      el.value = Math.abs(Number(el.max) - from) >= Math.abs(Number(el.min) - from) ? el.max : el.min;
      el.dispatchEvent(new Event("input", { bubbles: true }));
      el.dispatchEvent(new Event("change", { bubbles: true }));
      return { from, to: Number(el.value), label: el.labels?.[0]?.textContent ?? "" };
    });
    if (!check(moved !== null, "slider #joint-0 exists")) return;
    await page.waitForTimeout(500);
    const b = await viewer.screenshot();
    await writeFile(artefacts + "web-viewer-a.png", a);
    await writeFile(artefacts + "web-viewer-b.png", b);
    check(!a.equals(b), `moving #joint-0 from ${moved.from} to ${moved.to} changes the view (${moved.label})`);
    await checkSliderKeys({ page, check });
  });

  // 4b. true and fitted axes, read off the viewer's pixels ---------------------------------
  await step("true and fitted axes", async () => {
    const toggle = async (id, on) => {
      await page.evaluate(([id, on]) => {
        const el = document.getElementById(id);
        el.checked = on;
        el.dispatchEvent(new Event("change", { bubbles: true }));
      }, [id, on]);
      await page.waitForTimeout(700);
    };
    if (!check(await page.locator("#show-truth-label").isVisible(), "the true-axes toggle is offered for the demo")) return;
    await toggle("show-axes", true);
    await toggle("show-truth", true);
    const both = await snapshot(page);
    await toggle("show-truth", false);
    const fitted = await snapshot(page);
    await toggle("show-axes", false);
    const none = await snapshot(page);
    await toggle("show-axes", true);
    await toggle("show-truth", true);
    // Pixels that change when a set of axes goes: dark ones for the truth, coloured ones for the fit.
    const dark = await changed(page, both, fitted, { threshold: 60, alpha: false, darkBelow: 70 });
    const coloured = await changed(page, fitted, none, { threshold: 60, alpha: false, colourAbove: 80 });
    check(dark > 30, `the true axes are drawn, in black (${dark} dark pixels go with them)`);
    check(coloured > 30, `the fitted axes are drawn, in colour (${coloured} coloured pixels go with them)`);
  });
  await step("result viewer", () => checkResultViewer({ page, check, artefacts }));
  await step("phone width and touch", () => checkMobileAndTouch({ page, browser, url, check, native, work, artefacts }));

  // 5. downloads ---------------------------------------------------------------------------
  await step("downloads", async () => {
    const saved = {};
    for (const [id, name] of [["#download-glb", "twin.glb"], ["#download-zip", "twin.zip"],
      ["#download-joints", "joints.json"], ["#download-report", "report.json"],
      ["#download-preview", "preview.png"]]) {
      const [dl] = await Promise.all([page.waitForEvent("download", { timeout: 30_000 }), page.click(id)]);
      const path = join(work, "download-" + name);
      await dl.saveAs(path);
      saved[name] = path;
      check(dl.suggestedFilename() === name, `${id} downloads ${dl.suggestedFilename()}`);
    }
    const png = new Uint8Array(await readFile(saved["preview.png"]));
    const shown = await page.$eval("#preview", (img) => [img.closest("figure").hidden, img.naturalWidth, img.naturalHeight]);
    check(png[1] === 0x50 && png[2] === 0x4e && png[3] === 0x47 && !shown[0] && shown[1] > shown[2],
      `preview.png (${png.length} bytes) is shown under the viewer, ${shown[1]}×${shown[2]}`);
    const glb = new Uint8Array(await readFile(saved["twin.glb"]));
    const report = await validator.validateBytes(glb, {
      maxIssues: 1000,
      externalResourceFunction: (uri) => Promise.reject(new Error(`external resource ${uri}`)),
    });
    const issues = report.issues;
    const errors = issues.messages.filter((m) => m.severity === 0).slice(0, 5)
      .map((m) => `${m.code} at ${m.pointer ?? "-"}: ${m.message}`);
    check(issues.numErrors === 0, `twin.glb (${glb.length} bytes) passes the glTF validator: ${issues.numErrors} errors, ` +
      `${issues.numWarnings} warnings${errors.length ? " — " + errors.join("; ") : ""}`);

    const py = [
      "import json, sys, zipfile",
      "z = zipfile.ZipFile(sys.argv[1])",
      "names = z.namelist()",
      "urdf = [n for n in names if n.endswith('.urdf')]",
      "print(json.dumps({'names': names, 'urdf': z.read(urdf[0]).decode('utf-8', 'replace') if urdf else ''}))",
    ].join("\n");
    const zip = JSON.parse(execFileSync("python3", ["-c", py, saved["twin.zip"]], { encoding: "utf8" }));
    // The archive holds one folder named after the object: <name>/twin.urdf, <name>/meshes/…
    const entry = zip.names.find((n) => /^[^/]+\/twin\.urdf$/.test(n));
    check(Boolean(entry), `twin.zip holds ${entry ?? "no <folder>/twin.urdf"} (${zip.names.length} entries)`);
    const limits = zip.urdf.match(/<limit\s[^>]*>/g) ?? [];
    check(limits.some((l) => /\blower\s*=/.test(l) && /\bupper\s*=/.test(l)),
      `the URDF has joint limits: ${limits[0] ?? "none"}`);
    const joints = JSON.parse(await readFile(saved["joints.json"], "utf8"));
    const count = Number((await body()).jointCount);
    check(Array.isArray(joints) && joints.length === count, `joints.json lists ${joints.length} joints (sliders: ${count})`);
    const rep = JSON.parse(await readFile(saved["report.json"], "utf8"));
    check(rep && typeof rep === "object", `report.json parses (${Object.keys(rep).length} fields)`);
    await checkJointsTable({ page, check, report: rep });
    const trueRows = await page.locator("#joints-table tr.truth").count();
    check(trueRows === (rep.metrics?.joints ?? []).length && (rep.truth ?? []).length > 0,
      `each fitted joint has its true joint under it (${trueRows} rows; report.json's truth: ${(rep.truth ?? []).length})`);
  });

  // 6. malformed datasets ------------------------------------------------------------------
  await step("malformed dataset", async () => {
    const good = join(work, "good"), broken = join(work, "broken");
    native(["sample", "--out", good, "--width", "24", "--height", "16", "--views", "3"]);
    // Loaded with the keyboard alone: Tab from the top of the page to the folder picker, Enter opens
    // the browser's chooser (the one step that is the operating system's), the dataset loads.
    await clearFlags("dataset");
    await page.evaluate(() => { document.activeElement?.blur(); window.scrollTo(0, 0); });
    let presses = 0, focused = null;
    while (presses < 80 && focused !== "folder") {
      await page.keyboard.press("Tab");
      presses++;
      focused = await page.evaluate(() => document.activeElement?.id ?? null);
    }
    check(focused === "folder", `Tab reaches the folder picker (${presses} presses)`);
    const [chooser] = await Promise.all([page.waitForEvent("filechooser", { timeout: 10_000 }), page.keyboard.press("Enter")]);
    await chooser.setFiles(good);
    await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 60_000 });
    const goodText = await page.locator("#dataset-result").textContent();
    check((await body()).dataset === "ok", `sample dataset loaded with the keyboard alone: ${goodText.split("\n")[0]}`);

    await cp(good, broken, { recursive: true });
    const png = join(broken, "end", "train", "rgba", "0001.png");
    await writeFile(png, (await readFile(png)).subarray(0, 40));
    await clearFlags("dataset");
    await page.setInputFiles("#folder", broken);
    await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 60_000 });
    let text = await page.locator("#dataset-result").textContent();
    check((await body()).dataset === "problems" && text.includes("end/train/rgba/0001.png"),
      `truncated PNG in a folder reported by name: ${text.split("\n")[1] ?? text}`);

    const zipPath = join(work, "broken.zip");
    const py = [
      "import os, sys, zipfile",
      "root, out = sys.argv[1], sys.argv[2]",
      "with zipfile.ZipFile(out, 'w', zipfile.ZIP_DEFLATED) as z:",
      "    for d, _, files in sorted(os.walk(root)):",
      "        for f in sorted(files):",
      "            p = os.path.join(d, f)",
      "            z.write(p, 'broken/' + os.path.relpath(p, root).replace(os.sep, '/'))",
    ].join("\n");
    execFileSync("python3", ["-c", py, broken, zipPath], { stdio: ["ignore", "ignore", "inherit"] });
    const bytes = await readFile(zipPath);
    await clearFlags("dataset");
    await page.evaluate(() => { document.getElementById("dataset-result").textContent = ""; });
    const dt = await page.evaluateHandle((data) => {
      const transfer = new DataTransfer();
      transfer.items.add(new File([new Uint8Array(data)], "broken.zip", { type: "application/zip" }));
      return transfer;
    }, [...bytes]);
    await page.dispatchEvent("#dropzone", "drop", { dataTransfer: dt });
    await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 60_000 });
    text = await page.locator("#dataset-result").textContent();
    check((await body()).dataset === "problems" && text.includes("end/train/rgba/0001.png"),
      `truncated PNG in a dropped .zip (${bytes.length} bytes) reported by name: ${text.split("\n")[1] ?? text}`);
    await page.screenshot({ path: artefacts + "web-dataset-error.png", fullPage: true });
  });

  await step("budgets", async () => {
    // 1.2 GB of zeros in gt/ (read whole, so needed) packed into 5 MB: past the page's 1 GiB.
    const bomb = join(work, "bomb.zip");
    const py = [
      "import sys, zipfile",
      "zeros = bytes(1 << 20)",
      "with zipfile.ZipFile(sys.argv[1], 'w', zipfile.ZIP_DEFLATED, compresslevel=1) as z:",
      "    z.writestr('bomb/transforms_train_start.json', '{}')",
      "    for i in range(12):",
      "        with z.open(f'bomb/gt/zeros{i}.bin', 'w') as f:",
      "            for _ in range(100): f.write(zeros)",
    ].join("\n");
    execFileSync("python3", ["-c", py, bomb], { stdio: ["ignore", "ignore", "inherit"] });
    await clearFlags("dataset");
    const t0 = performance.now();
    await page.setInputFiles("#zipfile", bomb);
    await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 60_000 });
    const text = await page.locator("#dataset-result").textContent();
    check((await body()).dataset === "problems" && text.includes("bomb.zip") && text.includes("over the budget"),
      `a zip bomb is refused in ${((performance.now() - t0) / 1000).toFixed(1)} s: ${text}`);

    // The sample dataset beside a sparse 4 GB recording, which must not be read.
    const big = join(work, "beside-4gb");
    await cp(join(work, "good"), big, { recursive: true });
    await writeFile(join(big, "capture.mp4"), "");
    await truncate(join(big, "capture.mp4"), 4 * 2 ** 30);
    await page.evaluate(() => {
      window.artmeshRead = [];
      const read = Blob.prototype.arrayBuffer;
      Blob.prototype.arrayBuffer = function () { window.artmeshRead.push(this.name); return read.call(this); };
    });
    await clearFlags("dataset");
    await page.setInputFiles("#folder", big);
    await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 60_000 });
    const read = await page.evaluate(() => window.artmeshRead);
    check((await body()).dataset === "ok" && read.length > 0 && !read.includes("capture.mp4"),
      `after the bomb, a dataset beside a 4 GB file loads reading ${read.length} files, not the 4 GB one`);
  });

  await step("zipped URDF", () => checkUrdfZip({ page, check, native, work }));
  await step("shared objects fitted", () => checkSharedObjectFit({ page, check, work, artefacts, preset: demoPreset }));
  // 7. nothing leaves the page -------------------------------------------------------------
  await step("offline", async () => {
    const foreign = requests.filter((r) => /^https?:/i.test(r) && !r.startsWith(url));
    check(foreign.length === 0, `no requests beyond the page's own files (${foreign.join(", ") || "none"})`);
    check(pageErrors.length === 0, `no uncaught errors in the page (${pageErrors.join(" | ") || "none"})`);
    const banner = await page.locator("#error").isVisible();
    check(!banner, `no error banner at the end${banner ? ": " + (await page.locator("#error-text").textContent()) : ""}`);
  });

  // 8. the --dist folder: refuses to replace files; reopens from its service worker, host gone -
  await step("dist folder", async () => {
    // --dist never replaces files: a folder with something in it is refused before any build.
    const full = join(work, "full-folder");
    await mkdir(full);
    await writeFile(join(full, "keep.txt"), "mine");
    let refused = false;
    try {
      execFileSync("bash", [fileURLToPath(new URL("../build.sh", import.meta.url)), "--dist", full], { stdio: "pipe" });
    } catch (e) {
      refused = String(e.stderr).includes("not an empty folder");
    }
    check(refused && (await readFile(join(full, "keep.txt"), "utf8")) === "mine",
      "web/build.sh --dist refuses a folder that has files in it and leaves them as they were");
    await page.evaluate(() => navigator.serviceWorker.ready);
    const isDist = await readFile(join(webRoot, "build.json")).then(() => true, () => false);
    if (!isDist) { note("web/ itself is served (no build.json): reopening offline is checked on a --dist folder"); return; }
    // The host goes away (emulated offline would not reach the service worker's own fetches).
    server.close();
    server.closeAllConnections();
    await page.reload();
    await page.waitForFunction(() => document.body.dataset.state !== "loading", null, { timeout: 300_000 });
    const state = await body();
    check(state.state === "done", `with the host gone the page reopens from its service worker and starts (state=${state.state})`);
  });
} finally {
  await browser.close();
  if (server.listening) server.close();
}
console.log("step timings: " + timings.map(([n, s]) => `${n} ${s.toFixed(1)} s`).join(", "));
console.log(`page: ${passed} passed, ${failed} failed`);
process.exit(failed === 0 && passed > 0 ? 0 : 1);
