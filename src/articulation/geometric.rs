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
//! **Decision.** Every hypothesis is judged by its residuals point by point ([`evidence`], a
//! paired z): the revolute against the prismatic model, not moving against both, and the chosen motion against every other optimum that fits about as well (a door slab
//! turned over, a mirrored slide). A joint settles only when the chosen motion is decisively
//! better than each of them ([`DECISIVE`]); otherwise it goes on to the photometric stages. How
//! far its residual is from the one a motionless surface shows between the two states (the
//! part's `noise`) is reported beside it.
//!
//! The registration itself is in `registration` ([`CloudPair`]), the choice among equally good
//! hinges in `plausibility` ([`Anchor`]); this file runs the multi-start search per model and
//! decides the type.

mod alignment;
mod angle_range;
mod evidence;
mod plausibility;
mod registration;

use glam::DVec3;
use serde::Serialize;

use alignment::{aligned, build_directions};
use angle_range::angle_range;
pub use evidence::{DECISIVE, color_evidence, evidence};
pub use plausibility::Anchor;
use plausibility::{hinged, most_plausible};
pub use registration::{CloudPair, PointFit};
use registration::{Model, refine};

use super::init::initial_hypotheses;
use super::motion::PartMotion;
use super::observed::{ObservedState, PartCloud};
use crate::data::JointKind;
use crate::data::parallel;

/// A joint counts as explained while its best model's lower-quartile residual is at most this
/// many times the one a correct motion is expected to leave (the part's `noise`): twice, so the
/// estimate's own error does not decide. Reported, not a condition of settling: the estimate
/// holds a part's sampling and its surface seen in one state only to be the static base's, and
/// they are not (correct joints reach 3.6× on the clean quick sample and 13.5× on the
/// consumer-sensor one, a suitcase lid whose lining shows only when open; docs/results.md).
pub(crate) const EXPLAINED: f64 = 2.0;

/// Fewer points than this in either state: the part is too small in the data to fit here.
pub(crate) const MIN_POINTS: usize = 30;

/// A hypothesis the data could not rule out.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Alternative {
    pub kind: JointKind,
    pub motion: PartMotion,
    /// Its trimmed RMS residual (m).
    pub residual: f64,
    /// The [`evidence`] of the chosen motion over it.
    pub evidence: f64,
}

/// Open hypotheses kept beside the chosen motion, at most: the other type, the turned-over hinge
/// and the mirrored slide the search looks for; more would only be further optima of the same
/// kinds, and [`DECISIVE`] is split over five comparisons on this count.
pub const MAX_RIVALS: usize = 3;

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
    /// The [`evidence`] of the revolute model over the prismatic one (positive: revolute fits
    /// better).
    pub type_evidence: f64,
    /// The weakest evidence of the chosen motion over any hypothesis (the other type, the other
    /// optima), in units of [`DECISIVE`]: at least 1 when every one is ruled out.
    pub margin: f64,
    /// The best model's lower-quartile point residual (m).
    pub quartile_residual: f64,
    /// The lower-quartile point residual (m) a correct motion of this part is expected to leave:
    /// the static base's between the states, with the part's own point noise (`None`: unknown).
    pub noise: Option<f64>,
    /// Whether `quartile_residual` is within [`EXPLAINED`] times `noise`.
    pub explained: bool,
    /// Whether moving fits decisively better than not moving, in depth or in colour.
    pub observable: bool,
    /// Points in the start and end clouds.
    pub points: [usize; 2],
    /// The revolute model's turns (degrees less and more than its angle) nearest to it that the
    /// depth rules out, at most 180 (`angle_range`): how well the depth knows the angle.
    pub angle_range: Option<[f64; 2]>,
    /// The hypotheses not ruled out decisively, weakest evidence first.
    pub rivals: [Option<Alternative>; MAX_RIVALS],
}

impl GeometricJoint {
    /// The fitted motion of `kind`.
    pub fn motion(&self, kind: JointKind) -> PartMotion {
        match kind {
            JointKind::Revolute => self.revolute,
            JointKind::Prismatic => self.prismatic,
        }
    }

    /// Whether the data settle this joint: both states measured, the motion visible, and the
    /// best model decisively better than every other hypothesis ([`EXPLAINED`] says why
    /// `explained` is not asked for).
    pub fn settled(&self) -> bool {
        self.observable && self.margin >= 1.0 && self.points.iter().all(|&n| n >= MIN_POINTS)
    }

    /// Whether the part turned about an axis it is symmetric about: its motion does not show, but
    /// a hinge fits decisively better than any slide (a bounded part moved along any line leaves
    /// where it was), as a knob turned about its own axis.
    pub fn symmetric_turn(&self) -> bool {
        !self.observable && self.kind == JointKind::Revolute && self.type_evidence >= DECISIVE
    }

    /// The hypotheses not ruled out, weakest evidence first.
    pub fn open_rivals(&self) -> impl Iterator<Item = &Alternative> {
        self.rivals.iter().flatten()
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
        noise: cloud.noise,
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

/// The best revolute motion and the other hinges that fit about as well: the registrations
/// (`seeds`) and every turn of [`revolute_starts`] refined briefly on thinned clouds; the best
/// few distinct ones (within twice the best residual) refined fully; of those the hinges the
/// shape allows ([`hinged`]), and the [`most_plausible`] of them first, each with its
/// point-by-point fit (the first seed alone when no hinge is left).
fn best_revolute(
    pair: &CloudPair,
    seeds: &[PartMotion],
    anchor: Option<&Anchor>,
    noise: f64,
) -> Vec<(PartMotion, PointFit)> {
    let starts: Vec<PartMotion> = seeds
        .iter()
        .copied()
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
    let hinges = hinged(&fits, pair, anchor, noise);
    let Some(chosen) = most_plausible(&hinges) else {
        return seeds
            .first()
            .map(|&m| (m, pair.point_fit(&m)))
            .into_iter()
            .collect();
    };
    let (same, others): (Vec<_>, Vec<_>) = hinges.into_iter().partition(|h| h.0 == chosen);
    same.into_iter().take(1).chain(others).collect()
}

/// Slides refined fully after the coarse search.
const SLIDE_FINALISTS: usize = 2;

/// The best translation, and the best distinct one (over 10° apart) as its rival: from the
/// registration's slide, from where the best revolute motion takes the part's centroid (a drawer
/// seen deeper when open pulls the centroids apart), from 0.7 to 1.3 times the slide, and the
/// slide reversed and mirrored in the start cloud's principal planes (a part symmetric about
/// one fits as well moved the mirrored way); searched coarsely, the best [`SLIDE_FINALISTS`]
/// and the best distinct start refined fully.
fn best_prismatic(pair: &CloudPair, seed: PartMotion, revolute: &PartMotion) -> Vec<PartMotion> {
    let n = pair.start.points.len().max(1) as f64;
    let centroid = pair
        .start
        .points
        .iter()
        .map(|p| p.as_dvec3())
        .sum::<DVec3>()
        / n;
    let t = seed.translation;
    // A slide seen partly (a drawer's sides hidden when closed) can stop short of or past the
    // travel: starts along the seed's direction at a range of fractions of it, too.
    let along = [0.7, 0.85, 1.15, 1.3].map(|f| PartMotion::prismatic(t * f));
    let mirrored: Vec<PartMotion> = super::init::principal_frame(&pair.start.points)
        .map(|f| (0..3).map(|a| f.axes.col(a)).collect::<Vec<_>>())
        .unwrap_or_default()
        .into_iter()
        .map(|a| PartMotion::prismatic(t - 2.0 * t.dot(a) * a))
        .chain([PartMotion::prismatic(-t)])
        .collect();
    let starts: Vec<PartMotion> = [
        seed,
        PartMotion::prismatic(revolute.forward(centroid) - centroid),
    ]
    .into_iter()
    .chain(along)
    .chain(mirrored)
    .collect();
    let tried = coarse_search(pair, Model::Prismatic, &starts);
    let mut finalists: Vec<PartMotion> = tried.iter().take(SLIDE_FINALISTS).map(|t| t.1).collect();
    let apart = |a: &PartMotion, b: &PartMotion| {
        a.translation.angle_between(b.translation) > 10f64.to_radians()
    };
    if let Some((_, m)) = tried
        .iter()
        .find(|(_, m)| finalists.iter().all(|f| apart(f, m)))
    {
        finalists.push(*m);
    }
    let mut fits = full_fits(pair, Model::Prismatic, &finalists);
    fits.sort_by(|x, y| x.0.total_cmp(&y.0));
    let Some(&(_, best)) = fits.first() else {
        return vec![seed];
    };
    let rival = fits.iter().map(|f| f.1).find(|m| apart(m, &best));
    std::iter::once(best).chain(rival).collect()
}

/// The geometric fit of a part measured as `start` and `end`, `anchor` holding the rest of the
/// object in the start state (when known), `noise` the residual a correct motion leaves (when
/// known); `None` when either cloud has fewer than 3 points.
pub fn fit_joint(
    start: &PartCloud,
    end: &PartCloud,
    anchor: Option<&Anchor>,
    noise: Option<f64>,
) -> Option<GeometricJoint> {
    let (seeds, turns) = initial_hypotheses(&start.points, &end.points)?;
    let pair = CloudPair::new(start, end);
    let revolute_seeds: Vec<PartMotion> = std::iter::once(seeds.revolute).chain(turns).collect();
    let hinges = best_revolute(&pair, &revolute_seeds, anchor, noise.unwrap_or(0.0));
    let (revolute, points_r) = hinges.first()?;
    let slides: Vec<(PartMotion, PointFit)> = best_prismatic(&pair, seeds.prismatic, revolute)
        .into_iter()
        .map(|m| (m, pair.point_fit(&m)))
        .collect();
    let (prismatic, points_p) = slides.first()?;
    let type_evidence = evidence(points_r, points_p);
    // A tie goes to revolute, as the paper's bake-off breaks it; it is no decision either way.
    let (kind, best_points, others, other) = if type_evidence >= 0.0 {
        (
            JointKind::Revolute,
            points_r,
            &hinges,
            (JointKind::Prismatic, &slides[0]),
        )
    } else {
        (
            JointKind::Prismatic,
            points_p,
            &slides,
            (JointKind::Revolute, &hinges[0]),
        )
    };
    let mut hypotheses: Vec<Alternative> = std::iter::once(other)
        .chain(others.iter().skip(1).map(|h| (kind, h)))
        .map(|(kind, (motion, fit))| Alternative {
            kind,
            motion: *motion,
            residual: fit.residual,
            evidence: evidence(best_points, fit),
        })
        .collect();
    hypotheses.sort_by(|a, b| a.evidence.total_cmp(&b.evidence));
    let weakest = hypotheses.first().map_or(f64::INFINITY, |h| h.evidence);
    let mut rivals = [None; MAX_RIVALS];
    for (slot, h) in rivals
        .iter_mut()
        .zip(hypotheses.iter().filter(|h| h.evidence < DECISIVE))
    {
        *slot = Some(*h);
    }
    // The type and the rivals are decided between free axes, each model charged its own
    // parameters alike; then each model's motion is offered along the directions the object
    // and the part are built in (`alignment`). A hinge about a fixed direction with its pivot
    // far off is a slide in any direction across it, so aligned models would not compare fairly
    // with each other.
    let frames = [
        anchor.map(|a| a.directions.clone()).unwrap_or_default(),
        build_directions(&start.normals),
    ];
    let [(revolute, aligned_r), (prismatic, aligned_p)] = parallel::map(
        &[
            (Model::Revolute, (*revolute, points_r.clone())),
            (Model::Prismatic, (*prismatic, points_p.clone())),
        ],
        |(model, fit)| aligned(&pair, *model, fit.clone(), &frames),
    )
    .try_into()
    .ok()?;
    // The motion is visible where the depth or the colours (a knob's pointer mark turned about
    // the knob's own axis) decisively prefer the motion reported over not moving.
    let chosen = match kind {
        JointKind::Revolute => &aligned_r,
        JointKind::Prismatic => &aligned_p,
    };
    let angle_range = angle_range(&pair, &(revolute, aligned_r.clone()));
    let not_moving = pair.point_fit(&PartMotion::IDENTITY);
    let still = evidence(chosen, &not_moving).max(color_evidence(chosen, &not_moving));
    Some(GeometricJoint {
        revolute,
        prismatic,
        revolute_residual: points_r.residual,
        prismatic_residual: points_p.residual,
        identity_residual: not_moving.residual,
        kind,
        type_evidence,
        margin: weakest / DECISIVE,
        noise,
        quartile_residual: best_points.quartile,
        explained: noise.is_none_or(|n| best_points.quartile <= EXPLAINED * n),
        observable: still >= DECISIVE,
        points: [start.points.len(), end.points.len()],
        angle_range,
        rivals,
    })
}

/// The lower quartile of |x| for x normal with unit deviation (Φ⁻¹(5/8)): the lower quartile of
/// the point-to-plane residuals of two clouds whose points scatter by σ₁ and σ₂ along the normal
/// is this times √(σ₁² + σ₂²).
const NORMAL_QUARTILE: f64 = 0.318_639_363_964_375;

/// The lower-quartile point residual (m) two clouds with point noise `a` and `b` (m) leave.
fn point_noise(a: f32, b: f32) -> f64 {
    NORMAL_QUARTILE * f64::from(a).hypot(f64::from(b))
}

/// What a correct motion's lower-quartile point residual (m) holds beyond the points' own noise:
/// the static base's between its two clouds (`start`, `end`: it does not move), less their point
/// noise ([`PartCloud::noise`]). Sampling, the surface seen in one state only and camera-pose
/// error show there, and are taken to be the same for every part: a part is expected to leave
/// this and its own [`point_noise`] in quadrature. `None` when the base has too few points.
pub fn residual_floor(start: &PartCloud, end: &PartCloud) -> Option<f64> {
    if start.points.len().min(end.points.len()) < MIN_POINTS {
        return None;
    }
    let observed = CloudPair::new(start, end)
        .point_fit(&PartMotion::IDENTITY)
        .quartile;
    let own = point_noise(start.noise, end.noise);
    Some((observed.powi(2) - own.powi(2)).max(0.0).sqrt())
}

/// Points of the rest of the object a measured joint's axis is checked against.
const ANCHOR_POINTS: usize = 20_000;

/// The joints both states' measured clouds (`clouds`) show, one per part: `None` for the base
/// (part 0) and for a part with fewer than 3 points in either state. Each part's expected
/// residual is its point noise over the static base's [`residual_floor`].
pub fn measure_joints(clouds: &[ObservedState; 2]) -> Vec<Option<GeometricJoint>> {
    let measurer = JointMeasurer::new(clouds);
    (0..measurer.parts()).map(|p| measurer.measure(p)).collect()
}

/// [`measure_joints`] a part at a time, for a driver that reports (and yields) between parts:
/// each part costs seconds.
pub struct JointMeasurer<'a> {
    clouds: &'a [ObservedState; 2],
    floor: Option<f64>,
}

impl<'a> JointMeasurer<'a> {
    pub fn new(clouds: &'a [ObservedState; 2]) -> Self {
        let [s, e] = clouds;
        let floor = s
            .parts
            .first()
            .zip(e.parts.first())
            .and_then(|(a, b)| residual_floor(a, b));
        Self { clouds, floor }
    }

    /// Parts measured in both states, the base included.
    pub fn parts(&self) -> usize {
        self.clouds[0].parts.len().min(self.clouds[1].parts.len())
    }

    /// The joint of `part` (`None` for the base).
    pub fn measure(&self, part: usize) -> Option<GeometricJoint> {
        let [s, e] = self.clouds;
        if part == 0 || part >= self.parts() {
            return None;
        }
        let anchor = Anchor::new(
            &s.others(part, ANCHOR_POINTS),
            &e.others(part, ANCHOR_POINTS),
        )
        .built_along(&s.parts[0].normals);
        let (a, b) = (&s.parts[part], &e.parts[part]);
        let noise = self.floor.map(|f| f.hypot(point_noise(a.noise, b.noise)));
        fit_joint(a, b, Some(&anchor), noise)
    }
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
        noise: cloud.noise,
    }
}

#[cfg(test)]
mod tests;
