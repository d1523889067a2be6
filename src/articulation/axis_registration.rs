//! The joint's magnitude registered along its fitted axis (ours, after the paper's refinement).
//!
//! The pixel-wise terms pin a joint's axis well but leave its magnitude — the angle of a door,
//! the travel of a drawer — to sub-pixel image differences: at 32–64 px one pixel of a 30 cm lid
//! is a few degrees, and the fitted angle lands 0.1–0.5° either side of the truth depending on
//! rounding (SwiftShader vs lavapipe) or the SSIM weight's last digits, while the axis moves far
//! less. The vertex-wise term compares colours and opacities only, so nothing in the objective
//! looks at the geometry directly.
//!
//! This step does, with everything else held: the axis direction, the pivot (revolute) and the
//! slide direction (prismatic) stay as fitted; one number s, the angle or the travel, is found by
//! trimmed point-to-plane ICP between the part's two reconstructed surfaces in both directions
//! (state t₁'s vertices carried by g⁺ onto state t₂'s faces, state t₂'s by g⁻ onto t₁'s), by
//! Gauss–Newton in s with the correspondences renewed every iteration. Thousands of vertices
//! average out a few faces' difference between two reconstructions, so two fits that agree on
//! the axis agree on the magnitude too.

use glam::{DMat3, DQuat, DVec3};
use serde::Serialize;

use super::motion::PartMotion;
use super::vertex_motion::StateSurface;
use crate::data::JointKind;

/// Fraction of each direction's matches kept (the rest: surface seen in one state only, such as
/// a drawer's sides).
const KEEP: f64 = 0.8;
/// Gauss–Newton iterations at most, and the step (radians or metres) that counts as converged.
const ITERATIONS: usize = 50;
const CONVERGED: f64 = 1e-9;
/// Fewer matches than this in both directions together leave the motion as fitted.
const MIN_MATCHES: usize = 12;
/// The largest Gauss–Newton step: radians (revolute) or metres (prismatic). A part that barely
/// constrains its own magnitude (a knob symmetric about its axis) gives a near-zero curvature;
/// capped steps keep a weakly constrained part from jumping far on one iteration's noise.
const MAX_STEP: [f64; 2] = [0.035, 0.01];
/// The geometry must see the motion: Σ(∂r/∂s)² / Σ|∂m/∂s|² (the mean squared cosine between the
/// surface normals and the points' motion) below this leaves the fitted magnitude alone — a
/// part symmetric about its axis or along its slide (~0) has its magnitude in its colours only.
const MIN_OBSERVABILITY: f64 = 0.05;

/// What the registration did to one joint.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AxisRegistration {
    /// The magnitude before and after (degrees for revolute, metres for prismatic).
    pub fitted: f64,
    pub registered: f64,
    /// RMS point-to-plane distance (m) of the kept matches, before and after.
    pub rms_before: f64,
    pub rms_after: f64,
    /// Matches kept in the last iteration (both directions).
    pub matches: usize,
    pub iterations: usize,
    /// Σ(∂r/∂s)² / Σ|∂m/∂s|² at the fitted magnitude ([`MIN_OBSERVABILITY`]).
    pub observability: f64,
    /// Whether the registered magnitude replaced the fitted one (the part's geometry sees its
    /// motion and the RMS did not rise).
    pub applied: bool,
}

/// A one-parameter family of motions around a fitted one: s is the angle (radians) about the
/// fitted axis through the fitted pivot, or the travel (metres) along the fitted slide.
struct AxisFamily {
    motion: PartMotion,
    kind: JointKind,
    axis: DVec3,
}

impl AxisFamily {
    /// The family through `motion` and its current s; `None` when the motion has no direction
    /// to follow (a zero rotation or translation).
    fn new(motion: PartMotion, kind: JointKind) -> Option<(Self, f64)> {
        let (axis, s) = motion.axis_and_magnitude(kind);
        (s > 1e-9).then_some((Self { motion, kind, axis }, s))
    }

    /// The motion at s.
    fn at(&self, s: f64) -> PartMotion {
        match self.kind {
            JointKind::Revolute => PartMotion {
                rotation: DQuat::from_axis_angle(self.axis, s),
                ..self.motion
            },
            JointKind::Prismatic => PartMotion {
                translation: self.axis * s,
                ..self.motion
            },
        }
    }

    /// (A, b) of g⁺(x) = A x + b at s, and their derivatives with respect to s.
    fn affine(&self, s: f64) -> ((DMat3, DVec3), (DMat3, DVec3)) {
        let (a, b) = self.at(s).forward_affine();
        let d = match self.kind {
            // A = R(s), b = P − R P + T: ∂A = [axis]× R, ∂b = −∂A P.
            JointKind::Revolute => {
                let da = skew(self.axis) * a;
                (da, -(da * self.motion.pivot))
            }
            JointKind::Prismatic => (DMat3::ZERO, self.axis),
        };
        ((a, b), d)
    }
}

fn skew(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}

/// One match: the point-to-plane residual r and ∂r/∂s.
#[derive(Clone, Copy)]
struct Residual {
    distance: f64,
    r: f64,
    dr: f64,
    /// |∂m/∂s|²: how fast the point moves with s.
    speed2: f64,
}

/// The kept (closest [`KEEP`] fraction) residuals of carrying `source`'s vertices of `part` by
/// `carry` (the moved point and its derivative in s) onto `target`'s faces of that part.
fn matches(
    source: &StateSurface,
    target: &StateSurface,
    part: usize,
    carry: impl Fn(DVec3) -> (DVec3, DVec3),
) -> Vec<Residual> {
    let mut out: Vec<Residual> = source
        .positions()
        .iter()
        .zip(source.parts())
        .filter(|(_, p)| **p as usize == part)
        .filter_map(|(x, _)| {
            let (m, dm) = carry(x.as_dvec3());
            let (c, n) = target.closest_with_normal(part, m)?;
            Some(Residual {
                distance: (m - c).length(),
                r: n.dot(m - c),
                dr: n.dot(dm),
                speed2: dm.length_squared(),
            })
        })
        .collect();
    out.sort_by(|a, b| a.distance.total_cmp(&b.distance));
    out.truncate((out.len() as f64 * KEEP).ceil() as usize);
    out
}

/// Both directions' kept residuals at s.
fn residuals(
    family: &AxisFamily,
    s: f64,
    start: &StateSurface,
    end: &StateSurface,
    part: usize,
) -> Vec<Residual> {
    let ((a, b), (da, db)) = family.affine(s);
    let at = a.transpose();
    let mut all = matches(start, end, part, |x| (a * x + b, da * x + db));
    // g⁻(y) = Aᵀ(y − b): ∂ = ∂Aᵀ (y − b) − Aᵀ ∂b.
    all.extend(matches(end, start, part, |y| {
        (at * (y - b), da.transpose() * (y - b) - at * db)
    }));
    all
}

fn rms(res: &[Residual]) -> f64 {
    (res.iter().map(|r| r.r * r.r).sum::<f64>() / res.len().max(1) as f64).sqrt()
}

/// Registers the magnitude of `part`'s fitted `motion` of type `kind` between the two states'
/// surfaces (`start` = state t₁, `end` = state t₂), axis, pivot and slide direction held.
/// Returns the motion unchanged, and no report, when the motion has no direction to follow or the
/// part has too few matches; unchanged with a report (`applied: false`) when the part's geometry
/// barely sees its motion ([`MIN_OBSERVABILITY`]) or registering raises the residual.
pub(crate) fn register_along_axis(
    motion: PartMotion,
    kind: JointKind,
    start: &StateSurface,
    end: &StateSurface,
    part: usize,
) -> (PartMotion, Option<AxisRegistration>) {
    let Some((family, s0)) = AxisFamily::new(motion, kind) else {
        return (motion, None);
    };
    let first = residuals(&family, s0, start, end, part);
    if first.len() < MIN_MATCHES {
        return (motion, None);
    }
    let (seen, moved) = first
        .iter()
        .fold((0.0, 0.0), |(a, b), r| (a + r.dr * r.dr, b + r.speed2));
    let observability = seen / moved.max(f64::MIN_POSITIVE);
    let rms_before = rms(&first);
    let (mut s, mut res, mut iterations) = (s0, first, 0);
    while observability >= MIN_OBSERVABILITY && iterations < ITERATIONS {
        iterations += 1;
        let (num, den) = res
            .iter()
            .fold((0.0, 0.0), |(n, d), r| (n + r.r * r.dr, d + r.dr * r.dr));
        if den <= 0.0 {
            break;
        }
        let cap = MAX_STEP[(family.kind == JointKind::Prismatic) as usize];
        let step = (-num / den).clamp(-cap, cap);
        s += step;
        res = residuals(&family, s, start, end, part);
        if res.len() < MIN_MATCHES {
            return (motion, None);
        }
        if step.abs() < CONVERGED {
            break;
        }
    }
    let unit = |v: f64| match kind {
        JointKind::Revolute => v.to_degrees(),
        JointKind::Prismatic => v,
    };
    let rms_after = rms(&res);
    // Not worse than the fitted magnitude: trimming renews the matches, so this is not a given.
    // (A threshold here would switch the registration off for fits already close to its
    // optimum, the very ones that should agree with each other.)
    let applied = iterations > 0 && rms_after <= rms_before;
    let report = AxisRegistration {
        fitted: unit(s0),
        registered: unit(s),
        rms_before,
        rms_after,
        matches: res.len(),
        iterations,
        observability,
        applied,
    };
    (if applied { family.at(s) } else { motion }, Some(report))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::articulation::motion::rotation_axis_angle;
    use glam::Vec3;

    /// A surface whose every vertex is part 1 of 2, its positions carried by `motion`.
    fn part_one(positions: &[Vec3], faces: Vec<[u32; 3]>, motion: &PartMotion) -> StateSurface {
        let positions: Vec<Vec3> = positions
            .iter()
            .map(|p| motion.forward(p.as_dvec3()).as_vec3())
            .collect();
        let count = positions.len();
        StateSurface::new(
            positions,
            faces,
            vec![1; count],
            vec![Vec3::ONE; count],
            vec![1.0; count],
            2,
        )
        .unwrap()
    }

    /// A closed box (a door slab or a drawer) of `size` at `min`, subdivided `n` times per edge,
    /// all part 1 of 2, carried by `motion`.
    fn slab(min: Vec3, size: Vec3, n: u32, motion: &PartMotion) -> StateSurface {
        let mut positions = Vec::new();
        let mut faces = Vec::new();
        // Six faces: a grid over (u, v) for each fixed axis and side.
        for axis in 0..3 {
            for side in 0..2 {
                let (ua, va) = ((axis + 1) % 3, (axis + 2) % 3);
                let base = positions.len() as u32;
                for j in 0..=n {
                    for i in 0..=n {
                        let mut p = min;
                        p[axis] += size[axis] * side as f32;
                        p[ua] += size[ua] * i as f32 / n as f32;
                        p[va] += size[va] * j as f32 / n as f32;
                        positions.push(p);
                    }
                }
                for j in 0..n {
                    for i in 0..n {
                        let v = base + j * (n + 1) + i;
                        faces.push([v, v + 1, v + n + 2]);
                        faces.push([v, v + n + 2, v + n + 1]);
                    }
                }
            }
        }
        part_one(&positions, faces, motion)
    }

    #[test]
    fn a_door_angle_off_by_three_degrees_is_registered_back() {
        let (min, size) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.5, 0.8, 0.03));
        let pivot = DVec3::new(0.0, 0.0, 0.0);
        let truth = PartMotion::revolute(DVec3::Y, pivot, 60f64.to_radians());
        let start = slab(min, size, 12, &PartMotion::IDENTITY);
        let end = slab(min, size, 9, &truth);
        let off = PartMotion::revolute(DVec3::Y, pivot, 63f64.to_radians());
        let (motion, report) = register_along_axis(off, JointKind::Revolute, &start, &end, 1);
        let report = report.unwrap();
        let (axis, angle) = rotation_axis_angle(motion.rotation);
        assert!((angle.to_degrees() - 60.0).abs() < 0.05, "{report:?}");
        assert!(axis.dot(DVec3::Y) > 1.0 - 1e-12, "the axis is held: {axis}");
        assert_eq!(motion.pivot, pivot);
        assert!(report.rms_after < 0.2 * report.rms_before, "{report:?}");
    }

    #[test]
    fn a_drawer_travel_off_by_two_centimetres_is_registered_back() {
        let (min, size) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.4, 0.15, 0.35));
        let dir = DVec3::new(0.0, 0.0, 1.0);
        let truth = PartMotion::prismatic(dir * 0.25);
        let start = slab(min, size, 10, &PartMotion::IDENTITY);
        let end = slab(min, size, 7, &truth);
        let (motion, report) = register_along_axis(
            PartMotion::prismatic(dir * 0.27),
            JointKind::Prismatic,
            &start,
            &end,
            1,
        );
        assert!(
            (motion.translation - dir * 0.25).length() < 1e-3,
            "{report:?}"
        );
    }

    /// A capped cylinder about the y axis (a knob), `segments` around, all part 1 of 2,
    /// carried by `motion`.
    fn knob(radius: f32, height: f32, segments: u32, motion: &PartMotion) -> StateSurface {
        let mut positions = vec![Vec3::ZERO, Vec3::new(0.0, height, 0.0)];
        let mut faces = Vec::new();
        for i in 0..segments {
            let t = std::f32::consts::TAU * i as f32 / segments as f32;
            let (x, z) = (radius * t.cos(), radius * t.sin());
            positions.extend([Vec3::new(x, 0.0, z), Vec3::new(x, height, z)]);
            let (a, b) = (2 + 2 * i, 2 + 2 * ((i + 1) % segments));
            faces.extend([
                [0, b, a],
                [1, a + 1, b + 1],
                [a, b, b + 1],
                [a, b + 1, a + 1],
            ]);
        }
        part_one(&positions, faces, motion)
    }

    #[test]
    fn a_knob_symmetric_about_its_axis_keeps_its_fitted_angle() {
        let truth = PartMotion::revolute(DVec3::Y, DVec3::ZERO, 30f64.to_radians());
        let start = knob(0.05, 0.04, 40, &PartMotion::IDENTITY);
        let end = knob(0.05, 0.04, 33, &truth);
        let fitted = PartMotion::revolute(DVec3::Y, DVec3::ZERO, 34f64.to_radians());
        let (motion, report) = register_along_axis(fitted, JointKind::Revolute, &start, &end, 1);
        let report = report.unwrap();
        assert!(report.observability < 0.01, "{report:?}");
        assert!(!report.applied && motion == fitted, "{report:?}");
    }

    #[test]
    fn no_motion_or_no_surface_leaves_the_fit_alone() {
        let s = slab(Vec3::ZERO, Vec3::ONE, 2, &PartMotion::IDENTITY);
        let still = PartMotion::IDENTITY;
        assert_eq!(
            register_along_axis(still, JointKind::Prismatic, &s, &s, 1),
            (still, None)
        );
        let door = PartMotion::revolute(DVec3::Y, DVec3::ZERO, 0.5);
        // Part 0 has no vertices here: nothing to match.
        assert_eq!(
            register_along_axis(door, JointKind::Revolute, &s, &s, 0),
            (door, None)
        );
    }
}
