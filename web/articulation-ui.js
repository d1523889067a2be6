// The articulation in pictures (part of the Fit section): the start state's mesh moved by the
// joint seeds and by the fitted joints beside an end-state photo, and each part's bake-off —
// the part moved by a hinge and by a slide, side by side, with the evidence and the winner.
// `document.body.dataset.bakeOffs` counts the parts shown; `dataset.moved` lists the moved
// previews drawn ("joint seeds,fitted joints").
import { $, drawRgba } from "./util.js";

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
}

/** Draws a preview of the start mesh moved by the seeds or the fitted joints (others are ignored). */
export function showMoved(ev) {
  const id = MOVED[ev.moved_by];
  if (!id) return;
  $("articulation-panel").hidden = false;
  drawRgba($(id), ev.width, ev.height, ev.render);
  drawRgba($("moved-photo"), ev.width, ev.height, ev.target);
  $(id).setAttribute("aria-label", `The start state's mesh moved by the ${ev.moved_by}, seen from end-state view ${ev.view}`);
  const drawn = new Set((document.body.dataset.moved ?? "").split(",").filter(Boolean));
  drawn.add(ev.moved_by);
  document.body.dataset.moved = [...drawn].join(",");
}

/** A canvas with one RGBA image and a text alternative. */
function picture(ev, rgba, label) {
  const canvas = document.createElement("canvas");
  canvas.setAttribute("role", "img");
  canvas.setAttribute("aria-label", label);
  drawRgba(canvas, ev.width, ev.height, rgba);
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
    const td = cell(picture(ev, ev[type], `Part ${ev.part} moved by the ${TYPE[type]} candidate`),
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
