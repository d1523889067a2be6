//! Joint metrics (Axis Ang, Axis Pos, Part Motion) and the matching of predicted to ground-truth joints.
//!
//! Every quantity is computed in `f64` from the `f32` joints so that identical joints give exactly zero and the
//! matching compares sums without rounding ties away. A predicted joint is read with the GT `trans.json`
//! conventions ([`GtJoint`]): degrees for revolute motion, metres for prismatic motion.

use glam::{DQuat, DVec3};

use super::EvalError;
use crate::data::{GtJoint, JointKind};

/// Below this `sin θ` two unit axis directions count as parallel for the line distance; the skew-line formula
/// divides by `sin θ` and loses all precision there (ArtGS uses the same cut-off).
pub(crate) const PARALLEL_SIN_EPS: f64 = 1e-6;

/// Axis Pos is reported in units of 0.1 m, as in the paper's tables.
pub(crate) const AXIS_POS_UNITS_PER_METRE: f64 = 10.0;

/// [`Solver::Auto`] matches by brute force while both sides have at most this many joints (8! = 40 320
/// assignments); beyond it the Hungarian algorithm gives the same optimum in polynomial time.
pub(crate) const BRUTE_FORCE_MAX_JOINTS: usize = 8;

fn dvec(v: glam::Vec3) -> DVec3 {
    DVec3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z))
}

fn unit(v: glam::Vec3) -> DVec3 {
    dvec(v).normalize_or_zero()
}

/// Why a joint cannot be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JointFault {
    /// The axis origin has a NaN or infinite coordinate.
    #[error("axis origin {0} is not finite")]
    Origin(glam::Vec3),
    /// The axis direction is (nearly) zero or not finite.
    #[error("axis direction {0} is zero or not finite")]
    Direction(glam::Vec3),
    /// A joint value is NaN or infinite.
    #[error("joint values start {start} / end {end} are not finite")]
    Values {
        /// Value in the start state.
        start: f32,
        /// Value in the end state.
        end: f32,
    },
}

/// Checks that a joint can be evaluated: finite values and a non-zero direction.
pub(crate) fn validate_joint(joint: &GtJoint) -> Result<(), JointFault> {
    if !joint.origin.is_finite() {
        return Err(JointFault::Origin(joint.origin));
    }
    if !joint.direction.is_finite() || dvec(joint.direction).length() <= 1e-12 {
        return Err(JointFault::Direction(joint.direction));
    }
    if !joint.start.is_finite() || !joint.end.is_finite() {
        return Err(JointFault::Values {
            start: joint.start,
            end: joint.end,
        });
    }
    Ok(())
}

/// Axis Ang (°): the angle between two axis directions, sign-free, i.e. `min(θ, 180° − θ)`.
///
/// Computed as `atan2(|a × b|, |a · b|)`, which equals `min(θ, 180° − θ)` and stays accurate near 0°
/// (where `acos` of the dot product is ill-conditioned). Zero vectors give 0 (callers validate first).
pub fn axis_angle_deg(a: glam::Vec3, b: glam::Vec3) -> f64 {
    let (a, b) = (unit(a), unit(b));
    a.cross(b).length().atan2(a.dot(b).abs()).to_degrees()
}

/// Distance (metres) between the infinite lines `o_a + s·d_a` and `o_b + t·d_b`.
///
/// Skew or intersecting lines: `|(o_b − o_a) · n| / |n|` with `n = d_a × d_b`. Parallel lines (`sin θ` below
/// [`PARALLEL_SIN_EPS`]): the distance from `o_b` to line a, `|(o_b − o_a) × d_a|` — the true separation, where
/// PARIS returns 0.
pub fn axis_line_distance(
    o_a: glam::Vec3,
    d_a: glam::Vec3,
    o_b: glam::Vec3,
    d_b: glam::Vec3,
) -> f64 {
    let (d_a, d_b) = (unit(d_a), unit(d_b));
    let w = dvec(o_b) - dvec(o_a);
    let n = d_a.cross(d_b);
    let sin = n.length();
    if sin < PARALLEL_SIN_EPS {
        w.cross(d_a).length()
    } else {
        w.dot(n).abs() / sin
    }
}

/// Axis Pos (0.1 m units) between two joints' axis lines: [`axis_line_distance`] × 10.
pub fn axis_pos(pred: &GtJoint, gt: &GtJoint) -> f64 {
    axis_line_distance(pred.origin, pred.direction, gt.origin, gt.direction)
        * AXIS_POS_UNITS_PER_METRE
}

/// The rotation of a joint from its start to its end state (identity for a prismatic joint).
fn joint_rotation(joint: &GtJoint) -> DQuat {
    match joint.kind {
        JointKind::Revolute => DQuat::from_axis_angle(
            unit(joint.direction),
            f64::from(joint.motion()).to_radians(),
        ),
        JointKind::Prismatic => DQuat::IDENTITY,
    }
}

/// The translation of a joint along its axis, metres (zero for a revolute joint).
fn joint_translation(joint: &GtJoint) -> DVec3 {
    match joint.kind {
        JointKind::Revolute => DVec3::ZERO,
        JointKind::Prismatic => unit(joint.direction) * f64::from(joint.motion()),
    }
}

/// Geodesic angle (°) between two rotations, in [0°, 180°].
pub(crate) fn rotation_geodesic_deg(a: DQuat, b: DQuat) -> f64 {
    // For unit quaternions the chord min(|a − b|, |a + b|) = 2·sin(θ/4): exactly 0 for equal rotations (a
    // product a⁻¹·b leaves rounding residue) and well conditioned near 0, unlike acos of the dot product.
    let (a, b) = (a.normalize(), b.normalize());
    let chord = (a - b).length().min((a + b).length());
    (4.0 * (0.5 * chord).min(1.0).asin()).to_degrees()
}

/// Part Motion error of a predicted joint against a GT joint, in the GT joint's units.
///
/// Revolute GT: geodesic angle (°) between the rotation by the predicted motion about the predicted axis and the
/// GT one — a flipped axis with a negated angle is the same rotation and scores 0. Prismatic GT:
/// `‖t_pred − t_gt‖` (m) with `t = unit direction × motion`. A prediction of the other type is read as the rigid
/// motion it describes: a prismatic joint does not rotate (its rotation is the identity), a revolute joint does
/// not translate along an axis (its translation is zero), so a type error costs the whole GT motion.
pub fn motion_error(pred: &GtJoint, gt: &GtJoint) -> f64 {
    match gt.kind {
        JointKind::Revolute => rotation_geodesic_deg(joint_rotation(pred), joint_rotation(gt)),
        JointKind::Prismatic => (joint_translation(pred) - joint_translation(gt)).length(),
    }
}

/// Errors of one matched (predicted, GT) joint pair.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JointPairMetrics {
    /// Index of the predicted joint (= predicted movable part).
    pub pred: usize,
    /// Index of the GT joint (= GT movable part).
    pub gt: usize,
    /// Type of the GT joint; the errors below are in its units.
    pub gt_kind: JointKind,
    /// Type of the predicted joint.
    pub pred_kind: JointKind,
    /// Whether the predicted type equals the GT type.
    pub type_correct: bool,
    /// Axis Ang (°).
    pub axis_ang: f64,
    /// Axis Pos (0.1 m units); only for a revolute GT joint (against the predicted axis line whatever its type).
    pub axis_pos: Option<f64>,
    /// Part Motion: degrees for a revolute GT joint, metres for a prismatic one.
    pub part_motion: f64,
}

impl JointPairMetrics {
    /// All metrics of a pair (both joints must be valid, see [`validate_joint`]).
    pub fn new(pred_index: usize, pred: &GtJoint, gt_index: usize, gt: &GtJoint) -> Self {
        JointPairMetrics {
            pred: pred_index,
            gt: gt_index,
            gt_kind: gt.kind,
            pred_kind: pred.kind,
            type_correct: pred.kind == gt.kind,
            axis_ang: axis_angle_deg(pred.direction, gt.direction),
            axis_pos: (gt.kind == JointKind::Revolute).then(|| axis_pos(pred, gt)),
            part_motion: motion_error(pred, gt),
        }
    }

    /// The pair's total error that the matching minimises: Axis Ang + Axis Pos + Part Motion, the numbers the
    /// tables average (in their mixed table units, as the peers sum them).
    pub fn total_error(&self) -> f64 {
        self.axis_ang + self.axis_pos.unwrap_or(0.0) + self.part_motion
    }
}

/// The optimal one-to-one assignment of predicted to GT joints.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JointMatching {
    /// Matched pairs in GT order, with their errors; `min(#pred, #gt)` of them.
    pub pairs: Vec<JointPairMetrics>,
    /// Predicted joints left without a GT joint (more predictions than GT joints).
    pub unmatched_pred: Vec<usize>,
    /// GT joints left without a prediction (fewer predictions than GT joints).
    pub unmatched_gt: Vec<usize>,
    /// Number of matched pairs whose types differ.
    pub type_errors: usize,
}

impl JointMatching {
    /// `(pred, gt)` index pairs, in GT order.
    pub fn index_pairs(&self) -> Vec<(usize, usize)> {
        self.pairs.iter().map(|p| (p.pred, p.gt)).collect()
    }

    /// Sum of the pairs' [`JointPairMetrics::total_error`].
    pub fn total_error(&self) -> f64 {
        self.pairs.iter().map(JointPairMetrics::total_error).sum()
    }
}

/// Matches predicted to GT joints: among all one-to-one assignments of `min(#pred, #gt)` pairs, the one with the
/// fewest type errors and, among those, the lowest total error ([`JointPairMetrics::total_error`]).
///
/// A type-consistent assignment is thus always preferred; when the types cannot all agree (e.g. a revolute GT
/// joint predicted as prismatic), the wrong-type pair is still matched, flagged `type_correct = false` and scored
/// in the GT type's units (see [`motion_error`]). Exact: brute force while both sides have at most
/// [`BRUTE_FORCE_MAX_JOINTS`] joints, the Hungarian algorithm beyond. Ties go to the lexicographically first
/// assignment in brute force.
pub fn match_joints(pred: &[GtJoint], gt: &[GtJoint]) -> Result<JointMatching, EvalError> {
    match_joints_using(pred, gt, Solver::Auto)
}

/// Which exact assignment solver [`match_joints_using`] runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Solver {
    /// Brute force up to [`BRUTE_FORCE_MAX_JOINTS`] joints per side, Hungarian beyond.
    Auto,
    /// Exhaustive search (falls back to Hungarian beyond [`BRUTE_FORCE_MAX_JOINTS`], where it would take hours).
    BruteForce,
    /// Hungarian algorithm.
    Hungarian,
}

/// [`match_joints`] with a chosen solver; both give the same optimal total (used to cross-check them).
pub fn match_joints_using(
    pred: &[GtJoint],
    gt: &[GtJoint],
    solver: Solver,
) -> Result<JointMatching, EvalError> {
    for (side, joints) in [("predicted", pred), ("ground-truth", gt)] {
        for (index, j) in joints.iter().enumerate() {
            validate_joint(j).map_err(|reason| EvalError::InvalidJoint {
                side,
                index,
                reason: reason.to_string(),
            })?;
        }
    }
    let metrics: Vec<Vec<JointPairMetrics>> = pred
        .iter()
        .enumerate()
        .map(|(p, pj)| {
            gt.iter()
                .enumerate()
                .map(|(g, gj)| JointPairMetrics::new(p, pj, g, gj))
                .collect()
        })
        .collect();
    let small = pred.len().max(gt.len()) <= BRUTE_FORCE_MAX_JOINTS;
    let oriented = Oriented::new(&metrics, pred.len(), gt.len());
    let col_of_row = match solver {
        Solver::Auto | Solver::BruteForce if small => assign_brute_force(&oriented),
        _ => assign_hungarian(&oriented),
    };
    let assignment = oriented.assignment(&col_of_row, pred.len());
    Ok(build_matching(metrics, &assignment, pred.len(), gt.len()))
}

/// Turns `assignment[p] = Some(g)` into a [`JointMatching`].
fn build_matching(
    metrics: Vec<Vec<JointPairMetrics>>,
    assignment: &[Option<usize>],
    n_pred: usize,
    n_gt: usize,
) -> JointMatching {
    let mut pairs: Vec<JointPairMetrics> = Vec::new();
    let mut gt_used = vec![false; n_gt];
    for (row, a) in metrics.into_iter().zip(assignment) {
        if let Some(g) = *a
            && let Some(m) = row.into_iter().nth(g)
        {
            gt_used[g] = true;
            pairs.push(m);
        }
    }
    pairs.sort_by_key(|p| p.gt);
    let unmatched_pred = (0..n_pred)
        .filter(|&p| assignment.get(p).copied().flatten().is_none())
        .collect();
    let unmatched_gt = (0..n_gt).filter(|&g| !gt_used[g]).collect();
    let type_errors = pairs.iter().filter(|p| !p.type_correct).count();
    JointMatching {
        pairs,
        unmatched_pred,
        unmatched_gt,
        type_errors,
    }
}

/// Lexicographic cost of a set of pairs: (type errors, total error).
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
struct Cost(usize, f64);

/// The pair metrics seen with the smaller side as rows, so that every row gets a column.
struct Oriented<'a> {
    metrics: &'a [Vec<JointPairMetrics>],
    transposed: bool,
    rows: usize,
    cols: usize,
}

impl<'a> Oriented<'a> {
    fn new(metrics: &'a [Vec<JointPairMetrics>], n_pred: usize, n_gt: usize) -> Self {
        let transposed = n_pred > n_gt;
        let (rows, cols) = if transposed {
            (n_gt, n_pred)
        } else {
            (n_pred, n_gt)
        };
        Self {
            metrics,
            transposed,
            rows,
            cols,
        }
    }

    fn pred_gt(&self, r: usize, c: usize) -> (usize, usize) {
        if self.transposed { (c, r) } else { (r, c) }
    }

    fn pair(&self, r: usize, c: usize) -> &'a JointPairMetrics {
        let (p, g) = self.pred_gt(r, c);
        &self.metrics[p][g]
    }

    /// `col_of_row` back to `assignment[p] = Some(g)` per predicted joint.
    fn assignment(&self, col_of_row: &[usize], n_pred: usize) -> Vec<Option<usize>> {
        let mut assignment = vec![None; n_pred];
        for (r, &c) in col_of_row.iter().enumerate() {
            let (p, g) = self.pred_gt(r, c);
            assignment[p] = Some(g);
        }
        assignment
    }
}

/// Exhaustive search over all injective assignments of rows to columns; returns the column per row.
fn assign_brute_force(oriented: &Oriented<'_>) -> Vec<usize> {
    let (rows, cols) = (oriented.rows, oriented.cols);
    let pair = |r: usize, c: usize| oriented.pair(r, c);
    struct Search<'a, F: Fn(usize, usize) -> &'a JointPairMetrics> {
        rows: usize,
        cols: usize,
        pair: F,
        current: Vec<usize>,
        used: Vec<bool>,
        best: Option<(Cost, Vec<usize>)>,
    }
    impl<'a, F: Fn(usize, usize) -> &'a JointPairMetrics> Search<'a, F> {
        fn go(&mut self, row: usize, cost: Cost) {
            if let Some((best, _)) = &self.best
                && cost.0 > best.0
            {
                return; // more type errors than the best complete assignment: cannot win
            }
            if row == self.rows {
                if self.best.as_ref().is_none_or(|(best, _)| cost < *best) {
                    self.best = Some((cost, self.current.clone()));
                }
                return;
            }
            for c in 0..self.cols {
                if self.used[c] {
                    continue;
                }
                let m = (self.pair)(row, c);
                let next = Cost(
                    cost.0 + usize::from(!m.type_correct),
                    cost.1 + m.total_error(),
                );
                self.used[c] = true;
                self.current.push(c);
                self.go(row + 1, next);
                self.current.pop();
                self.used[c] = false;
            }
        }
    }
    let mut search = Search {
        rows,
        cols,
        pair,
        current: Vec::with_capacity(rows),
        used: vec![false; cols],
        best: None,
    };
    search.go(0, Cost(0, 0.0));
    search.best.map(|(_, cols)| cols).unwrap_or_default()
}

/// The same optimum by the Hungarian algorithm (shortest augmenting paths with potentials, O(n²m)).
/// Type errors are made to dominate by a penalty larger than any possible total error.
fn assign_hungarian(oriented: &Oriented<'_>) -> Vec<usize> {
    let (rows, cols) = (oriented.rows, oriented.cols);
    let max_error = oriented
        .metrics
        .iter()
        .flatten()
        .map(JointPairMetrics::total_error)
        .fold(0.0_f64, f64::max);
    // One type error more must cost more than any difference in total error between two assignments.
    let penalty = 2.0 * (rows as f64 * max_error + 1.0);
    let cost = |r: usize, c: usize| {
        let m = oriented.pair(r, c);
        m.total_error() + if m.type_correct { 0.0 } else { penalty }
    };
    hungarian(rows, cols, cost)
}

/// Minimum-cost assignment of every row (`rows ≤ cols`) to a distinct column; returns the column per row.
fn hungarian(rows: usize, cols: usize, cost: impl Fn(usize, usize) -> f64) -> Vec<usize> {
    // 1-based with a virtual column 0 holding the row being inserted (classic potentials formulation).
    let mut u = vec![0.0_f64; rows + 1];
    let mut v = vec![0.0_f64; cols + 1];
    let mut row_of_col = vec![0_usize; cols + 1];
    let mut way = vec![0_usize; cols + 1];
    for r in 1..=rows {
        row_of_col[0] = r;
        let mut c0 = 0;
        let mut min_to = vec![f64::INFINITY; cols + 1];
        let mut used = vec![false; cols + 1];
        loop {
            used[c0] = true;
            let r0 = row_of_col[c0];
            let mut delta = f64::INFINITY;
            let mut c1 = 0;
            for c in 1..=cols {
                if used[c] {
                    continue;
                }
                let reduced = cost(r0 - 1, c - 1) - u[r0] - v[c];
                if reduced < min_to[c] {
                    min_to[c] = reduced;
                    way[c] = c0;
                }
                if min_to[c] < delta {
                    delta = min_to[c];
                    c1 = c;
                }
            }
            if c1 == 0 {
                break; // unreachable with finite costs; keeps a corrupt cost from looping forever
            }
            for c in 0..=cols {
                if used[c] {
                    u[row_of_col[c]] += delta;
                    v[c] -= delta;
                } else {
                    min_to[c] -= delta;
                }
            }
            c0 = c1;
            if row_of_col[c0] == 0 {
                break;
            }
        }
        // Augment along the alternating path back to the virtual column.
        while c0 != 0 {
            let prev = way[c0];
            row_of_col[c0] = row_of_col[prev];
            c0 = prev;
        }
    }
    let mut col_of_row = vec![0; rows];
    for c in 1..=cols {
        if row_of_col[c] != 0 {
            col_of_row[row_of_col[c] - 1] = c - 1;
        }
    }
    col_of_row
}

#[cfg(test)]
mod tests {
    use super::hungarian;
    use crate::rng::Rng;

    /// Cheapest assignment of every row to a distinct column by exhaustive search.
    fn brute(cost: &[Vec<f64>], row: usize, used: &mut Vec<bool>) -> f64 {
        if row == cost.len() {
            return 0.0;
        }
        let mut best = f64::INFINITY;
        for c in 0..used.len() {
            if !used[c] {
                used[c] = true;
                best = best.min(cost[row][c] + brute(cost, row + 1, used));
                used[c] = false;
            }
        }
        best
    }

    #[test]
    fn hungarian_finds_the_optimum_of_raw_cost_matrices() {
        let mut rng = Rng::new(5);
        for (rows, cols) in [(1, 1), (3, 3), (4, 6), (6, 6), (2, 7)] {
            for _ in 0..20 {
                // Small integer costs make ties common.
                let cost: Vec<Vec<f64>> = (0..rows)
                    .map(|_| (0..cols).map(|_| f64::from(rng.below(5))).collect())
                    .collect();
                let cols_of = hungarian(rows, cols, |r, c| cost[r][c]);
                let mut seen = vec![false; cols];
                for &c in &cols_of {
                    assert!(!seen[c], "column {c} used twice");
                    seen[c] = true;
                }
                let total: f64 = cols_of.iter().enumerate().map(|(r, &c)| cost[r][c]).sum();
                assert_eq!(total, brute(&cost, 0, &mut vec![false; cols]));
            }
        }
    }
}
