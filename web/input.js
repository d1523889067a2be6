// The Input section's dataset half: reads a dropped or picked folder or .zip into a wasm Dataset,
// shows its summary and thumbnails, or the readers' problems. `document.body.dataset.dataset`
// becomes "ok" or "problems" (tests wait on it).
import { $, errorText, drawRgba, freeQuietly } from "./util.js";

let Dataset = null;
let hooks = { onDataset: () => {}, onProblems: () => {} };
let loadToken = 0;

const isZip = (name) => /\.zip$/i.test(name);

function entryFile(entry) {
  return new Promise((resolve, reject) => entry.file(resolve, reject));
}

// Walks a FileSystemEntry tree; paths include the entry's own name ("folder/sub/file").
async function readEntry(entry, prefix, out) {
  if (entry.isFile) {
    out.push([prefix + entry.name, await entryFile(entry)]);
  } else if (entry.isDirectory) {
    const reader = entry.createReader();
    for (;;) {
      const batch = await new Promise((resolve, reject) => reader.readEntries(resolve, reject));
      if (batch.length === 0) break;
      for (const child of batch) await readEntry(child, prefix + entry.name + "/", out);
    }
  }
}

// Paths relative to the dropped folder: when every path starts with the same folder, drop it.
function stripRoot(paths) {
  if (paths.length === 0 || !paths.every((p) => p.includes("/"))) return paths;
  const root = paths[0].split("/")[0];
  if (!paths.every((p) => p.split("/")[0] === root)) return paths;
  return paths.map((p) => p.slice(root.length + 1));
}

const hidden = (path) => path.split("/").some((part) => part.startsWith(".") || part === "");

function status(text) {
  const out = $("dataset-result");
  out.hidden = false;
  out.className = "";
  out.textContent = text;
}

function problems(message) {
  // The message counts its problems itself (and lists at most 50 of them).
  const lines = message.split("\n").filter((l) => l.trim() !== "");
  const out = $("dataset-result");
  out.hidden = false;
  out.className = "fail";
  out.textContent = "The dataset cannot be used: " + lines.join("\n");
  $("thumbs").hidden = true;
  $("fit-controls").hidden = true;
  document.body.dataset.dataset = "problems";
  hooks.onProblems();
}

/** Shows a validated dataset: its summary, thumbnails per state and the fit button. */
export function showDataset(ds) {
  const out = $("dataset-result");
  out.hidden = false;
  out.className = "ok";
  let summary = "";
  try { summary = ds.summary(); } catch (e) { summary = `(no summary: ${errorText(e)})`; }
  out.textContent = summary;
  const box = $("thumbs");
  box.replaceChildren();
  let thumbs = [];
  try { thumbs = ds.thumbnails(4) ?? []; } catch (e) { console.warn("thumbnails:", e); }
  for (const state of ["start", "end"]) {
    const row = document.createElement("div");
    row.className = "thumb-row";
    const label = document.createElement("span");
    label.className = "thumb-label";
    label.textContent = state;
    row.append(label);
    for (const t of thumbs.filter((t) => t.state === state)) {
      const canvas = document.createElement("canvas");
      canvas.title = `${state} state, training view ${t.view}`;
      if (drawRgba(canvas, t.width, t.height, t.rgba)) row.append(canvas);
    }
    box.append(row);
  }
  box.hidden = thumbs.length === 0;
  $("fit-controls").hidden = false;
  document.body.dataset.dataset = "ok";
}

async function loadFiles(pairs) {
  const token = ++loadToken;
  const stripped = stripRoot(pairs.map(([path]) => path));
  const keep = [];
  stripped.forEach((path, i) => { if (!hidden(path)) keep.push([path, pairs[i][1]]); });
  if (keep.length === 0) { problems("No files found (hidden files are skipped)."); return; }
  const paths = [], contents = [];
  for (const [i, [path, file]] of keep.entries()) {
    if (i % 20 === 0) status(`Reading files: ${i} of ${keep.length}…`);
    paths.push(path);
    contents.push(new Uint8Array(await file.arrayBuffer()));
    if (token !== loadToken) return;
  }
  status(`Checking ${keep.length} files…`);
  let ds;
  try {
    ds = Dataset.from_files(paths, contents);
  } catch (e) {
    if (token === loadToken) problems(errorText(e));
    return;
  }
  if (token !== loadToken) { freeQuietly(ds); return; }
  hooks.onDataset(ds);
}

async function loadZip(file) {
  const token = ++loadToken;
  status(`Reading ${file.name}…`);
  const bytes = new Uint8Array(await file.arrayBuffer());
  if (token !== loadToken) return;
  status(`Checking ${file.name}…`);
  let ds;
  try {
    ds = Dataset.from_zip(file.name, bytes);
  } catch (e) {
    if (token === loadToken) problems(errorText(e));
    return;
  }
  if (token !== loadToken) { freeQuietly(ds); return; }
  hooks.onDataset(ds);
}

async function loadDropped(entries, files) {
  try {
    if (entries.length + files.length === 1) {
      const entry = entries[0];
      if (entry && entry.isFile && isZip(entry.name)) return await loadZip(await entryFile(entry));
      if (files[0] && isZip(files[0].name)) return await loadZip(files[0]);
    }
    const pairs = [];
    for (const entry of entries) await readEntry(entry, "", pairs);
    for (const file of files) pairs.push([file.webkitRelativePath || file.name, file]);
    await loadFiles(pairs);
  } catch (e) {
    problems(`Could not read the dropped files: ${errorText(e)}`);
  }
}

/** Wires the drop zone and both pickers. `onDataset(ds)` gets each validated Dataset. */
export function setupInput(DatasetClass, { onDataset, onProblems }) {
  Dataset = DatasetClass;
  hooks = { onDataset, onProblems };
  const zone = $("dropzone");
  for (const type of ["dragenter", "dragover"]) {
    zone.addEventListener(type, (e) => { e.preventDefault(); zone.classList.add("over"); });
  }
  zone.addEventListener("dragleave", () => zone.classList.remove("over"));
  zone.addEventListener("drop", (e) => {
    e.preventDefault();
    zone.classList.remove("over");
    // Items must be taken now: a real drop's DataTransfer is emptied once this handler returns.
    const dt = e.dataTransfer;
    const entries = [], files = [];
    for (const item of dt?.items ?? []) {
      if (item.kind !== "file") continue;
      const entry = item.webkitGetAsEntry?.();
      if (entry) entries.push(entry);
      else {
        const file = item.getAsFile();
        if (file) files.push(file);
      }
    }
    if (entries.length === 0 && files.length === 0 && dt?.files) files.push(...dt.files);
    loadDropped(entries, files);
  });
  // The page itself ignores drops outside the zone (instead of navigating to the file).
  window.addEventListener("dragover", (e) => e.preventDefault());
  window.addEventListener("drop", (e) => e.preventDefault());

  $("folder").addEventListener("change", (e) => {
    const files = [...e.target.files];
    e.target.value = "";
    if (files.length === 1 && isZip(files[0].name)) loadZip(files[0]).catch((err) => problems(errorText(err)));
    else loadFiles(files.map((f) => [f.webkitRelativePath || f.name, f])).catch((err) => problems(errorText(err)));
  });
  $("zipfile").addEventListener("change", (e) => {
    const file = e.target.files[0];
    e.target.value = "";
    if (file) loadZip(file).catch((err) => problems(errorText(err)));
  });
}
