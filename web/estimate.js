// How long a fit will take, shown beside the preset before it starts. A fit's cost grows with its
// work, W = (2 × (reconstruction + recovery iterations) + articulation iterations) × side² (side: the
// working size; full-size views count as 512 px), faster than linearly because the meshes grow
// with it: t ≈ rate × (W / 10⁶)^1.5. On a software adapter the rate comes from two measured fits
// (headless Chromium on SwiftShader, 2-core VM, 2026-12-06: tiny ≈ 30 s, fast ≈ 25–32 min); on any
// adapter, a finished fit replaces it with that adapter's own (kept in localStorage).
const SOFTWARE_RATE = 345; // seconds per (10⁶ work units)^1.5, from the tiny fit; predicts fast at 27 min
const KEY = "artmesh.fit-rate.";

function work(b) {
  const side = b.max_size || 512;
  return (2 * (b.reconstruction_iterations + b.recovery_iterations) + b.articulation_iterations) * side * side / 1e6;
}

function fmt(s) {
  if (s < 90) return `${Math.max(5, Math.round(s / 5) * 5)} s`;
  if (s < 90 * 60) return `${Math.round(s / 60)} min`;
  return `${(s / 3600).toFixed(1)} h`;
}

function storedRate(adapter) {
  try { return Number(localStorage.getItem(KEY + adapter)) || null; } catch { return null; }
}

/** "about 30 s on this adapter (…)" for `budget` (a preset's budget), or "" when nothing is known. */
export function estimateText(adapter, software, budget) {
  if (!adapter || !budget) return "";
  const own = storedRate(adapter);
  const rate = own ?? (software ? SOFTWARE_RATE : null);
  if (!rate) return "Time: not known for this GPU yet; the first fit's time sets the estimate.";
  const t = rate * work(budget) ** 1.5;
  return `Estimated fit time: about ${fmt(t)} ` +
    (own ? "on this GPU (from its last fit)." : "on a software adapter (measured on a 2-core machine).");
}

/** Remembers how fast this adapter fitted `budget` in `seconds`, for the next estimates. */
export function recordFit(adapter, budget, seconds) {
  const w = work(budget);
  if (!adapter || !(w > 0) || !(seconds > 0)) return;
  try { localStorage.setItem(KEY + adapter, String(seconds / w ** 1.5)); } catch { /* storage off: no estimate */ }
}
