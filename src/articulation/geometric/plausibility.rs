//! Choosing among revolute fits that explain the clouds equally well: the hinge that meets the
//! rest of the object ([`Anchor`]), then the one whose colours agree, then the smallest turn.
//! The hinges the shape allows ([`hinged`]) are also the hypotheses a joint must rule out.

use glam::{DVec3, Vec3};

use super::alignment::build_directions;

use super::evidence::{DECISIVE, color_evidence, evidence};
use super::registration::{CloudPair, PointFit};
use crate::articulation::motion::{PartMotion, rotation_axis_angle};
use crate::articulation::observed::PartCloud;
use crate::mesh::spatial::KdTree;

/// The rest of the object in both states, which a part's hinge joins it to, and the directions
/// it is built along.
pub struct Anchor {
    start: KdTree,
    end: KdTree,
    pub(super) directions: Vec<DVec3>,
}

impl Anchor {
    /// Search trees over the other parts' points in the start and end states.
    pub fn new(start: &[Vec3], end: &[Vec3]) -> Self {
        Self {
            start: KdTree::new(start),
            end: KdTree::new(end),
            directions: Vec::new(),
        }
    }

    /// The anchor built along the principal axes of `normals` (the static base's surface
    /// normals, [`build_directions`]).
    pub fn built_along(self, normals: &[Vec3]) -> Self {
        Self {
            directions: build_directions(normals),
            ..self
        }
    }

    /// How far (m) the axis of `m` passes from the rest of the object, the larger of the two
    /// states' gaps: a hinge stays where its part meets the rest in both, while a false axis
    /// near another moving part (a drawer pulled out in front of a door) is near it in one.
    fn gap(&self, m: &PartMotion, pair: &CloudPair) -> f64 {
        axis_gap(m, pair.start, &self.start).max(axis_gap(m, pair.end, &self.end))
    }
}

/// How far (m) the axis of `m`, over the stretch of it beside the part, passes from `anchor`.
fn axis_gap(m: &PartMotion, part: &PartCloud, anchor: &KdTree) -> f64 {
    let (axis, _) = rotation_axis_angle(m.rotation);
    let along: Vec<f64> = part
        .points
        .iter()
        .map(|p| (p.as_dvec3() - m.pivot).dot(axis))
        .collect();
    let (lo, hi) = along
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| {
            (a.min(t), b.max(t))
        });
    if anchor.is_empty() || !lo.is_finite() {
        return 0.0;
    }
    (0..=32)
        .map(|i| {
            let t = lo + (hi - lo) * f64::from(i) / 32.0;
            anchor.nearest_distance_squared((m.pivot + axis * t).as_vec3())
        })
        .fold(f64::INFINITY, f64::min)
        .sqrt()
}

/// Axis gaps within this (m) of the nearest count as meeting the rest of the object, plus twice
/// the points' noise (`noise`): the gap is measured between noisy points. Geometry: a door's
/// clearance to its frame is a few millimetres.
const SAME_GAP: f64 = 0.005;

/// Of fitted motions and their residuals, those the best does not fit decisively better
/// ([`evidence`] under [`DECISIVE`]) whose axis passes as close to the rest of the object as the
/// closest ([`axis_gap`], within [`SAME_GAP`]): the hinges the shape alone allows, each with its
/// point-by-point fit.
pub(super) fn hinged(
    fits: &[(f64, PartMotion)],
    pair: &CloudPair,
    anchor: Option<&Anchor>,
    noise: f64,
) -> Vec<(PartMotion, PointFit)> {
    let Some(best) = fits.iter().min_by(|a, b| a.0.total_cmp(&b.0)) else {
        return Vec::new();
    };
    let best = pair.point_fit(&best.1);
    let good: Vec<(f64, PartMotion, PointFit)> = fits
        .iter()
        .map(|t| (t.1, pair.point_fit(&t.1)))
        .filter(|(_, f)| evidence(&best, f) < DECISIVE)
        .map(|(m, f)| (anchor.map_or(0.0, |a| a.gap(&m, pair)), m, f))
        .collect();
    let nearest = good.iter().map(|g| g.0).fold(f64::INFINITY, f64::min);
    good.into_iter()
        .filter(|g| g.0 <= nearest + SAME_GAP + 2.0 * noise)
        .map(|g| (g.1, g.2))
        .collect()
}

/// Of [`hinged`] motions, those whose colours agree as well as the best's (not decisively worse,
/// [`color_evidence`]), then the smallest turn (joints rarely turn further).
pub(super) fn most_plausible(hinged: &[(PartMotion, PointFit)]) -> Option<PartMotion> {
    let mean = |f: &PointFit| f.colors.iter().sum::<f64>() / f.colors.len().max(1) as f64;
    let truest = hinged
        .iter()
        .min_by(|a, b| mean(&a.1).total_cmp(&mean(&b.1)))?;
    hinged
        .iter()
        .filter(|h| color_evidence(&truest.1, &h.1) < DECISIVE)
        .min_by(|x, y| {
            rotation_axis_angle(x.0.rotation)
                .1
                .total_cmp(&rotation_axis_angle(y.0.rotation).1)
        })
        .map(|h| h.0)
}
