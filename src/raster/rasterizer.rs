//! Forward and backward orchestration of the differentiable mesh rasterizer (DESIGN.md §4):
//! SH colours → projection and culling → tile binning with the GPU radix sort → per-tile
//! front-to-back compositing; backward: per-tile replay into per-(face, tile) gradients →
//! per-face chain rule → per-vertex gather → SH backward. No float atomics anywhere.

use bytemuck::Zeroable;
use glam::{Mat4, Vec3};

use super::field::GpuField;
use super::kernels::{
    BinKernels, CORNER_GRADS, FACE_RECORD_BYTES, Kernel, PAIR_GRADS, RasterParams, ShKernels, TILE,
};
use crate::data::Camera;
use crate::gpu::{GpuContext, GpuError, GpuResult, PrefixSum, RadixSort, compute_pass};

/// Output planes before the part logits: RGB, depth, alpha.
pub const BASE_CHANNELS: usize = 5;

/// Settings of one render: the annealed quantities and the compositing cut-offs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RasterSettings {
    /// Window sharpness γ: 1 is a soft pyramid, towards 0 a hard opaque triangle.
    pub gamma: f32,
    /// Face opacity = floor + (1 − floor) · mean vertex opacity (annealed to 1 for opaque meshes).
    pub opacity_floor: f32,
    /// Contributions with α below this are skipped (1/255; 0 for smooth gradient checks).
    pub alpha_min: f32,
    /// Compositing stops once the transmittance falls below this (1e-4; 0 for checks).
    pub transmittance_min: f32,
    /// Faces with a vertex closer than this to the camera plane are culled (metres).
    pub near: f32,
    /// Colour behind the mesh.
    pub background: Vec3,
    /// Active SH degree, 0..=3.
    pub sh_degree: u32,
}

impl Default for RasterSettings {
    fn default() -> Self {
        Self {
            gamma: 1.0,
            opacity_floor: 0.0,
            alpha_min: 1.0 / 255.0,
            transmittance_min: 1e-4,
            near: 0.01,
            background: Vec3::ZERO,
            sh_degree: 0,
        }
    }
}

impl RasterSettings {
    /// The same model without the hard cut-offs, so the output is smooth in every parameter
    /// (what finite-difference checks need, as Brush does).
    pub fn smooth(self) -> Self {
        Self {
            alpha_min: 0.0,
            transmittance_min: 0.0,
            ..self
        }
    }
}

/// Sort-key split for an image: (tile bits, depth bits), tile bits + depth bits a multiple of 8
/// (whole radix passes) with at least 16 depth bits where possible.
pub fn sort_key_bits(width: u32, height: u32) -> GpuResult<(u32, u32)> {
    let tiles = width.div_ceil(TILE) * height.div_ceil(TILE);
    let tile_bits = (32 - tiles.saturating_sub(1).leading_zeros()).max(1);
    if tile_bits > 24 {
        return Err(GpuError::TooManyElements {
            what: format!("image tiles ({width}x{height} pixels)"),
            count: u64::from(tiles),
            max: 1 << 24,
        });
    }
    let total = (tile_bits + 16).next_multiple_of(8).min(32);
    Ok((tile_bits, total - tile_bits))
}

/// What a forward pass produced besides the images.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ForwardStats {
    /// (face, tile) pairs composited.
    pub pairs: u32,
    /// Key bits sorted.
    pub key_bits: u32,
}

/// Work done by one forward + backward pass (see [`RasterState::read_work`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct WorkCounts {
    pub forward_evaluations: u64,
    pub backward_evaluations: u64,
    pub hits: u64,
}

/// Rendered planes read back to the CPU (see [`RasterState::read_render`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RenderImages {
    pub width: u32,
    pub height: u32,
    pub num_parts: usize,
    /// `(5 + num_parts)` planes of `width · height`: RGB, depth, alpha, part logits.
    pub planes: Vec<f32>,
}

impl RenderImages {
    /// Plane `c` (0–2 RGB, 3 depth, 4 alpha, 5.. part logits).
    pub fn plane(&self, c: usize) -> &[f32] {
        let n = (self.width * self.height) as usize;
        &self.planes[c * n..(c + 1) * n]
    }

    /// RGB of pixel (x, y).
    pub fn rgb(&self, x: u32, y: u32) -> Vec3 {
        let i = (y * self.width + x) as usize;
        Vec3::new(self.plane(0)[i], self.plane(1)[i], self.plane(2)[i])
    }
}

/// Optional per-stage wall-clock timing (for benchmarks). When enabled, every
/// stage is submitted and waited for on its own, which serialises the GPU: use it to see where
/// time goes, not to measure throughput.
#[derive(Debug, Default)]
pub struct StageClock {
    enabled: bool,
    last: f64,
    /// (stage, milliseconds) in order, accumulated until [`StageClock::take`].
    times: Vec<(&'static str, f64)>,
}

impl StageClock {
    fn start(&mut self) {
        self.last = crate::gpu::now_seconds();
    }

    /// Submits what `encoder` holds, waits, and books the time since the last lap on `stage`.
    /// In the browser the wait is not possible: there the times only mark submissions.
    fn lap(&mut self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder, stage: &'static str) {
        if !self.enabled {
            return;
        }
        let done = std::mem::replace(
            encoder,
            ctx.device.create_command_encoder(&Default::default()),
        );
        ctx.queue.submit([done.finish()]);
        let _ = ctx.poll_wait();
        let now = crate::gpu::now_seconds();
        self.times.push((stage, (now - self.last) * 1e3));
        self.last = now;
    }

    /// The stage times booked so far (and clears them).
    pub fn take(&mut self) -> Vec<(&'static str, f64)> {
        std::mem::take(&mut self.times)
    }
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

/// Per-image-size and per-field working buffers, grown on demand.
pub struct RasterState {
    width: u32,
    height: u32,
    num_parts: u32,
    params: wgpu::Buffer,
    last_params: RasterParams,
    /// Planar output: `5 + P` planes plus the per-pixel consumed-entry count (u32 bits).
    render: wgpu::Buffer,
    /// dL/d(output), `5 + P` planes: written by the loss, read by the backward pass.
    grad_render: wgpu::Buffer,
    tile_ranges: wgpu::Buffer,
    face_capacity: u32,
    records: wgpu::Buffer,
    /// Tile counts per face (+1 trailing zero), scanned in place into emission offsets.
    offsets: wgpu::Buffer,
    scan: PrefixSum,
    corner_grads: wgpu::Buffer,
    face_stats: wgpu::Buffer,
    pair_capacity: u32,
    sorter: RadixSort,
    pair_face: wgpu::Buffer,
    sorted_face: wgpu::Buffer,
    pair_slot: wgpu::Buffer,
    pair_grads: wgpu::Buffer,
    pair_logit_grads: wgpu::Buffer,
    /// Per-stage timing, off unless [`RasterState::set_profiling`].
    pub clock: StageClock,
}

fn f32_bytes(n: u64) -> u64 {
    n * 4
}

impl RasterState {
    /// Buffers for `width × height` images with `num_parts` part logits; face and pair
    /// capacity grow as needed.
    pub fn new(ctx: &GpuContext, width: u32, height: u32, num_parts: u32) -> GpuResult<Self> {
        if width == 0 || height == 0 {
            return Err(GpuError::InvalidInput(format!(
                "cannot render a {width}x{height} image"
            )));
        }
        sort_key_bits(width, height)?;
        let npix = u64::from(width) * u64::from(height);
        let channels = BASE_CHANNELS as u64 + u64::from(num_parts);
        let tiles = u64::from(width.div_ceil(TILE) * height.div_ceil(TILE));
        let (face_capacity, pair_capacity) = (1024, 4096);
        let offsets =
            ctx.storage_buffer_zeroed("raster.offsets", f32_bytes(face_capacity as u64 + 1))?;
        let scan = PrefixSum::new(ctx, &offsets, face_capacity + 1)?;
        Ok(Self {
            width,
            height,
            num_parts,
            params: ctx.uniform_buffer("raster.params", &RasterParams::zeroed()),
            last_params: RasterParams::zeroed(),
            render: ctx.storage_buffer_zeroed("raster.render", f32_bytes(npix * (channels + 1)))?,
            grad_render: ctx
                .storage_buffer_zeroed("raster.grad_render", f32_bytes(npix * channels))?,
            tile_ranges: ctx.storage_buffer_zeroed("raster.tile_ranges", f32_bytes(2 * tiles))?,
            face_capacity,
            records: ctx.storage_buffer_zeroed(
                "raster.records",
                FACE_RECORD_BYTES * u64::from(face_capacity),
            )?,
            offsets,
            scan,
            corner_grads: Self::corner_buffer(ctx, face_capacity, num_parts)?,
            face_stats: ctx.storage_buffer_zeroed(
                "raster.face_stats",
                f32_bytes(2 * u64::from(face_capacity)),
            )?,
            pair_capacity,
            sorter: RadixSort::new(ctx, pair_capacity)?,
            pair_face: ctx
                .storage_buffer_zeroed("raster.pair_face", f32_bytes(pair_capacity.into()))?,
            sorted_face: ctx
                .storage_buffer_zeroed("raster.sorted_face", f32_bytes(pair_capacity.into()))?,
            pair_slot: ctx
                .storage_buffer_zeroed("raster.pair_slot", f32_bytes(pair_capacity.into()))?,
            pair_grads: ctx.storage_buffer_zeroed(
                "raster.pair_grads",
                f32_bytes(PAIR_GRADS * u64::from(pair_capacity)),
            )?,
            pair_logit_grads: ctx.storage_buffer_zeroed(
                "raster.pair_logit_grads",
                f32_bytes(3 * u64::from(num_parts) * u64::from(pair_capacity)),
            )?,
            clock: StageClock::default(),
        })
    }

    fn corner_buffer(ctx: &GpuContext, faces: u32, parts: u32) -> GpuResult<wgpu::Buffer> {
        ctx.storage_buffer_zeroed(
            "raster.corner_grads",
            f32_bytes(3 * u64::from(faces) * (CORNER_GRADS + u64::from(parts))),
        )
    }

    /// Books the time since the last stage on `stage` when profiling (an empty name starts a new
    /// interval without booking): lets callers time their own stages between rasterizer calls.
    pub fn clock_lap(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        stage: &'static str,
    ) {
        if stage.is_empty() {
            self.clock.start();
        } else {
            self.clock.lap(ctx, encoder, stage);
        }
    }

    /// Times every stage separately from now on (see [`StageClock`]).
    pub fn set_profiling(&mut self, enabled: bool) {
        self.clock.enabled = enabled;
    }

    /// Image width and height.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Part logits per pixel.
    pub fn num_parts(&self) -> u32 {
        self.num_parts
    }

    /// The planar render (`5 + P` planes, then the consumed-entry counts), for the loss.
    pub fn render(&self) -> &wgpu::Buffer {
        &self.render
    }

    /// dL/d(render), `5 + P` planes; the loss writes it before [`Rasterizer::encode_backward`].
    pub fn grad_render(&self) -> &wgpu::Buffer {
        &self.grad_render
    }

    /// Per-face (max blending weight as f32 bits, pixel count), accumulated over renders until
    /// [`RasterState::clear_face_stats`].
    pub fn face_stats(&self) -> &wgpu::Buffer {
        &self.face_stats
    }

    /// Zeroes the per-face statistics.
    pub fn clear_face_stats(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.face_stats, 0, None);
    }

    /// Reads the per-face (max blending weight, pixel count) statistics.
    pub async fn read_face_stats(
        &self,
        ctx: &GpuContext,
        faces: u32,
    ) -> GpuResult<Vec<(f32, u32)>> {
        let raw: Vec<u32> = ctx
            .read_buffer(&self.face_stats, 2 * faces as usize)
            .await?;
        Ok(raw
            .chunks_exact(2)
            .map(|s| (f32::from_bits(s[0]), s[1]))
            .collect())
    }

    /// Counts the work of the last forward pass (for benchmarks): per-pixel face evaluations of
    /// the forward and backward compositing loops, and the hits (contributions with α ≥ alpha_min)
    /// as the face statistics recorded them since they were last cleared.
    pub async fn read_work(&self, ctx: &GpuContext, faces: u32) -> GpuResult<WorkCounts> {
        let tiles_x = self.width.div_ceil(TILE);
        let tiles = (tiles_x * self.height.div_ceil(TILE)) as usize;
        let ranges: Vec<u32> = ctx.read_buffer(&self.tile_ranges, 2 * tiles).await?;
        let render = self.read_render(ctx).await?;
        let n = (self.width * self.height) as usize;
        let planes = BASE_CHANNELS + self.num_parts as usize;
        let consumed: Vec<u32> =
            ctx.read_buffer(&self.render, (planes + 1) * n).await?[planes * n..].to_vec();
        let t_min = self.last_params.transmittance_min;
        let (mut forward, mut backward) = (0u64, 0u64);
        for y in 0..self.height {
            for x in 0..self.width {
                let tile = ((y / TILE) * tiles_x + x / TILE) as usize;
                let len = u64::from(ranges[2 * tile + 1].saturating_sub(ranges[2 * tile]));
                let i = (y * self.width + x) as usize;
                let used = u64::from(consumed[i]);
                // A saturated pixel stops at its last contributor; the others scan the whole list.
                forward += if 1.0 - render.plane(4)[i] < t_min {
                    used
                } else {
                    len
                };
                backward += used;
            }
        }
        let hits = self
            .read_face_stats(ctx, faces)
            .await?
            .iter()
            .map(|s| u64::from(s.1))
            .sum();
        Ok(WorkCounts {
            forward_evaluations: forward,
            backward_evaluations: backward,
            hits,
        })
    }

    /// Reads the last forward pass's images.
    pub async fn read_render(&self, ctx: &GpuContext) -> GpuResult<RenderImages> {
        let planes = BASE_CHANNELS + self.num_parts as usize;
        let n = (self.width * self.height) as usize;
        Ok(RenderImages {
            width: self.width,
            height: self.height,
            num_parts: self.num_parts as usize,
            planes: ctx.read_buffer(&self.render, planes * n).await?,
        })
    }

    fn ensure_faces(&mut self, ctx: &GpuContext, faces: u32) -> GpuResult<()> {
        if faces <= self.face_capacity {
            return Ok(());
        }
        let cap = faces.max(self.face_capacity.saturating_mul(2));
        ctx.check_binding("mesh face records", FACE_RECORD_BYTES * u64::from(cap))?;
        self.records =
            ctx.storage_buffer_zeroed("raster.records", FACE_RECORD_BYTES * u64::from(cap))?;
        self.offsets =
            ctx.storage_buffer_zeroed("raster.offsets", f32_bytes(u64::from(cap) + 1))?;
        self.scan = PrefixSum::new(ctx, &self.offsets, cap + 1)?;
        self.corner_grads = Self::corner_buffer(ctx, cap, self.num_parts)?;
        self.face_stats =
            ctx.storage_buffer_zeroed("raster.face_stats", f32_bytes(2 * u64::from(cap)))?;
        self.face_capacity = cap;
        Ok(())
    }

    fn ensure_pairs(&mut self, ctx: &GpuContext, pairs: u32) -> GpuResult<()> {
        if pairs <= self.pair_capacity {
            return Ok(());
        }
        // Headroom so that a slowly growing mesh does not reallocate every iteration.
        let cap = pairs
            .saturating_add(pairs / 2)
            .max(self.pair_capacity.saturating_mul(2));
        let cap64 = u64::from(cap);
        ctx.check_binding("rasterizer pair gradients", f32_bytes(PAIR_GRADS * cap64))?;
        ctx.check_binding(
            "rasterizer pair part-logit gradients",
            f32_bytes(3 * u64::from(self.num_parts) * cap64),
        )?;
        self.sorter = RadixSort::new(ctx, cap)?;
        self.pair_face = ctx.storage_buffer_zeroed("raster.pair_face", f32_bytes(cap64))?;
        self.sorted_face = ctx.storage_buffer_zeroed("raster.sorted_face", f32_bytes(cap64))?;
        self.pair_slot = ctx.storage_buffer_zeroed("raster.pair_slot", f32_bytes(cap64))?;
        self.pair_grads =
            ctx.storage_buffer_zeroed("raster.pair_grads", f32_bytes(PAIR_GRADS * cap64))?;
        self.pair_logit_grads = ctx.storage_buffer_zeroed(
            "raster.pair_logit_grads",
            f32_bytes(3 * u64::from(self.num_parts) * cap64),
        )?;
        self.pair_capacity = cap;
        Ok(())
    }
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
                &state.pair_face,
                &state.sorted_face,
                &state.pair_slot,
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
                &state.sorted_face,
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
        self.backward.run(
            ctx,
            encoder,
            &[
                &state.params,
                &state.tile_ranges,
                &state.sorted_face,
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
                &state.pair_slot,
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

/// The uniform block for one view.
fn raster_params(
    camera: &Camera,
    settings: &RasterSettings,
    field: &GpuField,
    depth_bits: u32,
) -> RasterParams {
    let k = camera.intrinsics;
    let view: Mat4 = camera.world_to_camera();
    RasterParams {
        world_to_camera: view.to_cols_array_2d(),
        camera_position: camera.position().extend(1.0).into(),
        focal: [k.fx, k.fy, k.cx, k.cy],
        background: settings.background.extend(0.0).into(),
        width: k.width,
        height: k.height,
        tiles_x: k.width.div_ceil(TILE),
        tiles_y: k.height.div_ceil(TILE),
        num_faces: field.num_faces,
        num_vertices: field.num_vertices,
        num_parts: field.num_parts,
        sh_degree: settings.sh_degree.min(3),
        gamma: settings.gamma,
        opacity_floor: settings.opacity_floor.clamp(0.0, 1.0),
        alpha_min: settings.alpha_min,
        transmittance_min: settings.transmittance_min,
        near: settings.near,
        depth_bits,
        num_pairs: 0,
        _pad: 0,
    }
}
