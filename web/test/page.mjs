// End-to-end test of the page in headless Chromium with WebGPU (SwiftShader): the page loads
// the wasm module, reports the adapter and passes the GPU self-test. Screenshot saved to
// artefacts/web-selftest.png. Exit code 0 = pass. Needs web/pkg built (web/build.sh).
import { chromium } from "playwright-core";
import { mkdir } from "node:fs/promises";
import { serve } from "../serve.mjs";

const server = await serve(0);
const url = `http://127.0.0.1:${server.address().port}/`;
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: ["--no-sandbox", "--enable-unsafe-webgpu", "--disable-background-networking", "--disable-component-update",
    "--disable-sync", "--no-first-run", "--disable-quic"],
});
let failed = 0, passed = 0;
try {
  const page = await browser.newPage({ viewport: { width: 1000, height: 1100 } });
  const requests = [];
  page.on("request", (r) => requests.push(r.url()));
  page.on("console", (m) => m.type() === "error" && console.log("page console:", m.text()));
  await page.goto(url + "?max=65537");
  await page.waitForFunction(() => document.body.dataset.state !== "loading", null, { timeout: 300_000 });
  const state = await page.evaluate(() => ({ ...document.body.dataset }));
  await mkdir("artefacts", { recursive: true });
  await page.screenshot({ path: "artefacts/web-selftest.png", fullPage: true });

  const check = (ok, what) => { console.log(`${ok ? "ok  " : "FAIL"} ${what}`); if (ok) passed++; else failed++; };
  check(state.state === "done", `page finished (state=${state.state}${state.error ? ", error: " + state.error : ""})`);
  check(Boolean(state.adapter), `adapter reported: ${state.adapter}`);
  check(state.selftest === "pass", `GPU self-test passed (selftest=${state.selftest})`);
  const rows = await page.locator("#selftest-table tbody tr").count();
  check(rows >= 20, `self-test table shows ${rows} checks`);
  const foreign = requests.filter((r) => !r.startsWith(url));
  check(foreign.length === 0, `no requests beyond the page's own files (${foreign.join(", ") || "none"})`);
} finally {
  await browser.close();
  server.close();
}
console.log(`page: ${passed} passed, ${failed} failed`);
process.exit(failed === 0 && passed > 0 ? 0 : 1);
