//! The GPU half of the pixel-wise motion consistency (`shaders/articulation.wgsl`): move a state's
//! vertices by their part's rigid motion before rendering, and reduce the rasterizer's position
//! gradients to per-part [`PartSums`] afterwards. Only those few sums come back to the CPU.

use glam::{DMat3, DVec3, Vec3};

use super::sums::PartSums;
use crate::gpu::{Binding, GpuContext, GpuError, GpuResult, KernelFamily, compute_pass};
use crate::raster::GpuField;

const SOURCE: &str = include_str!("../../shaders/articulation.wgsl");

/// Workgroup size of the family (the prelude's `WG_SIZE`).
const WG_SIZE: u32 = 256;
/// Vertices per workgroup of the reduction (`REDUCE_ITEMS` × `WG_SIZE`).
const REDUCE_SPAN: u32 = 16 * WG_SIZE;
/// Moments per part in the partial sums: Σ g (3) and Σ g xᵀ (9).
const MOMENTS: usize = 12;

#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct MotionParams {
    num_vertices: u32,
    num_parts: u32,
    _pad: [u32; 2],
}
const _: () = assert!(size_of::<MotionParams>() == 16);

/// x̂ = A x + b: A's columns then b, each padded to a `vec4`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct PartAffine {
    columns: [[f32; 4]; 3],
    b: [f32; 4],
}
const _: () = assert!(size_of::<PartAffine>() == 64);

impl PartAffine {
    fn new((a, b): (DMat3, DVec3)) -> Self {
        let a = a.as_mat3();
        let b = b.as_vec3();
        Self {
            columns: [0, 1, 2].map(|c| a.col(c).extend(0.0).into()),
            b: b.extend(0.0).into(),
        }
    }
}

/// The two kernels, built once and shared by both states.
pub(crate) struct MotionKernels {
    family: KernelFamily,
    apply: wgpu::ComputePipeline,
    reduce: wgpu::ComputePipeline,
}

impl MotionKernels {
    pub fn new(ctx: &GpuContext) -> Self {
        let (family, [apply, reduce]) = KernelFamily::new(
            ctx,
            "articulation",
            SOURCE,
            &[
                Binding::Uniform,
                Binding::StorageRead,
                Binding::StorageRead,
                Binding::StorageRead,
                Binding::StorageReadWrite,
                Binding::StorageRead,
                Binding::StorageReadWrite,
            ],
            ["apply_motion", "reduce_motion_gradients"],
        );
        Self {
            family,
            apply,
            reduce,
        }
    }
}

/// One state's frozen mesh as the pixel-wise term moves it into the other state: its rest
/// positions and hardened part labels, bound to the field whose positions it overwrites.
pub(crate) struct MovedMesh {
    motions: wgpu::Buffer,
    partials: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    num_vertices: u32,
    num_parts: u32,
    /// Vertices per part (the sums' `count`).
    counts: Vec<u32>,
}

impl MovedMesh {
    /// Binds `field` (whose positions are the rest positions now) with per-vertex `parts`.
    pub fn new(
        ctx: &GpuContext,
        kernels: &MotionKernels,
        field: &GpuField,
        rest: &[Vec3],
        parts: &[u32],
    ) -> GpuResult<Self> {
        let (n, k) = (field.num_vertices, field.num_parts);
        if rest.len() != n as usize || parts.len() != n as usize {
            return Err(GpuError::InvalidInput(format!(
                "a moved mesh needs one rest position and one part per vertex: {} and {} for {n} vertices",
                rest.len(),
                parts.len()
            )));
        }
        if let Some(bad) = parts.iter().find(|&&p| p >= k) {
            return Err(GpuError::InvalidInput(format!(
                "vertex part {bad} is out of range for {k} parts"
            )));
        }
        let mut counts = vec![0; k as usize];
        for &p in parts {
            counts[p as usize] += 1;
        }
        let rest: Vec<[f32; 4]> = rest.iter().map(|p| p.extend(0.0).into()).collect();
        let params = ctx.uniform_buffer(
            "articulation.params",
            &MotionParams {
                num_vertices: n,
                num_parts: k,
                _pad: [0; 2],
            },
        );
        let motions = ctx.storage_buffer(
            "articulation.motions",
            &vec![PartAffine::new((DMat3::IDENTITY, DVec3::ZERO)); k as usize],
        )?;
        let rest = ctx.storage_buffer("articulation.rest_positions", &rest)?;
        let parts = ctx.storage_buffer("articulation.vertex_parts", parts)?;
        let groups = n.div_ceil(REDUCE_SPAN).max(1);
        let partials = ctx.storage_buffer_zeroed(
            "articulation.partials",
            u64::from(groups * k) * (MOMENTS * 4) as u64,
        )?;
        let bind_group = kernels.family.bind(
            ctx,
            &[
                &params,
                &motions,
                &rest,
                &parts,
                &field.positions,
                &field.grad_positions,
                &partials,
            ],
        );
        Ok(Self {
            motions,
            partials,
            bind_group,
            num_vertices: n,
            num_parts: k,
            counts,
        })
    }

    /// Records the move of every vertex by its part's `(A, b)` (one per part; missing parts stay).
    pub(crate) fn encode_apply(
        &self,
        ctx: &GpuContext,
        kernels: &MotionKernels,
        encoder: &mut wgpu::CommandEncoder,
        motions: &[(DMat3, DVec3)],
    ) {
        let affine: Vec<PartAffine> = (0..self.num_parts as usize)
            .map(|k| {
                PartAffine::new(
                    motions
                        .get(k)
                        .copied()
                        .unwrap_or((DMat3::IDENTITY, DVec3::ZERO)),
                )
            })
            .collect();
        ctx.queue
            .write_buffer(&self.motions, 0, bytemuck::cast_slice(&affine));
        let mut pass = compute_pass(encoder, "apply_motion");
        ctx.dispatch(
            &mut pass,
            &kernels.apply,
            &self.bind_group,
            self.num_vertices.div_ceil(WG_SIZE),
        );
    }

    /// Records the per-part reduction of the field's position gradients (after a backward pass).
    pub(crate) fn encode_reduce(
        &self,
        ctx: &GpuContext,
        kernels: &MotionKernels,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let mut pass = compute_pass(encoder, "reduce_motion_gradients");
        ctx.dispatch(
            &mut pass,
            &kernels.reduce,
            &self.bind_group,
            self.num_vertices.div_ceil(REDUCE_SPAN).max(1),
        );
    }

    /// The per-part sums of the last reduction, added up in f64 over workgroups.
    pub(crate) async fn read_sums(&self, ctx: &GpuContext) -> GpuResult<Vec<PartSums>> {
        let k = self.num_parts as usize;
        let groups = self.num_vertices.div_ceil(REDUCE_SPAN).max(1) as usize;
        let partials: Vec<f32> = ctx
            .read_buffer(&self.partials, groups * k * MOMENTS)
            .await?;
        let mut sums: Vec<PartSums> = self
            .counts
            .iter()
            .map(|&count| PartSums {
                count,
                ..PartSums::default()
            })
            .collect();
        for (i, m) in partials.chunks_exact(MOMENTS).enumerate() {
            let m: Vec<f64> = m.iter().map(|&v| f64::from(v)).collect();
            let s = &mut sums[i % k];
            s.g += DVec3::new(m[0], m[1], m[2]);
            s.gx += DMat3::from_cols_slice(&m[3..12]);
        }
        Ok(sums)
    }
}

/// How the GPU motion kernels disagree with the CPU ([`check_against_cpu`]).
#[derive(Debug, thiserror::Error)]
pub enum KernelMismatch {
    /// A GPU call failed.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A moved vertex is off by more than 1e-5 m.
    #[error("vertex {vertex} moved to {got}, expected {want}")]
    Position {
        /// Index of the vertex.
        vertex: usize,
        /// Where the GPU moved it.
        got: DVec3,
        /// Where the CPU moved it.
        want: DVec3,
    },
    /// A part's reduced sums differ beyond 1e-4 relative (or count differently).
    #[error("part {part}: GPU sums {got:?} differ from the CPU's {want:?} (max error {error})")]
    Sums {
        /// The part.
        part: usize,
        /// The GPU's sums.
        got: PartSums,
        /// The CPU's sums.
        want: PartSums,
        /// The largest absolute difference.
        error: f64,
    },
}

/// Moves a random mesh with random motions and reduces random gradients on the GPU, and compares
/// both with the CPU (f64): the positions to 1e-5 m, the sums to 1e-4 relative. Shared by the
/// native and browser tests.
pub async fn check_against_cpu(ctx: &GpuContext) -> Result<(), KernelMismatch> {
    use crate::rng::Rng;
    let mut rng = Rng::new(5);
    let (n, k) = (5000usize, 4usize);
    let mut r3 = |s: f32| Vec3::new(rng.uniform(-s, s), rng.uniform(-s, s), rng.uniform(-s, s));
    let rest: Vec<Vec3> = (0..n).map(|_| r3(0.5)).collect();
    let grads: Vec<Vec3> = (0..n).map(|_| r3(1.0)).collect();
    let faces: Vec<[u32; 3]> = (0..n as u32 / 3)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    let parts: Vec<u32> = (0..n).map(|i| ((i * 7 + i / 13) % k) as u32).collect();
    let motions: Vec<(DMat3, DVec3)> = (0..k)
        .map(|p| {
            super::PartMotion::revolute(
                DVec3::new(1.0, p as f64, 0.5),
                DVec3::new(0.1, 0.2, -0.3) * p as f64,
                0.3 * p as f64,
            )
            .forward_affine()
        })
        .collect();
    let field = crate::raster::MeshField::new(rest.clone(), faces, k, 0.0);
    let gpu = GpuField::upload(ctx, &field)?;
    let kernels = MotionKernels::new(ctx);
    let moved = MovedMesh::new(ctx, &kernels, &gpu, &rest, &parts)?;
    let g4: Vec<[f32; 4]> = grads.iter().map(|g| g.extend(0.0).into()).collect();
    ctx.queue
        .write_buffer(&gpu.grad_positions, 0, bytemuck::cast_slice(&g4));
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    moved.encode_apply(ctx, &kernels, &mut encoder, &motions);
    moved.encode_reduce(ctx, &kernels, &mut encoder);
    ctx.queue.submit([encoder.finish()]);
    let got: Vec<[f32; 4]> = ctx.read_buffer(&gpu.positions, n).await?;
    let sums = moved.read_sums(ctx).await?;
    let mut want = vec![PartSums::default(); k];
    for i in 0..n {
        let (a, b) = motions[parts[i] as usize];
        let x = rest[i].as_dvec3();
        let y = a * x + b;
        let g = Vec3::from_slice(&got[i][..3]).as_dvec3();
        if (g - y).length() > 1e-5 {
            return Err(KernelMismatch::Position {
                vertex: i,
                got: g,
                want: y,
            });
        }
        want[parts[i] as usize].add(grads[i].as_dvec3(), x);
    }
    for (p, (s, w)) in sums.iter().zip(&want).enumerate() {
        let scale = 1.0
            + w.g.abs().max_element()
            + w.gx
                .abs()
                .to_cols_array()
                .iter()
                .fold(0.0f64, |a, &b| a.max(b));
        let err = (s.g - w.g).abs().max_element().max(
            (s.gx - w.gx)
                .abs()
                .to_cols_array()
                .iter()
                .fold(0.0, |a: f64, &b| a.max(b)),
        );
        if err > 1e-4 * scale || s.count != w.count {
            return Err(KernelMismatch::Sums {
                part: p,
                got: *s,
                want: *w,
                error: err,
            });
        }
    }
    Ok(())
}
