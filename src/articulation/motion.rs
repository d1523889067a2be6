//! Rigid part motions (paper Eqs. 5–11). Per movable part k the forward motion from state t₁ to
//! state t₂ is g⁺(x) = R(x − P) + P + T = R x + b; the backward motion is its analytic inverse
//! g⁻(y) = Rᵀ(y − b), never a second set of parameters, so the two directions cannot drift apart.
//!
//! The gradients of both consistency terms arrive as [`PartSums`] (Σ g and Σ g xᵀ over a part's
//! vertices); [`PartMotion::gradient`] chains them to the parameters (q, P, T). [`MotionAdam`] is
//! the small CPU Adam over those ten numbers per part.

use glam::{DMat3, DQuat, DVec3, DVec4};
use serde::Serialize;

use super::sums::PartSums;
use crate::data::{GtJoint, JointKind};

/// One part's rigid motion from state t₁ to state t₂.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PartMotion {
    /// R as a unit quaternion (renormalised after every step).
    pub rotation: DQuat,
    /// P: the point the rotation turns about.
    pub pivot: DVec3,
    /// T: the translation after the rotation.
    pub translation: DVec3,
}

impl Default for PartMotion {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// ∂L/∂(q, P, T) of one part.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MotionGradient {
    /// With respect to the quaternion's (x, y, z, w), projected on the unit sphere's tangent plane.
    pub rotation: DVec4,
    pub pivot: DVec3,
    pub translation: DVec3,
}

impl MotionGradient {
    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.rotation.is_finite() && self.pivot.is_finite() && self.translation.is_finite()
    }
}

impl PartMotion {
    /// No motion.
    pub const IDENTITY: PartMotion = PartMotion {
        rotation: DQuat::IDENTITY,
        pivot: DVec3::ZERO,
        translation: DVec3::ZERO,
    };

    /// A rotation by `angle` (radians) about the line through `pivot` along `axis`.
    pub fn revolute(axis: DVec3, pivot: DVec3, angle: f64) -> PartMotion {
        PartMotion {
            rotation: DQuat::from_axis_angle(axis.normalize(), angle),
            pivot,
            translation: DVec3::ZERO,
        }
    }

    /// A translation by `t`.
    pub fn prismatic(t: DVec3) -> PartMotion {
        PartMotion {
            translation: t,
            ..PartMotion::IDENTITY
        }
    }

    /// (R, b) of g⁺(x) = R x + b, with b = −R P + P + T.
    pub(crate) fn forward_affine(&self) -> (DMat3, DVec3) {
        let r = DMat3::from_quat(self.rotation.normalize());
        (r, self.pivot - r * self.pivot + self.translation)
    }

    /// (Rᵀ, −Rᵀ b) of g⁻ = (g⁺)⁻¹.
    pub(crate) fn backward_affine(&self) -> (DMat3, DVec3) {
        let (r, b) = self.forward_affine();
        let rt = r.transpose();
        (rt, -(rt * b))
    }

    /// g⁺(x).
    pub fn forward(&self, x: DVec3) -> DVec3 {
        let (r, b) = self.forward_affine();
        r * x + b
    }

    /// g⁻(y).
    pub fn backward(&self, y: DVec3) -> DVec3 {
        let (r, b) = self.backward_affine();
        r * y + b
    }

    /// ∂L/∂(q, P, T) from the sums of the forward direction (source = state-t₁ vertices moved by
    /// g⁺) and of the backward direction (source = state-t₂ vertices moved by g⁻).
    pub fn gradient(&self, forward: &PartSums, backward: &PartSums) -> MotionGradient {
        let q = self.rotation.normalize();
        let r = DMat3::from_quat(q);
        let (p, t) = (self.pivot, self.translation);
        // Forward: x̂ = R x + P − R P + T.
        let mut d_r = forward.gx - super::sums::outer(forward.g, p);
        let mut d_p = (DMat3::IDENTITY - r).transpose() * forward.g;
        let mut d_t = forward.g;
        // Backward: ŷ = Rᵀ y + P − Rᵀ(P + T); the sums give ∂L/∂Rᵀ, transposed into ∂L/∂R.
        let d_rt = backward.gx - super::sums::outer(backward.g, p + t);
        d_r += d_rt.transpose();
        d_p += (DMat3::IDENTITY - r) * backward.g;
        d_t -= r * backward.g;
        let mut d_q = quaternion_gradient(q, &d_r);
        d_q -= d_q.dot(DVec4::from(q)) * DVec4::from(q);
        MotionGradient {
            rotation: d_q,
            pivot: d_p,
            translation: d_t,
        }
    }

    /// The joint's unit axis and magnitude: a revolute motion's rotation axis and angle
    /// (radians, in [0, π]), a prismatic one's slide direction and distance (m). A motion too
    /// small to have a direction gets the z axis and (about) 0.
    pub(crate) fn axis_and_magnitude(&self, kind: JointKind) -> (DVec3, f64) {
        match kind {
            JointKind::Revolute => rotation_axis_angle(self.rotation),
            JointKind::Prismatic => {
                let d = self.translation.length();
                let direction = if d > 1e-12 {
                    self.translation / d
                } else {
                    DVec3::Z
                };
                (direction, d)
            }
        }
    }

    /// The motion read as a joint in the ground-truth file's conventions: a revolute joint's axis
    /// through the point of the rotation axis closest to `center`, its angle in degrees; a
    /// prismatic joint's unit direction and distance in metres (origin at `center`). The start
    /// value is 0, the end value the motion.
    pub fn joint(&self, kind: JointKind, center: DVec3) -> GtJoint {
        let (axis, magnitude) = self.axis_and_magnitude(kind);
        let (origin, end) = match kind {
            // Points on the axis are fixed by g⁺ − T; the pivot is one of them.
            JointKind::Revolute => (
                closest_on_line(self.pivot, axis, center),
                magnitude.to_degrees(),
            ),
            JointKind::Prismatic => (center, magnitude),
        };
        GtJoint {
            kind,
            origin: origin.as_vec3(),
            direction: axis.as_vec3(),
            start: 0.0,
            end: end as f32,
        }
    }
}

/// The unit axis and angle (radians, in [0, π]) of a rotation; the angle's sign goes into the
/// axis. A rotation closer to identity than floating point resolves gets the z axis.
pub(crate) fn rotation_axis_angle(q: DQuat) -> (DVec3, f64) {
    let q = q.normalize();
    // q and −q are the same rotation: take w ≥ 0 so the angle stays in [0, π].
    let q = if q.w < 0.0 { -q } else { q };
    let v = DVec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-12 {
        return (DVec3::Z, 0.0);
    }
    (v / s, 2.0 * s.atan2(q.w))
}

/// The point of the line through `origin` along unit `dir` closest to `p`.
pub(crate) fn closest_on_line(origin: DVec3, dir: DVec3, p: DVec3) -> DVec3 {
    origin + dir * (p - origin).dot(dir)
}

/// Σ_ab (∂L/∂R)_ab ∂R_ab/∂q for the unit-quaternion rotation matrix, as (x, y, z, w).
fn quaternion_gradient(q: DQuat, d_r: &DMat3) -> DVec4 {
    let (x, y, z, w) = (q.x, q.y, q.z, q.w);
    // Row-major 3 × 3 partials of R(q) (times 2), from R = I + 2w[v]× + 2[v]×².
    let dw = [[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]];
    let dx = [[0.0, y, z], [y, -2.0 * x, -w], [z, w, -2.0 * x]];
    let dy = [[-2.0 * y, x, w], [x, 0.0, z], [-w, z, -2.0 * y]];
    let dz = [[-2.0 * z, -w, x], [w, -2.0 * z, y], [x, y, 0.0]];
    let contract = |m: [[f64; 3]; 3]| {
        let mut s = 0.0;
        for (row, m_row) in m.iter().enumerate() {
            for (col, v) in m_row.iter().enumerate() {
                // glam is column-major: element (row, col) is col(col)[row].
                s += v * d_r.col(col)[row];
            }
        }
        2.0 * s
    };
    DVec4::new(contract(dx), contract(dy), contract(dz), contract(dw))
}

/// Which parameters of a part are trained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct MotionMask {
    pub rotation: bool,
    pub pivot: bool,
    pub translation: bool,
}

impl MotionMask {
    /// Everything trained.
    pub const ALL: MotionMask = MotionMask {
        rotation: true,
        pivot: true,
        translation: true,
    };
    /// Nothing trained (the static base).
    pub(crate) const NONE: MotionMask = MotionMask {
        rotation: false,
        pivot: false,
        translation: false,
    };

    /// A joint type's parameters: revolute (q, P), prismatic T.
    pub fn of(kind: JointKind) -> MotionMask {
        match kind {
            JointKind::Revolute => MotionMask {
                translation: false,
                ..MotionMask::ALL
            },
            JointKind::Prismatic => MotionMask {
                translation: true,
                ..MotionMask::NONE
            },
        }
    }
}

/// Constant learning rates of the articulation phase (paper: rotation 8e-3, translation 1e-3,
/// pivot 0.1 × translation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotionRates {
    pub rotation: f64,
    pub translation: f64,
    pub pivot: f64,
}

impl Default for MotionRates {
    fn default() -> Self {
        Self {
            rotation: 8e-3,
            translation: 1e-3,
            pivot: 1e-4,
        }
    }
}

impl MotionRates {
    /// Every rate multiplied by `factor`.
    pub fn scaled(self, factor: f64) -> Self {
        Self {
            rotation: self.rotation * factor,
            translation: self.translation * factor,
            pivot: self.pivot * factor,
        }
    }
}

/// Adam over the motions of all parts: ten numbers per part (q, P, T), ε as the field's Adam.
#[derive(Debug, Clone)]
pub struct MotionAdam {
    rates: MotionRates,
    m: Vec<[f64; 10]>,
    v: Vec<[f64; 10]>,
    steps: Vec<u32>,
    /// Multiplies every rate (1 = the configured rates).
    scale: f64,
}

const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;
const EPSILON: f64 = 1e-15;

impl MotionAdam {
    /// Fresh moments for `parts` motions.
    pub fn new(parts: usize, rates: MotionRates) -> Self {
        Self {
            rates,
            m: vec![[0.0; 10]; parts],
            v: vec![[0.0; 10]; parts],
            steps: vec![0; parts],
            scale: 1.0,
        }
    }

    /// Scales every learning rate to `factor` × the initial ones (a decay schedule).
    pub(crate) fn set_scale(&mut self, factor: f64) {
        self.scale = factor;
    }

    /// Zeroes part `k`'s moments (after the joint-type decision).
    pub fn reset(&mut self, k: usize) {
        self.m[k] = [0.0; 10];
        self.v[k] = [0.0; 10];
        self.steps[k] = 0;
    }

    /// One step of part `k` with gradient `g`, only on the parameters `mask` trains.
    pub fn step(
        &mut self,
        k: usize,
        motion: &mut PartMotion,
        g: &MotionGradient,
        mask: MotionMask,
    ) {
        if !g.is_finite() {
            return;
        }
        self.steps[k] += 1;
        let t = self.steps[k] as i32;
        let (c1, c2) = (1.0 - BETA1.powi(t), 1.0 - BETA2.powi(t));
        let grads = [
            g.rotation.x,
            g.rotation.y,
            g.rotation.z,
            g.rotation.w,
            g.pivot.x,
            g.pivot.y,
            g.pivot.z,
            g.translation.x,
            g.translation.y,
            g.translation.z,
        ];
        let mut delta = [0.0; 10];
        for i in 0..10 {
            let (lr, on) = match i {
                0..4 => (self.rates.rotation, mask.rotation),
                4..7 => (self.rates.pivot, mask.pivot),
                _ => (self.rates.translation, mask.translation),
            };
            if !on {
                continue;
            }
            let (m, v) = (&mut self.m[k][i], &mut self.v[k][i]);
            *m = BETA1 * *m + (1.0 - BETA1) * grads[i];
            *v = BETA2 * *v + (1.0 - BETA2) * grads[i] * grads[i];
            delta[i] = -lr * self.scale * (*m / c1) / ((*v / c2).sqrt() + EPSILON);
        }
        let q = motion.rotation;
        motion.rotation = DQuat::from_xyzw(
            q.x + delta[0],
            q.y + delta[1],
            q.z + delta[2],
            q.w + delta[3],
        )
        .normalize();
        motion.pivot += DVec3::new(delta[4], delta[5], delta[6]);
        motion.translation += DVec3::new(delta[7], delta[8], delta[9]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn uniform3(rng: &mut Rng) -> DVec3 {
        DVec3::new(
            rng.uniform(-1.0, 1.0) as f64,
            rng.uniform(-1.0, 1.0) as f64,
            rng.uniform(-1.0, 1.0) as f64,
        )
    }

    fn random_motion(rng: &mut Rng) -> PartMotion {
        let mut v = || uniform3(rng);
        PartMotion {
            rotation: DQuat::from_scaled_axis(v() * 0.7),
            pivot: v(),
            translation: v() * 0.3,
        }
    }

    #[test]
    fn backward_inverts_forward_to_1e_6() {
        let mut rng = Rng::new(3);
        for _ in 0..100 {
            let m = random_motion(&mut rng);
            let x = uniform3(&mut rng) * 2.0;
            assert!((m.backward(m.forward(x)) - x).length() < 1e-6);
            assert!((m.forward(m.backward(x)) - x).length() < 1e-6);
            // Also through f32, as the GPU sees it.
            let (r, b) = m.forward_affine();
            let (ri, bi) = m.backward_affine();
            let y = r.as_mat3() * x.as_vec3() + b.as_vec3();
            let back = ri.as_mat3() * y + bi.as_vec3();
            assert!((back.as_dvec3() - x).length() < 1e-5);
        }
    }

    #[test]
    fn axis_extraction_recovers_known_rotations() {
        for (axis, deg) in [
            (DVec3::Z, 30.0),
            (DVec3::new(1.0, 2.0, -0.5), 95.0),
            (-DVec3::X, 170.0),
            (DVec3::Y, 0.5),
        ] {
            let axis = axis.normalize();
            let pivot = DVec3::new(0.3, -0.2, 0.5);
            let m = PartMotion::revolute(axis, pivot, f64::to_radians(deg));
            let j = m.joint(JointKind::Revolute, DVec3::ZERO);
            assert!((j.end as f64 - deg).abs() < 1e-4, "{} vs {deg}", j.end);
            assert!((j.direction.as_dvec3() - axis).length() < 1e-6);
            // The origin lies on the true axis line and is the point closest to the centre.
            let o = j.origin.as_dvec3();
            assert!((o - closest_on_line(pivot, axis, o)).length() < 1e-6);
            assert!(o.dot(axis).abs() < 1e-6);
            // A negated angle flips the axis and keeps the angle positive.
            let j2 = PartMotion::revolute(axis, pivot, f64::to_radians(-deg))
                .joint(JointKind::Revolute, DVec3::ZERO);
            assert!((j2.direction.as_dvec3() + axis).length() < 1e-6);
        }
        let j = PartMotion::prismatic(DVec3::new(0.0, 0.3, 0.4))
            .joint(JointKind::Prismatic, DVec3::ONE);
        assert!((j.end - 0.5).abs() < 1e-6);
        assert!((j.direction - glam::Vec3::new(0.0, 0.6, 0.8)).length() < 1e-6);
    }

    /// A loss over moved points with a known gradient: L = Σ wᵢ · x̂ᵢ + ½‖x̂ᵢ‖².
    fn loss_and_sums(pts: &[DVec3], w: &[DVec3], affine: (DMat3, DVec3)) -> (f64, PartSums) {
        let mut sums = PartSums::default();
        let mut loss = 0.0;
        for (x, w) in pts.iter().zip(w) {
            let y = affine.0 * *x + affine.1;
            loss += w.dot(y) + 0.5 * y.length_squared();
            sums.add(*w + y, *x);
        }
        (loss, sums)
    }

    #[test]
    fn parameter_gradients_match_finite_differences_in_both_directions() {
        let mut rng = Rng::new(11);
        let motion = random_motion(&mut rng);
        let mut pts = || -> Vec<DVec3> { (0..7).map(|_| uniform3(&mut rng)).collect() };
        let (xs, wf, ys, wb) = (pts(), pts(), pts(), pts());
        let total = |m: &PartMotion| {
            loss_and_sums(&xs, &wf, m.forward_affine()).0
                + loss_and_sums(&ys, &wb, m.backward_affine()).0
        };
        let g = motion.gradient(
            &loss_and_sums(&xs, &wf, motion.forward_affine()).1,
            &loss_and_sums(&ys, &wb, motion.backward_affine()).1,
        );
        let h = 1e-6;
        let fd = |f: &dyn Fn(f64) -> PartMotion| (total(&f(h)) - total(&f(-h))) / (2.0 * h);
        for i in 0..3 {
            let e = DVec3::AXES[i];
            let dp = fd(&|s| PartMotion {
                pivot: motion.pivot + e * s,
                ..motion
            });
            let dt = fd(&|s| PartMotion {
                translation: motion.translation + e * s,
                ..motion
            });
            assert!(
                (dp - g.pivot[i]).abs() < 1e-5 * (1.0 + dp.abs()),
                "pivot {i}: {dp} vs {}",
                g.pivot[i]
            );
            assert!(
                (dt - g.translation[i]).abs() < 1e-5 * (1.0 + dt.abs()),
                "translation {i}"
            );
        }
        // Quaternion: perturb along the tangent directions (the gradient is projected onto them).
        let q = DVec4::from(motion.rotation);
        for i in 0..4 {
            let mut e = DVec4::ZERO;
            e[i] = 1.0;
            let e = e - e.dot(q) * q;
            let dq = fd(&|s| PartMotion {
                rotation: DQuat::from_vec4(q + e * s).normalize(),
                ..motion
            });
            assert!(
                (dq - g.rotation.dot(e)).abs() < 1e-5 * (1.0 + dq.abs()),
                "rotation {i}: {dq} vs {}",
                g.rotation.dot(e)
            );
        }
    }

    #[test]
    fn adam_respects_the_mask_and_keeps_unit_quaternions() {
        let mut adam = MotionAdam::new(1, MotionRates::default());
        let mut m = PartMotion::revolute(DVec3::Z, DVec3::ONE, 0.3);
        let g = MotionGradient {
            rotation: DVec4::ONE,
            pivot: DVec3::ONE,
            translation: DVec3::ONE,
        };
        let before = m;
        adam.step(0, &mut m, &g, MotionMask::of(JointKind::Revolute));
        assert_eq!(m.translation, before.translation);
        assert!(m.pivot != before.pivot && m.rotation != before.rotation);
        assert!((m.rotation.length() - 1.0).abs() < 1e-12);
        let before = m;
        adam.step(0, &mut m, &g, MotionMask::of(JointKind::Prismatic));
        assert_eq!((m.rotation, m.pivot), (before.rotation, before.pivot));
        let step = m.translation - before.translation;
        assert!(
            step.max_element() < 0.0 && step.min_element() > -1.01e-3,
            "{step}"
        );
    }
}
