//! Adam on the GPU (kernels in `shaders/adam.wgsl`) for flat f32 parameter groups, with the
//! exponential learning-rate decay of the paper's schedules and moment remapping for when faces
//! and vertices are added or removed.
//!
//! One [`Adam`] owns the kernels; each [`AdamGroup`] owns its moments, uniform and bind group, so
//! several groups step in one submission. The parameter and gradient buffers belong to the caller.

pub mod check;

use bytemuck::{Pod, Zeroable};

use crate::gpu::{Binding, GpuContext, GpuError, GpuResult, KernelFamily, compute_pass};

/// Marks a fresh element (zero moments) in a remap table.
pub(crate) const FRESH: u32 = u32::MAX;
const WG_SIZE: u32 = 256;

/// Hyper-parameters of one group.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdamConfig {
    pub lr: f32,
    pub beta1: f32,
    pub beta2: f32,
    /// 1e-15 by default, as 3DGS and MeshSplatting use: per-pixel-mean losses give gradients of
    /// 1e-7 and below (positions, opacities of faces covering a few pixels), where torch's 1e-8
    /// would dominate √v̂ and silently shrink those steps. f32 keeps 1e-15 meaningful since √v̂ is
    /// formed before ε is added.
    pub eps: f32,
}

impl AdamConfig {
    /// β1 = 0.9, β2 = 0.999, ε = 1e-15 with the given learning rate.
    pub fn with_lr(lr: f32) -> Self {
        Self {
            lr,
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-15,
        }
    }
}

/// Log-linear learning-rate decay from `start` to `end` over `steps` steps, then held at `end`
/// (the paper's position schedule: 2e-4 → 2e-6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExponentialDecay {
    pub start: f32,
    pub end: f32,
    pub steps: u32,
}

impl ExponentialDecay {
    /// The learning rate at `step` (0-based). Non-positive endpoints, where a logarithm is
    /// undefined, fall back to linear interpolation.
    pub fn lr(&self, step: u32) -> f32 {
        let t = if self.steps == 0 {
            1.0
        } else {
            (f64::from(step) / f64::from(self.steps)).min(1.0)
        };
        let (a, b) = (f64::from(self.start), f64::from(self.end));
        let lr = if a > 0.0 && b > 0.0 {
            (a.ln() * (1.0 - t) + b.ln() * t).exp()
        } else {
            a * (1.0 - t) + b * t
        };
        lr as f32
    }
}

/// Uniform block of `adam.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct AdamParams {
    n: u32,
    stride: u32,
    _pad0: [u32; 2],
    lr: f32,
    beta1: f32,
    beta2: f32,
    eps: f32,
    bias1: f32,
    bias2: f32,
    _pad1: [f32; 2],
}
const _: () = assert!(size_of::<AdamParams>() == 48);

/// The Adam kernels, shared by every group.
pub struct Adam {
    family: KernelFamily,
    step: wgpu::ComputePipeline,
    remap: wgpu::ComputePipeline,
    /// Bound where an entry point ignores a binding.
    placeholder: wgpu::Buffer,
}

/// One parameter group: moments, hyper-parameters, step count, and its bind group.
pub struct AdamGroup {
    label: String,
    config: AdamConfig,
    len: u32,
    step: u32,
    params: wgpu::Buffer,
    grads: wgpu::Buffer,
    m: wgpu::Buffer,
    v: wgpu::Buffer,
    uniform: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

fn check_len(what: &str, buffer: &wgpu::Buffer, len: u32) -> GpuResult<()> {
    let need = u64::from(len) * 4;
    if buffer.size() < need {
        return Err(GpuError::InvalidInput(format!(
            "{what}: buffer has {} bytes, {len} floats need {need}",
            buffer.size()
        )));
    }
    Ok(())
}

impl Adam {
    /// Compiles the kernels.
    pub fn new(ctx: &GpuContext) -> GpuResult<Self> {
        let (family, [step, remap]) = KernelFamily::new(
            ctx,
            "adam",
            include_str!("../../shaders/adam.wgsl"),
            &[
                Binding::Uniform,
                Binding::StorageReadWrite,
                Binding::StorageRead,
                Binding::StorageReadWrite,
                Binding::StorageReadWrite,
                Binding::StorageRead,
                Binding::StorageRead,
                Binding::StorageRead,
            ],
            ["adam_step", "remap_moments"],
        );
        Ok(Self {
            family,
            step,
            remap,
            placeholder: ctx.storage_buffer_zeroed("adam.placeholder", 4)?,
        })
    }

    /// A group over the first `len` floats of `params`, updated from `grads` (same length), with
    /// zero moments.
    pub fn group(
        &self,
        ctx: &GpuContext,
        label: &str,
        params: &wgpu::Buffer,
        grads: &wgpu::Buffer,
        len: u32,
        config: AdamConfig,
    ) -> GpuResult<AdamGroup> {
        check_len(&format!("{label} parameters"), params, len)?;
        check_len(&format!("{label} gradients"), grads, len)?;
        let bytes = u64::from(len) * 4;
        let m = ctx.storage_buffer_zeroed(&format!("{label}.adam_m"), bytes)?;
        let v = ctx.storage_buffer_zeroed(&format!("{label}.adam_v"), bytes)?;
        let uniform = ctx.uniform_buffer(&format!("{label}.adam"), &AdamParams::zeroed());
        let bind_group = self.step_bind_group(ctx, &uniform, params, grads, &m, &v);
        Ok(AdamGroup {
            label: label.to_string(),
            config,
            len,
            step: 0,
            params: params.clone(),
            grads: grads.clone(),
            m,
            v,
            uniform,
            bind_group,
        })
    }

    fn step_bind_group(
        &self,
        ctx: &GpuContext,
        uniform: &wgpu::Buffer,
        params: &wgpu::Buffer,
        grads: &wgpu::Buffer,
        m: &wgpu::Buffer,
        v: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let p = &self.placeholder;
        self.family
            .bind(ctx, &[uniform, params, grads, m, v, p, p, p])
    }

    /// Records one Adam step of every group in `groups` (each at most once per submission: its
    /// uniform is written with `queue.write_buffer`), advancing their step counts.
    pub fn encode_step(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        groups: &mut [&mut AdamGroup],
    ) -> GpuResult<()> {
        // Validate every group first so an error leaves no group half-stepped.
        for group in groups.iter() {
            let c = group.config;
            let beta_ok = (0.0..1.0).contains(&c.beta1) && (0.0..1.0).contains(&c.beta2);
            if !(c.lr.is_finite() && c.eps >= 0.0 && beta_ok) {
                return Err(GpuError::InvalidInput(format!(
                    "{}: Adam needs a finite lr, 0 ≤ β < 1 and ε ≥ 0, got {c:?}",
                    group.label
                )));
            }
        }
        let mut pass = compute_pass(encoder, "adam");
        for group in groups.iter_mut() {
            let c = group.config;
            group.step += 1;
            let t = f64::from(group.step);
            let uniform = AdamParams {
                n: group.len,
                stride: 1,
                _pad0: [0; 2],
                lr: c.lr,
                beta1: c.beta1,
                beta2: c.beta2,
                eps: c.eps,
                bias1: (1.0 - f64::from(c.beta1).powf(t)) as f32,
                bias2: (1.0 - f64::from(c.beta2).powf(t)) as f32,
                _pad1: [0.0; 2],
            };
            ctx.queue
                .write_buffer(&group.uniform, 0, bytemuck::bytes_of(&uniform));
            ctx.dispatch(
                &mut pass,
                &self.step,
                &group.bind_group,
                group.len.div_ceil(WG_SIZE),
            );
        }
        Ok(())
    }

    /// Moves `group` onto new parameter/gradient buffers after elements were added, removed or
    /// reordered: `map[new element] = old element` (or [`FRESH`] for zero moments), `stride`
    /// floats per element (4 for positions stored as vec4, 48 for SH, P for part logits). The
    /// step count is kept, as torch keeps it for a densified 3DGS group. Runs its own submission.
    pub fn remap(
        &self,
        ctx: &GpuContext,
        group: &mut AdamGroup,
        new_params: &wgpu::Buffer,
        new_grads: &wgpu::Buffer,
        map: &[u32],
        stride: u32,
    ) -> GpuResult<()> {
        if stride == 0 || !group.len.is_multiple_of(stride) {
            return Err(GpuError::InvalidInput(format!(
                "{}: remap stride {stride} does not divide the group's {} floats",
                group.label, group.len
            )));
        }
        let old_elems = group.len / stride;
        if let Some((i, &bad)) = map
            .iter()
            .enumerate()
            .find(|&(_, &s)| s != FRESH && s >= old_elems)
        {
            return Err(GpuError::InvalidInput(format!(
                "{}: remap entry {i} points at old element {bad}, but the group had {old_elems}",
                group.label
            )));
        }
        let new_len = u32::try_from(map.len() as u64 * u64::from(stride)).map_err(|_| {
            GpuError::TooManyElements {
                what: format!("{} after remap", group.label),
                count: map.len() as u64 * u64::from(stride),
                max: u64::from(u32::MAX),
            }
        })?;
        check_len(
            &format!("{} new parameters", group.label),
            new_params,
            new_len,
        )?;
        check_len(
            &format!("{} new gradients", group.label),
            new_grads,
            new_len,
        )?;

        let bytes = u64::from(new_len) * 4;
        let m = ctx.storage_buffer_zeroed(&format!("{}.adam_m", group.label), bytes)?;
        let v = ctx.storage_buffer_zeroed(&format!("{}.adam_v", group.label), bytes)?;
        let map_buffer = ctx.storage_buffer("adam.remap", map)?;
        let uniform = ctx.uniform_buffer(
            "adam.remap",
            &AdamParams {
                n: new_len,
                stride,
                ..AdamParams::zeroed()
            },
        );
        let bind_group = self.family.bind(
            ctx,
            &[
                &uniform,
                new_params,
                new_grads,
                &m,
                &v,
                &map_buffer,
                &group.m,
                &group.v,
            ],
        );
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        ctx.dispatch(
            &mut compute_pass(&mut encoder, "adam.remap"),
            &self.remap,
            &bind_group,
            new_len.div_ceil(WG_SIZE),
        );
        ctx.queue.submit([encoder.finish()]);
        ctx.check()?;

        group.bind_group = self.step_bind_group(ctx, &group.uniform, new_params, new_grads, &m, &v);
        group.params = new_params.clone();
        group.grads = new_grads.clone();
        group.m = m;
        group.v = v;
        group.len = new_len;
        Ok(())
    }
}

impl AdamGroup {
    /// Sets the learning rate used from the next step on (e.g. from an [`ExponentialDecay`]).
    pub(crate) fn set_lr(&mut self, lr: f32) {
        self.config.lr = lr;
    }

    /// The current hyper-parameters.
    pub fn config(&self) -> AdamConfig {
        self.config
    }

    /// Steps taken since creation or the last [`AdamGroup::reset`].
    pub(crate) fn step_count(&self) -> u32 {
        self.step
    }

    /// Floats in the group.
    pub fn len(&self) -> u32 {
        self.len
    }

    /// True for an empty group.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The parameter buffer the group updates.
    pub fn params(&self) -> &wgpu::Buffer {
        &self.params
    }

    /// The gradient buffer the group reads.
    pub fn grads(&self) -> &wgpu::Buffer {
        &self.grads
    }

    /// First and second moments (`len` floats each).
    pub(crate) fn moments(&self) -> (&wgpu::Buffer, &wgpu::Buffer) {
        (&self.m, &self.v)
    }

    /// Zeroes both moments and the step count, so bias correction restarts too (a zero moment
    /// with an old step count would be under-corrected). Recorded into `encoder`.
    pub fn reset(&mut self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.m, 0, None);
        encoder.clear_buffer(&self.v, 0, None);
        self.step = 0;
    }
}
