// The page's driver: loads the wasm module, reports the WebGPU adapter, runs the GPU self-test
// and checks dropped datasets. All computation happens in the wasm module; this file only
// moves data in and shows results. `document.body.dataset.state` tells tests where it is.
import init, { adapter_report, gpu_self_test, inspect_dataset } from "./pkg/artmesh.js";

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
const maxSize = Number(params.get("max") ?? 1000003);

function show(el, text, cls) {
  el.textContent = text;
  el.className = "status" + (cls ? " " + cls : "");
}

async function gpuSection() {
  if (!navigator.gpu) {
    show($("adapter"), "This browser has no WebGPU. Use Chrome or Edge 113+ (on Linux start Chromium with " +
      "--enable-unsafe-webgpu), Safari 26+, or Firefox 141+ on Windows.", "fail");
    show($("selftest-status"), "Skipped: no WebGPU.", "fail");
    document.body.dataset.selftest = "skipped";
    return;
  }
  const adapter = JSON.parse(await adapter_report());
  // The browser's own adapter info names the vendor and architecture even when it hides the description.
  const info = (await navigator.gpu.requestAdapter())?.info;
  const vendor = [info?.vendor, info?.architecture].filter(Boolean).join(" ");
  const name = vendor ? `${vendor} — ${adapter.name}` : adapter.name;
  document.body.dataset.adapter = name;
  show($("adapter"), `${name} (${adapter.device_type === "Cpu" ? "software" : "hardware"} WebGPU)\n` +
    `largest storage binding ${(adapter.max_storage_buffer_binding_size / 2 ** 20).toFixed(0)} MiB, ` +
    `${adapter.max_compute_workgroups_per_dimension} workgroups per dimension`, "ok");

  show($("selftest-status"), "Running prefix sum and radix sort on the GPU…");
  const t0 = performance.now();
  const result = JSON.parse(await gpu_self_test(maxSize));
  const seconds = ((performance.now() - t0) / 1000).toFixed(1);
  const body = $("selftest-table").querySelector("tbody");
  for (const c of result.report.checks) {
    const row = body.insertRow();
    for (const v of [c.kernel, c.n.toLocaleString("en"), c.key_bits || "—"]) row.insertCell().textContent = v;
    const verdict = row.insertCell();
    verdict.textContent = c.mismatches === 0 ? "matches CPU" : `${c.mismatches} mismatches (first at ${c.first_mismatch})`;
    verdict.className = c.mismatches === 0 ? "ok" : "fail";
  }
  $("selftest-table").hidden = false;
  const n = result.report.checks.length;
  show($("selftest-status"), result.passed ? `All ${n} checks match the CPU (${seconds} s).`
    : `Some checks differ from the CPU: see the table.`, result.passed ? "ok" : "fail");
  document.body.dataset.selftest = result.passed ? "pass" : "fail";
}

// --- dataset drop -------------------------------------------------------------------------

async function readEntry(entry, prefix, out) {
  if (entry.isFile) {
    const file = await new Promise((res, rej) => entry.file(res, rej));
    out.push([prefix + entry.name, file]);
  } else if (entry.isDirectory) {
    const reader = entry.createReader();
    for (;;) {
      const batch = await new Promise((res, rej) => reader.readEntries(res, rej));
      if (batch.length === 0) break;
      for (const child of batch) await readEntry(child, prefix + entry.name + "/", out);
    }
  }
}

async function inspect(pairs) {
  // Paths relative to the dropped folder: drop its own name.
  const strip = (p) => p.split("/").slice(1).join("/");
  const paths = [], contents = [];
  for (const [path, file] of pairs) {
    if (file.name.startsWith(".")) continue;
    paths.push(strip(path));
    contents.push(new Uint8Array(await file.arrayBuffer()));
  }
  const result = JSON.parse(inspect_dataset(paths, contents));
  const out = $("dataset-result");
  out.hidden = false;
  out.textContent = result.ok ? result.text : `${result.problems.length} problem(s) found:\n` + result.problems.join("\n");
  out.className = result.ok ? "ok" : "fail";
  document.body.dataset.dataset = result.ok ? "ok" : "problems";
}

function wireDrop() {
  const zone = $("dropzone");
  zone.addEventListener("dragover", (e) => { e.preventDefault(); zone.classList.add("over"); });
  zone.addEventListener("dragleave", () => zone.classList.remove("over"));
  zone.addEventListener("drop", async (e) => {
    e.preventDefault();
    zone.classList.remove("over");
    const pairs = [];
    for (const item of e.dataTransfer.items) {
      const entry = item.webkitGetAsEntry?.();
      if (entry) await readEntry(entry, "", pairs);
    }
    await inspect(pairs);
  });
  $("folder").addEventListener("change", (e) =>
    inspect([...e.target.files].map((f) => [f.webkitRelativePath || f.name, f])));
}

async function main() {
  try {
    await init();
    wireDrop();
    await gpuSection();
    document.body.dataset.state = "done";
  } catch (e) {
    show($("selftest-status"), `Error: ${e.message ?? e}`, "fail");
    document.body.dataset.state = "error";
    document.body.dataset.error = String(e.message ?? e);
  }
}

main();
