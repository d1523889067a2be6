//! Where the articulation field starts (paper appendix: "axis directions seeded from PCA of each
//! movable part's vertices, pivots computed from part geometry").
//!
//! Ours goes one step further with the same ingredients: the part's principal frames in the two
//! states give a first rotation between them (the sign flips tried, the best-overlapping kept),
//! a few trimmed ICP iterations between the two states' vertices of that part refine it, and the
//! rigid motion found seeds both joint-type candidates: the revolute one with its rotation axis
//! and a pivot on that axis near the part, the prismatic one with a translation-only registration.
//! The optimisation then only refines; the bake-off still decides the type.

use glam::{DMat3, DQuat, DVec3, Vec3};
use serde::Serialize;

use super::motion::{PartMotion, closest_on_line, rotation_axis_angle};
use crate::data::parallel;
use crate::mesh::spatial::KdTree;

/// Eigen-decomposition of a symmetric n × n matrix by cyclic Jacobi rotations: eigenvalues in
/// decreasing order and the matching unit eigenvectors.
pub(crate) fn symmetric_eigen<const N: usize>(mut a: [[f64; N]; N]) -> ([f64; N], [[f64; N]; N]) {
    let mut v = [[0.0; N]; N];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _sweep in 0..50 {
        let off: f64 = (0..N)
            .flat_map(|i| (0..N).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        if off < 1e-30 {
            break;
        }
        for p in 0..N {
            for q in p + 1..N {
                if a[p][q].abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                // A ← Jᵀ A J: columns p, q, then rows p, q.
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (rp, rq) = (a[p], a[q]);
                a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
                a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
                for row in v.iter_mut() {
                    let (vkp, vkq) = (row[p], row[q]);
                    row[p] = c * vkp - s * vkq;
                    row[q] = s * vkp + c * vkq;
                }
            }
        }
    }
    let mut order: Vec<usize> = (0..N).collect();
    order.sort_by(|&i, &j| a[j][j].total_cmp(&a[i][i]));
    let values = std::array::from_fn(|i| a[order[i]][order[i]]);
    let vectors = std::array::from_fn(|i| std::array::from_fn(|k| v[k][order[i]]));
    (values, vectors)
}

/// A point set's centroid and principal axes (columns, by decreasing variance; right-handed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrincipalFrame {
    pub centroid: DVec3,
    pub axes: DMat3,
    /// Variances along the axes.
    pub variances: DVec3,
}

/// The principal frame of `points`; `None` when there are fewer than 3.
pub fn principal_frame(points: &[Vec3]) -> Option<PrincipalFrame> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let centroid = points.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / n;
    let mut cov = [[0.0; 3]; 3];
    for p in points {
        let d = p.as_dvec3() - centroid;
        for i in 0..3 {
            for j in 0..3 {
                cov[i][j] += d[i] * d[j] / n;
            }
        }
    }
    let (values, vectors) = symmetric_eigen(cov);
    let [e0, e1, _] = vectors.map(DVec3::from_array);
    Some(PrincipalFrame {
        centroid,
        // The third axis from the first two keeps the frame right-handed.
        axes: DMat3::from_cols(e0, e1, e0.cross(e1)),
        variances: DVec3::from_array(values),
    })
}

/// The rotation that best maps centred points `from` onto `to` (Horn's quaternion method).
pub(crate) fn best_rotation(pairs: &[(DVec3, DVec3)]) -> DQuat {
    let mut s = [[0.0; 3]; 3];
    for (a, b) in pairs {
        for i in 0..3 {
            for j in 0..3 {
                s[i][j] += a[i] * b[j];
            }
        }
    }
    let [[sxx, sxy, sxz], [syx, syy, syz], [szx, szy, szz]] = s;
    let n = [
        [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
        [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
        [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
        [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
    ];
    let (_, vectors) = symmetric_eigen(n);
    let [w, x, y, z] = vectors[0];
    DQuat::from_xyzw(x, y, z, w).normalize()
}

/// A rigid registration of one part from state t₁ to state t₂: x₂ ≈ R x₁ + t.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Registration {
    pub rotation: DQuat,
    pub translation: DVec3,
    /// Mean distance (m) of the kept (trimmed) matches.
    pub residual: f64,
}

impl Registration {
    fn apply(&self, x: DVec3) -> DVec3 {
        self.rotation * x + self.translation
    }
}

/// Fraction of matches kept by the trimmed ICP (the rest: surface seen in one state only).
const KEEP: f64 = 0.8;

/// Mean of the kept (closest `KEEP` fraction) match distances, and the kept pairs.
fn matches(from: &[Vec3], to: &KdTree, reg: &Registration) -> (f64, Vec<(DVec3, DVec3)>) {
    let mut pairs: Vec<(f64, DVec3, DVec3)> = from
        .iter()
        .filter_map(|&p| {
            let x = p.as_dvec3();
            let (q, d2) = to.nearest(reg.apply(x).as_vec3())?;
            Some((d2, x, q.as_dvec3()))
        })
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    pairs.truncate(((pairs.len() as f64 * KEEP).ceil() as usize).max(1));
    let mean = pairs.iter().map(|p| p.0.sqrt()).sum::<f64>() / pairs.len().max(1) as f64;
    (mean, pairs.into_iter().map(|(_, a, b)| (a, b)).collect())
}

/// Trimmed ICP from `start`; `rotate = false` keeps the rotation fixed (translation only).
fn icp(from: &[Vec3], to: &KdTree, mut reg: Registration, rotate: bool) -> Registration {
    for _ in 0..30 {
        let (residual, pairs) = matches(from, to, &reg);
        reg.residual = residual;
        if pairs.len() < 3 {
            break;
        }
        let n = pairs.len() as f64;
        let ca = pairs.iter().map(|p| p.0).sum::<DVec3>() / n;
        let cb = pairs.iter().map(|p| p.1).sum::<DVec3>() / n;
        let rotation = if rotate {
            let centred: Vec<_> = pairs.iter().map(|(a, b)| (*a - ca, *b - cb)).collect();
            best_rotation(&centred)
        } else {
            reg.rotation
        };
        let next = Registration {
            rotation,
            translation: cb - rotation * ca,
            residual,
        };
        let moved =
            (next.apply(ca) - reg.apply(ca)).length() + next.rotation.angle_between(reg.rotation);
        reg = next;
        if moved < 1e-7 {
            break;
        }
    }
    reg.residual = matches(from, to, &reg).0;
    reg
}

/// Both joint-type candidates of one movable part, and the registration they come from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct JointCandidates {
    pub revolute: PartMotion,
    pub prismatic: PartMotion,
    pub registration: Registration,
    /// Translation-only registration residual (m), next to `registration.residual`.
    pub prismatic_residual: f64,
    /// Residual (m) of not moving at all.
    pub identity_residual: f64,
}

impl JointCandidates {
    /// Whether staying put fits about as well as the best registration: the part's motion is
    /// below what the two reconstructions resolve.
    pub(crate) fn barely_moves(&self) -> bool {
        let best = self.registration.residual.min(self.prismatic_residual);
        self.identity_residual <= 1.25 * best + SAME_FIT
    }
}

/// Rotations below this (radians) leave the axis to PCA: the registration cannot resolve it.
const MIN_ANGLE: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// Registrations this much (m) worse than the best still count as fitting as well.
const SAME_FIT: f64 = 0.002;

/// Seeds both candidates of a part seen as `start` (state t₁ vertices) and `end` (state t₂);
/// `None` when either state has fewer than 3 vertices of the part.
pub(crate) fn initial_candidates(start: &[Vec3], end: &[Vec3]) -> Option<JointCandidates> {
    initial_hypotheses(start, end).map(|(c, _)| c)
}

/// [`initial_candidates`], and every registration from the principal frames' flips read as a
/// revolute motion: a flat part (a door slab) registers about as well turned over, and each of
/// those is a hypothesis the measurements must rule out.
pub(crate) fn initial_hypotheses(
    start: &[Vec3],
    end: &[Vec3],
) -> Option<(JointCandidates, Vec<PartMotion>)> {
    let f1 = principal_frame(start)?;
    let f2 = principal_frame(end)?;
    let tree = KdTree::new(end);
    // The principal axes are defined up to sign: of the four proper flips, keep the rotation
    // whose registration overlaps best (the identity competes too: a part that barely moves).
    let flips = [
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(-1.0, -1.0, 1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(1.0, -1.0, -1.0),
    ];
    let mut seeds: Vec<DQuat> = flips
        .iter()
        .map(|s| DQuat::from_mat3(&(f2.axes * DMat3::from_diagonal(*s) * f1.axes.transpose())))
        .collect();
    seeds.push(DQuat::IDENTITY);
    // Independent registrations: on every core, results in seed order.
    let registrations: Vec<Registration> = parallel::map(&seeds, |&rotation| {
        let reg = Registration {
            rotation,
            translation: f2.centroid - rotation * f1.centroid,
            residual: 0.0,
        };
        icp(start, &tree, reg, true)
    });
    let turns: Vec<PartMotion> = registrations
        .iter()
        .map(|r| revolute_of(r, &f1, start))
        .collect();
    // Symmetric parts (a door slab) register equally well turned by 180°: among the registrations
    // that fit about as well as the best, take the smallest rotation — joints rarely turn further.
    let best = registrations
        .iter()
        .map(|r| r.residual)
        .fold(f64::INFINITY, f64::min);
    let registration = registrations
        .into_iter()
        .filter(|r| r.residual <= 1.25 * best + SAME_FIT)
        .min_by(|a, b| {
            rotation_axis_angle(a.rotation)
                .1
                .total_cmp(&rotation_axis_angle(b.rotation).1)
        })?;
    // The slide starts from the centroid shift and from where the rigid registration moves the
    // centroid (the centroids disagree when one state shows more of the part, e.g. a drawer's sides).
    let slide = [
        f2.centroid - f1.centroid,
        registration.apply(f1.centroid) - f1.centroid,
    ]
    .into_iter()
    .map(|translation| {
        let reg = Registration {
            rotation: DQuat::IDENTITY,
            translation,
            residual: 0.0,
        };
        icp(start, &tree, reg, false)
    })
    .min_by(|a, b| a.residual.total_cmp(&b.residual))?;
    let still = Registration {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
        residual: 0.0,
    };
    let candidates = JointCandidates {
        revolute: revolute_of(&registration, &f1, start),
        prismatic: PartMotion::prismatic(slide.translation),
        registration,
        prismatic_residual: slide.residual,
        identity_residual: matches(start, &tree, &still).0,
    };
    Some((candidates, turns))
}

/// The revolute motion nearest a rigid registration of `start` (principal frame `f1`).
fn revolute_of(registration: &Registration, f1: &PrincipalFrame, start: &[Vec3]) -> PartMotion {
    let (axis, angle) = rotation_axis_angle(registration.rotation);
    let radius = start
        .iter()
        .map(|p| (p.as_dvec3() - f1.centroid).length())
        .fold(0.0, f64::max);
    if angle < MIN_ANGLE {
        // No measurable rotation: the largest principal axis through the centroid, a small angle.
        return PartMotion::revolute(f1.axes.col(0), f1.centroid, MIN_ANGLE);
    }
    // Points P on the axis satisfy t = (I − R) P; least squares near the centroid, then the
    // point of that axis line closest to the centroid, kept within the part's reach so a
    // far-away axis cannot imitate a translation.
    let r = DMat3::from_quat(registration.rotation);
    let a = DMat3::IDENTITY - r;
    let lhs = a.transpose() * a + DMat3::from_diagonal(DVec3::splat(1e-9));
    let rhs = a.transpose() * (registration.translation - a * f1.centroid);
    let p = f1.centroid + lhs.inverse() * rhs;
    let mut pivot = closest_on_line(p, axis, f1.centroid);
    let off = pivot - f1.centroid;
    if off.length() > radius {
        pivot = f1.centroid + off * (radius / off.length());
    }
    PartMotion {
        rotation: registration.rotation,
        pivot,
        translation: DVec3::ZERO,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// A door-like slab sampled on its surface (1 × 0.6 × 0.04 m).
    fn slab(rng: &mut Rng) -> Vec<Vec3> {
        (0..1500)
            .map(|_| {
                let face = rng.below(2) as f32;
                Vec3::new(rng.uniform(0.0, 0.6), rng.uniform(0.0, 1.0), 0.04 * face)
            })
            .collect()
    }

    #[test]
    fn jacobi_diagonalises() {
        let a = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 1.0]];
        let (values, vectors) = symmetric_eigen(a);
        for (l, v) in values.iter().zip(vectors) {
            for (i, row) in a.iter().enumerate() {
                let av: f64 = row.iter().zip(v).map(|(x, y)| x * y).sum();
                assert!((av - l * v[i]).abs() < 1e-10);
            }
        }
        assert!(values[0] >= values[1] && values[1] >= values[2]);
    }

    #[test]
    fn a_door_swing_seeds_a_revolute_candidate_on_its_hinge() {
        let mut rng = Rng::new(2);
        let start = slab(&mut rng);
        let truth = PartMotion::revolute(DVec3::Y, DVec3::new(0.0, 0.3, 0.0), 50f64.to_radians());
        let end: Vec<Vec3> = slab(&mut rng)
            .iter()
            .map(|p| truth.forward(p.as_dvec3()).as_vec3())
            .collect();
        let c = initial_candidates(&start, &end).unwrap();
        let (axis, angle) = rotation_axis_angle(c.revolute.rotation);
        assert!(
            (angle.to_degrees() - 50.0).abs() < 2.0,
            "{}",
            angle.to_degrees()
        );
        assert!(axis.dot(DVec3::Y).abs() > 0.995, "{axis}");
        // The pivot is on the hinge line x = z = 0.
        assert!(
            DVec3::new(c.revolute.pivot.x, 0.0, c.revolute.pivot.z).length() < 0.03,
            "{}",
            c.revolute.pivot
        );
        assert!(c.registration.residual < c.prismatic_residual);
    }

    #[test]
    fn a_drawer_slide_seeds_a_prismatic_candidate() {
        let mut rng = Rng::new(4);
        let start = slab(&mut rng);
        let t = DVec3::new(0.0, 0.0, 0.35);
        let end: Vec<Vec3> = slab(&mut rng).iter().map(|p| *p + t.as_vec3()).collect();
        let c = initial_candidates(&start, &end).unwrap();
        assert!(
            (c.prismatic.translation - t).length() < 0.02,
            "{}",
            c.prismatic.translation
        );
        assert!(c.prismatic_residual < 0.02);
        assert!(!c.barely_moves());
        let still = initial_candidates(&start, &slab(&mut rng)).unwrap();
        assert!(still.barely_moves(), "{still:?}");
    }

    #[test]
    fn too_few_points_give_no_candidates() {
        assert!(initial_candidates(&[Vec3::ZERO; 2], &[Vec3::ONE; 10]).is_none());
    }
}
