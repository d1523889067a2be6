//! Choosing among revolute fits that explain the clouds equally well: the hinge that meets the
//! rest of the object ([`Anchor`]), then the one whose colours agree, then the smallest turn.

use glam::Vec3;

use super::registration::CloudPair;
use crate::articulation::motion::{PartMotion, rotation_axis_angle};
use crate::articulation::observed::PartCloud;
use crate::mesh::spatial::KdTree;

/// The rest of the object in both states, which a part's hinge joins it to.
pub struct Anchor {
    start: KdTree,
    end: KdTree,
}

impl Anchor {
    /// Search trees over the other parts' points in the start and end states.
    pub fn new(start: &[Vec3], end: &[Vec3]) -> Self {
        Self {
            start: KdTree::new(start),
            end: KdTree::new(end),
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

/// Residuals within this factor of the best (plus a tenth of a millimetre) fit as well: a plain
/// door slab fits turned about its hinge and, flipped, about a line in front of it.
const SAME_FIT: f64 = 1.5;

/// Colour residuals this close (0–1 scale) count as equal.
const SAME_COLOR: f64 = 0.005;

/// Of fitted motions and their residuals, among those fitting as well as the best
/// ([`SAME_FIT`]): those whose axis passes closest to the rest of the object ([`axis_gap`],
/// within 5 mm), then those whose colours agree best ([`CloudPair::color_residual`]), then the
/// smallest turn (joints rarely turn further).
pub(super) fn most_plausible(
    fits: &[(f64, PartMotion)],
    pair: &CloudPair,
    anchor: Option<&Anchor>,
) -> Option<PartMotion> {
    let best = fits.iter().map(|t| t.0).fold(f64::INFINITY, f64::min);
    let good: Vec<(f64, PartMotion)> = fits
        .iter()
        .filter(|t| t.0 <= SAME_FIT * best + 1e-4)
        .map(|t| (anchor.map_or(0.0, |a| a.gap(&t.1, pair)), t.1))
        .collect();
    let nearest = good.iter().map(|g| g.0).fold(f64::INFINITY, f64::min);
    let hinged: Vec<(f64, PartMotion)> = good
        .iter()
        .filter(|g| g.0 <= nearest + 0.005)
        .map(|g| (pair.color_residual(&g.1), g.1))
        .collect();
    let truest = hinged.iter().map(|g| g.0).fold(f64::INFINITY, f64::min);
    hinged
        .iter()
        .filter(|g| g.0 <= truest + SAME_COLOR)
        .min_by(|x, y| {
            rotation_axis_angle(x.1.rotation)
                .1
                .total_cmp(&rotation_axis_angle(y.1.rotation).1)
        })
        .map(|g| g.1)
}
