// The Result section's joints table: each fitted joint, and when the truth is known the true joint
// below it with three errors a reader can recompute from the two rows (their definitions are shown
// under the table). Every joint is shown moving a positive amount, its axis the one it turns or
// slides positively about, as a URDF whose limits start at 0 gives it; the true joint is then
// shown the fitted way round. Degrees have one decimal, positions and lengths are in millimetres.
import { $, fmtNum, row } from "./util.js";

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => Math.hypot(a[0], a[1], a[2]);
const unit = (a) => { const n = norm(a) || 1; return a.map((x) => x / n); };
const sub = (a, b) => a.map((x, i) => x - b[i]);

/** The angle (°) between two axes, either way round (the paper's Axis Ang). */
const axisAngle = (a, b) => (Math.atan2(norm(cross(unit(a), unit(b))), Math.abs(dot(unit(a), unit(b)))) * 180) / Math.PI;

/** The shortest distance between two lines (the paper's Axis Pos, here in the lines' unit). */
function lineDistance(oa, da, ob, db) {
  const [a, b] = [unit(da), unit(db)];
  const w = sub(ob, oa), n = cross(a, b), sin = norm(n);
  return sin < 1e-6 ? norm(cross(w, a)) : Math.abs(dot(w, n)) / sin;
}

/** `j` with its motion made positive (its axis flipped where the motion was negative). */
const positive = (j) => (j.motion < 0 ? { ...j, direction: j.direction.map((x) => -x), motion: -j.motion } : j);

const isSlide = (j) => j.type === "prismatic";
const vec = (v, k = 1, digits = 3) => `(${v.map((x) => fmtNum(x * k, digits)).join(", ")})`;
/** A motion in its unit: degrees for a hinge, millimetres for a slide. */
const motionText = (j) => (isSlide(j) ? `${fmtNum(j.motion * 1000, 1)} mm` : `${fmtNum(j.motion, 1)}°`);

/** An error cell: the text, and the number (in the shown unit) for scripts and tests. */
function errorCell(tr, metric, value, unit, note) {
  const cell = tr.insertCell();
  cell.dataset.metric = metric;
  if (value == null) { cell.textContent = note ?? "—"; return; }
  cell.textContent = `${fmtNum(value, 1)} ${unit}`;
  cell.dataset.value = String(value);
}

/** The three errors of fitted joint `j` against true joint `t` (shown the fitted way round). */
function errors(j, t) {
  const same = j.type === t.type;
  return {
    axis: axisAngle(j.direction, t.direction),
    // Between hinge lines only: a slide's line can be anywhere along its direction.
    line: same && !isSlide(j) ? 1000 * lineDistance(j.origin, j.direction, t.origin, t.direction) : null,
    motion: same ? Math.abs(j.motion - t.motion) * (isSlide(j) ? 1000 : 1) : null,
  };
}

/**
 * Fills the joints table with `joints` (joints.json's) and, where `truth` (the true joints) and
 * `scored` (report.json's matched pairs) are given, the true joint matched to each with the errors.
 */
export function fillJoints(joints, truth, scored) {
  const table = $("joints-table");
  const tbody = table.querySelector("tbody");
  tbody.replaceChildren();
  const known = Array.isArray(truth) && truth.length > 0;
  table.classList.toggle("with-truth", known);
  $("joints-defined").hidden = !known;
  joints.forEach((raw, i) => {
    const j = positive(raw);
    const m = Array.isArray(scored) ? scored.find((s) => s.pred === i) : null;
    const tr = row(tbody, [String(j.part), "fitted", j.type, vec(j.direction),
      isSlide(j) ? "—" : `${vec(j.origin, 1000, 1)} mm`, motionText(j)]);
    tr.dataset.joint = String(i);
    if (!known) return;
    let t = m ? positive(truth[m.gt]) : null;
    // An axis and its opposite with the opposite motion are one joint: the truth the fitted way round.
    if (t && dot(t.direction, j.direction) < 0) t = { ...t, direction: t.direction.map((x) => -x), motion: -t.motion };
    const e = t ? errors(j, t) : { axis: null, line: null, motion: null };
    const wrong = t && t.type !== j.type ? `wrong type (${t.type === "prismatic" ? "a slide" : "a hinge"})` : null;
    errorCell(tr, "axis_ang", e.axis, "°", t ? null : "no true joint");
    errorCell(tr, "axis_pos", e.line, "mm", wrong ?? (t && isSlide(t) ? "— (a slide)" : null));
    errorCell(tr, "part_motion", e.motion, isSlide(j) ? "mm" : "°", wrong);
    if (t) {
      const tt = row(tbody, ["", "true", t.type, vec(t.direction), isSlide(t) ? "—" : `${vec(t.origin, 1000, 1)} mm`,
        motionText(t), "", "", ""]);
      tt.className = "truth";
    }
  });
}
