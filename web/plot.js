// A small line-plot helper for the loss curves: x linear, y on a log axis, one colour per series.
// `series` is [{label, colour, points: [[x, y], ...]}]; points with y <= 0 or non-finite are skipped.

/** Sizes the canvas's backing store to its CSS size × devicePixelRatio; returns [width, height, dpr]. */
export function fitCanvas(canvas) {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w) canvas.width = w;
  if (canvas.height !== h) canvas.height = h;
  return [w, h, dpr];
}

function fmtTick(v) {
  if (v >= 1000 || v < 0.01) return v.toExponential(0).replace("e+", "e");
  return String(Number(v.toPrecision(2)));
}

/** Linear ticks over [a, b]: about five at 1, 2 or 5 × a power of ten. */
function linearTicks(a, b) {
  const raw = (b - a) / 5, p = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map((m) => m * p).find((s) => s >= raw) ?? raw;
  const ticks = [];
  for (let v = Math.ceil(a / step) * step; v <= b + 1e-9 * step; v += step) ticks.push(Number(v.toPrecision(6)));
  return ticks;
}

/** Log ticks over [ly0, ly1] (log10 units): powers of ten, then 2× and 5×, then finer, until at
 *  least two fall in the range, so the axis always has a scale to read. */
function logTicks(ly0, ly1) {
  for (const mults of [[1], [1, 2, 5], [1, 1.5, 2, 3, 5, 7]]) {
    const ticks = [];
    for (let e = Math.floor(ly0); e <= Math.ceil(ly1); e++) {
      for (const m of mults) {
        const v = m * 10 ** e, lv = Math.log10(v);
        if (lv >= ly0 && lv <= ly1) ticks.push(v);
      }
    }
    if (ticks.length >= 2 && (mults.length > 1 || ly1 - ly0 >= 1.5)) return ticks;
  }
  // A range narrower than the finest steps: its two ends.
  return [10 ** ly0, 10 ** ly1].map((v) => Number(v.toPrecision(3)));
}

/** Draws `series` with labelled axes: `xLabel` under the x ticks, `yLabel` up the left side;
 *  `marks` ([{x, label}]) as grey vertical lines labelled where each stage began. */
export function drawLogPlot(canvas, series, { xLabel = "", yLabel = "loss (log scale)", marks = [] } = {}) {
  const [w, h, dpr] = fitCanvas(canvas);
  const ctx = canvas.getContext("2d");
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.clearRect(0, 0, w, h);
  ctx.scale(dpr, dpr);
  const W = w / dpr, H = h / dpr;
  const pad = { l: 60, r: 12, t: 22, b: 38 };
  const pw = Math.max(10, W - pad.l - pad.r), ph = Math.max(10, H - pad.t - pad.b);
  ctx.font = "11px system-ui, sans-serif";

  let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
  for (const s of series) for (const [x, y] of s.points) {
    if (!(y > 0) || !Number.isFinite(y) || !Number.isFinite(x)) continue;
    x0 = Math.min(x0, x); x1 = Math.max(x1, x);
    y0 = Math.min(y0, y); y1 = Math.max(y1, y);
  }
  ctx.strokeStyle = "#9aa8b5";
  ctx.lineWidth = 1;
  ctx.strokeRect(pad.l, pad.t, pw, ph);
  if (!Number.isFinite(x0)) {
    ctx.fillStyle = "#6b7680";
    ctx.fillText("waiting for the first loss…", pad.l + 8, pad.t + 16);
    return;
  }
  if (x1 <= x0) x1 = x0 + 1;
  let ly0 = Math.log10(y0), ly1 = Math.log10(y1);
  if (ly1 - ly0 < 0.3) { const m = (ly0 + ly1) / 2; ly0 = m - 0.15; ly1 = m + 0.15; }
  ly0 -= 0.05 * (ly1 - ly0); ly1 += 0.05 * (ly1 - ly0);
  const X = (x) => pad.l + ((x - x0) / (x1 - x0)) * pw;
  const Y = (y) => pad.t + (1 - (Math.log10(y) - ly0) / (ly1 - ly0)) * ph;

  // y ticks: at least two, labelled.
  ctx.fillStyle = "#4a5560";
  ctx.textAlign = "right";
  ctx.textBaseline = "middle";
  for (const v of logTicks(ly0, ly1)) {
    const y = Y(v);
    ctx.strokeStyle = "#e4e9ee";
    ctx.beginPath(); ctx.moveTo(pad.l, y); ctx.lineTo(pad.l + pw, y); ctx.stroke();
    ctx.fillText(fmtTick(v), pad.l - 4, y);
  }
  // Stage marks: a grey line and the stage's name at the top of the plot area.
  ctx.textAlign = "left";
  ctx.textBaseline = "top";
  for (const m of marks) {
    if (!(m.x >= x0 && m.x <= x1)) continue;
    ctx.strokeStyle = "#b7c0c9";
    ctx.beginPath(); ctx.moveTo(X(m.x), pad.t); ctx.lineTo(X(m.x), pad.t + ph); ctx.stroke();
    ctx.fillStyle = "#6b7680";
    ctx.fillText(m.label, X(m.x) + 3, pad.t + 3);
  }
  ctx.fillStyle = "#4a5560";
  ctx.textAlign = "center";
  ctx.textBaseline = "top";
  for (const v of linearTicks(x0, x1)) {
    ctx.fillRect(X(v) - 0.5, pad.t + ph, 1, 4);
    ctx.fillText(String(v), X(v), pad.t + ph + 5);
  }
  ctx.fillText(xLabel, pad.l + pw / 2, pad.t + ph + 20);
  ctx.save();
  ctx.translate(11, pad.t + ph / 2);
  ctx.rotate(-Math.PI / 2);
  ctx.fillText(yLabel, 0, -6);
  ctx.restore();

  for (const s of series) {
    ctx.strokeStyle = s.colour;
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    let pen = false;
    for (const [x, y] of s.points) {
      if (!(y > 0) || !Number.isFinite(y)) { pen = false; continue; }
      if (pen) ctx.lineTo(X(x), Y(y)); else { ctx.moveTo(X(x), Y(y)); pen = true; }
    }
    ctx.stroke();
  }

  // Legend along the top.
  ctx.textAlign = "left";
  ctx.textBaseline = "middle";
  let lx = pad.l;
  for (const s of series) {
    if (s.points.length === 0) continue;
    ctx.fillStyle = s.colour;
    ctx.fillRect(lx, 7, 14, 4);
    ctx.fillStyle = "#1d232a";
    ctx.fillText(s.label, lx + 18, 9);
    lx += 26 + ctx.measureText(s.label).width;
  }
}
