// Reading the result viewer's canvas in the browser tests (page.mjs, result.mjs, touch.mjs).
// Snapshots and the counts over them stay in the page: copying a canvas out to node took most of
// a minute over the checks. Node holds snapshot ids.

/** Keeps a copy of the viewer canvas's RGBA bytes in the page; its id. */
export const snapshot = (page) => page.evaluate(() => {
  const c = document.getElementById("viewer");
  const snaps = (window.__viewerSnaps ||= []);
  snaps.push(c.getContext("2d").getImageData(0, 0, c.width, c.height).data);
  return snaps.length - 1;
});

/**
 * Pixels whose RGBA (RGB with `alpha` false) differs by more than `threshold` (summed over the
 * channels) between snapshots `a` and `b`; with `darkBelow`, only those whose brightest channel in
 * `a` is under it; with `colourAbove`, only those whose channels in `a` spread more than it.
 * Infinity when the sizes differ.
 */
export const changed = (page, a, b, { threshold = 12, alpha = true, darkBelow = Infinity, colourAbove = -1 } = {}) =>
  page.evaluate(([a, b, threshold, alpha, darkBelow, colourAbove]) => {
    [a, b] = [window.__viewerSnaps[a], window.__viewerSnaps[b]];
    if (a.length !== b.length) return Infinity;
    let n = 0;
    for (let i = 0; i < a.length; i += 4) {
      const d = Math.abs(a[i] - b[i]) + Math.abs(a[i + 1] - b[i + 1]) + Math.abs(a[i + 2] - b[i + 2]) +
        (alpha ? Math.abs(a[i + 3] - b[i + 3]) : 0);
      if (d <= threshold) continue;
      const hi = Math.max(a[i], a[i + 1], a[i + 2]), lo = Math.min(a[i], a[i + 1], a[i + 2]);
      if (hi < darkBelow && hi - lo > colourAbove) n++;
    }
    return n;
  }, [a, b, threshold, alpha, darkBelow, colourAbove]);

/** Pixels of snapshot `id` unlike its top-left corner's (the background): the twin's size. */
export const covered = (page, id) => page.evaluate((id) => {
  const p = window.__viewerSnaps[id];
  let n = 0;
  for (let i = 0; i < p.length; i += 4) {
    if (Math.abs(p[i] - p[0]) + Math.abs(p[i + 1] - p[1]) + Math.abs(p[i + 2] - p[2]) > 30) n++;
  }
  return n;
}, id);

/** Reads the canvas until two reads `gap` ms apart agree (draws in flight have landed): the
 * last snapshot's id and the last difference seen (0 when it settled). */
export async function settle(page, gap = 900, tries = 5) {
  let last = await snapshot(page), diff = Infinity;
  for (let i = 0; i < tries && diff > 0; i++) {
    await page.waitForTimeout(gap);
    const now = await snapshot(page);
    diff = await changed(page, last, now);
    last = now;
  }
  return { diff, image: last };
}
