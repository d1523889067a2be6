//! One state's reconstruction as the paper's stages in order: initialise, optimise with
//! densification and pruning, harden and remesh, recover with the topology fixed. Each stage
//! reports its [`Progress`] and lets the observer pause or cancel at its checkpoints.

use super::StateViews;
use super::config::ReconstructionConfig;
use super::config::SurfaceSource;
use super::densify::{densify_and_prune, pixels_per_metre};
use super::free_space::FreeSpace;
use super::remesh::{measures_every_part, remesh};
use super::results::{PhaseTimes, RemeshStats, StateReconstruction};
use crate::articulation::observed::ObservedState;
use crate::data::{Camera, Frame, State};
use crate::fit::init::initial_field;
use crate::fit::observer::{Observer, Phase, Progress, checkpoint};
use crate::fit::photometric::{CurvePoint, PhotometricConfig, Trainer};
use crate::gpu::{GpuContext, GpuError, GpuResult, now_seconds};
use crate::mesh::{harden_parts, part_meshes};
use crate::raster::{MeshField, RasterSettings};

/// What the stages of one state's reconstruction share: where to report, and the clock.
struct StateRun<'a> {
    ctx: &'a GpuContext,
    state: State,
    config: &'a ReconstructionConfig,
    observer: &'a mut dyn Observer,
    /// When the state's reconstruction began, and when the last lap ended.
    t0: f64,
    last: f64,
    times: PhaseTimes,
}

impl StateRun<'_> {
    /// Seconds since the last lap.
    fn lap(&mut self) -> f64 {
        let now = now_seconds();
        let dt = now - self.last;
        self.last = now;
        dt
    }

    /// A progress event of this state; `sizes` are the field's (vertices, faces).
    fn event(
        &self,
        phase: Phase,
        (iteration, iterations): (u32, u32),
        loss: Option<f32>,
        psnr: Option<f64>,
        sizes: (usize, usize),
    ) -> Progress {
        Progress {
            state: self.state,
            phase,
            iteration,
            iterations,
            loss,
            psnr,
            vertices: sizes.0,
            faces: sizes.1,
            elapsed_s: now_seconds() - self.t0,
            candidate: None,
            open: 0,
        }
    }

    /// A checkpoint without a preview.
    async fn report(&mut self, event: &Progress) -> GpuResult<()> {
        checkpoint(self.observer, event).await
    }

    /// A training checkpoint: reports `event`, then renders training view 0 for the observer
    /// when it asks for a preview.
    async fn watch(
        &mut self,
        trainer: &mut Trainer<'_>,
        event: &Progress,
        settings: &RasterSettings,
    ) -> GpuResult<()> {
        checkpoint(self.observer, event).await?;
        if self.observer.wants_preview() {
            let at = (event.state, event.phase, event.iteration);
            let preview = trainer.preview(self.ctx, 0, settings, at).await?;
            self.observer.preview(preview);
        }
        Ok(())
    }

    /// An invalid-input error naming this state.
    fn error(&self, what: String) -> GpuError {
        GpuError::InvalidInput(format!("{} state: {what}", self.state.name()))
    }
}

fn sizes(field: &MeshField) -> (usize, usize) {
    (field.num_vertices(), field.faces.len())
}

/// Reconstructs one state from its training views (see the module docs), and measures the
/// result on its held-out views (may be none) at the end.
pub async fn reconstruct_state(
    ctx: &GpuContext,
    state: State,
    views: &StateViews,
    num_parts: usize,
    config: &ReconstructionConfig,
    observer: &mut dyn Observer,
) -> GpuResult<StateReconstruction> {
    let (frames, held_out) = (&views.train[..], &views.held_out[..]);
    let t0 = now_seconds();
    // Where the dataset measured every part, the optimised vertices would all be replaced at the
    // remesh: the photometric steps go to the recovery on the measured surface instead.
    let skip = ReconstructionConfig {
        fit: PhotometricConfig {
            iterations: 0,
            ..config.fit
        },
        ..*config
    };
    let measured = views.surface.as_ref();
    let all_measured = config.surface == SurfaceSource::Measured
        && measured.is_some_and(|m| measures_every_part(m, num_parts));
    let config = if all_measured { &skip } else { config };
    let mut run = StateRun {
        ctx,
        state,
        config,
        observer,
        t0,
        last: t0,
        times: PhaseTimes::default(),
    };
    let cameras: Vec<Camera> = frames.iter().map(|f| f.camera).collect();
    let Some(first) = frames.first() else {
        return Err(GpuError::InvalidInput(format!(
            "the {} state has no training views",
            state.name()
        )));
    };
    let (width, height) = (first.rgba.width, first.rgba.height);

    let (field, px_per_m) = initialise(&mut run, frames, &cameras, num_parts).await?;
    let fit = &config.fit;
    let mut trainer = Trainer::new(
        ctx,
        &cameras,
        frames,
        &field,
        fit.rates(fit.position_decay().lr(0)),
        fit.seed,
    )?;
    let optimised = optimise(&mut run, &mut trainer, &field, frames.len(), px_per_m).await?;
    let free = views.free_space.as_deref();
    let (remeshed, remesh_stats) = remesh_stage(&mut run, &optimised.field, measured, free).await?;
    let recovered = recover(&mut run, &mut trainer, &remeshed).await?;
    let recovery = config.recovery();
    let last = recovery.settings_at(recovery.iterations);
    let psnr_test = held_out_psnr(ctx, &mut trainer, held_out, (width, height), &last).await?;

    let field = recovered.field;
    let parts = harden_parts(&field);
    let meshes = part_meshes(&field.positions, &field.faces, &parts, num_parts);
    run.times.total_s = now_seconds() - t0;
    let done = run.event(
        Phase::Done,
        (0, 0),
        None,
        Some(recovered.psnr_recovered),
        sizes(&remeshed),
    );
    run.report(&done).await?;
    Ok(StateReconstruction {
        state,
        field,
        parts,
        part_meshes: meshes,
        remesh: remesh_stats,
        faces_split: optimised.faces_split,
        faces_pruned: optimised.faces_pruned,
        initial_faces: optimised.initial_faces,
        psnr_optimised: optimised.psnr,
        psnr_remeshed: recovered.psnr_remeshed,
        psnr_recovered: recovered.psnr_recovered,
        psnr_test,
        curve: optimised.curve,
        times: run.times,
        width,
        height,
        views: frames.len(),
    })
}

/// Stage 1: the triangle soup from the depth maps, and the pixels per metre at its distance.
async fn initialise(
    run: &mut StateRun<'_>,
    frames: &[Frame],
    cameras: &[Camera],
    num_parts: usize,
) -> GpuResult<(MeshField, f32)> {
    let field =
        initial_field(frames, num_parts, &run.config.init).map_err(|e| run.error(e.to_string()))?;
    let px_per_m = pixels_per_metre(&field, cameras);
    run.times.initialise_s = run.lap();
    let at = run.event(Phase::Initialise, (0, 0), None, None, sizes(&field));
    run.report(&at).await?;
    Ok((field, px_per_m))
}

/// What the optimisation left: the field before remeshing and how it got there.
struct Optimised {
    field: MeshField,
    /// Mean training PSNR at the end of the optimisation.
    psnr: f64,
    curve: Vec<CurvePoint>,
    initial_faces: usize,
    faces_split: usize,
    faces_pruned: usize,
}

/// Stage 2: the optimisation of `field` (already in `trainer`), densifying and pruning every
/// `densify.every` steps (at least once per view) inside the densification window.
async fn optimise(
    run: &mut StateRun<'_>,
    trainer: &mut Trainer<'_>,
    field: &MeshField,
    views: usize,
    px_per_m: f32,
) -> GpuResult<Optimised> {
    let (ctx, config) = (run.ctx, run.config);
    let fit = &config.fit;
    let mut current = sizes(field);
    let every = config.densify.every.max(views as u32).max(1);
    let window = (
        (config.densify.from * fit.iterations as f32) as u32,
        (config.densify.until * fit.iterations as f32) as u32,
    );
    let (mut faces_split, mut faces_pruned) = (0, 0);
    let mut curve = Vec::new();
    trainer.clear_face_stats(ctx);
    for i in 0..fit.iterations {
        if let (settings, Some(point)) = trainer.scheduled_step(ctx, fit, i).await? {
            run.times.optimise_s += run.lap();
            let at = run.event(
                Phase::Optimise,
                (i + 1, fit.iterations),
                Some(point.loss.total),
                point.psnr,
                current,
            );
            run.watch(trainer, &at, &settings).await?;
            curve.push(point);
        }
        if i > 0 && i % every == 0 {
            run.times.optimise_s += run.lap();
            if (window.0..=window.1).contains(&i) {
                let (split, pruned, edited) = densify(run, trainer, i, px_per_m).await?;
                faces_split += split;
                faces_pruned += pruned;
                current = edited;
            }
            trainer.clear_face_stats(ctx);
        }
    }
    run.times.optimise_s += run.lap();
    let final_settings = fit.settings_at(fit.iterations);
    let psnr = trainer.mean_psnr(ctx, &final_settings).await?;
    let optimised = trainer.download(ctx).await?;
    run.times.measure_s += run.lap();
    Ok(Optimised {
        field: optimised,
        psnr,
        curve,
        initial_faces: field.faces.len(),
        faces_split,
        faces_pruned,
    })
}

/// One densify-and-prune edit of the trainer's field at step `i`, from the window's face
/// statistics: (faces split, faces pruned, the new (vertices, faces)).
async fn densify(
    run: &mut StateRun<'_>,
    trainer: &mut Trainer<'_>,
    i: u32,
    px_per_m: f32,
) -> GpuResult<(usize, usize, (usize, usize))> {
    let (ctx, config) = (run.ctx, run.config);
    let current = trainer.download(ctx).await?;
    let stats = trainer.read_face_stats(ctx).await?;
    let (edited, map, split, pruned) =
        densify_and_prune(&current, &stats, &config.densify, px_per_m);
    if edited.faces.is_empty() {
        return Err(run.error(format!(
            "pruning removed every face at iteration {i} (is the object in view?)"
        )));
    }
    trainer.replace_field(ctx, &edited, &map)?;
    let edited = sizes(&edited);
    run.times.densify_s += run.lap();
    let at = run.event(
        Phase::Densify,
        (i + 1, config.fit.iterations),
        None,
        None,
        edited,
    );
    run.report(&at).await?;
    Ok((split, pruned, edited))
}

/// Stage 3: hardening and part-aware remeshing of the optimised field.
async fn remesh_stage(
    run: &mut StateRun<'_>,
    optimised: &MeshField,
    measured: Option<&ObservedState>,
    free: Option<&FreeSpace>,
) -> GpuResult<(MeshField, RemeshStats)> {
    let (remeshed, stats) = remesh(optimised, measured, free, run.state, run.config);
    if remeshed.faces.is_empty() {
        return Err(run.error(format!(
            "remeshing built no faces from {} vertices",
            optimised.num_vertices()
        )));
    }
    run.times.remesh_s = run.lap();
    let at = run.event(Phase::Remesh, (0, 0), None, None, sizes(&remeshed));
    run.report(&at).await?;
    Ok((remeshed, stats))
}

/// What the recovery left: the final field and the PSNR before and after it.
struct Recovered {
    field: MeshField,
    psnr_remeshed: f64,
    psnr_recovered: f64,
}

/// Stage 4: a short fit of the remeshed field with its topology fixed.
async fn recover(
    run: &mut StateRun<'_>,
    trainer: &mut Trainer<'_>,
    remeshed: &MeshField,
) -> GpuResult<Recovered> {
    let (ctx, config) = (run.ctx, run.config);
    let recovery = config.recovery();
    trainer.restart(
        ctx,
        remeshed,
        recovery.rates(recovery.position_lr.0),
        config.fit.seed ^ 1,
    )?;
    let psnr_remeshed = trainer.mean_psnr(ctx, &recovery.settings_at(0)).await?;
    run.times.measure_s += run.lap();
    for i in 0..recovery.iterations {
        if let (settings, Some(point)) = trainer.scheduled_step(ctx, &recovery, i).await? {
            let at = run.event(
                Phase::Recover,
                (i + 1, recovery.iterations),
                Some(point.loss.total),
                point.psnr,
                sizes(remeshed),
            );
            run.watch(trainer, &at, &settings).await?;
        }
    }
    run.times.recover_s = run.lap();
    let psnr_recovered = trainer
        .mean_psnr(ctx, &recovery.settings_at(recovery.iterations))
        .await?;
    let field = trainer.download(ctx).await?;
    run.times.measure_s += run.lap();
    Ok(Recovered {
        field,
        psnr_remeshed,
        psnr_recovered,
    })
}

/// Mean PSNR of the field in `trainer` over `held_out` (views it was not fitted on) with
/// `settings`; `None` without such views or when their size is not the training views'.
async fn held_out_psnr(
    ctx: &GpuContext,
    trainer: &mut Trainer<'_>,
    held_out: &[Frame],
    (width, height): (u32, u32),
    settings: &RasterSettings,
) -> GpuResult<Option<f64>> {
    let sized = |f: &Frame| (f.rgba.width, f.rgba.height) == (width, height);
    if held_out.is_empty() || !held_out.iter().all(sized) {
        return Ok(None);
    }
    let cameras: Vec<Camera> = held_out.iter().map(|f| f.camera).collect();
    let psnr = trainer
        .mean_psnr_over(ctx, &cameras, held_out, settings)
        .await?;
    Ok(Some(psnr))
}
