// End-to-end test of the page in headless Chromium with WebGPU (SwiftShader): the page loads
// the wasm module, reports the adapter and passes the GPU self-test. Screenshot saved to
// artefacts/web-selftest.png (repository root). Exit code 0 = pass. Needs web/pkg built (web/build.sh).
import { chromium } from "playwright-core";
import { mkdir, mkdtemp, writeFile, cp, readFile } from "node:fs/promises";
import { execFileSync } from "node:child_process";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { fileURLToPath } from "node:url";
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
  const artefacts = fileURLToPath(new URL("../../artefacts/", import.meta.url));
  await mkdir(artefacts, { recursive: true });
  await page.screenshot({ path: artefacts + "web-selftest.png", fullPage: true });

  const check = (ok, what) => { console.log(`${ok ? "ok  " : "FAIL"} ${what}`); if (ok) passed++; else failed++; };
  check(state.state === "done", `page finished (state=${state.state}${state.error ? ", error: " + state.error : ""})`);
  check(Boolean(state.adapter), `adapter reported: ${state.adapter}`);
  check(state.selftest === "pass", `GPU self-test passed (selftest=${state.selftest})`);
  const rows = await page.locator("#selftest-table tbody tr").count();
  check(rows >= 20, `self-test table shows ${rows} checks`);

  // Dataset check as a user does it: pick a folder written by `artmesh sample`, then a broken copy.
  const bin = process.env.ARTMESH_BIN ?? fileURLToPath(new URL("../../target/debug/artmesh", import.meta.url));
  const work = await mkdtemp(join(tmpdir(), "artmesh-page-"));
  execFileSync(bin, ["sample", "--out", join(work, "good"), "--width", "24", "--height", "16", "--views", "3"]);
  await page.setInputFiles("#folder", join(work, "good"));
  await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 60_000 });
  const good = await page.evaluate(() => [document.body.dataset.dataset, document.getElementById("dataset-result").textContent]);
  check(good[0] === "ok" && good[1].includes("parts"), `sample dataset accepted in the page: ${good[1].split("\n")[0]}`);

  await cp(join(work, "good"), join(work, "broken"), { recursive: true });
  const png = join(work, "broken", "end", "train", "rgba", "0001.png");
  await writeFile(png, (await readFile(png)).subarray(0, 40));
  await page.evaluate(() => delete document.body.dataset.dataset);
  await page.setInputFiles("#folder", join(work, "broken"));
  await page.waitForFunction(() => document.body.dataset.dataset, null, { timeout: 60_000 });
  const broken = await page.evaluate(() => [document.body.dataset.dataset, document.getElementById("dataset-result").textContent]);
  check(broken[0] === "problems" && broken[1].includes("end/train/rgba/0001.png"),
    `truncated PNG reported by name: ${broken[1].split("\n")[1] ?? broken[1]}`);
  await page.screenshot({ path: artefacts + "web-dataset-error.png", fullPage: true });

  const foreign = requests.filter((r) => !r.startsWith(url));
  check(foreign.length === 0, `no requests beyond the page's own files (${foreign.join(", ") || "none"})`);
} finally {
  await browser.close();
  server.close();
}
console.log(`page: ${passed} passed, ${failed} failed`);
process.exit(failed === 0 && passed > 0 ? 0 : 1);
