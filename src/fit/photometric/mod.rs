//! The photometric inner loop on its own: optimise a mesh field against posed views with the GPU
//! image loss and Adam — no densification, remeshing or articulation. It shows that the
//! differentiable rasterizer learns (the rasterizer issue's driver) and is the loop the
//! reconstruction phase builds on. Its test problems (a procedural object and a jittered copy
//! of its surface) are test fixtures, kept outside the pipeline.
//!
//! Files: `config` (the schedule and the curve), `adam` (Adam over the field's parameter
//! groups), `image` (targets and the loss's backward pass), `trainer` (the training state), `timing` (the rasterizer's training-iteration benchmark);
//! this file runs a whole fit and renders its preview strip.

mod adam;
mod config;
mod image;
pub mod timing;
mod trainer;

pub use adam::{FieldAdam, FieldLearningRates};
pub use config::{CurvePoint, PhotometricConfig};
pub(crate) use image::{encode_loss_and_backward, planes_to_rgb8, target_rgb};
pub use trainer::Trainer;

use crate::data::{Camera, Frame};
use crate::gpu::{GpuContext, GpuError, GpuResult};
use crate::raster::{GpuField, MeshField, RasterState, Rasterizer};

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
