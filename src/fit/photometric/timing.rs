//! Training-iteration timing of the differentiable rasterizer (forward, loss, backward, Adam) on a
//! benchmark mesh, with a model FLOP rate against an FMA peak probe: `artmesh bench raster`
//! natively and `tests/web_bench.rs` in the browser run this same code.

use serde::Serialize;

use super::{FieldAdam, FieldLearningRates};
use crate::data::{DepthMap, PartMap, RgbaImage};
use crate::gpu::{AdapterReport, FmaPeak, GpuContext, GpuResult, fma_peak, now_seconds};
use crate::loss::{ImageLoss, LossWeights, TargetImages, TargetView};
use crate::raster::check::{Scene, sphere_scene};
use crate::raster::{GpuField, RasterState, Rasterizer, SH_FLOATS, WorkCounts};

/// The cases `artmesh bench raster` times by default: (image side, target face count).
pub const DEFAULT_CASES: [(u32, usize); 3] = [(128, 20_000), (256, 100_000), (800, 300_000)];

/// Floating-point operations the rasterizer's compositing loops perform, counted by hand from the
/// WGSL (a transcendental counts as one): every per-pixel face evaluation pays the coverage test;
/// a hit pays the compositing (forward) or the replay and chain rule (backward), plus per part.
pub const FLOP_MODEL: &str = "per evaluation 19 (coverage test); per forward hit 41 + 8 P; \
    per backward hit 120 + 20 P; P = part logits";

fn model_flops(work: &WorkCounts, parts: u64) -> f64 {
    let coverage = 19.0 * (work.forward_evaluations + work.backward_evaluations) as f64;
    let hits = work.hits as f64;
    coverage + hits * (41.0 + 8.0 * parts as f64) + hits * (120.0 + 20.0 * parts as f64)
}

/// One `artmesh bench raster` case.
#[derive(Debug, Clone, Serialize)]
pub struct RasterTiming {
    pub width: u32,
    pub height: u32,
    pub faces: usize,
    pub parts: usize,
    /// (face, tile) pairs per view.
    pub pairs: u32,
    pub repeats: usize,
    /// Median wall time of one training iteration: forward (with its pair-count read-back), loss,
    /// backward and Adam on all four parameter groups, submitted and waited for.
    pub median_ms: f64,
    pub min_ms: f64,
    /// Per-stage times of one extra iteration with every stage submitted and waited for alone
    /// (native only: empty in the browser).
    pub stages_ms: Vec<(String, f64)>,
    pub work: WorkCounts,
    /// Pixel–face evaluations (forward + backward) per second of the median iteration.
    pub evaluations_per_second: f64,
    /// Hits (contributions with α ≥ alpha_min) per pixel–face evaluation of the forward pass:
    /// 1.0 when every evaluation contributes (the backward pass replays only the forward's hits).
    pub hit_rate: f64,
    /// Model FLOPs of the compositing loops per iteration (see `flop_model`).
    pub model_flops: f64,
    /// Model FLOP rate over the whole iteration, and over the compositing kernels alone.
    pub gflops_iteration: f64,
    pub gflops_compositing: f64,
    /// `gflops_iteration` / FMA peak, and `gflops_compositing` / FMA peak.
    pub peak_fraction_iteration: f64,
    pub peak_fraction_compositing: f64,
}

/// `artmesh bench raster` output.
#[derive(Debug, Clone, Serialize)]
pub struct RasterBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub fma_peak: FmaPeak,
    pub flop_model: &'static str,
    pub scene: &'static str,
    pub results: Vec<RasterTiming>,
}

/// Times training iterations of the rasterizer on the benchmark sphere (`raster::check::
/// sphere_scene`: γ = 0.5, mid-training opacity, 4 parts) for each (size, faces) case, against a
/// target rendered from the same mesh with its colours shuffled, after one warm-up iteration.
pub async fn raster_bench(
    ctx: &GpuContext,
    cases: &[(u32, usize)],
    repeats: usize,
) -> GpuResult<RasterBench> {
    let peak = fma_peak(ctx).await?;
    let raster = Rasterizer::new(ctx);
    let mut results = Vec::new();
    for &(size, faces) in cases {
        results.push(time_case(ctx, &raster, &peak, size, faces, repeats).await?);
    }
    Ok(RasterBench {
        bench: "raster",
        adapter: ctx.adapter.clone(),
        fma_peak: peak,
        flop_model: FLOP_MODEL,
        scene: "bumpy UV sphere, random colours, opacity 0.62, gamma 0.5, 4 parts; target: shuffled colours",
        results,
    })
}

/// One case: `repeats` timed iterations after a warm-up, then one profiled iteration for the
/// per-stage times and the work counts.
async fn time_case(
    ctx: &GpuContext,
    raster: &Rasterizer,
    peak: &FmaPeak,
    size: u32,
    faces: usize,
    repeats: usize,
) -> GpuResult<RasterTiming> {
    let scene = sphere_scene(faces, size, size, 1);
    let parts = scene.field.num_parts as u32;
    let mut state = RasterState::new(ctx, size, size, parts)?;
    let targets = shuffled_target(ctx, raster, &scene, size, &mut state).await?;
    let loss = ImageLoss::new(ctx, size, size, parts)?;
    let field = GpuField::upload(ctx, &scene.field)?;
    let mut optimizer = FieldAdam::new(
        ctx,
        &field,
        FieldLearningRates {
            position: 1e-5,
            sh: 1e-3,
            opacity: 1e-3,
            part: 1e-3,
        },
    )?;
    let mut times = Vec::with_capacity(repeats);
    let mut pairs = 0;
    let case = Case {
        raster,
        field: &field,
        scene: &scene,
        loss: &loss,
        targets: &targets,
    };
    for run in 0..=repeats {
        let start = now_seconds();
        pairs = case.iteration(ctx, &mut state, &mut optimizer).await?;
        if run > 0 {
            times.push((now_seconds() - start) * 1e3);
        }
    }
    // Work counts and a per-stage breakdown from one more (profiled) iteration; in the browser
    // a stage cannot be waited for alone, so there are no stage times.
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    state.clear_face_stats(&mut encoder);
    ctx.queue.submit([encoder.finish()]);
    state.set_profiling(cfg!(not(target_arch = "wasm32")));
    case.iteration(ctx, &mut state, &mut optimizer).await?;
    state.set_profiling(false);
    let stages: Vec<(String, f64)> = state
        .clock
        .take()
        .into_iter()
        .filter(|(s, _)| !s.is_empty())
        .map(|(s, t)| (s.to_string(), t))
        .collect();
    let work = state.read_work(ctx, field.num_faces).await?;
    let (median_ms, min_ms) = median_min(&mut times);
    let compositing_ms: f64 = stages
        .iter()
        .filter(|(s, _)| s.starts_with("composite"))
        .map(|(_, t)| t)
        .sum();
    let evaluations = work.forward_evaluations + work.backward_evaluations;
    let flops = model_flops(&work, u64::from(parts));
    let gflops_iteration = flops / (median_ms * 1e6);
    let gflops_compositing = if compositing_ms > 0.0 {
        flops / (compositing_ms * 1e6)
    } else {
        f64::NAN
    };
    Ok(RasterTiming {
        width: size,
        height: size,
        faces: scene.field.faces.len(),
        parts: parts as usize,
        pairs,
        repeats,
        median_ms,
        min_ms,
        stages_ms: stages,
        work,
        evaluations_per_second: evaluations as f64 / (median_ms / 1e3),
        hit_rate: work.hits as f64 / work.forward_evaluations.max(1) as f64,
        model_flops: flops,
        gflops_iteration,
        gflops_compositing,
        peak_fraction_iteration: gflops_iteration / peak.gflops,
        peak_fraction_compositing: gflops_compositing / peak.gflops,
    })
}

/// The target: the scene's mesh with shuffled colours, rendered into `state` and read back as
/// dataset images (colour, depth, part labels), uploaded as the loss's one view.
async fn shuffled_target(
    ctx: &GpuContext,
    raster: &Rasterizer,
    scene: &Scene,
    size: u32,
    state: &mut RasterState,
) -> GpuResult<TargetImages> {
    let parts = scene.field.num_parts;
    let mut target_field = scene.field.clone();
    target_field.sh.rotate_left(SH_FLOATS * 7);
    let target_gpu = GpuField::upload(ctx, &target_field)?;
    raster
        .forward(ctx, &target_gpu, state, &scene.camera, &scene.settings)
        .await?;
    let img = state.read_render(ctx).await?;
    drop(target_gpu);
    let n = (size * size) as usize;
    let rgba = RgbaImage {
        width: size,
        height: size,
        pixels: (0..n)
            .flat_map(|i| {
                let q = |c: usize| (img.plane(c)[i].clamp(0.0, 1.0) * 255.0).round() as u8;
                [q(0), q(1), q(2), (img.plane(4)[i] > 0.5) as u8 * 255]
            })
            .collect(),
    };
    let depth = DepthMap {
        width: size,
        height: size,
        millimetres: img
            .plane(3)
            .iter()
            .map(|d| (d * 1000.0).round() as u16)
            .collect(),
    };
    let labels = PartMap {
        width: size,
        height: size,
        ids: (0..n)
            .map(|i| {
                if img.plane(4)[i] < 0.5 {
                    return -1;
                }
                (0..parts)
                    .max_by(|&a, &b| img.plane(5 + a)[i].total_cmp(&img.plane(5 + b)[i]))
                    .unwrap_or(0) as i16
            })
            .collect(),
    };
    TargetImages::upload(
        ctx,
        size,
        size,
        &[TargetView {
            rgba: &rgba,
            depth: Some(&depth),
            parts: Some(&labels),
        }],
    )
}

/// What one timed case renders and optimises.
struct Case<'a> {
    raster: &'a Rasterizer,
    field: &'a GpuField,
    scene: &'a Scene,
    loss: &'a ImageLoss,
    targets: &'a TargetImages,
}

impl Case<'_> {
    /// One training iteration, submitted and waited for (the loss terms' read-back waits on
    /// both targets); returns the (face, tile) pairs of its forward pass.
    async fn iteration(
        &self,
        ctx: &GpuContext,
        state: &mut RasterState,
        optimizer: &mut FieldAdam,
    ) -> GpuResult<u32> {
        let scene = self.scene;
        let stats = self
            .raster
            .forward(ctx, self.field, state, &scene.camera, &scene.settings)
            .await?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        state.clock_lap(ctx, &mut encoder, "");
        self.loss.encode(
            ctx,
            &mut encoder,
            state.render(),
            self.targets,
            0,
            &LossWeights::default(),
            scene.settings.background.to_array(),
            state.grad_render(),
        )?;
        state.clock_lap(ctx, &mut encoder, "loss");
        self.raster
            .encode_backward(ctx, &mut encoder, self.field, state);
        state.clock_lap(ctx, &mut encoder, "");
        optimizer.encode_step(ctx, &mut encoder)?;
        state.clock_lap(ctx, &mut encoder, "adam");
        ctx.queue.submit([encoder.finish()]);
        self.loss.read_terms(ctx).await?;
        ctx.check()?;
        Ok(stats.pairs)
    }
}

/// Median and minimum of `times` (sorts it).
fn median_min(times: &mut [f64]) -> (f64, f64) {
    times.sort_by(f64::total_cmp);
    let median = times.get(times.len() / 2).copied().unwrap_or(f64::NAN);
    (median, times.first().copied().unwrap_or(f64::NAN))
}
