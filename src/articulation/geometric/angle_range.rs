//! How far a fitted hinge could turn before its depth rules the turn out. A door's slab moves
//! its points by centimetres per degree, and one degree either way is decisively worse; a knob
//! round about its own axis moves only its fin, which a consumer camera's noise at two metres
//! all but hides, and tens of degrees fit about as well. The range is what the depth knows of the
//! angle: a joint whose range is wide has its angle from elsewhere (colour, photometry), and a
//! user is told so.

use glam::DQuat;

use super::evidence::{DECISIVE, evidence};
use super::registration::{CloudPair, Model, PointFit, refine};
use crate::articulation::motion::{PartMotion, rotation_axis_angle};
use crate::data::parallel;

/// The sweep's step (degrees). A part's points are voxel means over 1/120 of its extent
/// (`observed::CloudOptions::voxels_across`), so round its rim they lie about 360 / (120 π) =
/// 0.95° apart: a finer step only moves matches within a voxel.
const STEP_DEG: f64 = 1.0;

/// The sweep goes at most half a turn each way: past that it comes round to the other side.
const MAX_DEG: f64 = 180.0;

/// Levenberg–Marquardt steps of the pivot at each turn of the sweep: it starts at the last
/// turn's, a degree away.
const PIVOT_STEPS: usize = 8;

/// The turns (degrees, below and above the fitted angle) closest to `fit`'s (a hinge on `pair`
/// with its point-by-point fit) that the depth rules out, stepped out from it by [`STEP_DEG`]:
/// where [`evidence`] of the fitted hinge over the same axis turned further, its pivot refitted
/// (a turn that barely moves leaves its pivot anywhere), reaches [`DECISIVE`]; [`MAX_DEG`] where
/// nothing within half a turn is ruled out. `None` for a motion that does not turn.
pub(super) fn angle_range(pair: &CloudPair, fit: &(PartMotion, PointFit)) -> Option<[f64; 2]> {
    let (axis, angle) = rotation_axis_angle(fit.0.rotation);
    if axis == glam::DVec3::ZERO {
        return None;
    }
    let ruled_out_at = |sign: f64| {
        let steps = (MAX_DEG / STEP_DEG).round() as usize;
        let mut pivot = fit.0.pivot;
        for k in 1..=steps {
            let by = k as f64 * STEP_DEG;
            let turned = PartMotion {
                rotation: DQuat::from_axis_angle(axis, angle + sign * by.to_radians()),
                pivot,
                ..fit.0
            };
            let turned = refine(pair, Model::Pivot, turned, PIVOT_STEPS);
            pivot = turned.pivot;
            // Charged the fitted hinge's parameters: only the angle differs.
            let other = PointFit {
                dims: fit.1.dims,
                ..pair.point_fit(&turned)
            };
            if evidence(&fit.1, &other) >= DECISIVE {
                return by;
            }
        }
        MAX_DEG
    };
    let [less, more]: [f64; 2] = parallel::map(&[-1.0, 1.0], |&s| ruled_out_at(s))
        .try_into()
        .ok()?;
    Some([less, more])
}
