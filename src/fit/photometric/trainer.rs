//! The photometric training state ([`Trainer`]): one mesh field on the GPU stepped against one
//! set of posed views by the image loss and Adam, with the reads a driver needs between steps
//! (loss terms, PSNR, previews, face statistics, the field) and the topology edits of the
//! reconstruction.

use super::adam::{FieldAdam, FieldLearningRates};
use super::config::{CurvePoint, PhotometricConfig};
use super::image::{encode_loss_and_backward, planes_to_rgb8, target_rgb};
use crate::data::{Camera, Frame, State};
use crate::fit::observer::{Phase, Preview};
use crate::fit::views::ViewCycle;
use crate::gpu::{GpuContext, GpuError, GpuResult};
use crate::loss::{ImageLoss, LossTerms, LossWeights, TargetImages, TargetView};
use crate::raster::{GpuField, MeshField, RasterSettings, RasterState, Rasterizer};
use crate::rng::Rng;

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
    pub(crate) async fn mean_psnr(
        &mut self,
        ctx: &GpuContext,
        settings: &RasterSettings,
    ) -> GpuResult<f64> {
        self.mean_psnr_over(ctx, self.cameras, self.frames, settings)
            .await
    }

    /// Mean PSNR with `settings` over `frames` seen from `cameras` (of the training views'
    /// size: views the fit may not have seen, such as held-out ones).
    pub(crate) async fn mean_psnr_over(
        &mut self,
        ctx: &GpuContext,
        cameras: &[Camera],
        frames: &[Frame],
        settings: &RasterSettings,
    ) -> GpuResult<f64> {
        let mut sum = 0.0;
        for (camera, frame) in cameras.iter().zip(frames) {
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
        Ok(sum / frames.len().max(1) as f64)
    }

    /// The current render of training view `view` and its target (composited on the
    /// background), as RGB8: the [`Preview`] of `state` at `iteration`.
    pub async fn preview(
        &mut self,
        ctx: &GpuContext,
        view: usize,
        settings: &RasterSettings,
        (state, phase, iteration): (State, Phase, u32),
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
            phase,
            moved_by: None,
            width: render.width,
            height: render.height,
            render: planes_to_rgb8(&render.planes[..3 * n]),
            target: planes_to_rgb8(&target_rgb(frame, settings.background)),
            marks: Default::default(),
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
    pub(crate) async fn scheduled_step(
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
    pub(crate) async fn read_face_stats(&self, ctx: &GpuContext) -> GpuResult<Vec<(f32, u32)>> {
        self.state.read_face_stats(ctx, self.field.num_faces).await
    }

    /// The field as it is now.
    pub async fn download(&self, ctx: &GpuContext) -> GpuResult<MeshField> {
        self.field.download(ctx).await
    }

    /// Starts a new fit of `field` against the same views: fresh Adam moments at `lr` and a new
    /// view order from `seed`. The rasterizer, the loss and the uploaded targets are kept (the
    /// reconstruction's recovery stage needs no second upload or pipeline build).
    pub(crate) fn restart(
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
    pub(crate) fn replace_field(
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

impl PhotometricConfig {
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
