//! What the articulation phase produces: per movable part the fitted joint, the bake-off's
//! decision and the evidence behind it; the curve of the photometric stages and their times.

use glam::Vec3;
use serde::Serialize;

use super::config::ArticulationConfig;
use crate::articulation::PartMotion;
use crate::articulation::axis_registration::AxisRegistration;
use crate::articulation::geometric::GeometricJoint;
use crate::articulation::init::JointCandidates;
use crate::data::{GtJoint, JointKind};
use crate::fit::observer::Phase;

/// The per-part joint-type decision.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BakeOff {
    /// Mean masked loss with the revolute / prismatic candidate (`None`: the part owns no
    /// pixel in any state-t₂ view, and the registration residuals decided instead).
    pub revolute_loss: Option<f64>,
    pub prismatic_loss: Option<f64>,
    /// Pixels of the part over all state-t₂ views.
    pub pixels: usize,
    pub kind: JointKind,
}

/// One movable part's fitted joint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedJoint {
    /// The part (1 ..= K).
    pub part: usize,
    pub kind: JointKind,
    /// The fitted forward motion g⁺.
    pub motion: PartMotion,
    /// The joint in the ground-truth file's conventions.
    pub joint: GtJoint,
    /// The seeds, when the part was seen in both states.
    pub initial: Option<JointCandidates>,
    pub bake_off: BakeOff,
    /// What the axis registration changed (`None`: off, or nothing to register).
    pub axis_registration: Option<AxisRegistration>,
    /// The joint measured from the full-resolution depth and part maps (`None`: off, or the
    /// part was not measured in both states).
    pub geometry: Option<GeometricJoint>,
    /// What decided the type and the motion: `geometry`, `bake-off`, `geometry+refined`, …
    pub decided_by: &'static str,
    /// The hypothesis the evidence could not rule out (`None`: every one was ruled out).
    pub ambiguity: Option<Ambiguity>,
    /// Why this joint should be checked by hand (a close type call, a part too small or
    /// unobservable in the data); `None` when nothing is known to be wrong.
    pub flag: Option<String>,
}

/// A joint the evidence leaves open: the strongest alternative and how far behind it is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Ambiguity {
    /// The evidence (a paired z) of the measured choice over the alternative on the depth maps
    /// ([`evidence`](crate::articulation::geometric::evidence)).
    pub evidence: f64,
    /// `evidence` in units of the decisive level (under 1: not ruled out).
    pub margin: f64,
    /// The alternative, in the ground truth's conventions.
    pub alternative: GtJoint,
    /// What chose between them.
    pub decided_by: &'static str,
}

/// One reported point of the articulation curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ArticulationPoint {
    pub iteration: u32,
    pub phase: Phase,
    /// Forward pixel-wise loss of this step's view (the mean over the views when the
    /// refinement uses them all).
    pub forward_loss: f32,
    /// Backward pixel-wise loss, when on.
    pub backward_loss: Option<f32>,
    /// Vertex-wise loss (both directions), when on.
    pub vertex_loss: Option<f64>,
}

/// Seconds per stage of the articulation phase.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct ArticulationTimes {
    pub setup_s: f64,
    pub candidates_s: f64,
    pub bake_off_s: f64,
    pub refine_s: f64,
    pub total_s: f64,
}

/// The articulation field and how it was found.
#[derive(Debug, Clone, Serialize)]
pub struct Articulation {
    pub config: ArticulationConfig,
    /// One per movable part, in part order (part k ↔ joint k − 1).
    pub joints: Vec<FittedJoint>,
    /// The point revolute axis origins are reported closest to (the object's centre).
    pub center: Vec3,
    pub curve: Vec<ArticulationPoint>,
    /// Things a user should know (a part unseen in one state, one that does not move).
    pub warnings: Vec<String>,
    pub times: ArticulationTimes,
    /// The refinement step at which its objective was flat and it stopped (`None`: it ran its
    /// steps, or did not run).
    pub refine_stopped_at: Option<u32>,
}

impl Articulation {
    /// The joints in `gt/trans.json` order.
    pub fn gt_joints(&self) -> Vec<GtJoint> {
        self.joints.iter().map(|j| j.joint).collect()
    }

    /// Where the refinement started: per joint its registration seed of the fitted type, read
    /// as a joint like [`Self::gt_joints`] (`None` for a part seen in only one state).
    pub fn seed_joints(&self) -> Vec<Option<GtJoint>> {
        let center = self.center.as_dvec3();
        self.joints
            .iter()
            .map(|j| {
                let c = j.initial.as_ref()?;
                let seed = match j.kind {
                    JointKind::Revolute => c.revolute,
                    JointKind::Prismatic => c.prismatic,
                };
                Some(seed.joint(j.kind, center))
            })
            .collect()
    }
}
