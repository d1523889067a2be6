//! Checks of the GPU image loss that the native tests and the browser tests both run: every term
//! and the full gradient against the f64 CPU [`reference`](super::reference), and central finite
//! differences of each term (weights isolating it) and of the weighted total.

use serde::Serialize;

use super::{ImageLoss, LossTerms, LossWeights, TargetImages, TargetView, reference};
use crate::data::{DepthMap, PartMap, RgbaImage};
use crate::gpu::{GpuContext, GpuResult};
use crate::rng::Rng;

/// A random render and target: background pixels, partial masks, invalid depth, unlabelled pixels.
#[derive(Debug, Clone)]
pub struct Scene {
    pub width: u32,
    pub height: u32,
    pub num_parts: u32,
    pub render: Vec<f32>,
    pub rgba: RgbaImage,
    pub depth: DepthMap,
    pub parts: PartMap,
    pub background: [f32; 3],
}

/// Keeps every |x − target| at least this far from 0, so L1 kinks stay away from perturbations.
const KINK_MARGIN: f32 = 0.03;

fn away_from_kink(value: f32, target: f32) -> f32 {
    if (value - target).abs() >= KINK_MARGIN {
        value
    } else if value >= target {
        target + KINK_MARGIN
    } else {
        target - KINK_MARGIN
    }
}

impl Scene {
    /// A seeded random scene; the render is the target plus noise so SSIM sees structure.
    pub fn random(seed: u64, width: u32, height: u32, num_parts: u32) -> Self {
        let mut rng = Rng::new(seed);
        let n = (width * height) as usize;
        let background = [0.2, 0.5, 0.9];
        let mut rgba = Vec::with_capacity(n * 4);
        let mut mm = Vec::with_capacity(n);
        let mut ids = Vec::with_capacity(n);
        for _ in 0..n {
            let alpha = match rng.below(4) {
                0 => 0,
                1 => rng.below(256) as u8,
                _ => 255,
            };
            for _ in 0..3 {
                rgba.push(rng.below(256) as u8);
            }
            rgba.push(alpha);
            mm.push(if rng.chance(0.2) {
                0
            } else {
                500 + rng.below(2500) as u16
            });
            ids.push(if alpha == 0 || rng.chance(0.1) {
                -1
            } else {
                rng.below(num_parts) as i16
            });
        }
        let channels = super::render_channels(num_parts) as usize;
        let mut render = vec![0.0f32; channels * n];
        for i in 0..n {
            let m = f32::from(rgba[4 * i + 3]) / 255.0;
            for c in 0..3 {
                let t = f32::from(rgba[4 * i + c]) / 255.0 * m + background[c] * (1.0 - m);
                let x = (t + rng.uniform(-0.25, 0.25)).clamp(0.0, 1.0);
                render[c * n + i] = away_from_kink(x, t);
            }
            let d = f32::from(mm[i]) / 1000.0;
            render[3 * n + i] = if mm[i] == 0 {
                rng.uniform(0.0, 3.0)
            } else {
                away_from_kink(d + rng.uniform(-0.3, 0.3), d)
            };
            render[4 * n + i] = away_from_kink(rng.uniform(0.0, 1.0), m);
            for j in 0..num_parts as usize {
                render[(5 + j) * n + i] = rng.uniform(-3.0, 3.0);
            }
        }
        Self {
            width,
            height,
            num_parts,
            render,
            rgba: RgbaImage {
                width,
                height,
                pixels: rgba,
            },
            depth: DepthMap {
                width,
                height,
                millimetres: mm,
            },
            parts: PartMap { width, height, ids },
            background,
        }
    }

    /// The target images as the loss takes them.
    pub fn target(&self) -> TargetView<'_> {
        TargetView {
            rgba: &self.rgba,
            depth: Some(&self.depth),
            parts: Some(&self.parts),
        }
    }
}

/// The loss, its targets and its render/gradient buffers for one scene.
struct Harness {
    loss: ImageLoss,
    targets: TargetImages,
    render: wgpu::Buffer,
    grad: wgpu::Buffer,
    background: [f32; 3],
}

impl Harness {
    fn new(ctx: &GpuContext, scene: &Scene) -> GpuResult<Self> {
        let loss = ImageLoss::new(ctx, scene.width, scene.height, scene.num_parts)?;
        let targets = TargetImages::upload(ctx, scene.width, scene.height, &[scene.target()])?;
        let bytes = loss.render_len() as u64 * 4;
        Ok(Self {
            render: ctx.storage_buffer("loss_check.render", &scene.render)?,
            grad: ctx.storage_buffer_zeroed("loss_check.grad", bytes)?,
            loss,
            targets,
            background: scene.background,
        })
    }

    async fn run(
        &self,
        ctx: &GpuContext,
        render: &[f32],
        weights: &LossWeights,
    ) -> GpuResult<LossTerms> {
        ctx.queue
            .write_buffer(&self.render, 0, bytemuck::cast_slice(render));
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.loss.encode(
            ctx,
            &mut encoder,
            &self.render,
            &self.targets,
            0,
            weights,
            self.background,
            &self.grad,
        )?;
        ctx.queue.submit([encoder.finish()]);
        self.loss.read_terms(ctx).await
    }

    async fn gradient(&self, ctx: &GpuContext) -> GpuResult<Vec<f32>> {
        ctx.read_buffer(&self.grad, self.loss.render_len()).await
    }
}

/// One term's GPU value against the CPU reference.
#[derive(Debug, Clone, Serialize)]
pub struct TermCheck {
    pub term: &'static str,
    pub gpu: f64,
    pub cpu: f64,
}

/// The worst gradient mismatch of one render channel against the CPU reference.
#[derive(Debug, Clone, Serialize)]
pub struct ChannelCheck {
    pub channel: u32,
    /// max |g_gpu − g_cpu|
    pub max_abs_error: f64,
    /// max |g_cpu| over the channel (the scale the error is judged against)
    pub max_abs_cpu: f64,
}

/// GPU terms and gradient against the CPU reference on one scene.
#[derive(Debug, Clone, Serialize)]
pub struct ValueCheck {
    pub width: u32,
    pub height: u32,
    pub num_parts: u32,
    pub terms: Vec<TermCheck>,
    pub channels: Vec<ChannelCheck>,
    pub depth_pixels: (u32, usize),
    pub label_pixels: (u32, usize),
    /// A term passes when |gpu − cpu| ≤ this · max(|cpu|, 1e-2).
    pub term_tolerance: f64,
    /// A channel passes when max |g_gpu − g_cpu| ≤ this · max |g_cpu| (+ 1e-9).
    pub grad_tolerance: f64,
}

impl ValueCheck {
    pub fn passed(&self) -> bool {
        self.terms
            .iter()
            .all(|t| (t.gpu - t.cpu).abs() <= self.term_tolerance * t.cpu.abs().max(1e-2))
            && self
                .channels
                .iter()
                .all(|c| c.max_abs_error <= self.grad_tolerance * c.max_abs_cpu + 1e-9)
            && self.depth_pixels.0 as usize == self.depth_pixels.1
            && self.label_pixels.0 as usize == self.label_pixels.1
    }

    /// Largest relative term error (the number the tolerance is judged on).
    pub fn worst_term_error(&self) -> f64 {
        self.terms
            .iter()
            .map(|t| (t.gpu - t.cpu).abs() / t.cpu.abs().max(1e-2))
            .fold(0.0, f64::max)
    }

    /// Largest per-channel gradient error relative to that channel's largest gradient.
    pub fn worst_grad_error(&self) -> f64 {
        self.channels
            .iter()
            .map(|c| c.max_abs_error / c.max_abs_cpu.max(1e-30))
            .fold(0.0, f64::max)
    }
}

fn term_values(t: &LossTerms) -> [f64; 6] {
    [t.l1, t.one_minus_ssim, t.depth, t.part, t.mask, t.total].map(f64::from)
}

/// Names of the checked terms, in [`term_values`] order.
pub const TERM_NAMES: [&str; 6] = ["l1", "one_minus_ssim", "depth", "part", "mask", "total"];

/// Weights under which the loss is exactly term `i` of [`TERM_NAMES`] (the last: the default total).
fn isolating_weights(i: usize) -> LossWeights {
    let mut w = LossWeights::ZERO;
    match i {
        0 => w.l1 = 1.0,
        1 => w.ssim = 1.0,
        2 => w.depth = 1.0,
        3 => w.part = 1.0,
        4 => w.mask = 1.0,
        _ => w = LossWeights::default(),
    }
    w
}

/// Every term and the whole gradient (default weights) on a random scene against the CPU.
pub async fn check_values(
    ctx: &GpuContext,
    seed: u64,
    width: u32,
    height: u32,
    num_parts: u32,
) -> GpuResult<ValueCheck> {
    let scene = Scene::random(seed, width, height, num_parts);
    let harness = Harness::new(ctx, &scene)?;
    let weights = LossWeights::default();
    let gpu = harness.run(ctx, &scene.render, &weights).await?;
    let grad = harness.gradient(ctx).await?;
    let cpu = reference::image_loss(
        width,
        height,
        num_parts,
        &scene.render,
        &scene.target(),
        &weights,
        scene.background,
    )?;
    let cpu_values = [
        cpu.l1,
        cpu.one_minus_ssim,
        cpu.depth,
        cpu.part,
        cpu.mask,
        cpu.total,
    ];
    let terms = TERM_NAMES
        .iter()
        .zip(term_values(&gpu))
        .zip(cpu_values)
        .map(|((&term, gpu), cpu)| TermCheck { term, gpu, cpu })
        .collect();
    let n = (width * height) as usize;
    let channels = (0..super::render_channels(num_parts))
        .map(|c| {
            let range = c as usize * n..(c as usize + 1) * n;
            let (g, r) = (&grad[range.clone()], &cpu.grad[range]);
            ChannelCheck {
                channel: c,
                max_abs_error: g
                    .iter()
                    .zip(r)
                    .map(|(&a, b)| (f64::from(a) - b).abs())
                    .fold(0.0, f64::max),
                max_abs_cpu: r.iter().map(|v| v.abs()).fold(0.0, f64::max),
            }
        })
        .collect();
    Ok(ValueCheck {
        width,
        height,
        num_parts,
        terms,
        channels,
        depth_pixels: (gpu.depth_pixels, cpu.depth_pixels),
        label_pixels: (gpu.label_pixels, cpu.label_pixels),
        term_tolerance: 1e-4,
        grad_tolerance: 1e-4,
    })
}

const STEP: f32 = 1e-2;
const LOGIT_STEP: f32 = 5e-2;

/// One finite-difference comparison: term `term`, render element `channel`·npix + `pixel`.
#[derive(Debug, Clone, Serialize)]
pub struct FdSample {
    pub term: &'static str,
    pub channel: u32,
    pub pixel: u32,
    /// (L(x + h) − L(x − h)) / (2h), from the GPU's own loss values
    pub fd: f64,
    /// the GPU's gradient under weights isolating the term
    pub gpu: f64,
}

/// Central finite differences of every term and the total against the GPU gradient.
#[derive(Debug, Clone, Serialize)]
pub struct GradientCheck {
    pub samples: Vec<FdSample>,
    /// h on colour, depth and alpha
    pub step: f32,
    /// h on the part logits
    pub logit_step: f32,
    /// A sample passes when |fd − g| ≤ rel_tol · max(|fd|, |g|) + abs_tol.
    pub rel_tol: f64,
    pub abs_tol: f64,
}

impl GradientCheck {
    fn sample_passed(&self, s: &FdSample) -> bool {
        (s.fd - s.gpu).abs() <= self.rel_tol * s.fd.abs().max(s.gpu.abs()) + self.abs_tol
    }

    pub fn passed(&self) -> bool {
        !self.samples.is_empty() && self.samples.iter().all(|s| self.sample_passed(s))
    }

    /// Samples that failed.
    pub fn failures(&self) -> Vec<&FdSample> {
        self.samples
            .iter()
            .filter(|s| !self.sample_passed(s))
            .collect()
    }

    /// Largest |fd − g| / max(|fd|, |g|) over samples whose gradient is above the absolute tolerance.
    pub fn worst_relative_error(&self) -> f64 {
        self.samples
            .iter()
            .filter(|s| s.fd.abs().max(s.gpu.abs()) > 10.0 * self.abs_tol)
            .map(|s| (s.fd - s.gpu).abs() / s.fd.abs().max(s.gpu.abs()))
            .fold(0.0, f64::max)
    }

    /// Number of samples with a nonzero gradient.
    pub fn nonzero_samples(&self) -> usize {
        self.samples.iter().filter(|s| s.gpu != 0.0).count()
    }
}

/// Finite differences on a random scene: `per_channel` random pixels in every render channel,
/// each perturbed by ±h (scenes keep |x − target| ≥ 0.03 > h away from the L1 kinks).
///
/// The losses are f32 means of order 1 while one element moves them by ~1e-3 · h, so h is as large
/// as the terms allow: 1e-2 where an L1 kink is near (colour, depth, alpha), 5e-2 on the logits
/// (smooth). The f32 resolution of the loss then limits fd to about 1e-5 relative.
pub async fn check_gradients(
    ctx: &GpuContext,
    seed: u64,
    width: u32,
    height: u32,
    num_parts: u32,
    per_channel: u32,
) -> GpuResult<GradientCheck> {
    let scene = Scene::random(seed, width, height, num_parts);
    let harness = Harness::new(ctx, &scene)?;
    let mut grads = Vec::with_capacity(TERM_NAMES.len());
    for i in 0..TERM_NAMES.len() {
        harness
            .run(ctx, &scene.render, &isolating_weights(i))
            .await?;
        grads.push(harness.gradient(ctx).await?);
    }
    let n = width * height;
    let mut rng = Rng::new(seed ^ 0xfd);
    let mut render = scene.render.clone();
    let weights = LossWeights::default();
    let mut samples = Vec::new();
    for channel in 0..super::render_channels(num_parts) {
        for _ in 0..per_channel {
            let pixel = rng.below(n);
            let e = (channel * n + pixel) as usize;
            let x = scene.render[e];
            let step = if channel >= super::BASE_CHANNELS {
                LOGIT_STEP
            } else {
                STEP
            };
            let (plus, minus) = (x + step, x - step);
            render[e] = plus;
            let up = term_values(&harness.run(ctx, &render, &weights).await?);
            render[e] = minus;
            let down = term_values(&harness.run(ctx, &render, &weights).await?);
            render[e] = x;
            // The actual f32 step, not the nominal one.
            let h = f64::from(plus) - f64::from(minus);
            for (i, &term) in TERM_NAMES.iter().enumerate() {
                samples.push(FdSample {
                    term,
                    channel,
                    pixel,
                    fd: (up[i] - down[i]) / h,
                    gpu: f64::from(grads[i][e]),
                });
            }
        }
    }
    Ok(GradientCheck {
        samples,
        step: STEP,
        logit_step: LOGIT_STEP,
        rel_tol: 1e-2,
        abs_tol: 2e-6,
    })
}
