// The articulation in pictures (part of the Fit section): the start state's mesh moved by the
// joint seeds and by the fitted joints beside an end-state photo, and each part's bake-off —
// the part moved by a hinge and by a slide, side by side, with the evidence and the winner.
// Each moved render is tinted by part (the viewer's part colours) and carries the moved parts'
// joint axes (orange: hinge, blue: slide, as in the viewer).
// `document.body.dataset.bakeOffs` counts the parts shown; `dataset.moved` lists the moved
// previews drawn ("joint seeds,fitted joints"); `dataset.movedAxes` counts the axes last drawn.
import { $, drawRgba } from "./util.js";

const AXIS_COLOUR = { revolute: "#e8710a", prismatic: "#1a73e8" };
const EMPTY = 255;
let partColours = []; // [[r, g, b] in 0..255] per part; none: no tint

/** The part colours the moved renders are tinted with (the viewer's legend's). */
export function setPartColours(colours) {
  partColours = colours ?? [];
}

/**
 * Draws a render with its marks: each covered pixel mixed 40 % with its part's colour, then the
 * axes as segments. The canvas is drawn at a whole multiple of the render's size (≥ 256 px wide)
 * so the lines stay thin.
 */
function drawMarked(canvas, width, height, rgba, parts, axes) {
  const tinted = new Uint8ClampedArray(rgba.subarray ? rgba.subarray(0, width * height * 4) : rgba);
  if (parts && parts.length === width * height) {
    for (let i = 0; i < parts.length; i++) {
      const c = parts[i] === EMPTY ? null : partColours[parts[i] % Math.max(1, partColours.length)];
      if (!c) continue;
      for (let ch = 0; ch < 3; ch++) tinted[4 * i + ch] = 0.6 * tinted[4 * i + ch] + 0.4 * c[ch];
    }
  }
  const image = document.createElement("canvas");
  if (!drawRgba(image, width, height, tinted)) return;
  const scale = Math.max(1, Math.ceil(256 / width));
  canvas.width = width * scale;
  canvas.height = height * scale;
  const g = canvas.getContext("2d");
  g.imageSmoothingEnabled = false;
  g.drawImage(image, 0, 0, canvas.width, canvas.height);
  g.lineWidth = Math.max(2, scale / 2);
  g.lineCap = "round";
  for (const a of axes ?? []) {
    g.strokeStyle = AXIS_COLOUR[a.kind] ?? "#000";
    g.beginPath();
    g.moveTo(a.from[0] * scale, a.from[1] * scale);
    g.lineTo(a.to[0] * scale, a.to[1] * scale);
    g.stroke();
    if (a.kind === "prismatic") { // an arrow head: the slide's direction
      const dx = a.to[0] - a.from[0], dy = a.to[1] - a.from[1], l = Math.hypot(dx, dy) || 1;
      const [ux, uy] = [dx / l, dy / l], h = 3 * g.lineWidth;
      g.beginPath();
      g.moveTo(a.to[0] * scale - h * (ux - 0.6 * uy), a.to[1] * scale - h * (uy + 0.6 * ux));
      g.lineTo(a.to[0] * scale, a.to[1] * scale);
      g.lineTo(a.to[0] * scale - h * (ux + 0.6 * uy), a.to[1] * scale - h * (uy - 0.6 * ux));
      g.stroke();
    }
  }
}

const TYPE = { revolute: "hinge (revolute)", prismatic: "slide (prismatic)" };
const MOVED = { "joint seeds": "moved-seeds", "fitted joints": "moved-fitted" };

/** Empties the panel before a fit. */
export function resetArticulation() {
  $("articulation-panel").hidden = true;
  $("bake-off-table").querySelector("tbody").replaceChildren();
  for (const id of ["moved-seeds", "moved-fitted", "moved-photo"]) {
    const c = $(id);
    c.width = 1; c.height = 1;
  }
  delete document.body.dataset.bakeOffs;
  delete document.body.dataset.moved;
  delete document.body.dataset.movedAxes;
}

/** Draws a preview of the start mesh moved by the seeds or the fitted joints (others are ignored). */
export function showMoved(ev) {
  const id = MOVED[ev.moved_by];
  if (!id) return;
  $("articulation-panel").hidden = false;
  drawMarked($(id), ev.width, ev.height, ev.render, ev.parts, ev.axes);
  drawMarked($("moved-photo"), ev.width, ev.height, ev.target, null, null);
  const axes = (ev.axes ?? []).map((a) => `part ${a.part}: ${a.kind === "revolute" ? "hinge" : "slide"}`);
  $(id).setAttribute("aria-label", `The start state's mesh moved by the ${ev.moved_by}, seen from end-state view ` +
    `${ev.view}, coloured by part` + (axes.length ? `, axes drawn (${axes.join(", ")})` : ""));
  document.body.dataset.movedAxes = String(axes.length);
  const drawn = new Set((document.body.dataset.moved ?? "").split(",").filter(Boolean));
  drawn.add(ev.moved_by);
  document.body.dataset.moved = [...drawn].join(",");
}

/** A canvas with one RGBA image (with its marks, when given) and a text alternative. */
function picture(ev, rgba, label, parts = null, axes = null) {
  const canvas = document.createElement("canvas");
  canvas.setAttribute("role", "img");
  canvas.setAttribute("aria-label", label);
  drawMarked(canvas, ev.width, ev.height, rgba, parts, axes);
  return canvas;
}

/** "image loss 0.0123; depth residual 1.4 mm" (what is known of one candidate). */
function evidence(loss, residualMm) {
  const parts = [];
  if (loss != null) parts.push(`image loss ${Number(loss).toPrecision(3)}`);
  if (residualMm != null) parts.push(`depth residual ${Number(residualMm).toFixed(1)} mm`);
  return parts.join("; ") || "no evidence";
}

/** Adds one part's bake-off row: both candidates' renders and evidence, the photo, the winner. */
export function addBakeOff(ev) {
  $("articulation-panel").hidden = false;
  const row = document.createElement("tr");
  row.dataset.part = ev.part;
  const cell = (...children) => {
    const td = document.createElement("td");
    td.append(...children);
    row.append(td);
    return td;
  };
  const head = document.createElement("th");
  head.scope = "row";
  head.textContent = `part ${ev.part}`;
  row.append(head);
  for (const type of ["revolute", "prismatic"]) {
    const loss = ev[`${type}_loss`], residual = ev[`${type}_residual_mm`];
    const td = cell(picture(ev, ev[type], `Part ${ev.part} moved by the ${TYPE[type]} candidate, its axis drawn`,
      ev[`${type}_parts`], ev[`${type}_axes`]),
      document.createElement("br"), evidence(loss, residual));
    td.className = "candidate" + (ev.winner === type ? " winner" : "");
    td.dataset.kind = type;
  }
  cell(picture(ev, ev.target, `End-state photo (view ${ev.view})`));
  const verdict = document.createElement("b");
  verdict.textContent = TYPE[ev.winner] ?? ev.winner;
  cell(verdict, document.createElement("br"), `decided by ${ev.decided_by}`);
  $("bake-off-table").querySelector("tbody").append(row);
  document.body.dataset.bakeOffs = String($("bake-off-table").querySelectorAll("tbody tr").length);
}
