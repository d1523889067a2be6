// The Input section's dataset half: reads a dropped or picked folder or .zip into a wasm Dataset
// (of a folder only the files the dataset needs; a folder or .zip past the page's budgets is
// refused before it is read), shows its summary and thumbnails, or the readers' problems. A .zip
// of a URDF with its meshes is an object: the page photographs it on the GPU (app.js's
// captureObject) and it becomes a dataset like any other.
// `document.body.dataset.dataset` becomes "ok" or "problems" (tests wait on it).
import { $, errorText, drawRgba, freeQuietly } from "./util.js";

let Dataset = null;
let hooks = { onDataset: () => {}, onProblems: () => {}, captureObject: null };
let loadToken = 0;
// The page's budgets (Dataset.file_limits()); set in setupInput.
let limits = { max_listed_files: Infinity, max_zip_bytes: Infinity };

const isZip = (name) => /\.zip$/i.test(name);

function entryFile(entry) {
  return new Promise((resolve, reject) => entry.file(resolve, reject));
}

// Walks a FileSystemEntry tree; paths include the entry's own name ("folder/sub/file"). Stops
// once past the page's file limit: wasm then refuses the folder by its count.
async function readEntry(entry, prefix, out) {
  if (out.length > limits.max_listed_files) return;
  if (entry.isFile) {
    out.push([prefix + entry.name, await entryFile(entry)]);
  } else if (entry.isDirectory) {
    const reader = entry.createReader();
    while (out.length <= limits.max_listed_files) {
      const batch = await new Promise((resolve, reject) => reader.readEntries(resolve, reject));
      if (batch.length === 0) break;
      for (const child of batch) await readEntry(child, prefix + entry.name + "/", out);
    }
  }
}

const mb = (bytes) => `${Math.round(bytes / 1e6)} MB`;

// The dropped folder's name for errors: the first path's top folder.
const folderName = (paths) => (paths[0]?.includes("/") ? paths[0].split("/")[0] : "the dropped files");

function status(text) {
  const out = $("dataset-result");
  out.hidden = false;
  out.className = "";
  out.textContent = text;
}

function problems(message, what = "dataset") {
  // The message counts its problems itself (and lists at most 50 of them).
  const lines = message.split("\n").filter((l) => l.trim() !== "");
  const out = $("dataset-result");
  out.hidden = false;
  out.className = "fail";
  out.textContent = `The ${what} cannot be used: ` + lines.join("\n");
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

// Reads `paths` of the dropped files `byPath`; null once a newer load has begun.
async function readFiles(paths, byPath, token) {
  const contents = [];
  for (const [i, path] of paths.entries()) {
    if (i % 20 === 0) status(`Reading files: ${i} of ${paths.length}…`);
    try {
      contents.push(new Uint8Array(await byPath.get(path).arrayBuffer()));
    } catch (e) {
      throw new Error(`${path}: cannot read: ${errorText(e)}`);
    }
    if (token !== loadToken) return null;
  }
  return contents;
}

// A dropped folder: wasm picks the files the dataset needs from the paths and sizes (the
// transforms files and gt/ first, then the images they name) and only those are read, so an
// unrelated video beside the dataset is never loaded. Hidden files and an enclosing folder are
// wasm's to skip too.
async function loadFiles(pairs) {
  const token = ++loadToken;
  if (pairs.length === 0) { problems("No files found in what was dropped."); return; }
  const paths = pairs.map(([path]) => path);
  const byPath = new Map(pairs);
  const sizes = Float64Array.from(pairs, ([, file]) => file.size);
  const folder = folderName(paths);
  const read = [], contents = [];
  try {
    for (let round = 0; round < 2; round++) {
      const wanted = Dataset.files_needed(folder, paths, sizes, read, contents);
      const got = await readFiles(wanted, byPath, token);
      if (!got) return;
      read.push(...wanted);
      contents.push(...got);
    }
  } catch (e) {
    if (token === loadToken) problems(errorText(e));
    return;
  }
  status(`Checking ${read.length} files…`);
  let ds;
  try {
    ds = Dataset.from_files(read, contents);
  } catch (e) {
    if (token === loadToken) problems(errorText(e));
    return;
  }
  if (token !== loadToken) { freeQuietly(ds); return; }
  hooks.onDataset(ds);
}

async function loadZip(file) {
  const token = ++loadToken;
  if (file.size > limits.max_zip_bytes) {
    problems(`${file.name}: the archive takes ${mb(file.size)}, more than the ${mb(limits.max_zip_bytes)} ` +
      "the page reads of a .zip; unzip it and drop the folder instead (only the dataset's own files are then read)");
    return;
  }
  status(`Reading ${file.name}…`);
  const bytes = new Uint8Array(await file.arrayBuffer());
  if (token !== loadToken) return;
  let object = false;
  try { object = Dataset.zip_holds_object(bytes); } catch { /* from_zip says what is wrong */ }
  if (object) return loadObject(file.name, bytes, token);
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

// A .zip holding a URDF: imported and photographed in both states on the GPU, it then shows
// as a dataset (the truth comes with it, so its fit is scored).
async function loadObject(name, bytes, token) {
  status(`${name} holds a URDF: importing it and photographing both states on the GPU…`);
  $("thumbs").hidden = true;
  $("fit-controls").hidden = true;
  const t0 = performance.now();
  let ds;
  try {
    ds = await hooks.captureObject(name, bytes, (p) => {
      if (token === loadToken && p?.total > 0) status(`Photographing ${name}: ${p.done} of ${p.total} views rendered…`);
    });
  } catch (e) {
    if (token === loadToken) problems(errorText(e), "object");
    return;
  }
  if (token !== loadToken) { freeQuietly(ds); return; }
  document.body.dataset.captureSeconds = ((performance.now() - t0) / 1000).toFixed(2);
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

/** Wires the drop zone and both pickers. `onDataset(ds)` gets each validated Dataset;
 *  `captureObject(name, bytes, onProgress)` photographs a zipped URDF into one (a Promise). */
export function setupInput(DatasetClass, { onDataset, onProblems, captureObject }) {
  Dataset = DatasetClass;
  hooks = { onDataset, onProblems, captureObject };
  limits = JSON.parse(Dataset.file_limits());
  const zone = $("dropzone");
  for (const type of ["dragenter", "dragover"]) {
    zone.addEventListener(type, (e) => { e.preventDefault(); zone.classList.add("over"); });
  }
  zone.addEventListener("dragleave", () => zone.classList.remove("over"));
  // From the keyboard, Tab reaches the two pickers inside the zone ("a folder", "a .zip"), and Enter
  // or Space opens them: the zone itself is only a drop target (a button around them would nest
  // controls, which screen readers cannot announce).
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
