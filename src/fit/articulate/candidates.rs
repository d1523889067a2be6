//! Stage 1 of the articulation: a revolute and a prismatic candidate per movable part, seeded
//! from the reconstructed meshes ([`initial_candidates`]) or, where there are, from the
//! measured joints, and trained on alternating steps by the forward pixel-wise motion
//! consistency (PMC: state t₁'s mesh moved by g⁺, rendered from a state-t₂ camera), plus the
//! backward term once its step comes.

use glam::Vec3;

use super::measured::Measured;
use super::moved_view::{backward_maps, forward_maps};
use super::results::ArticulationPoint;
use super::run::Run;
use crate::articulation::init::{JointCandidates, initial_candidates};
use crate::articulation::{MotionAdam, MotionMask, PartMotion, PartSums};
use crate::data::JointKind;
use crate::fit::observer::{Observer, Phase, Progress, checkpoint};
use crate::fit::reconstruct::StateReconstruction;
use crate::gpu::{GpuResult, now_seconds};
use crate::raster::MeshField;

/// Both joint-type candidates per part (part 0, the static base, stays still).
pub(super) struct Candidates {
    /// The reconstructions' seeds, when the part was seen in both states.
    pub(super) seeds: Vec<Option<JointCandidates>>,
    pub(super) revolute: Vec<PartMotion>,
    pub(super) prismatic: Vec<PartMotion>,
    /// Parts the photometric stages train: seeded, and not settled by the measurements.
    pub(super) trainable: Vec<bool>,
}

/// Vertices of `part` in a state's field.
fn part_points(field: &MeshField, parts: &[u32], part: usize) -> Vec<Vec3> {
    field
        .positions
        .iter()
        .zip(parts)
        .filter(|(_, p)| **p as usize == part)
        .map(|(x, _)| *x)
        .collect()
}

/// The reconstructions' seeds of `k` parts (`None` for a movable part without a surface in one
/// of the states).
pub(super) fn reconstruction_seeds(
    s1: &StateReconstruction,
    s2: &StateReconstruction,
    k: usize,
) -> Vec<Option<JointCandidates>> {
    (0..k)
        .map(|part| {
            if part == 0 {
                return None;
            }
            let a = part_points(&s1.field, &s1.parts, part);
            let b = part_points(&s2.field, &s2.parts, part);
            initial_candidates(&a, &b)
        })
        .collect()
}

/// A warning for each movable part the reconstruction left without a surface: without one in
/// a state its joint comes from the depth alone, or, not measured either, cannot be fitted;
/// without faces in the start state the twin has no mesh for it.
pub(super) fn surface_warnings(
    s1: &StateReconstruction,
    seeds: &[Option<JointCandidates>],
    measured: &Measured,
    warnings: &mut Vec<String>,
) {
    for (part, seed) in seeds.iter().enumerate().skip(1) {
        let faceless = s1
            .part_meshes
            .get(part)
            .is_some_and(|m| m.triangles.is_empty());
        let joint = match (seed, &measured.joints[part]) {
            (Some(_), _) if !faceless => continue,
            (Some(_), _) => "its joint is fitted",
            (None, Some(_)) => "its joint is measured from the depth and part maps alone",
            (None, None) => {
                "its joint cannot be fitted and is reported as a motionless revolute joint"
            }
        };
        let missing = match seed {
            None if part_points(&s1.field, &s1.parts, part).len() < 3 => {
                "no surface for it in the start state"
            }
            None => "no surface for it in the end state",
            Some(_) => "no faces for it in the start state",
        };
        warnings.push(format!(
            "part {part}: the reconstruction found {missing} (too small at the working size?): {joint}{}",
            if faceless { ", and the twin has no mesh for it" } else { "" }
        ));
    }
}

impl Candidates {
    /// The candidates from the reconstructions' `seeds`, replaced by the measured joints
    /// where there are; the parts the measurements settle are not trained.
    pub(super) fn seeded(seeds: Vec<Option<JointCandidates>>, measured: &Measured) -> Self {
        let k = seeds.len();
        let pick = |f: fn(&JointCandidates) -> PartMotion| -> Vec<PartMotion> {
            seeds
                .iter()
                .map(|c| c.as_ref().map_or(PartMotion::IDENTITY, f))
                .collect()
        };
        let mut revolute = pick(|c| c.revolute);
        let mut prismatic = pick(|c| c.prismatic);
        for part in 1..k {
            if let Some(g) = &measured.joints[part] {
                revolute[part] = g.revolute;
                prismatic[part] = g.prismatic;
            }
        }
        let trainable = (0..k)
            .map(|p| seeds[p].is_some() && !measured.settled[p])
            .collect();
        Self {
            seeds,
            revolute,
            prismatic,
            trainable,
        }
    }

    /// Whether any part is left for the photometric stages.
    pub(super) fn any_trainable(&self) -> bool {
        self.trainable.iter().any(|&t| t)
    }
}

/// Trains both candidates of every trainable part on alternating steps (revolute on even
/// steps) up to the decision step, the rates decayed log-linearly to `final_rate`. Returns the
/// stage's seconds.
pub(super) async fn train_candidates(
    run: &mut Run<'_>,
    candidates: &mut Candidates,
    observer: &mut dyn Observer,
) -> GpuResult<f64> {
    let (ctx, config, k) = (run.ctx, run.config, run.k);
    let decide = run.schedule.decide;
    checkpoint(observer, &run.event(Phase::Candidates, 0, decide, None)).await?;
    let mut adam_rot = MotionAdam::new(k, config.rates);
    let mut adam_trans = MotionAdam::new(k, config.rates);
    let t_candidates = now_seconds();
    for i in 0..decide {
        let is_rot = i % 2 == 0;
        let decay = config
            .final_rate
            .powf(f64::from(i) / f64::from(decide.max(1)));
        adam_rot.set_scale(decay);
        adam_trans.set_scale(decay);
        let (motions, adam, kind) = if is_rot {
            (&mut candidates.revolute, &mut adam_rot, JointKind::Revolute)
        } else {
            (
                &mut candidates.prismatic,
                &mut adam_trans,
                JointKind::Prismatic,
            )
        };
        let sums_f = run
            .forward
            .step(ctx, &run.renderer, &forward_maps(motions), &mut run.rng)
            .await?;
        let with_backward = config.ablation.backward && i >= run.schedule.backward_from;
        let sums_b = if with_backward {
            run.backward
                .step(ctx, &run.renderer, &backward_maps(motions), &mut run.rng)
                .await?
        } else {
            vec![PartSums::default(); k]
        };
        for part in (1..k).filter(|&p| candidates.trainable[p]) {
            let g = motions[part].gradient(
                &sums_f[part].scaled(config.pixel_weight),
                &sums_b[part].scaled(config.pixel_weight),
            );
            adam.step(part, &mut motions[part], &g, MotionMask::of(kind));
        }
        // Both candidates are reported, from consecutive steps: the hinge's and the slide's.
        let every = config.report_every.max(1);
        let reported = (i + 1).is_multiple_of(every) || (i + 2).is_multiple_of(every);
        if reported || i + 2 >= decide {
            let terms = run.forward.loss.read_terms(ctx).await?;
            run.curve.push(ArticulationPoint {
                iteration: i,
                phase: Phase::Candidates,
                forward_loss: terms.total,
                backward_loss: None,
                vertex_loss: None,
            });
            let at = Progress {
                candidate: Some(kind),
                ..run.event(Phase::Candidates, i + 1, decide, Some(terms.total))
            };
            checkpoint(observer, &at).await?;
            if observer.wants_preview() {
                let by = if is_rot {
                    "hinge candidates"
                } else {
                    "slide candidates"
                };
                run.show_moved(observer, motions, (Phase::Candidates, i + 1), by)
                    .await?;
            }
        }
    }
    Ok(now_seconds() - t_candidates)
}
