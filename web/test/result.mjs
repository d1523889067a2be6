// Browser checks of the Result viewer's teaching aids, called by page.mjs once a demo result is
// shown: the play button (aria-pressed, keyboard, the picture moves while playing and holds when
// paused, a slider or a state stops it), the part-colour legend (one entry per part, distinct
// colours, the wasm palette's, found in the picture), the true parts' overlay (changes the
// picture, and off restores it) and the opening view's score; no console errors meanwhile. Also the
// page demo's score against its ground truth, for a demo at a hardware adapter's preset.
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

/** The page demo's joints against its ground truth (report.json's metrics): both types right and
 * every axis within 2°, what a demo at a hardware adapter's preset must give (issue 46). */
export async function checkDemoScore({ page, check, preset }) {
  const last = await page.evaluate(() => window.artmeshLast ?? null);
  const report = typeof last?.report === "string" ? JSON.parse(last.report) : last?.report;
  const joints = report?.metrics?.joints ?? [];
  check(joints.length === 2 && joints.every((j) => j.type_correct),
    `the ${preset} demo types both joints right (${joints.map((j) => `${j.gt_kind}→${j.pred_kind}`).join(", ")})`);
  check(joints.length > 0 && joints.every((j) => j.axis_ang <= 2),
    `the ${preset} demo's axes are within 2° (${joints.map((j) => j.axis_ang.toFixed(2) + "°").join(", ")})`);
}
