//! Forward and backward orchestration of the differentiable mesh rasterizer (docs/design.md §4):
//! SH colours → projection and culling → tile binning with the GPU radix sort → per-tile
//! front-to-back compositing; backward: per-tile replay into per-(face, tile) gradients →
//! per-face chain rule → per-vertex gather → SH backward. No float atomics anywhere.
//!
//! The settings and uniform block are in `settings`, the working buffers and read-backs in
//! `state`; this file owns the kernels and the order they run in.

use super::field::GpuField;
use super::kernels::{BinKernels, Kernel, ShKernels};
use super::settings::{RasterSettings, raster_params, sort_key_bits};
use super::state::RasterState;
use crate::data::Camera;
use crate::gpu::{GpuContext, GpuError, GpuResult, compute_pass};

/// What a forward pass produced besides the images.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ForwardStats {
    /// (face, tile) pairs composited.
    pub pairs: u32,
    /// Key bits sorted.
    pub key_bits: u32,
}

/// The rasterizer's compiled kernels (one set per device).
pub struct Rasterizer {
    sh: ShKernels,
    project: Kernel,
    bin: BinKernels,
    composite: Kernel,
    backward: Kernel,
    face_gradients: Kernel,
    vertex_gradients: Kernel,
}

impl Rasterizer {
    /// Compiles every rasterizer kernel.
    pub fn new(ctx: &GpuContext) -> Self {
        Self {
            sh: ShKernels::new(ctx),
            project: Kernel::project(ctx),
            bin: BinKernels::new(ctx),
            composite: Kernel::composite(ctx),
            backward: Kernel::backward(ctx),
            face_gradients: Kernel::face_gradients(ctx),
            vertex_gradients: Kernel::vertex_gradients(ctx),
        }
    }

    /// Renders `field` from `camera` into `state`'s render buffer. One small read-back (the
    /// number of (face, tile) pairs) sizes the sort; everything else stays on the GPU.
    pub async fn forward(
        &self,
        ctx: &GpuContext,
        field: &GpuField,
        state: &mut RasterState,
        camera: &Camera,
        settings: &RasterSettings,
    ) -> GpuResult<ForwardStats> {
        if (camera.intrinsics.width, camera.intrinsics.height) != (state.width, state.height) {
            return Err(GpuError::InvalidInput(format!(
                "camera is {}x{} but the raster state was made for {}x{}",
                camera.intrinsics.width, camera.intrinsics.height, state.width, state.height
            )));
        }
        if field.num_parts != state.num_parts {
            return Err(GpuError::InvalidInput(format!(
                "mesh field has {} parts but the raster state was made for {}",
                field.num_parts, state.num_parts
            )));
        }
        state.ensure_faces(ctx, field.num_faces)?;
        let (tile_bits, depth_bits) = sort_key_bits(state.width, state.height)?;
        let mut params = raster_params(camera, settings, field, depth_bits);
        ctx.queue
            .write_buffer(&state.params, 0, bytemuck::bytes_of(&params));

        // 1. Colours, projection, tile counts and their scan.
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        state.clock.start();
        let sh_bind = self.sh_bind_group(ctx, field, state);
        let vertex_groups = field.num_vertices.div_ceil(256);
        let face_groups = field.num_faces.div_ceil(256);
        ctx.dispatch(
            &mut compute_pass(&mut encoder, "sh.colors"),
            &self.sh.vertex_colors,
            &sh_bind,
            vertex_groups,
        );
        state.clock.lap(ctx, &mut encoder, "sh colours");
        // The scan covers one extra (zero) element so offsets[F] is the total.
        encoder.clear_buffer(&state.offsets, 0, None);
        self.project.run(
            ctx,
            &mut encoder,
            &[
                &state.params,
                &field.positions,
                &field.faces,
                &field.opacity,
                &field.colors,
                &state.records,
                &state.offsets,
            ],
            face_groups,
        );
        state.clock.lap(ctx, &mut encoder, "project");
        state.scan.encode(ctx, &mut encoder, field.num_faces + 1)?;
        ctx.queue.submit([encoder.finish()]);
        let total: Vec<u32> = ctx.read_buffer(state.scan.total(), 1).await?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        state
            .clock
            .lap(ctx, &mut encoder, "scan + pair count read-back");
        let pairs = total.first().copied().unwrap_or(0);
        state.ensure_pairs(ctx, pairs)?;
        params.num_pairs = pairs;
        ctx.queue
            .write_buffer(&state.params, 0, bytemuck::bytes_of(&params));
        state.last_params = params;

        // 2. Binning, sort, tile ranges, compositing.
        let bin_bind = self.bin.family.bind(
            ctx,
            &[
                &state.params,
                &state.records,
                &state.offsets,
                state.sorter.keys(),
                state.sorter.values(),
                &state.pair_info,
                &state.sorted_info,
                &state.tile_ranges,
            ],
        );
        ctx.dispatch(
            &mut compute_pass(&mut encoder, "raster.emit"),
            &self.bin.emit_pairs,
            &bin_bind,
            face_groups,
        );
        state.clock.lap(ctx, &mut encoder, "emit pairs");
        state
            .sorter
            .encode(ctx, &mut encoder, pairs, tile_bits + depth_bits)?;
        state.clock.lap(ctx, &mut encoder, "radix sort");
        encoder.clear_buffer(&state.tile_ranges, 0, None);
        ctx.dispatch(
            &mut compute_pass(&mut encoder, "raster.ranges"),
            &self.bin.tile_ranges,
            &bin_bind,
            pairs.div_ceil(256),
        );
        state.clock.lap(ctx, &mut encoder, "tile ranges");
        self.composite.run(
            ctx,
            &mut encoder,
            &[
                &state.params,
                &state.tile_ranges,
                &state.sorted_info,
                &state.records,
                &field.part_logits,
                &state.render,
                &state.face_stats,
            ],
            params.tiles_x * params.tiles_y,
        );
        state.clock.lap(ctx, &mut encoder, "composite forward");
        ctx.queue.submit([encoder.finish()]);
        ctx.check()?;
        Ok(ForwardStats {
            pairs,
            key_bits: tile_bits + depth_bits,
        })
    }

    /// Records the backward pass of the last [`Rasterizer::forward`] into `encoder`: reads
    /// `state.grad_render()`, overwrites `field`'s gradient buffers.
    pub fn encode_backward(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        field: &GpuField,
        state: &mut RasterState,
    ) {
        let params = state.last_params;
        state.clock.start();
        // Pairs that no pixel reached are never written: they must read as zero.
        encoder.clear_buffer(&state.pair_grads, 0, None);
        encoder.clear_buffer(&state.pair_logit_grads, 0, None);
        self.backward.run(
            ctx,
            encoder,
            &[
                &state.params,
                &state.tile_ranges,
                &state.sorted_info,
                &state.records,
                &field.part_logits,
                &state.render,
                &state.grad_render,
                &state.pair_grads,
                &state.pair_logit_grads,
            ],
            params.tiles_x * params.tiles_y,
        );
        state.clock.lap(ctx, encoder, "composite backward");
        self.face_gradients.run(
            ctx,
            encoder,
            &[
                &state.params,
                &field.positions,
                &field.faces,
                &field.opacity,
                &state.offsets,
                &state.pair_grads,
                &state.pair_logit_grads,
                &state.corner_grads,
            ],
            field.num_faces.div_ceil(256),
        );
        state.clock.lap(ctx, encoder, "face gradients");
        let vertex_groups = field.num_vertices.div_ceil(256);
        self.vertex_gradients.run(
            ctx,
            encoder,
            &[
                &state.params,
                &field.csr_offsets,
                &field.csr_corners,
                &state.corner_grads,
                &field.grad_positions,
                &field.grad_colors,
                &field.grad_opacity,
                &field.grad_part_logits,
            ],
            vertex_groups,
        );
        state.clock.lap(ctx, encoder, "vertex gather");
        let sh_bind = self.sh_bind_group(ctx, field, state);
        ctx.dispatch(
            &mut compute_pass(encoder, "sh.backward"),
            &self.sh.backward,
            &sh_bind,
            vertex_groups,
        );
        state.clock.lap(ctx, encoder, "sh backward");
    }

    fn sh_bind_group(
        &self,
        ctx: &GpuContext,
        field: &GpuField,
        state: &RasterState,
    ) -> wgpu::BindGroup {
        self.sh.family.bind(
            ctx,
            &[
                &state.params,
                &field.positions,
                &field.sh,
                &field.colors,
                &field.grad_colors,
                &field.grad_sh,
                &field.grad_positions,
            ],
        )
    }
}
