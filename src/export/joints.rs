//! `joints.json`: each fitted joint as a record in the ground truth's conventions, plus what a
//! simulator export needs (its name, limits spanning both observed states) and the evidence
//! behind it (bake-off losses, measured residuals, flags).

use serde::Serialize;

use crate::articulation::axis_registration::AxisRegistration;
use crate::data::JointKind;
use crate::fit::articulate::Ambiguity;
use crate::fit::object::ObjectFit;
use crate::object::part_joint;

/// One joint as `joints.json` lists it: the joint in the ground-truth conventions plus what a
/// simulator export needs (limits spanning both observed states).
#[derive(Debug, Clone, Serialize)]
pub struct JointRecord {
    /// The movable part this joint moves (1 ..= K; part 0 is the static base).
    pub part: usize,
    /// The joint's name in the exported URDF and GLB (its link is `part_{part}`).
    pub joint: String,
    #[serde(rename = "type")]
    pub kind: JointKind,
    /// A point on the axis (m); for revolute joints the one closest to the object's centre.
    pub origin: [f32; 3],
    /// Unit axis direction.
    pub direction: [f32; 3],
    /// Motion from the start to the end state: degrees (revolute) or metres (prismatic).
    pub motion: f32,
    /// Joint value at the start and end states (start 0).
    pub limits: [f32; 2],
    /// The bake-off's masked losses (revolute, prismatic).
    pub bake_off: [Option<f64>; 2],
    /// The magnitude before and after its registration along the axis (absent when off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_registration: Option<AxisRegistration>,
    /// What decided the type and motion (`geometry`, `bake-off+refined`, …).
    pub decided_by: &'static str,
    /// The joint measured from the full-resolution depth and part maps: residuals (mm) of
    /// both models and of not moving, the evidence between them, and whether it settled.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub geometry: Option<GeometryRecord>,
    /// The strongest alternative the evidence could not rule out, and how far behind it is;
    /// absent when every alternative was ruled out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ambiguity: Option<Ambiguity>,
    /// Why the joint should be checked by hand; absent when nothing is known to be wrong.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flag: Option<String>,
    /// The fitted start → end motion g⁺ of the part as a 4 × 4 matrix, rows first (world frame).
    pub end_transform: [[f64; 4]; 4],
}

/// The measured evidence behind a joint, as `joints.json` lists it.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct GeometryRecord {
    #[serde(rename = "type")]
    pub kind: JointKind,
    /// The weakest evidence of the measured motion over any alternative, in units of the
    /// decisive level (under 1: an alternative was not ruled out).
    pub margin: f64,
    /// The evidence (a paired z) of the revolute model over the prismatic one.
    pub type_evidence: f64,
    /// The residual (mm) a correct motion of this part is expected to leave, estimated from the
    /// depth maps (absent: too little of the static base to tell).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_mm: Option<f64>,
    /// Whether the best model's residual is within the expected one.
    pub explained: bool,
    /// Whether the depth maps alone settled the joint.
    pub settled: bool,
    pub revolute_residual_mm: f64,
    pub prismatic_residual_mm: f64,
    pub identity_residual_mm: f64,
    pub observable: bool,
    /// Points of the part in the start and end clouds.
    pub points: [usize; 2],
    /// The measured hinge's nearest turns (degrees less and more than its angle) the depth
    /// rules out, at most 180: how well the depth knows the angle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub angle_range_deg: Option<[f64; 2]>,
}

/// The joints of `fit` for `joints.json`.
pub fn joint_records(fit: &ObjectFit) -> Vec<JointRecord> {
    fit.articulation
        .joints
        .iter()
        .map(|j| {
            let motion = j.joint.motion();
            let (r, b) = j.motion.forward_affine();
            let row = |i: usize| [r.row(i).x, r.row(i).y, r.row(i).z, b[i]];
            JointRecord {
                part: j.part,
                joint: part_joint(j.part),
                kind: j.kind,
                origin: j.joint.origin.to_array(),
                direction: j.joint.unit_direction().to_array(),
                motion,
                limits: [motion.min(0.0), motion.max(0.0)],
                bake_off: [j.bake_off.revolute_loss, j.bake_off.prismatic_loss],
                axis_registration: j.axis_registration,
                decided_by: j.decided_by,
                geometry: j.geometry.map(|g| GeometryRecord {
                    kind: g.kind,
                    margin: g.margin,
                    type_evidence: g.type_evidence,
                    noise_mm: g.noise.map(|n| 1000.0 * n),
                    explained: g.explained,
                    settled: g.settled(),
                    revolute_residual_mm: 1000.0 * g.revolute_residual,
                    prismatic_residual_mm: 1000.0 * g.prismatic_residual,
                    identity_residual_mm: 1000.0 * g.identity_residual,
                    observable: g.observable,
                    points: g.points,
                    angle_range_deg: g.angle_range,
                }),
                ambiguity: j.ambiguity,
                flag: j.flag.clone(),
                end_transform: [row(0), row(1), row(2), [0.0, 0.0, 0.0, 1.0]],
            }
        })
        .collect()
}
