//! The image loss of the reconstruction phase on the GPU, forward and backward (kernels in
//! `shaders/loss.wgsl`): L1 and 1 − SSIM on colour, L1 on depth where the target has depth, part
//! cross-entropy where the target has a label, and L1 between accumulated alpha and the mask.
//!
//! The rasterizer's output ("render") is planar f32, `render[c · npix + pix]` with `npix = W · H`,
//! `pix = y · W + x` from the top-left, channels 0..3 = RGB in [0, 1] (composited over the
//! background), 3 = expected depth Σ wᵢzᵢ in metres (not divided by alpha), 4 = accumulated alpha,
//! 5..5 + P = composited part logits. [`ImageLoss::encode`] overwrites a gradient buffer of the same
//! layout with dL/drender and leaves the terms in a small buffer that [`ImageLoss::read_terms`]
//! fetches when the caller wants them (not every iteration: it syncs with the GPU).
//!
//! Targets are uploaded once ([`TargetImages`]) and picked per call by view index. [`reference`]
//! is a plain f64 CPU version of every term and its gradient; [`check`] holds the GPU-vs-CPU and
//! finite-difference checks that the native and the browser tests both run.

pub mod check;
pub mod reference;
mod targets;

use bytemuck::{Pod, Zeroable};
use serde::Serialize;

pub use targets::{TARGET_PIXEL_BYTES, TargetImages, TargetView};

use crate::gpu::{Binding, GpuContext, GpuError, GpuResult, KernelFamily};

/// Most part channels the loss accepts (K + 1 parts): the rasterizer's limit.
pub const MAX_PARTS: u32 = crate::raster::MAX_PARTS as u32;
/// Render channels besides the part logits (RGB, depth, alpha), as the rasterizer writes them.
pub const BASE_CHANNELS: u32 = crate::raster::BASE_CHANNELS as u32;
/// Pixels per workgroup in `loss.wgsl`.
const WG_SIZE: u32 = 256;
/// Floats per workgroup in the partial-sums buffer.
const SUMS_STRIDE: u32 = 8;
/// Floats in the terms buffer.
const TERMS_LEN: usize = 8;
/// Gaussian window of SSIM: 11 taps, σ = 1.5 (as in 3DGS and the original SSIM).
pub(crate) const SSIM_WINDOW: usize = 11;
pub(crate) const SSIM_SIGMA: f64 = 1.5;
/// SSIM stabilisers (K1 = 0.01, K2 = 0.03, dynamic range 1).
pub(crate) const SSIM_C1: f64 = 0.01 * 0.01;
pub(crate) const SSIM_C2: f64 = 0.03 * 0.03;

/// Weights of the loss terms.
///
/// The defaults for L1, SSIM and depth (0.8 / 0.2 / 0.5) are the paper's; the part
/// cross-entropy and mask weights (0.1 each) are ours: the paper names the terms but not the weights.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LossWeights {
    pub l1: f32,
    pub ssim: f32,
    pub depth: f32,
    pub part: f32,
    pub mask: f32,
}

impl Default for LossWeights {
    fn default() -> Self {
        Self {
            l1: 0.8,
            ssim: 0.2,
            depth: 0.5,
            part: 0.1,
            mask: 0.1,
        }
    }
}

impl LossWeights {
    /// All weights zero: start from this to isolate one term.
    pub const ZERO: Self = Self {
        l1: 0.0,
        ssim: 0.0,
        depth: 0.0,
        part: 0.0,
        mask: 0.0,
    };
}

/// The loss terms of one evaluation (each already a mean; `total` is the weighted sum).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LossTerms {
    pub total: f32,
    /// Mean |Î − I| over the 3 · npix colour values.
    pub l1: f32,
    /// 1 − mean SSIM over the 3 · npix colour values.
    pub one_minus_ssim: f32,
    /// Mean |D̂ − D| (metres) over pixels with valid target depth.
    pub depth: f32,
    /// Mean cross-entropy of the part logits over labelled pixels.
    pub part: f32,
    /// Mean |A − m| over all pixels.
    pub mask: f32,
    /// Pixels with valid target depth (the depth term's denominator, if ≥ 1).
    pub depth_pixels: u32,
    /// Pixels with a part label (the part term's denominator, if ≥ 1).
    pub label_pixels: u32,
}

/// Uniform block of `loss.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct LossParams {
    width: u32,
    height: u32,
    npix: u32,
    num_parts: u32,
    target_offset: u32,
    num_groups: u32,
    depth_count: u32,
    label_count: u32,
    background: [f32; 4],
    weights: [f32; 4],
    mask_weight: f32,
    inv_depth_count: f32,
    inv_label_count: f32,
    _pad: f32,
    gauss: [f32; 12],
}
const _: () = assert!(size_of::<LossParams>() == 128);

/// The normalised 1-D Gaussian taps of the SSIM window (the 2-D window is their outer product).
pub(crate) fn ssim_taps() -> [f64; SSIM_WINDOW] {
    let r = (SSIM_WINDOW / 2) as f64;
    let mut taps = [0.0; SSIM_WINDOW];
    for (i, t) in taps.iter_mut().enumerate() {
        let d = i as f64 - r;
        *t = (-d * d / (2.0 * SSIM_SIGMA * SSIM_SIGMA)).exp();
    }
    let sum: f64 = taps.iter().sum();
    taps.map(|t| t / sum)
}

/// Number of render (and gradient) channels for `num_parts` part logits.
pub fn render_channels(num_parts: u32) -> u32 {
    BASE_CHANNELS + num_parts
}

/// The GPU image loss for one image size and part count; owns its scratch buffers.
pub struct ImageLoss {
    family: KernelFamily,
    ssim_h: wgpu::ComputePipeline,
    ssim_v: wgpu::ComputePipeline,
    ssim_back_h: wgpu::ComputePipeline,
    pixel: wgpu::ComputePipeline,
    finalize: wgpu::ComputePipeline,
    params: wgpu::Buffer,
    /// 15 planar maps: blurred SSIM moments, later the 9 blurred SSIM partials.
    stats: wgpu::Buffer,
    /// 9 planar maps: per-pixel SSIM partials.
    dssim: wgpu::Buffer,
    sums: wgpu::Buffer,
    terms: wgpu::Buffer,
    width: u32,
    height: u32,
    num_parts: u32,
    /// Workgroups of the column kernels (`ssim_v`, `pixel`), which write partial sums.
    num_groups: u32,
    /// Workgroups of the row kernels (`ssim_h`, `ssim_back_h`).
    row_groups: u32,
}

/// Pixels one invocation of the blur kernels walks along its row or column (`SEGMENT` in
/// `loss.wgsl`).
const BLUR_SEGMENT: u32 = 32;

/// Workgroups of the column kernels and of the row kernels for a `width`×`height` image.
fn blur_groups(width: u32, height: u32) -> (u32, u32) {
    let columns = u64::from(width) * u64::from(height.div_ceil(BLUR_SEGMENT));
    let rows = u64::from(height) * u64::from(width.div_ceil(BLUR_SEGMENT));
    let groups = |n: u64| n.div_ceil(u64::from(WG_SIZE)) as u32;
    (groups(columns), groups(rows))
}

impl ImageLoss {
    /// Builds the kernels and scratch buffers for `width`×`height` renders with `num_parts`
    /// (1..=16) part logits. The SSIM scratch takes 15 maps (60 bytes per pixel) in one binding.
    pub fn new(ctx: &GpuContext, width: u32, height: u32, num_parts: u32) -> GpuResult<Self> {
        let npix = targets::checked_pixels(width, height)?;
        if !(1..=MAX_PARTS).contains(&num_parts) {
            return Err(GpuError::InvalidInput(format!(
                "the image loss takes 1 to {MAX_PARTS} part channels, got {num_parts}"
            )));
        }
        let stats = ctx.storage_buffer_zeroed("loss.stats", 15 * npix * 4)?;
        let dssim = ctx.storage_buffer_zeroed("loss.dssim", 9 * npix * 4)?;
        let (num_groups, row_groups) = blur_groups(width, height);
        let sums = ctx.storage_buffer_zeroed(
            "loss.sums",
            u64::from(num_groups) * u64::from(SUMS_STRIDE) * 4,
        )?;
        let terms = ctx.storage_buffer_zeroed("loss.terms", TERMS_LEN as u64 * 4)?;
        let params = ctx.uniform_buffer("loss.params", &LossParams::zeroed());
        let (family, [ssim_h, ssim_v, ssim_back_h, pixel, finalize]) = KernelFamily::new(
            ctx,
            "loss",
            include_str!("../../shaders/loss.wgsl"),
            &[
                Binding::Uniform,
                Binding::StorageRead,
                Binding::StorageRead,
                Binding::StorageReadWrite,
                Binding::StorageReadWrite,
                Binding::StorageReadWrite,
                Binding::StorageReadWrite,
                Binding::StorageReadWrite,
            ],
            ["ssim_h", "ssim_v", "ssim_back_h", "pixel", "finalize"],
        );
        Ok(Self {
            family,
            ssim_h,
            ssim_v,
            ssim_back_h,
            pixel,
            finalize,
            params,
            stats,
            dssim,
            sums,
            terms,
            width,
            height,
            num_parts,
            num_groups,
            row_groups,
        })
    }

    /// Render width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Render height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Part-logit channels.
    pub fn num_parts(&self) -> u32 {
        self.num_parts
    }

    /// Floats in a render (and gradient) buffer: `(5 + P) · W · H`.
    pub fn render_len(&self) -> usize {
        render_channels(self.num_parts) as usize * self.width as usize * self.height as usize
    }

    /// The loss terms of the last encoded evaluation, as 8 f32 (total, l1, 1 − ssim, depth, part,
    /// mask, depth pixels, label pixels): for callers that copy them elsewhere on the GPU.
    pub fn terms_buffer(&self) -> &wgpu::Buffer {
        &self.terms
    }

    /// Records the loss of `render` against target `view` and its gradient into `grad` (every
    /// element written). Parameters go through `queue.write_buffer`: encode once per submission.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        render: &wgpu::Buffer,
        targets: &TargetImages,
        view: usize,
        weights: &LossWeights,
        background: [f32; 3],
        grad: &wgpu::Buffer,
    ) -> GpuResult<()> {
        if targets.width() != self.width || targets.height() != self.height {
            return Err(GpuError::InvalidInput(format!(
                "target views are {}×{}, but the loss was built for {}×{} renders",
                targets.width(),
                targets.height(),
                self.width,
                self.height
            )));
        }
        let (target_buffer, slot) = targets.slot(view)?;
        if slot.max_label > self.num_parts {
            return Err(GpuError::InvalidInput(format!(
                "target view {view} labels part {} but the loss has only {} part channels",
                slot.max_label - 1,
                self.num_parts
            )));
        }
        let bytes = self.render_len() as u64 * 4;
        for (what, buffer) in [("render", render), ("gradient", grad)] {
            if buffer.size() < bytes {
                return Err(GpuError::InvalidInput(format!(
                    "the {what} buffer has {} bytes; {}×{} with {} channels needs {bytes}",
                    buffer.size(),
                    self.width,
                    self.height,
                    render_channels(self.num_parts)
                )));
            }
        }
        if render == grad {
            return Err(GpuError::InvalidInput(
                "the render and gradient buffers must be different buffers".into(),
            ));
        }
        let w = weights;
        if ![w.l1, w.ssim, w.depth, w.part, w.mask]
            .iter()
            .chain(&background)
            .all(|v| v.is_finite())
        {
            return Err(GpuError::InvalidInput(format!(
                "loss weights and background must be finite, got {w:?} and {background:?}"
            )));
        }

        let mut gauss = [0.0f32; 12];
        for (g, t) in gauss.iter_mut().zip(ssim_taps()) {
            *g = t as f32;
        }
        let params = LossParams {
            width: self.width,
            height: self.height,
            npix: self.width * self.height,
            num_parts: self.num_parts,
            target_offset: slot.offset_words,
            num_groups: self.num_groups,
            depth_count: slot.depth_pixels,
            label_count: slot.label_pixels,
            background: [background[0], background[1], background[2], 0.0],
            weights: [w.l1, w.ssim, w.depth, w.part],
            mask_weight: w.mask,
            inv_depth_count: 1.0 / slot.depth_pixels.max(1) as f32,
            inv_label_count: 1.0 / slot.label_pixels.max(1) as f32,
            _pad: 0.0,
            gauss,
        };
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let bind_group = self.family.bind(
            ctx,
            &[
                &self.params,
                render,
                target_buffer,
                grad,
                &self.stats,
                &self.dssim,
                &self.sums,
                &self.terms,
            ],
        );
        let mut pass = crate::gpu::compute_pass(encoder, "loss");
        ctx.dispatch(&mut pass, &self.ssim_h, &bind_group, self.row_groups);
        ctx.dispatch(&mut pass, &self.ssim_v, &bind_group, self.num_groups);
        ctx.dispatch(&mut pass, &self.ssim_back_h, &bind_group, self.row_groups);
        ctx.dispatch(&mut pass, &self.pixel, &bind_group, self.num_groups);
        ctx.dispatch(&mut pass, &self.finalize, &bind_group, 1);
        Ok(())
    }

    /// Reads the terms of the last submitted evaluation back (waits for the GPU).
    pub async fn read_terms(&self, ctx: &GpuContext) -> GpuResult<LossTerms> {
        let t: Vec<f32> = ctx.read_buffer(&self.terms, TERMS_LEN).await?;
        if t.len() != TERMS_LEN {
            return Err(GpuError::Readback(format!(
                "loss terms: expected {TERMS_LEN} values, got {}",
                t.len()
            )));
        }
        Ok(LossTerms {
            total: t[0],
            l1: t[1],
            one_minus_ssim: t[2],
            depth: t[3],
            part: t[4],
            mask: t[5],
            depth_pixels: t[6] as u32,
            label_pixels: t[7] as u32,
        })
    }
}
