//! Joints from the measured surfaces ([`super::observed`]): per movable part, a revolute and a
//! prismatic model fitted to the part's start- and end-state points by trimmed point-to-plane
//! registration in both directions, and the joint type from their residuals.
//!
//! The starts come from [`initial_candidates`] (principal frames, sign flips, trimmed
//! point-to-point ICP). Each model then takes Levenberg–Marquardt steps in its own parameters —
//! revolute: angle, axis tilt (2), pivot shift across the axis (2); prismatic: the translation —
//! with correspondences found again before every step. Start points are moved by g⁺ onto the
//! end cloud and end points by g⁻ onto the start cloud, so a surface seen in one state only
//! pulls on neither model more than the trimming allows.
//!
//! **Type decision.** A slide is a limit of hinges (pivot far away, angle small), so a revolute
//! fit can always come close to a prismatic one but not the reverse. The prismatic model wins
//! when its residual is at most [`PRISMATIC_SLACK`] times the revolute one; the margin is how
//! far the residual ratio lies from that threshold on a log scale, in units of the threshold.
//! A part whose not moving fits about as well as either model (a knob symmetric about its own
//! axis) is not observable here: its type is left to the photometric bake-off.
//!
//! The registration itself is in `registration` ([`CloudPair`]), the choice among equally good
//! hinges in `plausibility` ([`Anchor`]); this file runs the multi-start search per model and
//! decides the type.

mod plausibility;
mod registration;

use glam::DVec3;
use serde::Serialize;

pub use plausibility::Anchor;
use plausibility::most_plausible;
pub use registration::CloudPair;
use registration::{Model, refine};

use super::init::{JointCandidates, initial_candidates};
use super::motion::PartMotion;
use super::observed::PartCloud;
use crate::data::JointKind;
use crate::data::parallel;

/// The prismatic model wins while its residual is at most this many times the revolute one.
pub(crate) const PRISMATIC_SLACK: f64 = 1.2;

/// Decisions with a margin under this are flagged.
pub(crate) const SMALL_MARGIN: f64 = 0.5;

/// Fewer points than this in either state: the part is too small in the data to fit here.
pub(crate) const MIN_POINTS: usize = 30;

/// One movable part's geometric fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GeometricJoint {
    /// The best rotation about a line, and the best translation.
    pub revolute: PartMotion,
    pub prismatic: PartMotion,
    /// Trimmed RMS point-to-plane distance (m) of each model and of not moving, both directions.
    pub revolute_residual: f64,
    pub prismatic_residual: f64,
    pub identity_residual: f64,
    /// The type the residuals pick.
    pub kind: JointKind,
    /// |ln(ratio / slack)| / ln(slack) with ratio = prismatic / revolute residual: 0 on the
    /// threshold, 1 when one model fits [`PRISMATIC_SLACK`] times better than the threshold.
    pub margin: f64,
    /// Whether moving fits clearly better than not moving.
    pub observable: bool,
    /// Points in the start and end clouds.
    pub points: [usize; 2],
}

impl GeometricJoint {
    /// The fitted motion of `kind`.
    pub fn motion(&self, kind: JointKind) -> PartMotion {
        match kind {
            JointKind::Revolute => self.revolute,
            JointKind::Prismatic => self.prismatic,
        }
    }

    /// Whether the data settle this joint: both states measured, the motion visible and the
    /// type picked by a clear margin.
    pub(crate) fn settled(&self) -> bool {
        self.observable
            && self.margin >= SMALL_MARGIN
            && self.points.iter().all(|&n| n >= MIN_POINTS)
    }
}

/// Every `step`-th point of a cloud.
fn thinned(cloud: &PartCloud, step: usize) -> PartCloud {
    let step = step.max(1);
    PartCloud {
        points: cloud.points.iter().step_by(step).copied().collect(),
        normals: cloud.normals.iter().step_by(step).copied().collect(),
        colors: cloud.colors.iter().step_by(step).copied().collect(),
        pixels: cloud.pixels,
        labelled: cloud.labelled,
    }
}

/// Points per state the multi-start search works on.
const SEARCH_POINTS: usize = 1500;

/// The revolute model's starting points besides the registration's: turns of 30° to 330°
/// about each principal axis of the start cloud through its centroid. A part with a small
/// feature on a symmetric body (a knob's fin) registers best at no rotation at all; from
/// these starts the fit finds the turn the feature made.
fn revolute_starts(start: &PartCloud) -> Vec<PartMotion> {
    let Some(frame) = super::init::principal_frame(&start.points) else {
        return Vec::new();
    };
    (0..3)
        .flat_map(|a| {
            (1..12).map(move |k| {
                PartMotion::revolute(
                    frame.axes.col(a),
                    frame.centroid,
                    f64::from(k * 30).to_radians(),
                )
            })
        })
        .collect()
}

/// Distinct starts refined fully after the coarse search.
const FINALISTS: usize = 12;

/// Steps of each start in the coarse search, and of each finalist on the whole clouds.
const COARSE_STEPS: usize = 6;
const FULL_STEPS: usize = 40;

/// `starts` refined briefly ([`COARSE_STEPS`]) on clouds thinned to about [`SEARCH_POINTS`],
/// best (smallest coarse residual) first.
fn coarse_search(pair: &CloudPair, model: Model, starts: &[PartMotion]) -> Vec<(f64, PartMotion)> {
    let step = pair.start.points.len().max(pair.end.points.len()) / SEARCH_POINTS + 1;
    let (a, b) = (thinned(pair.start, step), thinned(pair.end, step));
    let coarse = CloudPair::new(&a, &b);
    // The starts are independent: refined on every core, results in start order.
    let mut tried = parallel::map(starts, |&m| {
        let m = refine(&coarse, model, m, COARSE_STEPS);
        (coarse.residual(&m), m)
    });
    tried.sort_by(|x, y| x.0.total_cmp(&y.0));
    tried
}

/// `motions` refined fully ([`FULL_STEPS`]) on the whole clouds, with their residuals.
fn full_fits(pair: &CloudPair, model: Model, motions: &[PartMotion]) -> Vec<(f64, PartMotion)> {
    parallel::map(motions, |&m| {
        let m = refine(pair, model, m, FULL_STEPS);
        (pair.residual(&m), m)
    })
}

/// The best revolute motion: the registration seed and every turn of [`revolute_starts`]
/// refined briefly on thinned clouds; the best few distinct ones (within twice the best
/// residual) refined fully, then [`most_plausible`] of those.
fn best_revolute(pair: &CloudPair, seed: PartMotion, anchor: Option<&Anchor>) -> PartMotion {
    let starts: Vec<PartMotion> = std::iter::once(seed)
        .chain(revolute_starts(pair.start))
        .collect();
    let tried = coarse_search(pair, Model::Revolute, &starts);
    let best = tried.first().map_or(f64::INFINITY, |t| t.0);
    let mut finalists: Vec<PartMotion> = Vec::new();
    for (r, m) in &tried {
        let distinct = finalists
            .iter()
            .all(|f| f.rotation.angle_between(m.rotation) > 10f64.to_radians());
        if *r <= 2.0 * best + 1e-5 && distinct && finalists.len() < FINALISTS {
            finalists.push(*m);
        }
    }
    let fits = full_fits(pair, Model::Revolute, &finalists);
    most_plausible(&fits, pair, anchor).unwrap_or(seed)
}

/// Slides refined fully after the coarse search.
const SLIDE_FINALISTS: usize = 2;

/// The best translation: from the registration's slide, from where the best revolute motion
/// takes the part's centroid (a drawer seen deeper when open pulls the centroids apart), and
/// from 0.7 to 1.3 times the slide; searched coarsely, the best [`SLIDE_FINALISTS`] refined
/// fully.
fn best_prismatic(pair: &CloudPair, seed: PartMotion, revolute: &PartMotion) -> PartMotion {
    let n = pair.start.points.len().max(1) as f64;
    let centroid = pair
        .start
        .points
        .iter()
        .map(|p| p.as_dvec3())
        .sum::<DVec3>()
        / n;
    // A slide seen partly (a drawer's sides hidden when closed) can stop short of or past the
    // travel: starts along the seed's direction at a range of fractions of it, too.
    let along = [0.7, 0.85, 1.15, 1.3].map(|f| PartMotion::prismatic(seed.translation * f));
    let starts: Vec<PartMotion> = [
        seed,
        PartMotion::prismatic(revolute.forward(centroid) - centroid),
    ]
    .into_iter()
    .chain(along)
    .collect();
    let finalists: Vec<PartMotion> = coarse_search(pair, Model::Prismatic, &starts)
        .into_iter()
        .take(SLIDE_FINALISTS)
        .map(|t| t.1)
        .collect();
    full_fits(pair, Model::Prismatic, &finalists)
        .into_iter()
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map_or(seed, |t| t.1)
}

/// The geometric fit of a part measured as `start` and `end`, `anchor` holding the rest of the
/// object in the start state (when known); `None` when either cloud has fewer than 3 points.
pub fn fit_joint(
    start: &PartCloud,
    end: &PartCloud,
    anchor: Option<&Anchor>,
) -> Option<GeometricJoint> {
    let seeds: JointCandidates = initial_candidates(&start.points, &end.points)?;
    let pair = CloudPair::new(start, end);
    let revolute = best_revolute(&pair, seeds.revolute, anchor);
    let prismatic = best_prismatic(&pair, seeds.prismatic, &revolute);
    let revolute_residual = pair.residual(&revolute);
    let prismatic_residual = pair.residual(&prismatic);
    let identity_residual = pair.residual(&PartMotion::IDENTITY);
    let ratio = prismatic_residual / revolute_residual.max(1e-9);
    let kind = if ratio <= PRISMATIC_SLACK {
        JointKind::Prismatic
    } else {
        JointKind::Revolute
    };
    let best = revolute_residual.min(prismatic_residual);
    Some(GeometricJoint {
        revolute,
        prismatic,
        revolute_residual,
        prismatic_residual,
        identity_residual,
        kind,
        margin: (ratio.max(1e-9) / PRISMATIC_SLACK).ln().abs() / PRISMATIC_SLACK.ln(),
        // Not moving must fit clearly worse than the best model: by half again, and by more
        // than a tenth of the depth maps' millimetre.
        observable: identity_residual > 1.5 * best + 1e-4,
        points: [start.points.len(), end.points.len()],
    })
}

/// Points of a cloud moved rigidly (tests and fixtures).
pub fn moved_cloud(cloud: &PartCloud, m: &PartMotion) -> PartCloud {
    let (r, _) = m.forward_affine();
    PartCloud {
        points: cloud
            .points
            .iter()
            .map(|p| m.forward(p.as_dvec3()).as_vec3())
            .collect(),
        normals: cloud
            .normals
            .iter()
            .map(|n| (r * n.as_dvec3()).as_vec3())
            .collect(),
        colors: cloud.colors.clone(),
        pixels: cloud.pixels,
        labelled: cloud.labelled,
    }
}

#[cfg(test)]
mod tests;
