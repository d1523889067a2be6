// Browser checks of the page on a phone, called by page.mjs once a demo result is shown: at 390 px
// wide nothing scrolls sideways (the landing page, a dataset loaded, a fit running, the result), and
// the result viewer answers touch: one finger orbits, two fingers pinch-zoom, and the page does not
// scroll meanwhile. Touches are real input events sent through the DevTools protocol
// (Input.dispatchTouchEvent), so they travel the browser's own touch → pointer event path.
import { join } from "node:path";
import { changed, covered, settle } from "./canvas.mjs";

const PHONE = { width: 390, height: 844 };

/** The page's sideways overflow: its scroll width against the phone's width, and the elements
 * that stick out (outside a region that scrolls on its own), for the message. */
const overflow = (page) => page.evaluate((limit) => {
  const clips = (el) => {
    for (let p = el.parentElement; p && p !== document.body; p = p.parentElement) {
      if (["auto", "scroll", "hidden", "clip"].includes(getComputedStyle(p).overflowX)) return true;
    }
    return false;
  };
  const name = (el) => el.tagName.toLowerCase() + (el.id ? `#${el.id}` : "") +
    (el.classList.length ? `.${[...el.classList].join(".")}` : "");
  const out = [...document.body.querySelectorAll("*")]
    .filter((el) => el.getBoundingClientRect().right > limit + 0.5 && !clips(el))
    .map((el) => `${name(el)} to ${Math.round(el.getBoundingClientRect().right)}`);
  return { scrollWidth: document.scrollingElement.scrollWidth, innerWidth: window.innerWidth, out: out.slice(0, 6) };
}, PHONE.width);

/** Asserts no sideways scrolling at `label`; returns the scroll width measured. */
async function checkWidth(page, check, label) {
  const o = await overflow(page);
  check(o.scrollWidth <= PHONE.width && o.scrollWidth <= o.innerWidth,
    `${PHONE.width} px wide, ${label}: no sideways scrolling (scrollWidth ${o.scrollWidth}, innerWidth ` +
    `${o.innerWidth}${o.out.length ? `; sticking out: ${o.out.join(", ")}` : ""})`);
  return o.scrollWidth;
}

/** The landing page, a loaded dataset and a running fit on a fresh phone-sized page (touch, mobile
 * viewport), the fit cancelled once measured. */
async function checkPhonePages({ browser, url, check, native, work, artefacts, widths }) {
  const context = await browser.newContext({ viewport: PHONE, hasTouch: true, isMobile: true, deviceScaleFactor: 2 });
  try {
    const page = await context.newPage();
    page.setDefaultTimeout(60_000);
    await page.goto(url);
    await page.waitForFunction(() => document.body.dataset.state !== "loading", null, { timeout: 120_000 });
    widths.landing = await checkWidth(page, check, "the landing page");

    const sample = join(work, "mobile-sample");
    native(["sample", "--out", sample, "--width", "24", "--height", "16", "--views", "3"]);
    await page.setInputFiles("#folder", sample);
    await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 60_000 });
    widths.dataset = await checkWidth(page, check, `a dataset loaded (${await page.evaluate(() => document.body.dataset.dataset)})`);

    await page.selectOption("#fit-preset", "tiny");
    await page.click("#fit-run");
    // The first preview sizes the render and photo canvases: measure with them shown when it comes soon.
    await page.waitForFunction(() => document.body.dataset.fit === "running", null, { timeout: 30_000 });
    await page.waitForFunction(() => document.body.dataset.preview === "1" || document.body.dataset.fit !== "running",
      null, { timeout: 20_000 }).catch(() => {});
    const fit = await page.evaluate(() => `fit=${document.body.dataset.fit}, preview=${document.body.dataset.preview ?? "none"}`);
    widths.fit = await checkWidth(page, check, `during a fit (${fit})`);
    await page.screenshot({ path: artefacts + "web-mobile-fit.png", fullPage: true });
    if (await page.locator("#cancel").isEnabled()) await page.click("#cancel");
  } finally {
    await context.close();
  }
}

/** One touch gesture: fingers from `from` to `to` (arrays of [x, y]) in `steps` moves. */
async function gesture(cdp, from, to, steps = 8) {
  const at = (k) => from.map(([x, y], id) => ({ id, x: x + ((to[id][0] - x) * k) / steps, y: y + ((to[id][1] - y) * k) / steps }));
  await cdp.send("Input.dispatchTouchEvent", { type: "touchStart", touchPoints: at(0) });
  for (let k = 1; k <= steps; k++) {
    await cdp.send("Input.dispatchTouchEvent", { type: "touchMove", touchPoints: at(k) });
  }
  await cdp.send("Input.dispatchTouchEvent", { type: "touchEnd", touchPoints: [] });
}

/** Drag and pinch on the viewer (the page at phone width, touch emulated). */
async function checkViewerTouch(page, cdp, check) {
  await page.locator("#viewer").scrollIntoViewIfNeeded();
  // Counts the pointer events the touches become on the canvas, by kind.
  await page.evaluate(() => {
    window.artmeshTouches = {};
    document.getElementById("viewer").addEventListener("pointermove", (e) => {
      const k = `${e.pointerType}:${e.pointerId}`;
      window.artmeshTouches[k] = (window.artmeshTouches[k] ?? 0) + 1;
    });
  });
  const box = await page.locator("#viewer").boundingBox();
  const [cx, cy] = [box.x + box.width / 2, box.y + box.height / 2];
  const scrollY = () => page.evaluate(() => window.scrollY);

  const before = (await settle(page, 700, 6)).image;
  const y0 = await scrollY();
  // Mostly upwards: on the page outside the canvas this finger would scroll it.
  await gesture(cdp, [[cx - 40, cy + 60]], [[cx + 60, cy - 60]]);
  const dragged = (await settle(page, 700, 6)).image;
  const moves = await page.evaluate(() => ({ ...window.artmeshTouches }));
  const touchMoves = Object.entries(moves).filter(([k]) => k.startsWith("touch:"));
  check(touchMoves.length === 1, `a one-finger drag reaches the canvas as touch pointer events (${JSON.stringify(moves)})`);
  const drag = await changed(page, before, dragged, { alpha: false });
  check(drag > 200, `a one-finger drag orbits the twin (${drag} pixels changed)`);
  const y1 = await scrollY();
  check(y1 === y0, `the page does not scroll while dragging on the viewer (scrollY ${y0} → ${y1})`);

  await page.evaluate(() => { window.artmeshTouches = {}; });
  const small = await covered(page, dragged);
  // Two fingers moving apart, horizontally about the centre: zoom in.
  await gesture(cdp, [[cx - 25, cy], [cx + 25, cy]], [[cx - 110, cy + 10], [cx + 110, cy - 10]]);
  const pinched = (await settle(page, 700, 6)).image;
  const fingers = await page.evaluate(() => Object.keys(window.artmeshTouches).filter((k) => k.startsWith("touch:")).length);
  const pinch = await changed(page, dragged, pinched, { alpha: false }), large = await covered(page, pinched);
  check(fingers === 2 && pinch > 200, `a two-finger pinch changes the picture (${fingers} fingers, ${pinch} pixels changed)`);
  check(large > small * 1.3, `pinching out zooms in: the twin covers ${small} → ${large} pixels`);
  const y2 = await scrollY();
  check(y2 === y1, `the page does not scroll or zoom while pinching on the viewer (scrollY ${y1} → ${y2}, ` +
    `visual scale ${await page.evaluate(() => window.visualViewport?.scale ?? 1)})`);
  // Fingers together again: zoom back out, so later steps see the twin as before.
  await gesture(cdp, [[cx - 110, cy], [cx + 110, cy]], [[cx - 25, cy], [cx + 25, cy]]);
  const back = await covered(page, (await settle(page, 700, 6)).image);
  check(back < large, `pinching in zooms back out (the twin covers ${large} → ${back} pixels)`);
}

/**
 * At phone width (390 px): no sideways scrolling on a fresh page (landing, dataset, fit) and on
 * `page`'s result; then touch on its viewer. `page` must show a result; its viewport is restored.
 * `native(args)` runs the CLI, `work` is a scratch folder; screenshots go to `artefacts`.
 */
export async function checkMobileAndTouch({ page, browser, url, check, native, work, artefacts }) {
  const widths = {};
  await checkPhonePages({ browser, url, check, native, work, artefacts, widths });

  const viewport = page.viewportSize();
  const cdp = await page.context().newCDPSession(page);
  try {
    await page.setViewportSize(PHONE);
    await cdp.send("Emulation.setTouchEmulationEnabled", { enabled: true, maxTouchPoints: 5 });
    await page.waitForTimeout(500);
    widths.result = await checkWidth(page, check, "the result view");
    await page.screenshot({ path: artefacts + "web-mobile-result.png", fullPage: true });
    await checkViewerTouch(page, cdp, check);
  } finally {
    await cdp.send("Emulation.setTouchEmulationEnabled", { enabled: false }).catch(() => {});
    await cdp.detach().catch(() => {});
    await page.setViewportSize(viewport);
    await page.waitForTimeout(500);
  }
  console.log(`note scroll widths at ${PHONE.width} px: ${Object.entries(widths).map(([k, v]) => `${k} ${v}`).join(", ")}`);
}
