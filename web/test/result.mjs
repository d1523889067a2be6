// Browser checks of the Result viewer's teaching aids, called by page.mjs once a demo result is
// shown: the play button (aria-pressed, keyboard, the picture moves while playing and holds when
// paused, a slider or a state stops it), the part-colour legend (one entry per part, distinct
// colours, the wasm palette's, found in the picture), the true parts' overlay (changes the
// picture, and off restores it) and the opening view's score; no console errors meanwhile. Also the
// page demo's score against its ground truth, for a demo at a hardware adapter's preset, and the fit
// panel at the end.
import { writeFile } from "node:fs/promises";
import { changed, settle, snapshot } from "./canvas.mjs";

const pressed = (page) => page.getAttribute("#play", "aria-pressed");

const hex = (h) => [1, 3, 5].map((i) => parseInt(h.slice(i, i + 2), 16));

/** Per colour (RGB bytes), the lit pixels of snapshot `id` with its channel ratios (what shading
 * leaves alone), counted in the page. */
const pixelsOfColours = (page, id, colours) => page.evaluate(([id, colours]) => {
  const linear = (v) => { const s = v / 255; return s <= 0.04045 ? s / 12.92 : ((s + 0.055) / 1.055) ** 2.4; };
  const ratios = (rgb) => { const l = rgb.map(linear); const m = Math.max(...l, 1e-6); return l.map((x) => x / m); };
  const image = window.__viewerSnaps[id];
  return colours.map((rgb) => {
    const want = ratios(rgb);
    let n = 0;
    for (let i = 0; i < image.length; i += 4) {
      if (image[i + 3] !== 255) continue;
      const got = ratios([image[i], image[i + 1], image[i + 2]]);
      if (got.every((x, c) => Math.abs(x - want[c]) < 0.08)) n++;
    }
    return n;
  });
}, [id, colours]);

async function checkPlay(page, check) {
  if (!check(await page.locator("#play").isVisible(), "the play button is shown")) return;
  if ((await pressed(page)) === "true") await page.click("#play"); // autoplay (hardware adapters)
  check((await pressed(page)) === "false", `the motion is paused before play (aria-pressed=${await pressed(page)})`);
  const before = (await settle(page)).image;
  const slider0 = await page.inputValue("#joint-0");
  await page.focus("#play");
  await page.keyboard.press("Enter");
  check((await pressed(page)) === "true", "Enter on the focused play button starts the motion (aria-pressed=true)");
  // The picture keeps changing while playing: two reads a while apart differ, twice over.
  let moving = 0, frames = [];
  let previous = before;
  for (let i = 0; i < 8 && moving < 2; i++) {
    await page.waitForTimeout(700);
    const now = await snapshot(page);
    const diff = await changed(page, previous, now);
    if (diff > 50) { moving++; frames.push(diff); }
    previous = now;
  }
  check(moving >= 2, `the picture moves while playing (${frames.join(", ") || "no"} pixels changed between reads)`);
  check((await page.inputValue("#joint-0")) !== slider0, "the sliders follow the motion");
  await page.keyboard.press("Space");
  check((await pressed(page)) === "false", "Space pauses the motion (aria-pressed=false)");
  const still = await settle(page);
  check(still.diff === 0, `the picture holds still once paused (${still.diff} pixels still changing)`);

  await page.click("#play");
  await page.waitForTimeout(300);
  await page.evaluate(() => {
    const el = document.getElementById("joint-0");
    el.value = el.min;
    el.dispatchEvent(new Event("input", { bubbles: true }));
  });
  check((await pressed(page)) === "false", "moving a slider stops the motion");
  await page.click("#play");
  await page.waitForTimeout(300);
  await page.click("#state-end");
  check((await pressed(page)) === "false", "picking a state stops the motion");
  await settle(page);
}

async function checkLegend(page, check, artefacts) {
  await page.evaluate(() => {
    const el = document.getElementById("colour-by-part");
    el.checked = true;
    el.dispatchEvent(new Event("change", { bubbles: true }));
  });
  const image = (await settle(page)).image;
  const legend = await page.$$eval("#part-legend li", (items) => items.map((li) => ({
    part: Number(li.dataset.part), colour: li.dataset.colour, name: li.textContent.trim(),
    swatch: getComputedStyle(li.querySelector(".swatch")).backgroundColor,
  })));
  const joints = Number(await page.evaluate(() => document.body.dataset.jointCount));
  check(await page.locator("#part-legend").isVisible(), "the legend shows while colouring by part");
  check(legend.length === joints + 1, `the legend has one entry per part (${legend.length}: ` +
    `${legend.map((e) => `${e.name} ${e.colour}`).join(", ")}; ${joints} joints)`);
  check(new Set(legend.map((e) => e.colour)).size === legend.length, "the legend's colours are distinct");
  const palette = await page.evaluate(async () => Array.from((await import("./pkg/artmesh.js")).part_colours()));
  const same = legend.every((e) => e.colour === palette[e.part % palette.length] &&
    e.swatch === `rgb(${hex(e.colour).join(", ")})`);
  check(palette.length > 0 && same, `the swatches are wasm's part_colours() (${palette.join(" ")})`);
  // Each part's colour is in the picture: lit pixels keep a colour's channel ratios.
  const found = await pixelsOfColours(page, image, legend.map((e) => hex(e.colour)));
  check(found.every((n) => n >= 5), `every legend colour is drawn on the canvas (pixels per part: ${found.join(", ")})`);
  await page.locator("#result").screenshot({ path: artefacts + "web-result-legend.png" });
  await page.evaluate(() => {
    const el = document.getElementById("colour-by-part");
    el.checked = false;
    el.dispatchEvent(new Event("change", { bubbles: true }));
  });
  check(!(await page.locator("#part-legend").isVisible()), "the legend hides with colour by part off");
}

async function checkTruthParts(page, check, artefacts) {
  if (!check(await page.locator("#show-truth-parts-label").isVisible(), "the true-parts toggle is offered for the demo")) return;
  const toggle = (on) => page.evaluate((on) => {
    const el = document.getElementById("show-truth-parts");
    el.checked = on;
    el.dispatchEvent(new Event("change", { bubbles: true }));
  }, on);
  const off = (await settle(page)).image;
  await toggle(true);
  const on = (await settle(page)).image;
  const diff = await changed(page, off, on);
  check(diff > 100, `showing the true parts changes the picture (${diff} pixels)`);
  await writeFile(artefacts + "web-viewer-truth-parts.png", await page.locator("#viewer").screenshot());
  await toggle(false);
  const back = await changed(page, off, (await settle(page)).image);
  check(back === 0, `hiding them again restores the picture (${back} pixels differ)`);
}

/**
 * The Result viewer's play button, legend and true-parts overlay, on `page` with a result shown;
 * `check(ok, what)` records each result, screenshots go to `artefacts`.
 */
export async function checkResultViewer({ page, check, artefacts }) {
  const errors = [];
  const onConsole = (m) => { if (m.type() === "error") errors.push(m.text()); };
  const onError = (e) => errors.push(e.message);
  page.on("console", onConsole);
  page.on("pageerror", onError);
  try {
    await page.locator("#viewer").scrollIntoViewIfNeeded();
    const view = await page.evaluate(() => ({ ...document.getElementById("viewer").dataset }));
    check(Number(view.openingScore) >= Number(view.openingOldScore),
      `the opening view shows the movable parts at least as well as the old one (smallest visible share ` +
      `${Number(view.openingScore).toFixed(3)} vs ${Number(view.openingOldScore).toFixed(3)}, chosen in ` +
      `${Number(view.openingMs).toFixed(1)} ms)`);
    await checkPlay(page, check);
    await checkLegend(page, check, artefacts);
    await checkTruthParts(page, check, artefacts);
  } finally {
    page.off("console", onConsole);
    page.off("pageerror", onError);
  }
  check(errors.length === 0, `no console errors in the result viewer checks (${errors.join(" | ") || "none"})`);
}

/** The last fit's report.json as the page keeps it (`window.artmeshLast`), parsed; null before one. */
export async function lastReport(page) {
  const last = await page.evaluate(() => window.artmeshLast ?? null);
  return typeof last?.report === "string" ? JSON.parse(last.report) : last?.report ?? null;
}

/** The page demo's joints against its ground truth (report.json's metrics): both types right and
 * every axis within 2°, what a demo at a hardware adapter's preset must give (issue 46). */
export async function checkDemoScore({ page, check, preset }) {
  const report = await lastReport(page);
  const joints = report?.metrics?.joints ?? [];
  check(joints.length === 2 && joints.every((j) => j.type_correct),
    `the ${preset} demo types both joints right (${joints.map((j) => `${j.gt_kind}→${j.pred_kind}`).join(", ")})`);
  check(joints.length > 0 && joints.every((j) => j.axis_ang <= 2),
    `the ${preset} demo's axes are within 2° (${joints.map((j) => j.axis_ang.toFixed(2) + "°").join(", ")})`);
}

/** The fit panel once a fit is done: the stage says finished, the phase done, nothing remains, and
 * the elapsed time is the one the status line's "Done in" gives (issue 47: they agree at the end). */
export async function checkFinishedPanel({ page, check }) {
  const read = (id) => page.locator(`#${id}`).textContent();
  const [stage, phase, eta, elapsed, status] = await Promise.all(
    ["fit-stage", "fit-phase", "fit-eta", "fit-elapsed", "fit-status"].map(read));
  check(stage.startsWith("finished"), `the fit panel says the fit finished (stage: ${stage})`);
  check(phase.startsWith("done"), `the fit panel's phase is done at the end (phase: ${phase})`);
  check(!/about/.test(eta), `no time remaining is shown once the fit is done (remaining: ${eta})`);
  const done = /Done in (.+)\./.exec(status)?.[1];
  check(done != null && elapsed === done, `the elapsed time is the "Done in" time at the end (${elapsed}; ${status})`);
}

/** The three numbers of a "(x, y, z)" cell (and its unit after it), or null. */
const triple = (text) => {
  const m = /\(([^)]*)\)/.exec(text ?? "");
  const v = m?.[1].split(",").map(Number);
  return v?.length === 3 && v.every(Number.isFinite) ? v : null;
};

/** The joints table (issue 47): every error shown is recomputed from the two rows' own shown values
 * within what their rounding allows, agrees with report.json where the definitions are the paper's
 * (axis angle, line distance), and a row of the wrong type says so instead of a number. */
export async function checkJointsTable({ page, check, report }) {
  const rows = await page.$$eval("#joints-table tbody tr[data-joint]", (trs) => trs.map((tr) => ({
    joint: Number(tr.dataset.joint),
    fitted: [...tr.cells].map((c) => c.textContent),
    values: Object.fromEntries([...tr.cells].filter((c) => c.dataset.metric).map((c) => [c.dataset.metric, c.dataset.value])),
    truth: tr.nextElementSibling?.classList.contains("truth") ? [...tr.nextElementSibling.cells].map((c) => c.textContent) : null,
  })));
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const len = (a) => Math.hypot(...a);
  // The angle between two axes either way round (atan2 of the two products: their lengths cancel).
  const deg = (a, b) => (Math.atan2(len(cross(a, b)), Math.abs(dot(a, b))) * 180) / Math.PI;
  const shown = (text) => Number.parseFloat(text);
  let recomputed = 0;
  const problems = [];
  for (const r of rows) {
    const m = (report?.metrics?.joints ?? []).find((x) => x.pred === r.joint);
    if (!r.truth || !m) continue;
    const [, , type, axis, pivot, motion, eAxis, eLine, eMotion] = r.fitted;
    const [, , tType, tAxis, tPivot, tMotion] = r.truth;
    const [d, td] = [triple(axis), triple(tAxis)];
    // Unit vectors shown to 3 decimals: each is off by at most 0.0005·√3 rad; 1-decimal display adds 0.05.
    const axisTol = (2 * 0.0005 * Math.sqrt(3) * 180) / Math.PI + 0.05;
    if (Math.abs(deg(d, td) - shown(eAxis)) > axisTol) problems.push(`joint ${r.joint}: axis error ${eAxis} vs ${deg(d, td).toFixed(2)}°`);
    if (Math.abs(Number(r.values.axis_ang) - m.axis_ang) > 1e-3) problems.push(`joint ${r.joint}: axis error ≠ report's ${m.axis_ang}`);
    recomputed++;
    if (type !== tType) {
      if (!/^wrong type/.test(eLine) || !/^wrong type/.test(eMotion)) problems.push(`joint ${r.joint}: a wrong type shows "${eLine}", "${eMotion}"`);
      continue;
    }
    if (type === "revolute") {
      const [o, to] = [triple(pivot), triple(tPivot)];
      const w = o.map((x, i) => to[i] - x);
      const distance = (a, b) => {
        const n = cross(a, b), sin = len(n) / (len(a) * len(b));
        return sin < 1e-6 ? len(cross(w, a)) / len(a) : Math.abs(dot(w, n)) / len(n);
      };
      // Between nearly parallel lines the distance turns on the directions' last digits, so the shown
      // value must lie among the distances of directions that round to the shown ones (a grid over
      // each component's ±0.0005), give or take the pivots' and its own rounding (0.05 mm each).
      const nudged = (v, k) => v.map((x, c) => x + 0.0005 * (((Math.floor(k / 3 ** c) % 3) - 1)));
      let [lo, hi] = [Infinity, -Infinity];
      for (let a = 0; a < 27; a++) {
        for (let b = 0; b < 27; b++) {
          const dd = distance(nudged(d, a), nudged(td, b));
          [lo, hi] = [Math.min(lo, dd), Math.max(hi, dd)];
        }
      }
      const e = shown(eLine);
      if (e < lo - 0.15 || e > hi + 0.15) problems.push(`joint ${r.joint}: line distance ${eLine} outside ${lo.toFixed(1)}–${hi.toFixed(1)} mm`);
      if (Math.abs(Number(r.values.axis_pos) - m.axis_pos * 100) > 1e-2) problems.push(`joint ${r.joint}: line distance ≠ report's`);
      recomputed++;
    }
    const diff = Math.abs(shown(motion) - shown(tMotion));
    if (Math.abs(diff - shown(eMotion)) > 0.1 + 0.05) problems.push(`joint ${r.joint}: motion error ${eMotion} vs ${diff.toFixed(1)}`);
    if (!(shown(motion) >= 0)) problems.push(`joint ${r.joint}: the fitted motion ${motion} is not positive`);
    recomputed++;
  }
  check(recomputed > 0 && problems.length === 0,
    `the joints table's ${recomputed} errors follow from the rows' shown values (${problems.join("; ") || "all within rounding"})`);
}

/** The built-in demo (a clean capture of our own object, taken as `artmesh demo` takes it) at its
 * preset: no warning (issue 47: it used to warn of parts "not measured" and of no test views, neither
 * true); any that appears is named in the message. */
export async function checkNoWarnings({ page, check, what }) {
  const items = await page.$$eval("#warnings li", (lis) => lis.map((li) => li.textContent));
  check(items.length === 0, `${what}: no warnings (${items.join(" | ") || "none"})`);
}

/** A joint slider's keys step by a unit a reader thinks in (issue 47): 1° for a hinge, 1 mm for a
 * slide (its label's unit), from the range's low end. */
export async function checkSliderKeys({ page, check }) {
  const at = await page.evaluate(() => {
    const el = document.getElementById("joint-0");
    if (!el) return null;
    el.value = el.min;
    el.dispatchEvent(new Event("input", { bubbles: true }));
    return { min: Number(el.min), max: Number(el.max), metres: / mm$/.test(el.labels?.[0]?.textContent ?? "") };
  });
  if (!check(at !== null, "slider #joint-0 exists for the key check")) return;
  await page.focus("#joint-0");
  await page.keyboard.press("ArrowRight");
  const moved = Number(await page.inputValue("#joint-0")) - at.min;
  const want = Math.min(at.metres ? 0.001 : 1, at.max - at.min);
  check(Math.abs(moved - want) < 1e-9, `the right arrow moves joint 0 by ${at.metres ? "1 mm" : "1°"} (moved ${moved})`);
}

/** The result at desktop widths (issue 47): the page does not scroll sideways, and the joints table
 * fits its region without scrolling, at the test's own width and at 1280 px. */
export async function checkResultWidth({ page, check }) {
  const viewport = page.viewportSize();
  try {
    for (const width of [viewport.width, 1280]) {
      await page.setViewportSize({ width, height: viewport.height });
      await page.waitForTimeout(300);
      const o = await page.evaluate(() => {
        const table = document.getElementById("joints-table");
        return { page: document.scrollingElement.scrollWidth, inner: window.innerWidth,
          table: table.scrollWidth, region: table.parentElement.clientWidth };
      });
      check(o.page <= o.inner && o.table <= o.region + 1,
        `${width} px wide: the result needs no sideways scrolling (page ${o.page}/${o.inner}, joints table ${o.table}/${o.region})`);
    }
  } finally {
    await page.setViewportSize(viewport);
  }
}
