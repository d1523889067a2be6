//! The last stages of the articulation: each refined joint's magnitude registered along its
//! axis (ours, [`register_along_axis`]; `tiny` and `fast`), then judged against its measured
//! seed on held-out measurements and replaced by the seed where the seed fits better (never
//! worse than measured); and what a user should know about the joints.

use glam::DVec3;

use super::bake_off::Decision;
use super::candidates::Candidates;
use super::config::{ArticulationConfig, GeometryUse};
use super::measured::{Measured, observe};
use super::results::FittedJoint;
use crate::articulation::axis_registration::register_along_axis;
use crate::articulation::geometric::{CloudPair, GeometricJoint, SMALL_MARGIN};
use crate::articulation::init::JointCandidates;
use crate::articulation::observed::ObservedState;
use crate::articulation::vertex_motion::StateSurface;
use crate::data::{Dataset, JointKind, Split};

/// Rotations and translations below these count as "does not move".
const STILL_ANGLE_DEG: f64 = 0.5;
const STILL_DISTANCE_M: f64 = 0.002;

/// The cloud pair judging a refined joint of `part` against its measured seed: the test views'
/// (`clouds`), or `None` when either state has fewer than 3 points of the part.
fn judge(clouds: &[ObservedState; 2], part: usize) -> Option<CloudPair<'_>> {
    let [s, e] = clouds;
    let (a, b) = (&s.parts[part], &e.parts[part]);
    (a.points.len() >= 3 && b.points.len() >= 3).then(|| CloudPair::new(a, b))
}

/// Why a measured (or unmeasured) joint should be checked by hand.
fn flag(geometry: Option<&GeometricJoint>, measured: bool) -> Option<String> {
    use crate::articulation::geometric::MIN_POINTS;
    let Some(g) = geometry else {
        return measured.then(|| {
            "not measured in the depth and part maps (no view shows it with depth in both states): fitted from photometry alone".to_string()
        });
    };
    if g.points.iter().any(|&n| n < MIN_POINTS) {
        Some(format!(
            "too small in the depth and part maps ({} / {} points in the two states): its joint is unreliable",
            g.points[0], g.points[1]
        ))
    } else if !g.observable {
        Some(format!(
            "its motion is not visible in the depth maps (not moving fits within {:.1} mm of either joint: a part symmetric about its axis?): type and motion come from photometry",
            1000.0 * (g.identity_residual - g.revolute_residual.min(g.prismatic_residual))
        ))
    } else if g.margin < SMALL_MARGIN {
        Some(format!(
            "joint type decided by a small margin {:.2} (revolute residual {:.2} mm, prismatic {:.2} mm)",
            g.margin,
            1000.0 * g.revolute_residual,
            1000.0 * g.prismatic_residual
        ))
    } else {
        None
    }
}

/// The fitted joints of the movable parts: the decided motions, registered along their axes
/// and judged against their measured seeds.
pub(super) fn fitted_joints(
    dataset: &Dataset,
    config: &ArticulationConfig,
    measured: &Measured,
    candidates: &Candidates,
    decision: Decision,
    surfaces: &[StateSurface; 2],
    center: DVec3,
) -> Vec<FittedJoint> {
    let k = decision.kinds.len();
    let trainable = &candidates.trainable;
    // The clouds that judge refined joints against their measured seeds, observed only when a
    // measured joint was refined: the test views', else the training views'.
    let refined_measured = (1..k).any(|p| trainable[p] && measured.joints[p].is_some());
    let test_clouds = refined_measured
        .then(|| observe(dataset, config, Split::Test))
        .flatten();
    let judging = test_clouds.as_ref().or(measured.train_clouds.as_ref());
    let [surface1, surface2] = surfaces;

    (1..k)
        .map(|part| {
            let geometry = measured.joints[part];
            let kind = decision.kinds[part];
            let (mut motion, mut axis_registration) =
                if config.register_magnitude && trainable[part] {
                    register_along_axis(decision.motions[part], kind, surface1, surface2, part)
                } else {
                    (decision.motions[part], None)
                };
            let mut decided_by = if measured.settled[part] {
                "geometry"
            } else if trainable[part] {
                "bake-off+refined"
            } else {
                "none"
            };
            // Never worse than the measured seed on the held-out measurements.
            let pair = judging
                .filter(|_| trainable[part])
                .and_then(|c| judge(c, part));
            if let (Some(g), Some(pair)) = (geometry, pair) {
                let seed = g.motion(kind);
                if pair.residual(&seed) < pair.residual(&motion) {
                    motion = seed;
                    axis_registration = None;
                    decided_by = "geometry (kept over the refinement)";
                }
            }
            let flag = flag(geometry.as_ref(), config.geometry != GeometryUse::Off);
            FittedJoint {
                part,
                kind,
                motion,
                joint: motion.joint(kind, center),
                initial: candidates.seeds[part],
                bake_off: decision.bake_offs[part],
                axis_registration,
                geometry,
                decided_by,
                flag,
            }
        })
        .collect()
}

/// What a user should know about the fitted joints: each flag, then the parts that barely
/// move (unless the measurements saw them move).
pub(super) fn joint_warnings(joints: &[FittedJoint], warnings: &mut Vec<String>) {
    for j in joints {
        if let Some(f) = &j.flag {
            warnings.push(format!("part {}: {f}", j.part));
        }
    }
    for j in joints {
        let tiny = match j.kind {
            JointKind::Revolute => f64::from(j.joint.motion().abs()) < STILL_ANGLE_DEG,
            JointKind::Prismatic => f64::from(j.joint.motion().abs()) < STILL_DISTANCE_M,
        };
        let unresolved = j
            .initial
            .as_ref()
            .is_some_and(JointCandidates::barely_moves);
        // The measurements saw it move: the reconstructions' view does not count.
        let seen_moving = j.geometry.is_some_and(|g| g.observable);
        if ((tiny && j.initial.is_some()) || unresolved) && !seen_moving {
            warnings.push(format!(
                "part {} barely moves between the states (fitted {:.3} {}; not moving at all fits its two reconstructions about as well): its axis and joint type are guesses",
                j.part,
                j.joint.motion(),
                if j.kind == JointKind::Revolute { "°" } else { "m" }
            ));
        }
    }
}
