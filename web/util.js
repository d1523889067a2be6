// Small DOM helpers shared by the page's modules.

export const $ = (id) => document.getElementById(id);

/** Sets a status box's text and its ok/fail colour. */
export function show(el, text, cls) {
  el.hidden = false;
  el.textContent = text;
  el.className = "status" + (cls ? " " + cls : "");
}

/** The message of anything thrown (wasm-bindgen throws Error objects; be lenient about the rest). */
export function errorText(e) {
  if (e == null) return "unknown error";
  if (typeof e === "string") return e;
  return String(e.message ?? e);
}

/** Draws an RGBA image (Uint8ClampedArray or Uint8Array, width*height*4) into a canvas of that size. */
export function drawRgba(canvas, width, height, rgba) {
  if (!(width > 0 && height > 0) || !rgba || rgba.length < width * height * 4) return false;
  const data = rgba instanceof Uint8ClampedArray ? rgba : new Uint8ClampedArray(rgba);
  if (canvas.width !== width) canvas.width = width;
  if (canvas.height !== height) canvas.height = height;
  const pixels = data.length === width * height * 4 ? data : data.slice(0, width * height * 4);
  canvas.getContext("2d").putImageData(new ImageData(pixels, width, height), 0, 0);
  return true;
}

/** "12 s", "3 min 05 s", "1 h 02 min". */
export function fmtDuration(s) {
  if (s == null || !Number.isFinite(s)) return "—";
  s = Math.max(0, s);
  if (s < 60) return `${s.toFixed(s < 10 ? 1 : 0)} s`;
  if (s < 3600) return `${Math.floor(s / 60)} min ${String(Math.floor(s % 60)).padStart(2, "0")} s`;
  return `${Math.floor(s / 3600)} h ${String(Math.floor((s % 3600) / 60)).padStart(2, "0")} min`;
}

export function fmtNum(v, digits = 3) {
  if (v == null || !Number.isFinite(Number(v))) return "—";
  return Number(v).toFixed(digits);
}

// --- the error banner ---------------------------------------------------------------------

/** Shows the top banner with `message`; with `action` ({label, run}) a button next to it. */
export function showBanner(message, action) {
  const box = $("error");
  $("error-text").textContent = message;
  const button = $("error-action");
  if (action) {
    button.textContent = action.label;
    button.onclick = action.run;
    button.hidden = false;
  } else {
    button.hidden = true;
    button.onclick = null;
  }
  box.hidden = false;
}

export function hideBanner() {
  $("error").hidden = true;
}

/** Frees a wasm handle (Dataset, FitResult, Viewer) unless it is already gone. */
export function freeQuietly(handle) {
  try { handle?.free?.(); } catch { /* already freed */ }
}

/** Appends a row of text cells to `tbody`; returns it. */
export function row(tbody, cells) {
  const tr = tbody.insertRow();
  for (const c of cells) tr.insertCell().textContent = c;
  return tr;
}
