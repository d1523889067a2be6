//! Achievable f32 FMA rate of the adapter (kernel in `shaders/fma_peak.wgsl`): the denominator of
//! "achieved FLOP rate / peak" in the rasterizer benchmark.
//!
//! The probe dispatches enough invocations to fill any device (262 144), each running 8
//! independent FMA chains, grows the iteration count until one dispatch takes at least
//! [`TARGET_SECONDS`], then reports the median of [`RUNS`] timed runs after that warm-up. Timing is
//! wall clock around submit + a 4-byte readback, so submission overhead is included but negligible
//! at that duration. Natively the clock is `std::time::Instant`; in the browser `performance.now()`.

use bytemuck::{Pod, Zeroable};
use serde::Serialize;

use super::kernel::{Binding, KernelFamily, compute_pass};
use super::{GpuContext, GpuError, GpuResult};

/// Workgroups per dispatch (× 256 invocations).
const WORKGROUPS: u32 = 1024;
/// Scalar FMAs per invocation per loop iteration (2 vec4 chains × 4 unrolled steps).
const FMAS_PER_ITERATION: u64 = 32;
/// A timed dispatch should last at least this long.
pub(crate) const TARGET_SECONDS: f64 = 0.05;
/// Timed runs whose median is reported.
pub const RUNS: usize = 5;
const MAX_ITERATIONS: u32 = 1 << 20;

/// Uniform block of `fma_peak.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct FmaParams {
    iterations: u32,
    _pad: u32,
    mul: f32,
    add: f32,
}
const _: () = assert!(size_of::<FmaParams>() == 16);

/// Result of [`fma_peak`].
#[derive(Debug, Clone, Serialize)]
pub struct FmaPeak {
    /// Achieved f32 throughput, 2 flops per FMA.
    pub gflops: f64,
    /// Median wall-clock seconds of one timed dispatch.
    pub seconds: f64,
    /// FMAs per dispatch.
    pub fmas: u64,
    pub invocations: u32,
    pub iterations: u32,
    pub runs: usize,
}

/// Measures the adapter's achievable f32 FMA rate with the platform clock.
pub async fn fma_peak(ctx: &GpuContext) -> GpuResult<FmaPeak> {
    fma_peak_with_clock(ctx, &super::now_seconds).await
}

/// [`fma_peak`] with a caller's clock (seconds, monotonic).
pub async fn fma_peak_with_clock(ctx: &GpuContext, clock: &dyn Fn() -> f64) -> GpuResult<FmaPeak> {
    let invocations = WORKGROUPS * 256;
    let sink = ctx.storage_buffer_zeroed("fma_peak.sink", u64::from(invocations) * 4)?;
    let params = ctx.uniform_buffer("fma_peak.params", &FmaParams::zeroed());
    let (family, [pipeline]) = KernelFamily::new(
        ctx,
        "fma_peak",
        include_str!("../../shaders/fma_peak.wgsl"),
        &[Binding::Uniform, Binding::StorageReadWrite],
        ["fma_chains"],
    );
    let bind_group = family.bind(ctx, &[&params, &sink]);

    let run = async |iterations: u32| -> GpuResult<f64> {
        let p = FmaParams {
            iterations,
            _pad: 0,
            mul: 0.999,
            add: 1e-3,
        };
        ctx.queue.write_buffer(&params, 0, bytemuck::bytes_of(&p));
        let start = clock();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        ctx.dispatch(
            &mut compute_pass(&mut encoder, "fma_peak"),
            &pipeline,
            &bind_group,
            WORKGROUPS,
        );
        ctx.queue.submit([encoder.finish()]);
        let out: Vec<f32> = ctx.read_buffer(&sink, 1).await?;
        let elapsed = clock() - start;
        if !out.first().is_some_and(|v| v.is_finite()) {
            return Err(GpuError::Readback(format!(
                "FMA probe produced {out:?} instead of a finite value"
            )));
        }
        Ok(elapsed)
    };

    // Warm-up (pipeline creation, first-use costs), then grow until a run is long enough.
    run(1).await?;
    let mut iterations = 4u32;
    loop {
        let t = run(iterations).await?;
        if t >= TARGET_SECONDS || iterations >= MAX_ITERATIONS {
            break;
        }
        // Jump close to the target when far from it; never more than 16x at once.
        let factor = (TARGET_SECONDS / t.max(1e-6)).clamp(2.0, 16.0);
        iterations = ((f64::from(iterations) * factor).ceil() as u32).min(MAX_ITERATIONS);
    }
    let mut times = Vec::with_capacity(RUNS);
    for _ in 0..RUNS {
        times.push(run(iterations).await?);
    }
    times.sort_by(f64::total_cmp);
    let seconds = times[RUNS / 2];
    let fmas = u64::from(invocations) * u64::from(iterations) * FMAS_PER_ITERATION;
    if seconds <= 0.0 || !seconds.is_finite() {
        return Err(GpuError::Readback(format!(
            "FMA probe timing is not usable ({seconds} s): the clock has too coarse a resolution"
        )));
    }
    Ok(FmaPeak {
        gflops: 2.0 * fmas as f64 / seconds / 1e9,
        seconds,
        fmas,
        invocations,
        iterations,
        runs: RUNS,
    })
}
