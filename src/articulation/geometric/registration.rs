//! Trimmed point-to-plane registration of a part's start and end clouds under one motion model
//! (revolute or prismatic): nearest-neighbour matches in both directions, the closest fraction
//! kept, and Levenberg–Marquardt steps in the model's own parameters.

use glam::{DQuat, DVec3};

use crate::articulation::motion::{PartMotion, rotation_axis_angle};
use crate::articulation::observed::PartCloud;
use crate::mesh::spatial::KdTree;

/// The median of |x| for x normal with unit deviation (Φ⁻¹(3/4)): a residual's σ is its
/// median over this.
const NORMAL_MEDIAN: f64 = 0.674_489_750_196_081_7;

/// Fraction of matches kept (the rest: surface seen in one state only).
const KEEP: f64 = 0.85;

/// The parameters a model steps in, around a current motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Model {
    Revolute,
    Prismatic,
    /// A hinge about a fixed direction (`alignment`): angle and pivot.
    Turn(DVec3),
    /// A slide along a fixed direction (`alignment`): its length.
    Slide(DVec3),
    /// A hinge's pivot across its axis, the turn held (`angle_range`).
    Pivot,
}

impl Model {
    /// Number of local parameters.
    pub(super) fn dims(self) -> usize {
        match self {
            Model::Revolute => 5,
            Model::Prismatic => 3,
            Model::Turn(_) => 3,
            Model::Slide(_) => 1,
            Model::Pivot => 2,
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
            Model::Turn(d) => {
                let (axis, angle) = rotation_axis_angle(m.rotation);
                let angle = if axis.dot(d) < 0.0 { -angle } else { angle };
                let (u, v) = d.any_orthonormal_pair();
                PartMotion {
                    rotation: DQuat::from_axis_angle(d, angle + delta[0]),
                    pivot: m.pivot + delta[1] * u + delta[2] * v,
                    translation: DVec3::ZERO,
                }
            }
            Model::Slide(d) => PartMotion::prismatic(m.translation + delta[0] * d),
            Model::Pivot => {
                let (u, v) = rotation_axis_angle(m.rotation).0.any_orthonormal_pair();
                PartMotion {
                    pivot: m.pivot + delta[0] * u + delta[1] * v,
                    ..*m
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
    pub(super) start: &'a PartCloud,
    pub(super) end: &'a PartCloud,
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

    /// Every point's match under `m` with its squared distance, per direction (start points
    /// moved by g⁺ first), each cloud in its own order.
    fn all_matches(&self, m: &PartMotion) -> [Vec<(f64, Match)>; 2] {
        [true, false].map(|forward| {
            let (from, to, tree) = if forward {
                (self.start, self.end, &self.end_tree)
            } else {
                (self.end, self.start, &self.start_tree)
            };
            from.points
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
                .collect()
        })
    }

    /// The kept (closest [`KEEP`]) matches of `m`, per direction.
    fn matches(&self, m: &PartMotion) -> Vec<Match> {
        let mut all = Vec::new();
        for side in self.all_matches(m) {
            all.extend(kept(side).into_iter().map(|(_, m)| m));
        }
        all
    }

    /// Trimmed RMS point-to-plane residual (m) of `m`, both directions.
    pub(crate) fn residual(&self, m: &PartMotion) -> f64 {
        rms(&self.matches(m), m)
    }

    /// How `m` fits, point by point: every point's squared point-to-plane residual against its
    /// nearest neighbour in the other state, untrimmed, in a fixed order (start points, then
    /// end points), so two motions' fits of the same pair pair up point for point.
    pub fn point_fit(&self, m: &PartMotion) -> PointFit {
        let all = self.all_matches(m);
        let squared: Vec<f64> = all
            .iter()
            .flatten()
            .map(|(_, c)| c.residual(m).powi(2))
            .collect();
        // The trimmed RMS of [`CloudPair::residual`], from the same matches.
        let (mut sum, mut kept_count, mut offset) = (0.0, 0, 0);
        for side in &all {
            let by_distance: Vec<(f64, f64)> = side
                .iter()
                .zip(&squared[offset..offset + side.len()])
                .map(|((d2, _), r2)| (*d2, *r2))
                .collect();
            offset += side.len();
            for (_, r2) in kept(by_distance) {
                sum += r2;
                kept_count += 1;
            }
        }
        let mut sorted = squared.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted.get(sorted.len() / 2).map_or(0.0, |v| v.sqrt());
        PointFit {
            residual: (sum / kept_count.max(1) as f64).sqrt(),
            dims: free_parameters(m),
            quartile: sorted.get(sorted.len() / 4).map_or(0.0, |v| v.sqrt()),
            // Three standard deviations of the residuals, from their median: the usual bound
            // past which a point is an outlier.
            cap: (3.0 * median / NORMAL_MEDIAN).powi(2),
            squared,
            colors: all.iter().flatten().map(|(_, c)| c.color).collect(),
        }
    }
}

impl CloudPair<'_> {
    /// [`CloudPair::point_fit`] of a motion of `model`, charged that model's parameters.
    pub(super) fn model_fit(&self, m: &PartMotion, model: Model) -> PointFit {
        PointFit {
            dims: model.dims(),
            ..self.point_fit(m)
        }
    }
}

/// A motion's residual at every point of a [`CloudPair`] ([`CloudPair::point_fit`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PointFit {
    /// The trimmed RMS residual (m), both directions ([`CloudPair::residual`]).
    pub residual: f64,
    /// The free parameters of the motion's model ([`free_parameters`]).
    pub(super) dims: usize,
    /// The lower quartile of the points' residuals (m): robust to the surface seen in one state
    /// only (a suitcase's lining, seen open) as long as a quarter is seen in both.
    pub quartile: f64,
    /// Squared point-to-plane residuals (m²), start points then end points.
    pub(super) squared: Vec<f64>,
    /// Past this squared residual (three robust standard deviations) a point counts as not
    /// explained by the motion: a surface seen in one state only, a mislabelled pixel.
    pub(super) cap: f64,
    /// Each point's mean absolute colour difference (0–1, over RGB) from its match: what tells
    /// apart motions the shape alone cannot (a knob's pointer mark, a door's two faces).
    pub(super) colors: Vec<f64>,
}

/// The closest [`KEEP`] of one direction's matches (`(squared distance, match)`), closest first.
fn kept<T>(mut side: Vec<(f64, T)>) -> Vec<(f64, T)> {
    side.sort_by(|a, b| a.0.total_cmp(&b.0));
    side.truncate((side.len() as f64 * KEEP).ceil() as usize);
    side
}

/// The free parameters of the model `m` belongs to: a slide's 3, a hinge's 5 (angle, axis
/// direction, the axis line's place), none for not moving.
fn free_parameters(m: &PartMotion) -> usize {
    if m.translation != glam::DVec3::ZERO {
        Model::Prismatic.dims()
    } else if m.rotation != glam::DQuat::IDENTITY {
        Model::Revolute.dims()
    } else {
        0
    }
}

/// Root mean square of the matches' point-to-plane residuals under `m`.
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
pub(super) fn refine(
    pair: &CloudPair,
    model: Model,
    mut m: PartMotion,
    steps: usize,
) -> PartMotion {
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
