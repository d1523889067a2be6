//! The last stages of the articulation: each refined joint's magnitude registered along its
//! axis (ours, [`register_along_axis`]; `tiny` and `fast`), then judged against its measured
//! seed on the training views' measurements: the seed replaces it only where the depth maps
//! decisively prefer the seed (photometry decides what they cannot, never against them); and
//! what a user should know about the joints. The test split is for scoring only: nothing here
//! reads it.

use glam::DVec3;

use crate::articulation::PartMotion;

use super::bake_off::Decision;
use super::candidates::Candidates;
use super::config::{ArticulationConfig, GeometryUse};
use super::measured::Measured;
use super::results::{Ambiguity, FittedJoint};
use crate::articulation::axis_registration::register_along_axis;
use crate::articulation::geometric::{CloudPair, DECISIVE, GeometricJoint, evidence};
use crate::articulation::init::JointCandidates;
use crate::articulation::observed::ObservedState;
use crate::articulation::vertex_motion::StateSurface;
use crate::data::JointKind;

/// Rotations and translations below these count as "does not move".
const STILL_ANGLE_DEG: f64 = 0.5;
const STILL_DISTANCE_M: f64 = 0.002;

/// The cloud pair judging a refined joint of `part` against its measured seed: the training
/// views' (`clouds`), or `None` when either state has fewer than 3 points of the part.
fn judge(clouds: &[ObservedState; 2], part: usize) -> Option<CloudPair<'_>> {
    let [s, e] = clouds;
    let (a, b) = (&s.parts[part], &e.parts[part]);
    (a.points.len() >= 3 && b.points.len() >= 3).then(|| CloudPair::new(a, b))
}

/// A hinge whose depth does not rule out turns this many degrees either side of its measured
/// angle gets its angle flagged: the benchmark's line for a joint that is wrong (docs/results.md:
/// "joints over 10° or 5 cm off"), which issue 46 asks never to pass unflagged.
const LOOSE_ANGLE_DEG: f64 = 10.0;

/// Why a measured (or unmeasured) joint of `kind` should be checked by hand, apart from an
/// ambiguity.
fn flag(geometry: Option<&GeometricJoint>, measured: bool, kind: JointKind) -> Option<String> {
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
            "its motion is not visible in the depth maps (not moving fits within {:.1} mm of either joint: a part symmetric about its axis?): {}",
            1000.0 * (g.identity_residual - g.revolute_residual.min(g.prismatic_residual)),
            if g.symmetric_turn() {
                "a turn about its axis of symmetry, the only motion that does not show (a hinge fits decisively better than any slide); its angle comes from photometry"
            } else {
                "type and motion come from photometry"
            }
        ))
    } else if let Some([less, more]) = g
        .angle_range
        .filter(|r| kind == JointKind::Revolute && r[0].max(r[1]) > LOOSE_ANGLE_DEG)
    {
        Some(format!(
            "its angle is loose in the depth maps: turns up to {less:.0}° less or {more:.0}° more than measured fit about as well (a part round about its axis, its relief lost in the noise?); the fitted angle may be that far off"
        ))
    } else {
        None
    }
}

/// What stays ambiguous about the joint of `part` fitted as `motion` (`kind`): the measured
/// hypotheses the depth maps could not rule out, unless the photometric stages chose among them
/// (`photometric`), and none of them then beats the fitted joint decisively on the depth maps.
fn ambiguity(
    g: &GeometricJoint,
    kind: JointKind,
    motion: &PartMotion,
    photometric: bool,
    center: DVec3,
) -> Option<Ambiguity> {
    let rival = g.open_rivals().next()?;
    let by = if photometric {
        "the photometric stages, among the hypotheses the depth maps left open"
    } else {
        "the depth maps alone"
    };
    // The rival is the fitted joint itself when photometry picked it: the chosen one is its rival.
    let (alt_kind, alt_motion) = if rival.kind == kind && rival.motion == *motion {
        (g.kind, g.motion(g.kind))
    } else {
        (rival.kind, rival.motion)
    };
    Some(Ambiguity {
        evidence: rival.evidence,
        margin: rival.evidence / DECISIVE,
        alternative: alt_motion.joint(alt_kind, center),
        decided_by: by,
    })
}

/// A joint in words: "a hinge along (x, y, z) through (x, y, z) m turning a°" or "a slide
/// along (x, y, z) by d mm".
fn describe(j: &crate::data::GtJoint) -> String {
    let d = j.unit_direction();
    let (o, m) = (j.origin, j.motion());
    match j.kind {
        JointKind::Revolute => format!(
            "a hinge along ({:.2}, {:.2}, {:.2}) through ({:.3}, {:.3}, {:.3}) m turning {m:.1}°",
            d.x, d.y, d.z, o.x, o.y, o.z
        ),
        JointKind::Prismatic => format!(
            "a slide along ({:.2}, {:.2}, {:.2}) by {:.0} mm",
            d.x,
            d.y,
            d.z,
            1000.0 * m
        ),
    }
}

/// The fitted joints of the movable parts: the decided motions, registered along their axes
/// and judged against their measured seeds.
pub(super) fn fitted_joints(
    config: &ArticulationConfig,
    measured: &Measured,
    candidates: &Candidates,
    decision: Decision,
    surfaces: &[StateSurface; 2],
    center: DVec3,
) -> Vec<FittedJoint> {
    let k = decision.kinds.len();
    let trainable = &candidates.trainable;
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
            } else if geometry.is_some() {
                "geometry (not settled; nothing to train)"
            } else {
                "none"
            };
            // Photometry decides what the depth maps cannot, never against them: the measured
            // seed replaces a refined joint it beats decisively on the training views' points.
            let pair = measured
                .train_clouds
                .as_ref()
                .filter(|_| trainable[part])
                .and_then(|c| judge(c, part));
            if let (Some(g), Some(pair)) = (geometry, pair) {
                let seed = g.motion(kind);
                if evidence(&pair.point_fit(&seed), &pair.point_fit(&motion)) >= DECISIVE {
                    motion = seed;
                    axis_registration = None;
                    decided_by = "geometry (kept over the refinement)";
                }
            }
            let ambiguity = geometry
                .as_ref()
                .and_then(|g| ambiguity(g, kind, &motion, trainable[part], center));
            let flag = flag(geometry.as_ref(), config.geometry != GeometryUse::Off, kind).or_else(|| {
                ambiguity.as_ref().map(|a| {
                    format!(
                        "ambiguous: the depth maps could not rule out {} (evidence for the fitted joint z = {:.1}, decisive from {DECISIVE:.1}); decided by {}",
                        describe(&a.alternative),
                        a.evidence,
                        a.decided_by
                    )
                })
            });
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
                ambiguity,
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
        // The measurements saw it move: the reconstructions' view does not count. Nor does it
        // for a turn about the part's axis of symmetry, flagged as such with its type known (a
        // hinge decisively better than any slide): a knob fitted turning 70° is no guess.
        let seen_moving = j.geometry.is_some_and(|g| g.observable);
        let symmetric_turn = j.geometry.is_some_and(|g| g.symmetric_turn());
        if ((tiny && j.initial.is_some()) || unresolved) && !seen_moving && !symmetric_turn {
            warnings.push(format!(
                "part {} barely moves between the states (fitted {:.3} {}; not moving at all fits its two reconstructions about as well): its axis and joint type are guesses",
                j.part,
                j.joint.motion(),
                if j.kind == JointKind::Revolute { "°" } else { "m" }
            ));
        }
    }
}
