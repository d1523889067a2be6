//! The articulation phase (paper §3.2 and appendix "Training Details"): the two reconstructed
//! states' meshes are frozen and only the articulation field — one rigid motion per movable
//! part — is optimised.
//!
//! Schedule over `iterations` steps:
//! 1. **Candidates** (until `decide_at`): a revolute and a prismatic candidate per part, both
//!    seeded by [`initial_candidates`](crate::articulation::init::initial_candidates), trained on alternating steps by the forward pixel-wise
//!    motion consistency (state t₁'s mesh moved by g⁺, rendered from a state-t₂ camera).
//! 2. **Bake-off** at `decide_at`: per part, the loss masked to the part's pixels in state t₂ with
//!    only that part moved by each candidate, averaged over all state-t₂ views; the lower wins
//!    (ties to revolute, as in the paper). The winner's Adam moments start from zero.
//! 3. **Refine**: the winners with type-masked gradients, the backward pixel-wise term (state
//!    t₂'s mesh moved by the analytic inverse g⁻, rendered from state-t₁ cameras) from
//!    `backward_from`, and the vertex-wise term in both directions. Each step's pixel-wise
//!    gradients come from one view per direction (the paper) or from all of them
//!    ([`RefineViews`]).
//! 4. **Axis registration** (ours, [`register_along_axis`](crate::articulation::axis_registration::register_along_axis); `tiny` and `fast`): per joint, the
//!    angle or travel alone, axis and pivot held, by trimmed point-to-plane ICP between the
//!    part's two surfaces.
//!
//! The pixel-wise gradients come back as per-part [`PartSums`](crate::articulation::PartSums) from the GPU
//! ([`MovedMesh::read_sums`](crate::articulation::kernels::MovedMesh::read_sums)), the vertex-wise ones from the CPU; [`PartMotion::gradient`](crate::articulation::PartMotion::gradient) turns
//! both into parameter gradients.
//!
//! Ours: with [`GeometryUse`] on, the joints measured from the full-resolution depth and part
//! maps seed the candidates, settle the parts they can (no photometry for those), join the
//! bake-off's evidence, and judge the refined joints (never worse than measured).
//!
//! Files by stage: `measured` (the measured joints), `candidates` (seeds and stage 1),
//! `bake_off` (stage 2), `refine` (stage 3), `judge` (registration, the guard against the
//! measured seed, warnings); `moved_view` is the GPU side of the pixel-wise term, `ssim` the
//! bake-off's CPU loss, `run` what the photometric stages share; `config` and `results` the
//! phase's settings and output.

mod bake_off;
mod candidates;
mod config;
mod judge;
mod measured;
mod moved_view;
mod refine;
mod results;
mod run;
mod show;
mod ssim;

pub use config::{Ablation, ArticulationConfig, GeometryUse, RefineViews, UnknownOption};
pub use results::{
    Ambiguity, Articulation, ArticulationPoint, ArticulationTimes, BakeOff, FittedJoint,
};

use glam::DVec3;

use super::observer::{Observer, Phase, checkpoint};
use super::reconstruct::{Reconstruction, StateReconstruction, training_views};
use crate::articulation::init::principal_frame;
use crate::articulation::kernels::MotionKernels;
use crate::articulation::vertex_motion::StateSurface;
use crate::data::{Dataset, State};
use crate::gpu::{GpuContext, GpuError, GpuResult, now_seconds};
use crate::rng::Rng;
use bake_off::bake_off;
use candidates::{Candidates, reconstruction_seeds, surface_warnings, train_candidates};
use judge::{fitted_joints, joint_warnings};
use measured::{measure, unsettled_warning};
use moved_view::{MotionRenderer, MovedView};
use refine::refine;
use run::{Run, Schedule};
use show::seed_motions;

/// The reconstructions of both states, start first.
fn frozen_states(rec: &Reconstruction) -> GpuResult<[&StateReconstruction; 2]> {
    let (Some(s1), Some(s2)) = (
        rec.states.iter().find(|s| s.state == State::Start),
        rec.states.iter().find(|s| s.state == State::End),
    ) else {
        return Err(GpuError::InvalidInput(
            "the articulation phase needs reconstructions of both states".into(),
        ));
    };
    Ok([s1, s2])
}

/// Runs the articulation phase on a reconstruction of `dataset` (its two states' frozen meshes
/// and training views).
pub async fn articulate(
    ctx: &GpuContext,
    dataset: &Dataset,
    rec: &Reconstruction,
    config: &ArticulationConfig,
    observer: &mut dyn Observer,
) -> GpuResult<Articulation> {
    let t0 = now_seconds();
    let mut times = ArticulationTimes::default();
    let mut warnings = Vec::new();
    let [s1, s2] = frozen_states(rec)?;
    let k = rec.num_parts;
    let views1 = training_views(dataset, State::Start, &rec.config)
        .map_err(|e| GpuError::InvalidInput(e.to_string()))?;
    let views2 = training_views(dataset, State::End, &rec.config)
        .map_err(|e| GpuError::InvalidInput(e.to_string()))?;
    let kernels = MotionKernels::new(ctx);
    // Forward: state t₁'s mesh, moved by g⁺, against state t₂'s views; backward the reverse.
    let forward = MovedView::new(ctx, &kernels, &s1.field, &s1.parts, &views2)?;
    let backward = MovedView::new(ctx, &kernels, &s2.field, &s2.parts, &views1)?;
    let surfaces = [
        StateSurface::from_field(&s1.field).map_err(|e| GpuError::InvalidInput(e.to_string()))?,
        StateSurface::from_field(&s2.field).map_err(|e| GpuError::InvalidInput(e.to_string()))?,
    ];
    let renderer = MotionRenderer::new(ctx, kernels, &rec.config, config);
    let center = principal_frame(&s1.field.positions).map_or(DVec3::ZERO, |f| f.centroid);

    // Seeds: the reconstructions', then the measured joints where there are.
    let seeds = reconstruction_seeds(s1, s2, k);
    let sampled = rec.train_clouds.as_ref();
    let measured = measure(dataset, config, k, sampled, &mut warnings, observer).await?;
    let mut candidates = Candidates::seeded(seeds, &measured);
    unsettled_warning(&measured, &candidates.trainable, &mut warnings);
    surface_warnings(s1, &candidates.seeds, &measured, &mut warnings);
    times.setup_s = now_seconds() - t0;

    // No part left for photometry: no photometric step at all.
    let mut run = Run {
        ctx,
        config,
        k,
        schedule: Schedule::new(config, candidates.any_trainable()),
        renderer,
        forward,
        backward,
        rng: Rng::new(config.seed),
        curve: Vec::new(),
        t0,
        sizes: (
            s1.field.num_vertices() + s2.field.num_vertices(),
            s1.field.faces.len() + s2.field.faces.len(),
        ),
    };
    if observer.wants_articulation_views() {
        let seeds = seed_motions(&candidates);
        run.show_moved(observer, &seeds, (Phase::Candidates, 0), "joint seeds")
            .await?;
    }
    times.candidates_s = train_candidates(&mut run, &mut candidates, observer).await?;
    let (mut decision, seconds) =
        bake_off(&mut run, &candidates, &measured, observer, &mut warnings).await?;
    times.bake_off_s = seconds;
    let trainable = &candidates.trainable;
    let (refine_stopped_at, seconds) =
        refine(&mut run, &mut decision, trainable, &surfaces, observer).await?;
    times.refine_s = seconds;

    let joints = fitted_joints(config, &measured, &candidates, decision, &surfaces, center);
    joint_warnings(&joints, &mut warnings);
    times.total_s = now_seconds() - t0;
    let refine_steps = run.schedule.refine();
    if observer.wants_articulation_views() {
        let fitted: Vec<_> = (0..k)
            .map(|p| {
                joints
                    .iter()
                    .find(|j| j.part == p)
                    .map_or(crate::articulation::PartMotion::IDENTITY, |j| j.motion)
            })
            .collect();
        let at = (Phase::Done, refine_steps);
        run.show_moved(observer, &fitted, at, "fitted joints")
            .await?;
    }
    let done = run.event(Phase::Done, refine_steps, refine_steps, None);
    checkpoint(observer, &done).await?;
    Ok(Articulation {
        config: *config,
        joints,
        center: center.as_vec3(),
        curve: run.curve,
        warnings,
        times,
        refine_stopped_at,
    })
}
