//! The photometric inner loop on its own: optimise a mesh field against posed views with the GPU
//! image loss and Adam — no densification, remeshing or articulation. It shows that the
//! differentiable rasterizer learns (the rasterizer issue's driver) and is the loop the
//! reconstruction phase builds on.
//!
//! [`synthetic_scene`] makes a test problem from the procedural generator: an object captured at
//! one state, and as the starting mesh its ground-truth surface bisected to about one edge per
//! pixel or two, with jittered vertices, grey colour and half opacity.

use glam::Vec3;
use serde::Serialize;

use super::observer::Preview;
use super::subdivide::{subdivide_to_edge, weld};
use super::views::ViewCycle;
use crate::data::{Camera, Frame, Split, State};
use crate::gpu::{GpuContext, GpuError, GpuResult};
use crate::loss::{ImageLoss, LossTerms, LossWeights, TargetImages, TargetView};
use crate::optim::{Adam, AdamConfig, AdamGroup, ExponentialDecay};
use crate::raster::{GpuField, MeshField, RasterSettings, RasterState, Rasterizer, SH_FLOATS};
use crate::rng::Rng;

/// Schedules and learning rates of a photometric fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PhotometricConfig {
    pub iterations: u32,
    /// Position learning rate, decayed log-linearly over the run (paper: 2e-4 → 2e-6).
    pub position_lr: (f32, f32),
    /// SH coefficients (paper: 1.6e-3 for 20k iterations; short fits need more).
    pub sh_lr: f32,
    /// Opacity logits (paper: 3e-2).
    pub opacity_lr: f32,
    /// Part logits (paper: 5e-3).
    pub part_lr: f32,
    /// Window sharpness γ, annealed geometrically from the first to the second value.
    pub gamma: (f32, f32),
    /// The opacity floor ramps from 0 to 1 between these fractions of the run, so faces end opaque.
    pub opacity_ramp: (f32, f32),
    /// The active SH degree rises by one every this many iterations, up to `max_sh_degree`.
    pub sh_degree_every: u32,
    /// Active SH degree at iteration 0 (a recovery stage starts where the fit ended).
    pub sh_degree_start: u32,
    pub max_sh_degree: u32,
    pub weights: LossWeights,
    pub background: Vec3,
    pub seed: u64,
    /// Loss terms are read back (and reported) every this many iterations.
    pub report_every: u32,
}

impl Default for PhotometricConfig {
    fn default() -> Self {
        Self {
            iterations: 300,
            position_lr: (2e-4, 2e-6),
            sh_lr: 1e-2,
            opacity_lr: 3e-2,
            part_lr: 5e-3,
            gamma: (1.0, 0.02),
            opacity_ramp: (0.4, 0.7),
            sh_degree_every: 100,
            sh_degree_start: 0,
            max_sh_degree: 3,
            weights: LossWeights::default(),
            background: Vec3::ZERO,
            seed: 1,
            report_every: 25,
        }
    }
}

impl PhotometricConfig {
    /// Raster settings at iteration `i`.
    pub fn settings_at(&self, i: u32) -> RasterSettings {
        let t = i as f32 / self.iterations.max(1) as f32;
        let (g0, g1) = self.gamma;
        let (r0, r1) = self.opacity_ramp;
        RasterSettings {
            gamma: g0 * (g1 / g0).powf(t),
            opacity_floor: ((t - r0) / (r1 - r0).max(1e-6)).clamp(0.0, 1.0),
            background: self.background,
            sh_degree: (self.sh_degree_start + i / self.sh_degree_every.max(1))
                .min(self.max_sh_degree),
            ..RasterSettings::default()
        }
    }
}

/// One point of the learning curve.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct CurvePoint {
    pub iteration: u32,
    /// Loss of the view trained at this iteration.
    pub loss: LossTerms,
    /// Mean PSNR (dB) over all training views, when it was measured at this point.
    pub psnr: Option<f64>,
    pub gamma: f32,
    pub opacity_floor: f32,
}

/// The fitted field and how it got there.
#[derive(Debug, Clone)]
pub struct PhotometricResult {
    pub field: MeshField,
    pub curve: Vec<CurvePoint>,
    /// PSNR before the first step and after the last.
    pub psnr_start: f64,
    pub psnr_end: f64,
}

/// A fitting problem: posed views and a starting mesh field.
#[derive(Debug, Clone)]
pub struct Problem {
    pub cameras: Vec<Camera>,
    pub frames: Vec<Frame>,
    pub field: MeshField,
}

/// Learning rates of the mesh field's four parameter groups.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FieldLearningRates {
    pub position: f32,
    pub sh: f32,
    pub opacity: f32,
    pub part: f32,
}

/// Adam over a [`GpuField`]'s positions, SH coefficients, opacity logits and part logits.
pub struct FieldAdam {
    adam: Adam,
    groups: Vec<AdamGroup>,
}

impl FieldAdam {
    pub fn new(ctx: &GpuContext, field: &GpuField, lr: FieldLearningRates) -> GpuResult<Self> {
        let adam = Adam::new(ctx)?;
        let nv = field.num_vertices;
        let groups = vec![
            adam.group(
                ctx,
                "positions",
                &field.positions,
                &field.grad_positions,
                4 * nv,
                AdamConfig::with_lr(lr.position),
            )?,
            adam.group(
                ctx,
                "sh",
                &field.sh,
                &field.grad_sh,
                nv * SH_FLOATS as u32,
                AdamConfig::with_lr(lr.sh),
            )?,
            adam.group(
                ctx,
                "opacity",
                &field.opacity,
                &field.grad_opacity,
                nv,
                AdamConfig::with_lr(lr.opacity),
            )?,
            adam.group(
                ctx,
                "part_logits",
                &field.part_logits,
                &field.grad_part_logits,
                nv * field.num_parts,
                AdamConfig::with_lr(lr.part),
            )?,
        ];
        Ok(Self { adam, groups })
    }

    /// Sets the position learning rate (the one group with a schedule).
    pub fn set_position_lr(&mut self, lr: f32) {
        self.groups[0].set_lr(lr);
    }

    /// Sets every group's learning rate.
    pub fn set_rates(&mut self, lr: FieldLearningRates) {
        for (group, lr) in self
            .groups
            .iter_mut()
            .zip([lr.position, lr.sh, lr.opacity, lr.part])
        {
            group.set_lr(lr);
        }
    }

    /// Moves the optimiser onto `field` after a topology edit: `map[new vertex] = old vertex`, or
    /// [`crate::optim::FRESH`] for a vertex that starts with zero moments.
    pub fn remap(&mut self, ctx: &GpuContext, field: &GpuField, map: &[u32]) -> GpuResult<()> {
        let buffers = [
            (&field.positions, &field.grad_positions, 4),
            (&field.sh, &field.grad_sh, SH_FLOATS as u32),
            (&field.opacity, &field.grad_opacity, 1),
            (&field.part_logits, &field.grad_part_logits, field.num_parts),
        ];
        for (group, (params, grads, stride)) in self.groups.iter_mut().zip(buffers) {
            self.adam.remap(ctx, group, params, grads, map, stride)?;
        }
        Ok(())
    }

    /// Records one step of every group.
    pub fn encode_step(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
    ) -> GpuResult<()> {
        let mut refs: Vec<&mut AdamGroup> = self.groups.iter_mut().collect();
        self.adam.encode_step(ctx, encoder, &mut refs)
    }
}

/// `frame`'s colour composited over `background` by its alpha, as planes (R, G, B): what the
/// image loss compares a render with.
pub(crate) fn target_rgb(frame: &Frame, background: Vec3) -> Vec<f32> {
    let img = &frame.rgba;
    let n = (img.width * img.height) as usize;
    let mut out = vec![0.0; 3 * n];
    for i in 0..n {
        let px = &img.pixels[4 * i..4 * i + 4];
        let a = f32::from(px[3]) / 255.0;
        for c in 0..3 {
            out[c * n + i] = f32::from(px[c]) / 255.0 * a + background[c] * (1.0 - a);
        }
    }
    out
}

/// Channel planes (all R, then all G, then all B; values in [0, 1]) as interleaved RGB8.
fn planes_to_rgb8(planes: &[f32]) -> Vec<u8> {
    let n = planes.len() / 3;
    (0..3 * n)
        .map(|i| (planes[(i % 3) * n + i / 3].clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect()
}

/// Records the image loss of `state`'s last render against target view `view` and the
/// rasterizer's backward pass, which leaves the gradients in `field`'s gradient buffers.
#[allow(clippy::too_many_arguments)]
pub(crate) fn encode_loss_and_backward(
    ctx: &GpuContext,
    encoder: &mut wgpu::CommandEncoder,
    raster: &Rasterizer,
    (loss, targets, view): (&ImageLoss, &TargetImages, usize),
    state: &mut RasterState,
    field: &GpuField,
    weights: &LossWeights,
    settings: &RasterSettings,
) -> GpuResult<()> {
    loss.encode(
        ctx,
        encoder,
        state.render(),
        targets,
        view,
        weights,
        settings.background.to_array(),
        state.grad_render(),
    )?;
    raster.encode_backward(ctx, encoder, field, state);
    Ok(())
}

/// The photometric training state of one mesh field against one set of posed views: the
/// rasterizer, the image loss with its uploaded targets, the field on the GPU and its Adam. The
/// photometric fit and the reconstruction phase both step it; the reconstruction also edits the
/// topology in between ([`Trainer::replace_field`]).
pub struct Trainer<'a> {
    raster: Rasterizer,
    /// The field being optimised.
    pub field: GpuField,
    state: RasterState,
    /// Previews render into their own state: the training state's face statistics (which
    /// densification reads) would otherwise count the preview's view too, and a fit would
    /// depend on when, and whether, someone watched it.
    preview_state: Option<RasterState>,
    loss: ImageLoss,
    targets: TargetImages,
    optimizer: FieldAdam,
    cameras: &'a [Camera],
    frames: &'a [Frame],
    rng: Rng,
    views: ViewCycle,
}

impl<'a> Trainer<'a> {
    /// Uploads `field` and the targets; errors on mismatched or empty views.
    pub fn new(
        ctx: &GpuContext,
        cameras: &'a [Camera],
        frames: &'a [Frame],
        field: &MeshField,
        lr: FieldLearningRates,
        seed: u64,
    ) -> GpuResult<Self> {
        let Some(first) = frames.first() else {
            return Err(GpuError::InvalidInput(
                "a photometric fit needs at least one view".into(),
            ));
        };
        if cameras.len() != frames.len() {
            return Err(GpuError::InvalidInput(format!(
                "{} cameras for {} frames",
                cameras.len(),
                frames.len()
            )));
        }
        let (w, h) = (first.rgba.width, first.rgba.height);
        let parts = field.num_parts as u32;
        let gpu_field = GpuField::upload(ctx, field)?;
        let views: Vec<TargetView> = frames.iter().map(TargetView::from).collect();
        Ok(Self {
            raster: Rasterizer::new(ctx),
            state: RasterState::new(ctx, w, h, parts)?,
            preview_state: None,
            loss: ImageLoss::new(ctx, w, h, parts)?,
            targets: TargetImages::upload(ctx, w, h, &views)?,
            optimizer: FieldAdam::new(ctx, &gpu_field, lr)?,
            field: gpu_field,
            cameras,
            frames,
            rng: Rng::new(seed),
            views: ViewCycle::default(),
        })
    }

    /// One step on the next view of a shuffled cycle through all views.
    pub async fn step(
        &mut self,
        ctx: &GpuContext,
        settings: &RasterSettings,
        weights: &LossWeights,
    ) -> GpuResult<()> {
        let view = self.views.next(self.cameras.len(), &mut self.rng);
        self.raster
            .forward(
                ctx,
                &self.field,
                &mut self.state,
                &self.cameras[view],
                settings,
            )
            .await?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encode_loss_and_backward(
            ctx,
            &mut encoder,
            &self.raster,
            (&self.loss, &self.targets, view),
            &mut self.state,
            &self.field,
            weights,
            settings,
        )?;
        self.optimizer.encode_step(ctx, &mut encoder)?;
        ctx.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// The loss terms of the last step; an error when they are not finite.
    pub async fn read_terms(&self, ctx: &GpuContext, iteration: u32) -> GpuResult<LossTerms> {
        let terms = self.loss.read_terms(ctx).await?;
        if !terms.total.is_finite() {
            return Err(GpuError::InvalidInput(format!(
                "the loss became {} at iteration {iteration}: lower the learning rates",
                terms.total
            )));
        }
        Ok(terms)
    }

    /// Mean PSNR over all views with `settings`.
    pub async fn mean_psnr(
        &mut self,
        ctx: &GpuContext,
        settings: &RasterSettings,
    ) -> GpuResult<f64> {
        let mut sum = 0.0;
        for (camera, frame) in self.cameras.iter().zip(self.frames) {
            self.raster
                .forward(ctx, &self.field, &mut self.state, camera, settings)
                .await?;
            let render = self.state.read_render(ctx).await?;
            let n = (render.width * render.height) as usize;
            sum += crate::raster::reference::psnr(
                &render.planes[..3 * n],
                &target_rgb(frame, settings.background),
            );
        }
        Ok(sum / self.cameras.len().max(1) as f64)
    }

    /// The current render of training view `view` and its target (composited on the
    /// background), as RGB8: the [`Preview`] of `state` at `iteration`.
    pub async fn preview(
        &mut self,
        ctx: &GpuContext,
        view: usize,
        settings: &RasterSettings,
        (state, iteration): (State, u32),
    ) -> GpuResult<Preview> {
        let (Some(camera), Some(frame)) = (self.cameras.get(view), self.frames.get(view)) else {
            return Err(GpuError::InvalidInput(format!(
                "no training view {view} to preview"
            )));
        };
        let raster_state = match &mut self.preview_state {
            Some(raster_state) => raster_state,
            None => self.preview_state.insert(RasterState::new(
                ctx,
                frame.rgba.width,
                frame.rgba.height,
                self.field.num_parts,
            )?),
        };
        self.raster
            .forward(ctx, &self.field, raster_state, camera, settings)
            .await?;
        let render = raster_state.read_render(ctx).await?;
        let n = (render.width * render.height) as usize;
        Ok(Preview {
            state,
            view,
            iteration,
            width: render.width,
            height: render.height,
            render: planes_to_rgb8(&render.planes[..3 * n]),
            target: planes_to_rgb8(&target_rgb(frame, settings.background)),
        })
    }

    /// Runs `config`'s whole schedule (γ, opacity floor, SH degree, decaying position rate) on
    /// the current topology; `progress` hears every reported curve point, which are returned.
    pub async fn run(
        &mut self,
        ctx: &GpuContext,
        config: &PhotometricConfig,
        progress: &mut dyn FnMut(&CurvePoint),
    ) -> GpuResult<Vec<CurvePoint>> {
        let mut curve = Vec::new();
        for i in 0..config.iterations {
            if let (_, Some(point)) = self.scheduled_step(ctx, config, i).await? {
                progress(&point);
                curve.push(point);
            }
        }
        Ok(curve)
    }

    /// Step `i` of `config`'s schedule: its settings and position rate, one step, and the
    /// curve point when `i` is a reporting iteration. Returns the settings it stepped with.
    pub async fn scheduled_step(
        &mut self,
        ctx: &GpuContext,
        config: &PhotometricConfig,
        i: u32,
    ) -> GpuResult<(RasterSettings, Option<CurvePoint>)> {
        let settings = config.settings_at(i);
        self.optimizer
            .set_position_lr(config.position_decay().lr(i));
        self.step(ctx, &settings, &config.weights).await?;
        let point = config.report(ctx, self, i, &settings).await?;
        Ok((settings, point))
    }

    /// Zeroes the per-face statistics (max blending weight, pixel count) the renders accumulate.
    pub fn clear_face_stats(&self, ctx: &GpuContext) {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.state.clear_face_stats(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
    }

    /// Per face (max blending weight, pixels covered) since the last clear.
    pub async fn read_face_stats(&self, ctx: &GpuContext) -> GpuResult<Vec<(f32, u32)>> {
        self.state.read_face_stats(ctx, self.field.num_faces).await
    }

    /// The field as it is now.
    pub async fn download(&self, ctx: &GpuContext) -> GpuResult<MeshField> {
        self.field.download(ctx).await
    }

    /// Starts a new fit of `field` against the same views: fresh Adam moments at `lr` and a new
    /// view order from `seed`. The rasterizer, the loss and the uploaded targets are kept (the
    /// reconstruction's recovery stage needs no second upload or pipeline build).
    pub fn restart(
        &mut self,
        ctx: &GpuContext,
        field: &MeshField,
        lr: FieldLearningRates,
        seed: u64,
    ) -> GpuResult<()> {
        let gpu_field = GpuField::upload(ctx, field)?;
        self.optimizer = FieldAdam::new(ctx, &gpu_field, lr)?;
        self.field = gpu_field;
        self.rng = Rng::new(seed);
        self.views.restart();
        Ok(())
    }

    /// Replaces the field after a topology edit, carrying Adam's moments along `map`
    /// (`map[new vertex] = old vertex` or [`crate::optim::FRESH`]).
    pub fn replace_field(
        &mut self,
        ctx: &GpuContext,
        field: &MeshField,
        map: &[u32],
    ) -> GpuResult<()> {
        let gpu_field = GpuField::upload(ctx, field)?;
        self.optimizer.remap(ctx, &gpu_field, map)?;
        self.field = gpu_field;
        Ok(())
    }
}

/// Fits `problem.field` to `problem.frames`; `progress` hears every reported curve point.
pub async fn fit(
    ctx: &GpuContext,
    problem: &Problem,
    config: &PhotometricConfig,
    progress: &mut dyn FnMut(&CurvePoint),
) -> GpuResult<PhotometricResult> {
    let mut trainer = Trainer::new(
        ctx,
        &problem.cameras,
        &problem.frames,
        &problem.field,
        config.rates(config.position_lr.0),
        config.seed,
    )?;
    let psnr_start = trainer.mean_psnr(ctx, &config.settings_at(0)).await?;
    let curve = trainer.run(ctx, config, progress).await?;
    let psnr_end = trainer
        .mean_psnr(ctx, &config.settings_at(config.iterations))
        .await?;
    Ok(PhotometricResult {
        field: trainer.download(ctx).await?,
        curve,
        psnr_start,
        psnr_end,
    })
}

impl PhotometricConfig {
    /// The position learning rate's log-linear decay over the run.
    pub fn position_decay(&self) -> ExponentialDecay {
        ExponentialDecay {
            start: self.position_lr.0,
            end: self.position_lr.1,
            steps: self.iterations,
        }
    }

    /// The learning rates at the start, with `position` for the scheduled group.
    pub fn rates(&self, position: f32) -> FieldLearningRates {
        FieldLearningRates {
            position,
            sh: self.sh_lr,
            opacity: self.opacity_lr,
            part: self.part_lr,
        }
    }

    /// The curve point of iteration `i` when it is a reporting iteration (loss terms every
    /// `report_every`, mean PSNR every fourth report and at the end).
    pub async fn report(
        &self,
        ctx: &GpuContext,
        trainer: &mut Trainer<'_>,
        i: u32,
        settings: &RasterSettings,
    ) -> GpuResult<Option<CurvePoint>> {
        let every = self.report_every.max(1);
        let last = i + 1 == self.iterations;
        if !i.is_multiple_of(every) && !last {
            return Ok(None);
        }
        let loss = trainer.read_terms(ctx, i).await?;
        let psnr = if last || i.is_multiple_of(4 * every) {
            Some(trainer.mean_psnr(ctx, settings).await?)
        } else {
            None
        };
        Ok(Some(CurvePoint {
            iteration: i,
            loss,
            psnr,
            gamma: settings.gamma,
            opacity_floor: settings.opacity_floor,
        }))
    }
}

/// How to build a [`synthetic_scene`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneSpec {
    pub category: crate::synth::Category,
    pub movable_parts: Option<usize>,
    pub seed: u64,
    pub size: u32,
    pub views: usize,
    /// Longest edge of the starting mesh, in pixels at the object's distance.
    pub edge_pixels: f32,
    /// Vertex jitter as a fraction of that edge length.
    pub jitter: f32,
    /// Cap on the starting mesh's faces.
    pub max_faces: usize,
}

impl Default for SceneSpec {
    fn default() -> Self {
        Self {
            category: crate::synth::Category::Box,
            movable_parts: Some(1),
            seed: 3,
            size: 128,
            views: 16,
            edge_pixels: 1.5,
            jitter: 0.3,
            max_faces: 60_000,
        }
    }
}

/// A procedural object captured at its start state from `spec.views` views, and a starting mesh
/// made from its ground-truth surface (see the module docs).
pub async fn synthetic_scene(ctx: &GpuContext, spec: &SceneSpec) -> Result<Problem, String> {
    use crate::render::RenderSpec;
    use crate::synth::{SynthParams, generate};
    let object = generate(&SynthParams {
        category: spec.category,
        movable_parts: spec.movable_parts,
        seed: spec.seed,
    })?;
    let render = RenderSpec {
        width: spec.size,
        height: spec.size,
        train_views: spec.views,
        test_views: 0,
        seed: spec.seed,
        ..RenderSpec::default()
    };
    let dataset = crate::render::capture_dataset(ctx, &object, &render, &mut |_| {}).await?;
    let frames = dataset
        .views(State::Start, Split::Train)
        .map(|v| v.frames.clone())
        .ok_or("the capture has no start-state training views")?;
    let meshes = dataset
        .gt_meshes_for(State::Start)
        .ok_or("the capture has no ground-truth meshes")?;

    let mut positions = Vec::new();
    let mut faces = Vec::new();
    let mut part_of = Vec::new();
    for (part, mesh) in std::iter::once(&meshes.static_part)
        .chain(&meshes.movable)
        .enumerate()
    {
        let (p, f, _) = weld(&mesh.positions, &mesh.triangles, 1e-5);
        let base = positions.len() as u32;
        positions.extend(p.iter().copied());
        part_of.extend(std::iter::repeat_n(part, p.len()));
        faces.extend(f.iter().map(|t| t.map(|v| v + base)));
    }
    let num_parts = meshes.movable.len() + 1;
    let cameras: Vec<Camera> = frames.iter().map(|f| f.camera).collect();
    let centre = positions.iter().copied().sum::<Vec3>() / positions.len().max(1) as f32;
    let distance = cameras
        .iter()
        .map(|c| c.position().distance(centre))
        .sum::<f32>()
        / cameras.len().max(1) as f32;
    let edge = spec.edge_pixels * distance / cameras.first().map_or(1.0, |c| c.intrinsics.fx);
    subdivide_to_edge(
        &mut positions,
        &mut faces,
        edge,
        spec.max_faces,
        &mut |a, _| {
            part_of.push(part_of[a as usize]);
        },
    );
    let mut rng = Rng::new(spec.seed ^ 0x5eed);
    for p in positions.iter_mut() {
        let d = Vec3::new(
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        );
        *p += spec.jitter * edge * d;
    }
    let mut field = MeshField::new(positions, faces, num_parts, 0.0);
    for (v, &part) in part_of.iter().enumerate() {
        field.set_color(v, Vec3::splat(0.5));
        field.part_logits[v * num_parts + part] = 2.0;
    }
    Ok(Problem {
        cameras,
        frames,
        field,
    })
}

/// The short fit both the native and the browser tests run: a 48² capture of the default object
/// from 6 views, 60 iterations from a 3-pixel-edge starting mesh.
pub fn short_fit() -> (SceneSpec, PhotometricConfig) {
    (
        SceneSpec {
            size: 48,
            views: 6,
            edge_pixels: 3.0,
            ..SceneSpec::default()
        },
        PhotometricConfig {
            iterations: 60,
            report_every: 10,
            sh_degree_every: 30,
            ..PhotometricConfig::default()
        },
    )
}

/// A preview strip, RGB8: one row per view in `views`, each [target | starting mesh | fitted mesh],
/// rendered with the run's final settings.
pub async fn preview(
    ctx: &GpuContext,
    problem: &Problem,
    fitted: &MeshField,
    config: &PhotometricConfig,
    views: &[usize],
) -> GpuResult<(u32, u32, Vec<u8>)> {
    let Some(first) = problem.frames.first() else {
        return Err(GpuError::InvalidInput("no views to preview".into()));
    };
    let (w, h) = (first.rgba.width, first.rgba.height);
    let settings = config.settings_at(config.iterations);
    let raster = Rasterizer::new(ctx);
    let mut state = RasterState::new(ctx, w, h, problem.field.num_parts as u32)?;
    let fields = [
        GpuField::upload(ctx, &problem.field)?,
        GpuField::upload(ctx, fitted)?,
    ];
    let views: Vec<usize> = views
        .iter()
        .copied()
        .filter(|&v| v < problem.frames.len())
        .collect();
    let (sheet_w, sheet_h) = (3 * w, h * views.len().max(1) as u32);
    let mut pixels = vec![0u8; (sheet_w * sheet_h * 3) as usize];
    let n = (w * h) as usize;
    for (row, &view) in views.iter().enumerate() {
        let mut columns = vec![target_rgb(&problem.frames[view], settings.background)];
        for field in &fields {
            raster
                .forward(ctx, field, &mut state, &problem.cameras[view], &settings)
                .await?;
            columns.push(state.read_render(ctx).await?.planes[..3 * n].to_vec());
        }
        for (col, planes) in columns.iter().enumerate() {
            for (i, rgb) in planes_to_rgb8(planes).chunks_exact(3).enumerate() {
                let (x, y) = (col as u32 * w + i as u32 % w, row as u32 * h + i as u32 / w);
                let out = ((y * sheet_w + x) * 3) as usize;
                pixels[out..out + 3].copy_from_slice(rgb);
            }
        }
    }
    Ok((sheet_w, sheet_h, pixels))
}
