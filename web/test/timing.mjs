// Issue 47's time checks: the preset line's estimate within 2× of the time the fit took (the
// demo's photographs counted), and the ETA within 1.5× of it once a fifth of the fit has run.
// The page writes its numbers for this: the preset line's `data-estimate-s` (every joint settled
// by the depth) and `data-estimate-open-s` (one left to the image stages), #fit-eta's
// `data-elapsed-s` / `data-remaining-s`, the body's `data-fit-seconds` and `data-photograph-s`.
import { lastReport } from "./result.mjs";

/** The estimate on the preset line of the demo (`demo`) or of the fit. */
export async function readEstimate(page, demo) {
  return page.evaluate((id) => {
    const d = document.getElementById(id).dataset;
    return d.estimateS ? { settled: Number(d.estimateS), open: Number(d.estimateOpenS) } : null;
  }, demo ? "demo-preset-about" : "fit-preset-about");
}

/** Starts reading the ETA every second; the returned function stops and gives the samples,
 *  `[elapsed, remaining]` in the fit's own seconds. */
export function sampleEta(page) {
  const samples = [];
  let stop = false;
  const loop = (async () => {
    while (!stop) {
      const s = await page.evaluate(() => {
        const d = document.getElementById("fit-eta").dataset;
        return d.remainingS != null && document.body.dataset.fit === "running" ? [Number(d.elapsedS), Number(d.remainingS)] : null;
      }).catch(() => null);
      if (s) samples.push(s);
      await new Promise((r) => setTimeout(r, 1000));
    }
  })();
  return async () => { stop = true; await loop; return samples; };
}

/** Checks a finished fit's estimate and ETA samples. `open`: the image stages ran (the estimate
 *  that says so is the one to hold; read from the last report when not given). */
export async function checkTimes({ page, check, name, estimate, samples, open }) {
  open ??= ((await lastReport(page))?.articulation?.curve ?? []).length > 0;
  const d = await page.evaluate(() => ({ fit: Number(document.body.dataset.fitSeconds),
    photo: Number(document.body.dataset.photographS), stages: document.body.dataset.etaStages }));
  console.log(`note ${name}: stages predicted/took (s) ${d.stages}; photographs ${d.photo} s; ETA readings ` +
    samples.map(([e, l]) => `${e.toFixed(0)}+${l.toFixed(0)}`).join(" "));
  const fit = d.fit, total = fit + (name.includes("demo") ? d.photo || 0 : 0);
  if (!check(estimate && fit > 0, `${name}: the preset line gave an estimate (${JSON.stringify(estimate)}) and the fit its time (${fit} s)`)) return;
  const said = open ? estimate.open : estimate.settled;
  check(said <= 2 * total && total <= 2 * said,
    `${name}: estimated ${said.toFixed(0)} s (${open ? "a joint left open" : "joints settled by the depth"}), took ${total.toFixed(0)} s: within 2×`);
  const late = samples.filter(([elapsed]) => elapsed >= 0.2 * fit);
  const ratios = late.map(([elapsed, left]) => (elapsed + left) / fit);
  const worst = ratios.reduce((w, r) => (Math.abs(Math.log(r)) > Math.abs(Math.log(w)) ? r : w), 1);
  check(late.length >= 3 && ratios.every((r) => r <= 1.5 && r >= 1 / 1.5),
    `${name}: after a fifth of the fit, elapsed + ETA within 1.5× of the ${fit.toFixed(0)} s it took ` +
    `(${late.length} readings, worst ${worst.toFixed(2)}×)`);
}
