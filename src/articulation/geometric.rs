//! Joints from the measured surfaces ([`super::observed`]): per movable part, a revolute and a
//! prismatic model fitted to the part's start- and end-state points by trimmed point-to-plane
//! registration in both directions, and the joint type from their residuals.
//!
//! The starts come from [`initial_candidates`] (principal frames, sign flips, trimmed
//! point-to-point ICP). Each model then takes Levenberg–Marquardt steps in its own parameters —
//! revolute: angle, axis tilt (2), pivot shift across the axis (2); prismatic: the translation —
//! with correspondences found again before every step. Start points are moved by g⁺ onto the
//! end cloud and end points by g⁻ onto the start cloud, so a surface seen in one state only
//! pulls on neither model more than the trimming allows.
//!
//! **Type decision.** A slide is a limit of hinges (pivot far away, angle small), so a revolute
//! fit can always come close to a prismatic one but not the reverse. The prismatic model wins
//! when its residual is at most [`PRISMATIC_SLACK`] times the revolute one; the margin is how
//! far the residual ratio lies from that threshold on a log scale, in units of the threshold.
//! A part whose not moving fits about as well as either model (a knob symmetric about its own
//! axis) is not observable here: its type is left to the photometric bake-off.

use glam::{DQuat, DVec3, Vec3};
use serde::Serialize;

use super::init::{JointCandidates, initial_candidates};
use super::motion::{PartMotion, rotation_axis_angle};
use super::observed::PartCloud;
use crate::data::JointKind;
use crate::eval::chamfer::KdTree;

/// The prismatic model wins while its residual is at most this many times the revolute one.
pub const PRISMATIC_SLACK: f64 = 1.2;

/// Decisions with a margin under this are flagged.
pub const SMALL_MARGIN: f64 = 0.5;

/// Fewer points than this in either state: the part is too small in the data to fit here.
pub const MIN_POINTS: usize = 30;

/// Fraction of matches kept (the rest: surface seen in one state only).
const KEEP: f64 = 0.85;

/// One movable part's geometric fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GeometricJoint {
    /// The best rotation about a line, and the best translation.
    pub revolute: PartMotion,
    pub prismatic: PartMotion,
    /// Trimmed RMS point-to-plane distance (m) of each model and of not moving, both directions.
    pub revolute_residual: f64,
    pub prismatic_residual: f64,
    pub identity_residual: f64,
    /// The type the residuals pick.
    pub kind: JointKind,
    /// |ln(ratio / slack)| / ln(slack) with ratio = prismatic / revolute residual: 0 on the
    /// threshold, 1 when one model fits [`PRISMATIC_SLACK`] times better than the threshold.
    pub margin: f64,
    /// Whether moving fits clearly better than not moving.
    pub observable: bool,
    /// Points in the start and end clouds.
    pub points: [usize; 2],
}

impl GeometricJoint {
    /// The fitted motion of `kind`.
    pub fn motion(&self, kind: JointKind) -> PartMotion {
        match kind {
            JointKind::Revolute => self.revolute,
            JointKind::Prismatic => self.prismatic,
        }
    }

    /// Whether the data settle this joint: both states measured, the motion visible and the
    /// type picked by a clear margin.
    pub fn settled(&self) -> bool {
        self.observable
            && self.margin >= SMALL_MARGIN
            && self.points.iter().all(|&n| n >= MIN_POINTS)
    }
}

/// The parameters a model steps in, around a current motion.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Model {
    Revolute,
    Prismatic,
}

impl Model {
    fn dims(self) -> usize {
        match self {
            Model::Revolute => 5,
            Model::Prismatic => 3,
        }
    }

    /// `m` changed by `delta` in this model's local parameters.
    fn step(self, m: &PartMotion, delta: &[f64]) -> PartMotion {
        match self {
            Model::Prismatic => {
                PartMotion::prismatic(m.translation + DVec3::new(delta[0], delta[1], delta[2]))
            }
            Model::Revolute => {
                let (axis, angle) = rotation_axis_angle(m.rotation);
                let (u, v) = axis.any_orthonormal_pair();
                let axis = (axis + delta[1] * u + delta[2] * v).normalize();
                PartMotion {
                    rotation: DQuat::from_axis_angle(axis, angle + delta[0]),
                    pivot: m.pivot + delta[3] * u + delta[4] * v,
                    translation: DVec3::ZERO,
                }
            }
        }
    }
}

/// One match: a source point (in its own state), the target point and the target's normal, their
/// colour difference, and whether the source is the start cloud (moved by g⁺) or the end cloud
/// (moved by g⁻).
struct Match {
    x: DVec3,
    q: DVec3,
    n: DVec3,
    /// Mean absolute colour difference of the two points (0 without colours).
    color: f64,
    forward: bool,
}

impl Match {
    fn residual(&self, m: &PartMotion) -> f64 {
        let y = if self.forward {
            m.forward(self.x)
        } else {
            m.backward(self.x)
        };
        self.n.dot(y - self.q)
    }
}

/// A part's two clouds with their search trees.
pub struct CloudPair<'a> {
    start: &'a PartCloud,
    end: &'a PartCloud,
    start_tree: KdTree,
    end_tree: KdTree,
}

impl<'a> CloudPair<'a> {
    /// Search trees over both clouds.
    pub fn new(start: &'a PartCloud, end: &'a PartCloud) -> Self {
        Self {
            start,
            end,
            start_tree: KdTree::new(&start.points),
            end_tree: KdTree::new(&end.points),
        }
    }

    /// The kept (closest [`KEEP`]) matches of `m`, per direction.
    fn matches(&self, m: &PartMotion) -> Vec<Match> {
        let mut all = Vec::new();
        for forward in [true, false] {
            let (from, to, tree) = if forward {
                (self.start, self.end, &self.end_tree)
            } else {
                (self.end, self.start, &self.start_tree)
            };
            let mut side: Vec<(f64, Match)> = from
                .points
                .iter()
                .enumerate()
                .filter_map(|(k, p)| {
                    let x = p.as_dvec3();
                    let y = if forward { m.forward(x) } else { m.backward(x) };
                    let (i, d2) = tree.nearest_index(y.as_vec3())?;
                    let color = from
                        .colors
                        .get(k)
                        .zip(to.colors.get(i))
                        .map_or(0.0, |(a, b)| f64::from((*a - *b).abs().element_sum()) / 3.0);
                    Some((
                        d2,
                        Match {
                            x,
                            q: to.points[i].as_dvec3(),
                            n: to.normals[i].as_dvec3(),
                            color,
                            forward,
                        },
                    ))
                })
                .collect();
            side.sort_by(|a, b| a.0.total_cmp(&b.0));
            side.truncate((side.len() as f64 * KEEP).ceil() as usize);
            all.extend(side.into_iter().map(|(_, m)| m));
        }
        all
    }

    /// Mean colour difference (0–1 per channel, mean over RGB) between each point moved by `m`
    /// and its match in the other state, over the kept matches of both directions: what tells
    /// apart motions the shape alone cannot (a knob's pointer mark, a door's two faces).
    pub fn color_residual(&self, m: &PartMotion) -> f64 {
        let matches = self.matches(m);
        matches.iter().map(|c| c.color).sum::<f64>() / matches.len().max(1) as f64
    }

    /// Trimmed RMS point-to-plane residual (m) of `m`, both directions.
    pub fn residual(&self, m: &PartMotion) -> f64 {
        rms(&self.matches(m), m)
    }
}

fn rms(matches: &[Match], m: &PartMotion) -> f64 {
    let sum: f64 = matches.iter().map(|c| c.residual(m).powi(2)).sum();
    (sum / matches.len().max(1) as f64).sqrt()
}

/// Solves the n × n system `a x = b` (n ≤ 5) by Gaussian elimination with partial pivoting;
/// `None` when singular.
fn solve(mut a: [[f64; 5]; 5], mut b: [f64; 5], n: usize) -> Option<[f64; 5]> {
    for col in 0..n {
        let pivot = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let (top, below) = a.split_at_mut(col + 1);
        let pivot_row = top[col];
        for (offset, row) in below.iter_mut().take(n - col - 1).enumerate() {
            let f = row[col] / pivot_row[col];
            for (x, p) in row[col..n].iter_mut().zip(&pivot_row[col..n]) {
                *x -= f * p;
            }
            b[col + 1 + offset] -= f * b[col];
        }
    }
    let mut x = [0.0; 5];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Up to `steps` Levenberg–Marquardt steps on `model` from `m`, correspondences found again
/// before every step.
fn refine(pair: &CloudPair, model: Model, mut m: PartMotion, steps: usize) -> PartMotion {
    let n = model.dims();
    let mut lambda = 1e-3;
    const H: f64 = 1e-7;
    for _ in 0..steps {
        let matches = pair.matches(&m);
        if matches.len() < n {
            break;
        }
        let (mut jtj, mut jtr) = ([[0.0; 5]; 5], [0.0; 5]);
        let nudged: Vec<PartMotion> = (0..n)
            .map(|j| {
                let mut d = [0.0; 5];
                d[j] = H;
                model.step(&m, &d)
            })
            .collect();
        for c in &matches {
            let r = c.residual(&m);
            let mut row = [0.0; 5];
            for j in 0..n {
                row[j] = (c.residual(&nudged[j]) - r) / H;
            }
            for i in 0..n {
                jtr[i] += row[i] * r;
                for j in 0..n {
                    jtj[i][j] += row[i] * row[j];
                }
            }
        }
        let cost = rms(&matches, &m);
        let mut improved = false;
        for _ in 0..8 {
            let mut a = jtj;
            for (i, row) in a.iter_mut().enumerate().take(n) {
                row[i] += lambda * jtj[i][i].max(1e-12);
            }
            let Some(delta) = solve(a, jtr.map(|v| -v), n) else {
                lambda *= 10.0;
                continue;
            };
            let next = model.step(&m, &delta[..n]);
            if rms(&matches, &next) < cost {
                let size: f64 = delta[..n].iter().map(|d| d * d).sum::<f64>().sqrt();
                m = next;
                lambda = (lambda / 3.0).max(1e-9);
                improved = size > 1e-9;
                break;
            }
            lambda *= 4.0;
        }
        if !improved {
            break;
        }
    }
    m
}

/// Every `step`-th point of a cloud.
fn thinned(cloud: &PartCloud, step: usize) -> PartCloud {
    let step = step.max(1);
    PartCloud {
        points: cloud.points.iter().step_by(step).copied().collect(),
        normals: cloud.normals.iter().step_by(step).copied().collect(),
        colors: cloud.colors.iter().step_by(step).copied().collect(),
        pixels: cloud.pixels,
        labelled: cloud.labelled,
    }
}

/// Points per state the multi-start search works on.
const SEARCH_POINTS: usize = 1500;

/// The revolute model's starting points besides the registration's: turns of 30° to 330°
/// about each principal axis of the start cloud through its centroid. A part with a small
/// feature on a symmetric body (a knob's fin) registers best at no rotation at all; from
/// these starts the fit finds the turn the feature made.
fn revolute_starts(start: &PartCloud) -> Vec<PartMotion> {
    let Some(frame) = super::init::principal_frame(&start.points) else {
        return Vec::new();
    };
    (0..3)
        .flat_map(|a| {
            (1..12).map(move |k| {
                PartMotion::revolute(
                    frame.axes.col(a),
                    frame.centroid,
                    f64::from(k * 30).to_radians(),
                )
            })
        })
        .collect()
}

/// The rest of the object in both states, which a part's hinge joins it to.
pub struct Anchor {
    start: KdTree,
    end: KdTree,
}

impl Anchor {
    /// Search trees over the other parts' points in the start and end states.
    pub fn new(start: &[Vec3], end: &[Vec3]) -> Self {
        Self {
            start: KdTree::new(start),
            end: KdTree::new(end),
        }
    }

    /// How far (m) the axis of `m` passes from the rest of the object, the larger of the two
    /// states' gaps: a hinge stays where its part meets the rest in both, while a false axis
    /// near another moving part (a drawer pulled out in front of a door) is near it in one.
    fn gap(&self, m: &PartMotion, pair: &CloudPair) -> f64 {
        axis_gap(m, pair.start, &self.start).max(axis_gap(m, pair.end, &self.end))
    }
}

/// How far (m) the axis of `m`, over the stretch of it beside the part, passes from `anchor`.
fn axis_gap(m: &PartMotion, part: &PartCloud, anchor: &KdTree) -> f64 {
    let (axis, _) = rotation_axis_angle(m.rotation);
    let along: Vec<f64> = part
        .points
        .iter()
        .map(|p| (p.as_dvec3() - m.pivot).dot(axis))
        .collect();
    let (lo, hi) = along
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| {
            (a.min(t), b.max(t))
        });
    if anchor.is_empty() || !lo.is_finite() {
        return 0.0;
    }
    (0..=32)
        .map(|i| {
            let t = lo + (hi - lo) * f64::from(i) / 32.0;
            anchor.nearest_distance_squared((m.pivot + axis * t).as_vec3())
        })
        .fold(f64::INFINITY, f64::min)
        .sqrt()
}

/// Residuals within this factor of the best (plus a tenth of a millimetre) fit as well: a plain
/// door slab fits turned about its hinge and, flipped, about a line in front of it.
const SAME_FIT: f64 = 1.5;

/// Colour residuals this close (0–1 scale) count as equal.
const SAME_COLOR: f64 = 0.005;

/// Of fitted motions and their residuals, among those fitting as well as the best
/// ([`SAME_FIT`]): those whose axis passes closest to the rest of the object ([`axis_gap`],
/// within 5 mm), then those whose colours agree best ([`CloudPair::color_residual`]), then the
/// smallest turn (joints rarely turn further).
fn most_plausible(
    fits: &[(f64, PartMotion)],
    pair: &CloudPair,
    anchor: Option<&Anchor>,
) -> Option<PartMotion> {
    let best = fits.iter().map(|t| t.0).fold(f64::INFINITY, f64::min);
    let good: Vec<(f64, PartMotion)> = fits
        .iter()
        .filter(|t| t.0 <= SAME_FIT * best + 1e-4)
        .map(|t| (anchor.map_or(0.0, |a| a.gap(&t.1, pair)), t.1))
        .collect();
    let nearest = good.iter().map(|g| g.0).fold(f64::INFINITY, f64::min);
    let hinged: Vec<(f64, PartMotion)> = good
        .iter()
        .filter(|g| g.0 <= nearest + 0.005)
        .map(|g| (pair.color_residual(&g.1), g.1))
        .collect();
    let truest = hinged.iter().map(|g| g.0).fold(f64::INFINITY, f64::min);
    hinged
        .iter()
        .filter(|g| g.0 <= truest + SAME_COLOR)
        .min_by(|x, y| {
            rotation_axis_angle(x.1.rotation)
                .1
                .total_cmp(&rotation_axis_angle(y.1.rotation).1)
        })
        .map(|g| g.1)
}

/// Distinct starts refined fully after the coarse search.
const FINALISTS: usize = 12;

/// The best revolute motion: the registration seed and every turn of [`revolute_starts`]
/// refined briefly on thinned clouds; the best few distinct ones (within twice the best
/// residual) refined fully, then [`most_plausible`] of those.
fn best_revolute(pair: &CloudPair, seed: PartMotion, anchor: Option<&Anchor>) -> PartMotion {
    let step = pair.start.points.len().max(pair.end.points.len()) / SEARCH_POINTS + 1;
    let (a, b) = (thinned(pair.start, step), thinned(pair.end, step));
    let coarse = CloudPair::new(&a, &b);
    let mut tried: Vec<(f64, PartMotion)> = std::iter::once(seed)
        .chain(revolute_starts(pair.start))
        .map(|m| {
            let m = refine(&coarse, Model::Revolute, m, 6);
            (coarse.residual(&m), m)
        })
        .collect();
    tried.sort_by(|x, y| x.0.total_cmp(&y.0));
    let best = tried.first().map_or(f64::INFINITY, |t| t.0);
    let mut finalists: Vec<PartMotion> = Vec::new();
    for (r, m) in &tried {
        let distinct = finalists
            .iter()
            .all(|f| f.rotation.angle_between(m.rotation) > 10f64.to_radians());
        if *r <= 2.0 * best + 1e-5 && distinct && finalists.len() < FINALISTS {
            finalists.push(*m);
        }
    }
    let fits: Vec<(f64, PartMotion)> = finalists
        .into_iter()
        .map(|m| {
            let m = refine(pair, Model::Revolute, m, 40);
            (pair.residual(&m), m)
        })
        .collect();
    most_plausible(&fits, pair, anchor).unwrap_or(seed)
}

/// The best translation: from the registration's slide, from where the best revolute motion
/// takes the part's centroid (a drawer seen deeper when open pulls the centroids apart), and
/// from 0.7 to 1.3 times the slide.
fn best_prismatic(pair: &CloudPair, seed: PartMotion, revolute: &PartMotion) -> PartMotion {
    let n = pair.start.points.len().max(1) as f64;
    let centroid = pair
        .start
        .points
        .iter()
        .map(|p| p.as_dvec3())
        .sum::<DVec3>()
        / n;
    // A slide seen partly (a drawer's sides hidden when closed) can stop short of or past the
    // travel: starts along the seed's direction at a range of fractions of it, too.
    let along = [0.7, 0.85, 1.15, 1.3].map(|f| PartMotion::prismatic(seed.translation * f));
    [
        seed,
        PartMotion::prismatic(revolute.forward(centroid) - centroid),
    ]
    .into_iter()
    .chain(along)
    .map(|m| {
        let m = refine(pair, Model::Prismatic, m, 40);
        (pair.residual(&m), m)
    })
    .min_by(|x, y| x.0.total_cmp(&y.0))
    .map_or(seed, |t| t.1)
}

/// The geometric fit of a part measured as `start` and `end`, `anchor` holding the rest of the
/// object in the start state (when known); `None` when either cloud has fewer than 3 points.
pub fn fit_joint(
    start: &PartCloud,
    end: &PartCloud,
    anchor: Option<&Anchor>,
) -> Option<GeometricJoint> {
    let seeds: JointCandidates = initial_candidates(&start.points, &end.points)?;
    let pair = CloudPair::new(start, end);
    let revolute = best_revolute(&pair, seeds.revolute, anchor);
    let prismatic = best_prismatic(&pair, seeds.prismatic, &revolute);
    let revolute_residual = pair.residual(&revolute);
    let prismatic_residual = pair.residual(&prismatic);
    let identity_residual = pair.residual(&PartMotion::IDENTITY);
    let ratio = prismatic_residual / revolute_residual.max(1e-9);
    let kind = if ratio <= PRISMATIC_SLACK {
        JointKind::Prismatic
    } else {
        JointKind::Revolute
    };
    let best = revolute_residual.min(prismatic_residual);
    Some(GeometricJoint {
        revolute,
        prismatic,
        revolute_residual,
        prismatic_residual,
        identity_residual,
        kind,
        margin: (ratio.max(1e-9) / PRISMATIC_SLACK).ln().abs() / PRISMATIC_SLACK.ln(),
        // Not moving must fit clearly worse than the best model: by half again, and by more
        // than a tenth of the depth maps' millimetre.
        observable: identity_residual > 1.5 * best + 1e-4,
        points: [start.points.len(), end.points.len()],
    })
}

/// Points of a cloud moved rigidly (tests and fixtures).
pub fn moved_cloud(cloud: &PartCloud, m: &PartMotion) -> PartCloud {
    let (r, _) = m.forward_affine();
    PartCloud {
        points: cloud
            .points
            .iter()
            .map(|p| m.forward(p.as_dvec3()).as_vec3())
            .collect(),
        normals: cloud
            .normals
            .iter()
            .map(|n| (r * n.as_dvec3()).as_vec3())
            .collect(),
        colors: cloud.colors.clone(),
        pixels: cloud.pixels,
        labelled: cloud.labelled,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// A closed box surface (w × h × d m at `origin`) sampled with outward normals.
    fn box_cloud(rng: &mut Rng, size: DVec3, origin: DVec3, count: usize) -> PartCloud {
        let mut cloud = PartCloud::default();
        for _ in 0..count {
            let face = rng.below(6) as usize;
            let (axis, side) = (face / 2, (face % 2) as f64);
            let mut p = DVec3::new(
                rng.uniform(0.0, 1.0) as f64,
                rng.uniform(0.0, 1.0) as f64,
                rng.uniform(0.0, 1.0) as f64,
            );
            p[axis] = side;
            let mut n = DVec3::ZERO;
            n[axis] = if side > 0.5 { 1.0 } else { -1.0 };
            cloud.points.push((origin + p * size).as_vec3());
            cloud.normals.push(n.as_vec3());
        }
        cloud
    }

    fn door(rng: &mut Rng) -> PartCloud {
        box_cloud(
            rng,
            DVec3::new(0.5, 0.8, 0.03),
            DVec3::new(0.0, 0.0, 0.0),
            3000,
        )
    }

    #[test]
    fn a_door_swing_is_revolute_with_its_hinge_line() {
        let mut rng = Rng::new(3);
        let start = door(&mut rng);
        let truth = PartMotion::revolute(DVec3::Y, DVec3::ZERO, 35f64.to_radians());
        let end = moved_cloud(&door(&mut rng), &truth);
        let g = fit_joint(&start, &end, None).unwrap();
        assert_eq!(g.kind, JointKind::Revolute, "{g:?}");
        assert!(g.settled(), "{g:?}");
        let (axis, angle) = rotation_axis_angle(g.revolute.rotation);
        assert!(axis.dot(DVec3::Y).abs() > 0.9995, "{axis}");
        assert!(
            (angle.to_degrees() - 35.0).abs() < 0.3,
            "{}",
            angle.to_degrees()
        );
        let off = g.revolute.pivot - axis * g.revolute.pivot.dot(axis);
        assert!(off.length() < 0.003, "{}", g.revolute.pivot);
    }

    #[test]
    fn a_drawer_slide_is_prismatic_and_a_far_hinge_is_not() {
        let mut rng = Rng::new(5);
        let drawer = |rng: &mut Rng| {
            box_cloud(
                rng,
                DVec3::new(0.4, 0.15, 0.5),
                DVec3::new(0.0, 0.2, 0.0),
                3000,
            )
        };
        let start = drawer(&mut rng);
        let t = DVec3::new(0.0, 0.0, 0.25);
        let end = moved_cloud(&drawer(&mut rng), &PartMotion::prismatic(t));
        let g = fit_joint(&start, &end, None).unwrap();
        assert_eq!(g.kind, JointKind::Prismatic, "{g:?}");
        assert!((g.prismatic.translation - t).length() < 0.002, "{g:?}");
        // A hinge 1.5 m away turning 10° moves the drawer about as far, but it also turns it.
        let far = PartMotion::revolute(DVec3::Y, DVec3::new(1.5, 0.0, 0.0), 10f64.to_radians());
        let end = moved_cloud(&drawer(&mut rng), &far);
        let g = fit_joint(&start, &end, None).unwrap();
        assert_eq!(g.kind, JointKind::Revolute, "{g:?}");
        assert!(g.settled(), "{g:?}");
    }

    #[test]
    fn a_knob_turned_about_its_own_axis_is_not_observable() {
        let mut rng = Rng::new(9);
        // A cylinder of radius 2 cm, 2 cm long, along z.
        let knob = |rng: &mut Rng| {
            let mut c = PartCloud::default();
            for _ in 0..1500 {
                let a = rng.uniform(0.0, std::f32::consts::TAU);
                let z = rng.uniform(0.0, 0.02);
                let n = Vec3::new(a.cos(), a.sin(), 0.0);
                c.points
                    .push(Vec3::new(0.3, 0.4, 0.5) + 0.02 * n + Vec3::Z * z);
                c.normals.push(n);
            }
            c
        };
        let start = knob(&mut rng);
        let turn = PartMotion::revolute(DVec3::Z, DVec3::new(0.3, 0.4, 0.5), 60f64.to_radians());
        let end = moved_cloud(&knob(&mut rng), &turn);
        let g = fit_joint(&start, &end, None).unwrap();
        assert!(!g.observable, "{g:?}");
        assert!(!g.settled());
    }
}
