// The page's "bring your own object" check, called once from page.mjs: a zipped URDF with its
// meshes (`artmesh synth --object-only`, zipped here) picked as a .zip is photographed on the
// page's GPU and offered like a dataset (thumbnails, the fit button on); the same zip with a mesh
// left out, dropped on the zone, is refused inline naming the mesh and the URDF. No fit is run:
// the capture is the new part, the fit is the one the rest of page.mjs checks.
import { execFileSync } from "node:child_process";
import { existsSync, readdirSync, readFileSync, writeFileSync } from "node:fs";
import { fileURLToPath } from "node:url";
import { join } from "node:path";
import { lastReport } from "./result.mjs";
import { checkTimes, readEstimate, sampleEta } from "./timing.mjs";

// Zips `root` under `folder/`: the files and folders named after `skip` (relative to `root`; all of
// it when none are named), leaving out the one path `skip`.
const ZIP_PY = [
  "import os, sys, zipfile",
  "root, out, folder, skip = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]",
  "with zipfile.ZipFile(out, 'w', zipfile.ZIP_DEFLATED) as z:",
  "    for top in [os.path.join(root, r) for r in sys.argv[5:] or ['.']]:",
  "        paths = [os.path.join(d, f) for d, _, fs in os.walk(top) for f in fs] if os.path.isdir(top) else [top]",
  "        for p in sorted(paths):",
  "            rel = os.path.relpath(p, root).replace(os.sep, '/')",
  "            if rel != skip: z.write(p, folder + '/' + rel)",
].join("\n");

/** Zips `root` into `path` under `folder/` with ZIP_PY: `only` its paths (all when empty), less `skip`. */
function zipFolder(root, path, folder, { skip = "", only = [] } = {}) {
  execFileSync("python3", ["-c", ZIP_PY, root, path, folder, skip, ...only], { stdio: ["ignore", "ignore", "inherit"] });
  return path;
}

/** Runs the check on `page` (the page loaded, no GPU job running); `check(ok, what)` records,
 *  `native(args)` runs the CLI, `work` is a scratch folder. */
export async function checkUrdfZip({ page, check, native, work }) {
  const out = join(work, "urdf-object");
  native(["synth", "--category", "laptop", "--parts", "1", "--seed", "3", "--object-only", "--out", out]);
  const root = join(out, "object");
  const urdf = readdirSync(root).find((f) => f.endsWith(".urdf"));
  // A mesh the URDF refers to (meshes/ also holds .mtl files and textures).
  const mesh = readFileSync(join(root, urdf), "utf8").match(/filename="([^"]+\.obj)"/)?.[1];
  if (!check(Boolean(mesh), `the synthesised URDF refers to a mesh (${mesh})`)) return;
  const zip = (name, skip) => zipFolder(root, join(work, name), "laptop", { skip });
  const good = zip("laptop-urdf.zip", ""), broken = zip("laptop-no-mesh.zip", mesh);
  const flags = () => page.evaluate(() => ({ ...document.body.dataset }));
  const reset = () => page.evaluate(() => {
    delete document.body.dataset.dataset;
    delete document.body.dataset.captureSeconds;
  });
  // The smallest capture: the software adapter's tiny preset.
  await page.evaluate(() => {
    const select = document.getElementById("fit-preset");
    select.value = "tiny";
    select.dispatchEvent(new Event("change"));
  });

  // A mesh missing, dropped on the zone: refused inline, naming the mesh and the URDF.
  await reset();
  const bytes = [...readFileSync(broken)];
  const dt = await page.evaluateHandle((data) => {
    const transfer = new DataTransfer();
    transfer.items.add(new File([new Uint8Array(data)], "laptop-no-mesh.zip", { type: "application/zip" }));
    return transfer;
  }, bytes);
  await page.dispatchEvent("#dropzone", "drop", { dataTransfer: dt });
  await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 60_000 });
  let text = await page.locator("#dataset-result").textContent();
  check((await flags()).dataset === "problems" && text.includes(`laptop/${mesh}`) &&
    text.includes(`laptop/${urdf}`) && text.includes("laptop-no-mesh.zip"),
  `a zipped URDF missing a mesh is refused inline, naming both: ${text}`);

  // The whole object, picked as a .zip: photographed, then shown like a dataset.
  await reset();
  await page.setInputFiles("#zipfile", good);
  await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 120_000 });
  const state = await flags();
  text = await page.locator("#dataset-result").textContent();
  if (!check(state.dataset === "ok", `a zipped URDF is photographed and accepted in ${state.captureSeconds} s: ` +
    text.split("\n").slice(0, 2).join(" | "))) return;
  const thumbs = await page.locator("#thumbs canvas").count();
  check(thumbs >= 2, `the object's thumbnails are shown (${thumbs})`);
  check(await page.isEnabled("#fit-run"), "the fit button is on for the captured object");
  console.log(`note zipped URDF capture (tiny): ${state.captureSeconds} s`);
}

/** Objects authored outside this project (`../shared/objects`), each zipped as a user would with
 *  one URDF and its meshes: the archive's folder, and the files in it (relative to `dir`). */
const SHARED_OBJECTS = [
  // habitat-sim's fridge: two hinged doors, textured GLB meshes (MIT). Its folder also holds
  // fridge_static.urdf (a malformed scale) and fridge_scaled.urdf: one URDF goes in.
  { name: "fridge", dir: "habitat/fridge", files: ["fridge.urdf", "body.glb", "top_door.glb", "bottom_door.glb"] },
  // habitat-sim's kitchen counter: seven drawers (6+ movable parts), GLB meshes (MIT).
  { name: "kitchen_counter", dir: "habitat/kitchen_counter", files: ["kitchen_counter.urdf", "kitchen_counter.glb",
    "drawer1.glb", "drawer2.glb", "drawer3.glb", "drawer4.glb"] },
  // IsaacGymEnvs' IKEA-style cabinet: two doors (each behind a 1.5 cm slide), two drawers, OBJ
  // meshes found through package:// and package.xml (BSD-3).
  { name: "sektion", dir: "sektion", files: ["package.xml", "urdf/sektion_cabinet.urdf", "meshes"] },
];
// Kept aside: nothing here was tuned on them (ARTMESH_SHARED_OBJECTS=cabinet,doubledoor picks them).
const HELD_OUT = [
  // habitat-sim's cabinet: two sliding doors (MIT).
  { name: "cabinet", dir: "habitat/cabinet", files: ["cabinet.urdf", "cabinet.glb", "door.glb"] },
  // habitat-sim's double door: two hinged leaves (MIT).
  { name: "doubledoor", dir: "habitat/doors", files: ["doubledoor.urdf", "double_door_L.glb", "double_door_R.glb"] },
];
// ARTMESH_SHARED_OBJECTS: the objects to fit, by name (default: SHARED_OBJECTS).
const chosen = process.env.ARTMESH_SHARED_OBJECTS?.split(",").map((n) => n.trim());
const objects = chosen ? [...SHARED_OBJECTS, ...HELD_OUT].filter((o) => chosen.includes(o.name)) : SHARED_OBJECTS;

/** What the page must give on a dropped object, per preset (issue 47): every type right, the mean
 *  Axis Ang over the objects within `meanAxisDeg`, each fit within `fitSeconds` (on a 2-core machine's
 *  SwiftShader; checked with ARTMESH_PAGE_TIMED=1, printed always). */
const SHARED_BOUNDS = {
  tiny: { meanAxisDeg: 2, fitSeconds: 120 },
  fast: { meanAxisDeg: 1, fitSeconds: Infinity },
};
// ARTMESH_PAGE_TIMED=1: hold each fit to `fitSeconds` too.
const timed = process.env.ARTMESH_PAGE_TIMED === "1";

/** Zips `object` (one of `SHARED_OBJECTS`) from `root` into `work`; the archive's path. */
function zipShared(object, root, work) {
  return zipFolder(join(root, object.dir), join(work, `${object.name}.zip`), object.name, { only: object.files });
}

/** The shared objects (`SHARED_OBJECTS`), zipped, picked as a .zip, photographed and fitted at
 *  `preset` in the page, each scored against its URDF's truth and held to `SHARED_BOUNDS`; on the
 *  fridge the true parts overlay the twin (`artefacts/web-urdf-result-truth.png`). */
export async function checkSharedObjectFit({ page, check, work, artefacts, preset }) {
  const root = fileURLToPath(new URL("../../../shared/objects", import.meta.url));
  if (!check(existsSync(root), `the shared objects are there (${root})`)) return;
  const bounds = SHARED_BOUNDS[preset] ?? SHARED_BOUNDS.fast;
  const axes = [];
  for (const object of objects) {
    const scored = await fitShared({ page, check, object, zipPath: zipShared(object, root, work), preset, work });
    if (!scored) continue;
    const { joints, seconds, warnings } = scored;
    check(joints.length > 0 && joints.every((j) => j.type_correct),
      `${object.name} (${preset}): every type right (${joints.map((j) => `${j.gt_kind}→${j.pred_kind}`).join(", ")})`);
    // Times are reported, and held to the bound only when asked (ARTMESH_PAGE_TIMED=1): a CI machine's
    // speed varies 2-3× between runs, and performance is measured by benchmarks, not by timed tests.
    if (timed) check(seconds <= bounds.fitSeconds, `${object.name} (${preset}) fitted in ${seconds.toFixed(1)} s (at most ${bounds.fitSeconds} s)`);
    axes.push(joints.reduce((a, j) => a + j.axis_ang, 0) / joints.length);
    console.log(`note ${object.name} (${preset}): ${seconds.toFixed(1)} s, Axis Ang ` +
      joints.map((j) => j.axis_ang.toFixed(2) + "°").join(" ") + `; warnings: ${warnings.join(" | ") || "none"}`);
    if (object.name === "fridge") await checkTruthOverlay({ page, check, artefacts });
    if (scored.trained) {
      checkArticulationPlot(check, object.name, scored.plot);
      await page.locator("#fit").screenshot({ path: artefacts + `web-urdf-${object.name}-fit.png` });
    }
  }
  const mean = axes.reduce((a, x) => a + x, 0) / Math.max(axes.length, 1);
  check(axes.length === objects.length && axes.length > 0 && mean <= bounds.meanAxisDeg,
    `the ${axes.length} shared objects' mean Axis Ang at ${preset} is ${mean.toFixed(2)}° (at most ${bounds.meanAxisDeg}°)`);
}

/** Drops `zipPath` on the page, photographs and fits it at `preset`; its scored joints (report.json's
 *  metrics, the whole report written to `work`/<name>-report.json), warnings and the fit's seconds,
 *  or null (after a failed check). */
async function fitShared({ page, check, object, zipPath, preset, work }) {
  await page.evaluate((p) => {
    for (const n of ["dataset", "fit", "result", "preview"]) delete document.body.dataset[n];
    delete window.artmeshLast;
    const select = document.getElementById("fit-preset");
    select.value = p;
    select.dispatchEvent(new Event("change"));
  }, preset);
  await page.setInputFiles("#zipfile", zipPath);
  await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 120_000 });
  const text = await page.locator("#dataset-result").textContent();
  if (!check((await page.evaluate(() => document.body.dataset.dataset)) === "ok",
    `${object.name} (zipped URDF) is photographed: ${text.split("\n")[0]}`)) return null;
  const estimate = await readEstimate(page, false);
  const t0 = performance.now();
  await page.click("#fit-run");
  const stopEta = sampleEta(page);
  await page.waitForFunction(() => ["done", "error", "cancelled"].includes(document.body.dataset.fit) ||
    document.body.dataset.state === "panic", null, { timeout: 600_000, polling: 500 });
  const seconds = (performance.now() - t0) / 1000;
  const samples = await stopEta();
  const fit = await page.evaluate(() => ({ ...document.body.dataset }));
  if (!check(fit.fit === "done", `${object.name} is fitted in the page in ${seconds.toFixed(1)} s ` +
    `(fit=${fit.fit}${fit.fitError ? ": " + fit.fitError : ""})`)) return null;
  await page.waitForFunction(() => document.body.dataset.result === "ready", null, { timeout: 120_000 });
  const report = await lastReport(page);
  writeFileSync(join(work, `${object.name}-report.json`), JSON.stringify(report ?? null));
  const plot = await page.evaluate(() => ({ series: document.body.dataset.plotSeries, marks: document.body.dataset.plotMarks }));
  // The photometric stages ran: the articulation's curve has points.
  const trained = (report?.articulation?.curve ?? []).length > 0;
  await checkTimes({ page, check, name: `${object.name} (${preset})`, estimate, samples, open: trained });
  return { joints: report?.metrics?.joints ?? [], seconds, warnings: report?.warnings ?? [], plot, trained };
}

/** The fitted object's result: scored in the metrics table, and the true-parts toggle changes
 *  the viewer's picture. Writes `artefacts/web-urdf-result-truth.png`. */
async function checkTruthOverlay({ page, check, artefacts }) {
  const metrics = await page.locator("#metrics tbody tr").allTextContents();
  check(await page.locator("#metrics-box").isVisible() && metrics.length > 0,
    `the fit is scored against the URDF's truth (${metrics.map((m) => m.replace(/\s+/g, " ").trim()).slice(0, 3).join("; ")})`);
  if (!check(await page.locator("#show-truth-parts-label").isVisible(), "the true-parts toggle is offered for the URDF")) return;
  const shot = async () => {
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    await page.waitForTimeout(500);
    return page.locator("#viewer").screenshot();
  };
  const before = await shot();
  await page.check("#show-truth-parts");
  const after = await shot();
  check(!before.equals(after), "the true parts overlay the fitted fridge (the viewer's picture changes)");
  await page.locator("#result").screenshot({ path: artefacts + "web-urdf-result-truth.png" });
  await page.uncheck("#show-truth-parts");
}

/** Where the photometric stages ran, the articulation plot shows the hinge and the slide candidates as
 *  two series and the refinement as a third, and marks where the bake-off and the refinement began
 *  (issue 47: a student can read it). */
function checkArticulationPlot(check, name, plot) {
  const counts = Object.fromEntries((plot.series ?? "").split(",").map((e) => e.split(":")).map(([k, n]) => [k, Number(n)]));
  const marks = (plot.marks ?? "").split(",");
  check(counts.hinge > 0 && counts.slide > 0 && counts.refine > 0 &&
    ["candidates", "bake-off", "refinement"].every((m) => marks.includes(m)),
  `${name}: the articulation plot has hinge, slide and refinement series (${plot.series}) and marks each stage (${plot.marks})`);
}
