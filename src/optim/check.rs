//! Checks of GPU Adam against a CPU Adam in f64, run by the native and the browser tests: several
//! steps of two groups in one submission with a decaying learning rate, a remap that keeps,
//! reorders, drops and adds elements, more steps after it, and a reset.

use serde::Serialize;

use super::{Adam, AdamConfig, AdamGroup, ExponentialDecay, FRESH};
use crate::gpu::{GpuContext, GpuResult};
use crate::rng::Rng;

/// CPU Adam of one group, the formula of `adam.wgsl` in f64.
#[derive(Debug, Clone)]
pub(crate) struct CpuAdam {
    pub params: Vec<f64>,
    pub m: Vec<f64>,
    pub v: Vec<f64>,
    pub step: u32,
}

impl CpuAdam {
    pub fn new(params: &[f32]) -> Self {
        Self {
            params: params.iter().map(|&p| f64::from(p)).collect(),
            m: vec![0.0; params.len()],
            v: vec![0.0; params.len()],
            step: 0,
        }
    }

    pub fn step(&mut self, grads: &[f32], c: &AdamConfig) {
        self.step += 1;
        let t = f64::from(self.step);
        let (b1, b2) = (f64::from(c.beta1), f64::from(c.beta2));
        let (bias1, bias2) = (1.0 - b1.powf(t), 1.0 - b2.powf(t));
        for (i, &g) in grads.iter().enumerate() {
            let g = f64::from(g);
            self.m[i] = b1 * self.m[i] + (1.0 - b1) * g;
            self.v[i] = b2 * self.v[i] + (1.0 - b2) * g * g;
            self.params[i] -= f64::from(c.lr) * (self.m[i] / bias1)
                / ((self.v[i] / bias2).sqrt() + f64::from(c.eps));
        }
    }

    /// The CPU side of [`Adam::remap`]; new parameters are given.
    pub fn remap(&mut self, new_params: &[f32], map: &[u32], stride: usize) {
        let gather = |old: &[f64]| -> Vec<f64> {
            map.iter()
                .flat_map(|&src| {
                    (0..stride).map(move |k| {
                        if src == FRESH {
                            0.0
                        } else {
                            old[src as usize * stride + k]
                        }
                    })
                })
                .collect()
        };
        self.m = gather(&self.m);
        self.v = gather(&self.v);
        self.params = new_params.iter().map(|&p| f64::from(p)).collect();
    }
}

/// Largest deviation of one quantity from the CPU.
#[derive(Debug, Clone, Serialize)]
pub struct Deviation {
    pub what: String,
    /// max |gpu − cpu| / (1 + |cpu|)
    pub max_error: f64,
}

/// The Adam check's outcome.
#[derive(Debug, Clone, Serialize)]
pub struct AdamCheck {
    pub deviations: Vec<Deviation>,
    /// A deviation passes at or below this.
    pub tolerance: f64,
    /// After remap: fresh elements' moments were exactly zero.
    pub fresh_zero: bool,
    /// After reset: all moments zero and the step count 0.
    pub reset_zero: bool,
}

impl AdamCheck {
    pub fn passed(&self) -> bool {
        self.fresh_zero
            && self.reset_zero
            && !self.deviations.is_empty()
            && self
                .deviations
                .iter()
                .all(|d| d.max_error <= self.tolerance)
    }

    pub fn worst_error(&self) -> f64 {
        self.deviations
            .iter()
            .map(|d| d.max_error)
            .fold(0.0, f64::max)
    }
}

fn deviation(what: String, gpu: &[f32], cpu: &[f64]) -> Deviation {
    let mut max_error = if gpu.len() == cpu.len() {
        0.0
    } else {
        f64::INFINITY
    };
    for (&g, &c) in gpu.iter().zip(cpu) {
        let e = (f64::from(g) - c).abs() / (1.0 + c.abs());
        // NaN counts as a failure.
        max_error = if e.is_nan() {
            f64::INFINITY
        } else {
            max_error.max(e)
        };
    }
    Deviation { what, max_error }
}

fn random_vec(rng: &mut Rng, n: usize, scale: f32) -> Vec<f32> {
    (0..n).map(|_| rng.uniform(-scale, scale)).collect()
}

struct Group {
    gpu: AdamGroup,
    cpu: CpuAdam,
    grads: wgpu::Buffer,
    schedule: ExponentialDecay,
    grad_scale: f32,
}

async fn compare(
    ctx: &GpuContext,
    groups: &[Group],
    when: &str,
    out: &mut Vec<Deviation>,
) -> GpuResult<()> {
    for g in groups {
        let n = g.gpu.len() as usize;
        let params: Vec<f32> = ctx.read_buffer(g.gpu.params(), n).await?;
        let (m, v) = g.gpu.moments();
        let m: Vec<f32> = ctx.read_buffer(m, n).await?;
        let v: Vec<f32> = ctx.read_buffer(v, n).await?;
        let label = &g.gpu.label;
        out.push(deviation(
            format!("{label} params {when}"),
            &params,
            &g.cpu.params,
        ));
        out.push(deviation(format!("{label} m {when}"), &m, &g.cpu.m));
        // v is tiny for small gradients: compare it at the gradient's scale.
        let scale = f64::from(g.grad_scale).powi(2);
        let v_scaled: Vec<f32> = v.iter().map(|&x| (f64::from(x) / scale) as f32).collect();
        let cpu_scaled: Vec<f64> = g.cpu.v.iter().map(|x| x / scale).collect();
        out.push(deviation(
            format!("{label} v {when}"),
            &v_scaled,
            &cpu_scaled,
        ));
    }
    Ok(())
}

async fn run_steps(
    ctx: &GpuContext,
    adam: &Adam,
    groups: &mut [Group],
    rng: &mut Rng,
    steps: u32,
) -> GpuResult<()> {
    for _ in 0..steps {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        for g in groups.iter_mut() {
            let grads = random_vec(rng, g.gpu.len() as usize, g.grad_scale);
            ctx.queue
                .write_buffer(&g.grads, 0, bytemuck::cast_slice(&grads));
            let lr = g.schedule.lr(g.gpu.step_count());
            g.gpu.set_lr(lr);
            g.cpu.step(&grads, &g.gpu.config());
        }
        let mut refs: Vec<&mut AdamGroup> = groups.iter_mut().map(|g| &mut g.gpu).collect();
        adam.encode_step(ctx, &mut encoder, &mut refs)?;
        ctx.queue.submit([encoder.finish()]);
    }
    ctx.check()
}

/// Two groups (1000 floats with large gradients, 37 × 4 floats with 1e-6-scale gradients where
/// ε = 1e-15 matters) stepped together with decaying learning rates; then a remap of the second
/// (stride 4: kept, reordered, dropped and fresh elements), more steps, and a reset.
pub async fn check_adam(ctx: &GpuContext, seed: u64) -> GpuResult<AdamCheck> {
    let mut rng = Rng::new(seed);
    let adam = Adam::new(ctx)?;
    let mut groups = Vec::new();
    for (label, len, grad_scale, schedule) in [
        (
            "positions",
            1000usize,
            1.0f32,
            ExponentialDecay {
                start: 2e-2,
                end: 2e-4,
                steps: 6,
            },
        ),
        (
            "colours",
            37 * 4,
            1e-6,
            ExponentialDecay {
                start: 5e-3,
                end: 5e-3,
                steps: 0,
            },
        ),
    ] {
        let init = random_vec(&mut rng, len, 1.0);
        let params = ctx.storage_buffer(&format!("adam_check.{label}"), &init)?;
        let grads =
            ctx.storage_buffer_zeroed(&format!("adam_check.{label}.grad"), len as u64 * 4)?;
        let gpu = adam.group(
            ctx,
            label,
            &params,
            &grads,
            len as u32,
            AdamConfig::with_lr(schedule.start),
        )?;
        groups.push(Group {
            gpu,
            cpu: CpuAdam::new(&init),
            grads,
            schedule,
            grad_scale,
        });
    }
    let mut deviations = Vec::new();
    run_steps(ctx, &adam, &mut groups, &mut rng, 8).await?;
    compare(ctx, &groups, "after 8 steps", &mut deviations).await?;

    // Remap group 1: 37 old elements -> 41 new ones.
    let stride = 4usize;
    let mut map: Vec<u32> = (0..37u32).rev().filter(|i| i % 5 != 2).collect();
    for (i, slot) in [3usize, 10, 20, 25, 30, 33].iter().enumerate() {
        map.insert(*slot, if i % 2 == 0 { FRESH } else { 7 });
    }
    while map.len() < 41 {
        map.push(FRESH);
    }
    let new_len = map.len() * stride;
    let new_init = random_vec(&mut rng, new_len, 1.0);
    let new_params = ctx.storage_buffer("adam_check.colours.remapped", &new_init)?;
    let new_grads =
        ctx.storage_buffer_zeroed("adam_check.colours.remapped.grad", new_len as u64 * 4)?;
    let g = &mut groups[1];
    adam.remap(
        ctx,
        &mut g.gpu,
        &new_params,
        &new_grads,
        &map,
        stride as u32,
    )?;
    g.cpu.remap(&new_init, &map, stride);
    g.grads = new_grads;
    compare(ctx, &groups[1..], "after remap", &mut deviations).await?;
    let (m, v) = groups[1].gpu.moments();
    let m: Vec<f32> = ctx.read_buffer(m, new_len).await?;
    let v: Vec<f32> = ctx.read_buffer(v, new_len).await?;
    let fresh_zero = map.iter().enumerate().all(|(i, &src)| {
        src != FRESH || (0..stride).all(|k| m[i * stride + k] == 0.0 && v[i * stride + k] == 0.0)
    });

    run_steps(ctx, &adam, &mut groups, &mut rng, 4).await?;
    compare(ctx, &groups, "after 4 more steps", &mut deviations).await?;

    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    for g in groups.iter_mut() {
        g.gpu.reset(&mut encoder);
    }
    ctx.queue.submit([encoder.finish()]);
    let mut reset_zero = true;
    for g in &groups {
        let n = g.gpu.len() as usize;
        let (m, v) = g.gpu.moments();
        let m: Vec<f32> = ctx.read_buffer(m, n).await?;
        let v: Vec<f32> = ctx.read_buffer(v, n).await?;
        reset_zero &= g.gpu.step_count() == 0 && m.iter().chain(&v).all(|&x| x == 0.0);
    }
    Ok(AdamCheck {
        deviations,
        tolerance: 1e-5,
        fresh_zero,
        reset_zero,
    })
}
