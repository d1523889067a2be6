//! Joints along the directions an object is built in. Furniture and appliances are made of
//! boxes and slabs: a drawer slides along its carcass's depth, a door turns about its edge, a
//! knob about the normal of the panel it sits on. Those directions are the normals of the flat
//! faces ([`build_directions`]), which crowd a few directions where a curved surface's spread:
//! from the thousands of normals of the rest of the object they come out far more exactly than a
//! joint's axis does from the few hundred points that moved.
//!
//! A fitted motion is offered the same motion with its axis on the nearest such direction
//! ([`aligned`]), refined with the direction fixed (a hinge's angle and pivot, a slide's length).
//! The data choose between the two as between any hypotheses ([`evidence`], Schwarz's penalty
//! charging the free axis its two extra parameters): the aligned motion is kept unless the free
//! axis is decisively better, so a joint built askew keeps its own axis as soon as its points
//! show it, and a joint askew by less than the noise hides lies along its object.

use glam::{DMat3, DQuat, DVec3, Vec3};

use super::evidence::{DECISIVE, evidence};
use super::registration::{CloudPair, Model, PointFit, refine};
use crate::articulation::init::best_rotation;
use crate::articulation::motion::{PartMotion, rotation_axis_angle};
use crate::articulation::observed::MAX_NORMAL_ERROR;

/// A normal counts as lying on a face of the frame while within this many times its own error
/// bound ([`MAX_NORMAL_ERROR`]) of one of the frame's axes: two standard errors.
const ON_FACE: f64 = 2.0;

/// Rounds of [`build_directions`]' robust refinement; each starts from the last frame, and the
/// faces it keeps stop changing within a few.
const FRAME_ROUNDS: usize = 5;

/// Normals tried as the centre of the densest cone of normals: a face holding a twentieth of
/// them is tried about thirteen times.
const MODE_TRIES: usize = 256;

/// Of `normals` (unit), the direction most of them lie within `near` (a cosine) of, either way
/// round: each of [`MODE_TRIES`] of them tried as the centre, and the mean of the best one's
/// neighbours (signs matched). A flat face's normals crowd one direction; a curved surface's
/// spread over many.
fn densest(normals: &[DVec3], near: f64) -> Option<DVec3> {
    let step = normals.len() / MODE_TRIES + 1;
    let around = |c: DVec3| normals.iter().filter(move |n| n.dot(c).abs() >= near);
    let centre = normals
        .iter()
        .step_by(step)
        .max_by_key(|c| around(**c).count())?;
    let sum: DVec3 = around(*centre).map(|n| *n * n.dot(*centre).signum()).sum();
    Some(sum.normalize_or_zero()).filter(|d| *d != DVec3::ZERO)
}

/// The directions a surface made of boxes and slabs is built along, from its `normals` (none
/// for fewer than 3): the direction the most normals crowd ([`densest`]), the densest one across
/// it among the normals that lie across it, and their cross product; then the rotation that
/// best maps these axes onto the normals within [`ON_FACE`] error bounds of one of them, again
/// until it settles. The faces alone decide: a handle, a bevel or a curved lid, whose normals
/// would tilt their principal axes, are left out.
pub fn build_directions(normals: &[Vec3]) -> Vec<DVec3> {
    let normals: Vec<DVec3> = normals
        .iter()
        .map(|n| n.as_dvec3().normalize_or_zero())
        .filter(|n| *n != DVec3::ZERO)
        .collect();
    if normals.len() < 3 {
        return Vec::new();
    }
    let bound = ON_FACE * f64::from(MAX_NORMAL_ERROR);
    let Some(first) = densest(&normals, bound.cos()) else {
        return Vec::new();
    };
    let across: Vec<DVec3> = normals
        .iter()
        .filter(|n| n.dot(first).abs() <= bound.sin())
        .map(|n| n.reject_from(first).normalize_or_zero())
        .filter(|n| *n != DVec3::ZERO)
        .collect();
    let second = densest(&across, bound.cos())
        .map(|d| d.reject_from(first).normalize_or_zero())
        .filter(|d| *d != DVec3::ZERO)
        .unwrap_or_else(|| first.any_orthonormal_vector());
    let mut frame = DQuat::from_mat3(&DMat3::from_cols(first, second, first.cross(second)));
    for _ in 0..FRAME_ROUNDS {
        let pairs: Vec<(DVec3, DVec3)> = normals
            .iter()
            .filter_map(|&n| {
                let local = frame.inverse() * n;
                let k = local.abs().max_position();
                (local[k].abs() >= bound.cos()).then(|| {
                    let mut axis = DVec3::ZERO;
                    axis[k] = local[k].signum();
                    (axis, n)
                })
            })
            .collect();
        if pairs.len() < 3 {
            break;
        }
        frame = best_rotation(&pairs);
    }
    [DVec3::X, DVec3::Y, DVec3::Z].map(|a| frame * a).to_vec()
}

/// The direction a motion moves along: a hinge's axis, a slide's travel.
fn direction(m: &PartMotion, model: Model) -> DVec3 {
    match model {
        Model::Prismatic => m.translation.normalize_or_zero(),
        _ => rotation_axis_angle(m.rotation).0,
    }
}

/// `m` with its axis on `d` (`d`'s sign matched to it): the same turn about `d` through the same
/// pivot, or the slide's length along `d`.
fn projected(m: &PartMotion, model: Model, d: DVec3) -> PartMotion {
    match model {
        Model::Prismatic => PartMotion::prismatic(d * m.translation.dot(d)),
        _ => {
            let (axis, angle) = rotation_axis_angle(m.rotation);
            let d = if axis.dot(d) < 0.0 { -d } else { d };
            PartMotion::revolute(d, m.pivot, angle)
        }
    }
}

/// Levenberg–Marquardt steps of an aligned model: it starts within a few degrees of its optimum.
const ALIGNED_STEPS: usize = 20;

/// The better of `fit` (a motion of the free `model`, with its point-by-point fit) and the same
/// motion refined along the nearest direction of each of `frames` ([`build_directions`] of the
/// rest of the object, of the part itself): the best aligned one unless the free axis fits
/// decisively better ([`evidence`] past [`DECISIVE`], its two extra parameters charged). A
/// joint askew to its object is a claim like any other, and needs the same evidence.
pub(super) fn aligned(
    pair: &CloudPair,
    model: Model,
    fit: (PartMotion, PointFit),
    frames: &[Vec<DVec3>],
) -> (PartMotion, PointFit) {
    let along = direction(&fit.0, model);
    if along == DVec3::ZERO {
        return fit;
    }
    let nearest = frames.iter().filter_map(|frame| {
        frame
            .iter()
            .copied()
            .max_by(|a, b| a.dot(along).abs().total_cmp(&b.dot(along).abs()))
    });
    let best = nearest
        .map(|d| {
            let fixed = match model {
                Model::Prismatic => Model::Slide(d),
                _ => Model::Turn(d),
            };
            let m = refine(pair, fixed, projected(&fit.0, model, d), ALIGNED_STEPS);
            (m, pair.model_fit(&m, fixed))
        })
        .min_by(|a, b| a.1.residual.total_cmp(&b.1.residual));
    match best {
        Some(best) if evidence(&fit.1, &best.1) < DECISIVE => best,
        _ => fit,
    }
}
