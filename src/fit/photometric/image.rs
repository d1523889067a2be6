//! Between a render and the image loss: the target as the loss sees it (composited over the
//! background), planes as RGB8 for previews, and the loss-then-backward pass that leaves the
//! gradients in the field.

use glam::Vec3;

use crate::data::Frame;
use crate::gpu::{GpuContext, GpuResult};
use crate::loss::{ImageLoss, LossWeights, TargetImages};
use crate::raster::{GpuField, RasterSettings, RasterState, Rasterizer};

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
pub(crate) fn planes_to_rgb8(planes: &[f32]) -> Vec<u8> {
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
