// Writes the page as a self-contained static folder (`web/build.sh --dist OUT` calls this after the
// wasm build): index.html, the ES modules, the style, the service worker and pkg/ (wasm-bindgen's
// module and the wasm), nothing from node_modules or test/. It checks that every relative import
// of every module is in the folder, so a forgotten file fails here rather than on the host, and
// reports the wasm's gzipped size against the budget (enforced for release builds).
// Usage: node web/dist.mjs OUT [profile]
import { cp, mkdir, readdir, readFile, rename, rm, rmdir, stat, writeFile } from "node:fs/promises";
import { dirname, join, resolve, basename } from "node:path";
import { fileURLToPath } from "node:url";
import { gzipSync } from "node:zlib";

/** The gzipped wasm a class downloads before the page works (issue 28's budget). */
const WASM_GZIP_BUDGET = 3 * 1024 * 1024;

const web = dirname(fileURLToPath(import.meta.url));

/** The files of the page, relative to web/: the top-level modules, the page, its style, pkg/. */
async function pageFiles() {
  const top = (await readdir(web)).filter(
    (f) => (f.endsWith(".js") || f === "index.html" || f === "style.css") && !f.endsWith(".config.js"),
  );
  return [...top.sort(), "pkg/artmesh.js", "pkg/artmesh_bg.wasm"];
}

/** Relative module specifiers in `source` (static `from "./x"` and dynamic `import("./x")`). */
function relativeImports(source) {
  const found = [];
  for (const m of source.matchAll(/(?:from\s+|import\s*\(\s*)["'](\.{1,2}\/[^"']+)["']/g)) found.push(m[1]);
  return found;
}

/** Fails when a module in `folder` imports a file that is not there, or index.html names a missing one. */
async function checkComplete(folder, files) {
  const missing = [];
  const have = new Set(files);
  for (const f of files) {
    if (!f.endsWith(".js")) continue;
    const text = await readFile(join(folder, f), "utf8");
    for (const spec of relativeImports(text)) {
      const target = join(dirname(f), spec);
      if (!have.has(target)) missing.push(`${f} imports ${spec}`);
    }
  }
  const html = await readFile(join(folder, "index.html"), "utf8");
  for (const m of html.matchAll(/(?:src|href)="([^":]+)"/g)) {
    if (!have.has(m[1])) missing.push(`index.html refers to ${m[1]}`);
  }
  if (missing.length) throw new Error(`the dist folder would be incomplete:\n  ${missing.join("\n  ")}`);
}

async function main() {
  const [out, profile = "release"] = process.argv.slice(2);
  if (!out) throw new Error("usage: node web/dist.mjs OUT [profile]");
  const dest = resolve(out);
  // Staged beside the destination and moved into place at the end: a failure leaves nothing.
  const staging = join(dirname(dest), `.${basename(dest)}.partial-${process.pid}`);
  await rm(staging, { recursive: true, force: true });
  try {
    const files = await pageFiles();
    for (const f of files) {
      await mkdir(dirname(join(staging, f)), { recursive: true });
      await cp(join(web, f), join(staging, f));
    }
    await checkComplete(staging, files);
    const wasm = await readFile(join(staging, "pkg/artmesh_bg.wasm"));
    const gzip = gzipSync(wasm, { level: 9 }).length;
    const total = (await Promise.all(files.map((f) => stat(join(staging, f))))).reduce((s, x) => s + x.size, 0);
    const summary = {
      dist: dest, profile, files: files.length, bytes: total, wasm_bytes: wasm.length,
      wasm_gzip_bytes: gzip, wasm_gzip_budget: WASM_GZIP_BUDGET,
    };
    await writeFile(join(staging, "build.json"), JSON.stringify({ profile, files }, null, 1) + "\n");
    if (profile === "release" && gzip > WASM_GZIP_BUDGET) {
      throw new Error(`the wasm is ${(gzip / 2 ** 20).toFixed(2)} MiB gzipped, over the 3 MiB budget`);
    }
    // build.sh refused unless absent or empty; rmdir fails rather than delete anything put there since.
    await rmdir(dest).catch((e) => { if (e.code !== "ENOENT") throw e; });
    await rename(staging, dest);
    console.log(JSON.stringify(summary));
    const mib = (n) => (n / 2 ** 20).toFixed(2);
    console.error(`web: wrote ${dest}: ${files.length} files, wasm ${mib(wasm.length)} MiB (${mib(gzip)} MiB gzipped; budget 3 MiB)`);
  } catch (e) {
    await rm(staging, { recursive: true, force: true });
    throw e;
  }
}

main().catch((e) => {
  console.error(`web: --dist failed: ${e.message}`);
  process.exit(1);
});
