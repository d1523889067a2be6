//! The rasterizer's kernel families and the struct layouts they share with WGSL
//! (`shaders/raster_common.wgsl`): one wrapper per `.wgsl` file, each owning its pipelines and
//! bind-group layout. The orchestration lives in [`super::Rasterizer`].

use bytemuck::{Pod, Zeroable};

use crate::gpu::{Binding, GpuContext, KernelFamily, compute_pass};

const COMMON: &str = include_str!("../../shaders/raster_common.wgsl");
/// Bindings and helpers shared by the two per-tile compositing kernels.
const TILE_COMMON: &str = include_str!("../../shaders/raster_tile.wgsl");

/// Tile side in pixels (one workgroup per tile).
pub const TILE: u32 = 8;
/// Most part logits per vertex (K + 1 with K = 15 movable parts).
pub const MAX_PARTS: usize = 16;
/// Floats per (face, tile) pair gradient, without part logits (`PAIR_GRADS` in WGSL).
pub(crate) const PAIR_GRADS: u64 = 25;
/// Floats per corner gradient before its part logits (`CORNER_GRADS` in WGSL).
pub(crate) const CORNER_GRADS: u64 = 8;
/// SH coefficients per colour channel (degree 3).
pub(crate) const SH_COEFFS: usize = 16;
/// ln of the depth range the sort keys quantise (1 mm .. 1 km), as in WGSL.
pub(crate) const LOG_DEPTH_RANGE: (f32, f32) = (-6.907_755, 6.907_755);

/// Uniform block of every rasterizer kernel (`RasterParams` in WGSL).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct RasterParams {
    pub world_to_camera: [[f32; 4]; 4],
    pub camera_position: [f32; 4],
    pub focal: [f32; 4],
    pub background: [f32; 4],
    pub width: u32,
    pub height: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    pub num_faces: u32,
    pub num_vertices: u32,
    pub num_parts: u32,
    pub sh_degree: u32,
    pub gamma: f32,
    pub opacity_floor: f32,
    pub alpha_min: f32,
    pub transmittance_min: f32,
    pub near: f32,
    pub depth_bits: u32,
    pub num_pairs: u32,
    pub _pad: u32,
}
const _: () = assert!(size_of::<RasterParams>() == 176);

/// One projected face (`FaceRecord` in WGSL); only its size matters on the CPU.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct FaceRecord {
    pub words: [[f32; 4]; 9],
}
pub(crate) const FACE_RECORD_BYTES: u64 = size_of::<FaceRecord>() as u64;
const _: () = assert!(FACE_RECORD_BYTES == 144);

/// A kernel family compiled with the rasterizer's shared structs prepended.
fn family<const N: usize>(
    ctx: &GpuContext,
    label: &'static str,
    source: &str,
    bindings: &[Binding],
    entries: [&str; N],
) -> (KernelFamily, [wgpu::ComputePipeline; N]) {
    KernelFamily::new(
        ctx,
        label,
        &format!("{COMMON}\n{source}"),
        bindings,
        entries,
    )
}

use Binding::{StorageRead as R, StorageReadWrite as RW, Uniform as U};

/// `shaders/sh.wgsl`: view-dependent vertex colours and their backward pass.
pub(crate) struct ShKernels {
    pub family: KernelFamily,
    pub vertex_colors: wgpu::ComputePipeline,
    pub backward: wgpu::ComputePipeline,
}

impl ShKernels {
    pub fn new(ctx: &GpuContext) -> Self {
        let (family, [vertex_colors, backward]) = family(
            ctx,
            "sh",
            include_str!("../../shaders/sh.wgsl"),
            &[U, R, R, RW, R, RW, RW],
            ["vertex_colors", "sh_backward"],
        );
        Self {
            family,
            vertex_colors,
            backward,
        }
    }
}

/// A family with a single entry point.
pub(crate) struct Kernel {
    family: KernelFamily,
    pipeline: wgpu::ComputePipeline,
    label: &'static str,
}

impl Kernel {
    /// Binds `buffers` (in binding order) and records `workgroups` linear workgroups.
    pub fn run(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        buffers: &[&wgpu::Buffer],
        workgroups: u32,
    ) {
        let bind = self.family.bind(ctx, buffers);
        ctx.dispatch(
            &mut compute_pass(encoder, self.label),
            &self.pipeline,
            &bind,
            workgroups,
        );
    }

    fn new(
        ctx: &GpuContext,
        label: &'static str,
        source: &str,
        bindings: &[Binding],
        entry: &str,
    ) -> Self {
        let (family, [pipeline]) = family(ctx, label, source, bindings, [entry]);
        Self {
            family,
            pipeline,
            label,
        }
    }

    /// `shaders/raster_project.wgsl`: projection, culling, face records, tile counts.
    pub fn project(ctx: &GpuContext) -> Self {
        Self::new(
            ctx,
            "raster_project",
            include_str!("../../shaders/raster_project.wgsl"),
            &[U, R, R, R, R, RW, RW],
            "project_faces",
        )
    }

    /// `shaders/raster_composite.wgsl`: forward compositing per tile.
    pub fn composite(ctx: &GpuContext) -> Self {
        Self::new(
            ctx,
            "raster_composite",
            &format!(
                "{TILE_COMMON}\n{}",
                include_str!("../../shaders/raster_composite.wgsl")
            ),
            &[U, R, R, R, R, RW, RW],
            "composite_forward",
        )
    }

    /// `shaders/raster_backward.wgsl`: backward compositing per tile into pair gradients.
    pub fn backward(ctx: &GpuContext) -> Self {
        Self::new(
            ctx,
            "raster_backward",
            &format!(
                "{TILE_COMMON}\n{}",
                include_str!("../../shaders/raster_backward.wgsl")
            ),
            &[U, R, R, R, R, R, R, RW, RW],
            "composite_backward",
        )
    }

    /// `shaders/raster_face_grad.wgsl`: pair gradients → corner gradients.
    pub(crate) fn face_gradients(ctx: &GpuContext) -> Self {
        Self::new(
            ctx,
            "raster_face_grad",
            include_str!("../../shaders/raster_face_grad.wgsl"),
            &[U, R, R, R, R, R, R, RW],
            "face_gradients",
        )
    }

    /// `shaders/raster_vertex_grad.wgsl`: corner gradients → vertex gradients.
    pub(crate) fn vertex_gradients(ctx: &GpuContext) -> Self {
        Self::new(
            ctx,
            "raster_vertex_grad",
            include_str!("../../shaders/raster_vertex_grad.wgsl"),
            &[U, R, R, R, RW, RW, RW, RW],
            "vertex_gradients",
        )
    }
}

/// `shaders/raster_bin.wgsl`: pair emission and tile ranges after the sort.
pub(crate) struct BinKernels {
    pub family: KernelFamily,
    pub emit_pairs: wgpu::ComputePipeline,
    pub tile_ranges: wgpu::ComputePipeline,
}

impl BinKernels {
    pub fn new(ctx: &GpuContext) -> Self {
        let (family, [emit_pairs, tile_ranges]) = family(
            ctx,
            "raster_bin",
            include_str!("../../shaders/raster_bin.wgsl"),
            &[U, R, R, RW, RW, RW, RW, RW],
            ["emit_pairs", "find_tile_ranges"],
        );
        Self {
            family,
            emit_pairs,
            tile_ranges,
        }
    }
}
