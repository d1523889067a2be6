//! The rasterizer's working state: per-image-size and per-field GPU buffers (grown on demand),
//! the optional per-stage clock, and the read-backs of images, face statistics and work counts.

use bytemuck::Zeroable;
use glam::Vec3;

use super::kernels::{CORNER_GRADS, FACE_RECORD_BYTES, PAIR_GRADS, RasterParams, TILE};
use super::settings::{BASE_CHANNELS, sort_key_bits};
use crate::gpu::{GpuContext, GpuError, GpuResult, PrefixSum, RadixSort};

/// Work done by one forward + backward pass (see [`RasterState::read_work`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct WorkCounts {
    /// Per-pixel face evaluations of the forward compositing loop.
    pub forward_evaluations: u64,
    /// Per-pixel face evaluations of the backward replay.
    pub backward_evaluations: u64,
    /// Contributions with α ≥ alpha_min.
    pub hits: u64,
}

/// Rendered planes read back to the CPU (see [`RasterState::read_render`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RenderImages {
    /// Image width (pixels).
    pub width: u32,
    /// Image height (pixels).
    pub height: u32,
    /// Part-logit planes after the base ones.
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
    pub(super) fn start(&mut self) {
        self.last = crate::gpu::now_seconds();
    }

    /// Submits what `encoder` holds, waits, and books the time since the last lap on `stage`.
    /// In the browser the wait is not possible: there the times only mark submissions.
    pub(super) fn lap(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        stage: &'static str,
    ) {
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

/// Per-image-size and per-field working buffers, grown on demand.
pub struct RasterState {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) num_parts: u32,
    pub(super) params: wgpu::Buffer,
    pub(super) last_params: RasterParams,
    /// Planar output: `5 + P` planes plus the per-pixel consumed-entry count (u32 bits).
    pub(super) render: wgpu::Buffer,
    /// dL/d(output), `5 + P` planes: written by the loss, read by the backward pass.
    pub(super) grad_render: wgpu::Buffer,
    pub(super) tile_ranges: wgpu::Buffer,
    face_capacity: u32,
    pub(super) records: wgpu::Buffer,
    /// Tile counts per face (+1 trailing zero), scanned in place into emission offsets.
    pub(super) offsets: wgpu::Buffer,
    pub(super) scan: PrefixSum,
    pub(super) corner_grads: wgpu::Buffer,
    pub(super) face_stats: wgpu::Buffer,
    pair_capacity: u32,
    pub(super) sorter: RadixSort,
    /// Per emitted pair: face, coverage mask (two words), 0.
    pub(super) pair_info: wgpu::Buffer,
    /// `pair_info` in sorted order.
    pub(super) sorted_info: wgpu::Buffer,
    pub(super) pair_grads: wgpu::Buffer,
    pub(super) pair_logit_grads: wgpu::Buffer,
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
            pair_info: ctx.storage_buffer_zeroed(
                "raster.pair_info",
                f32_bytes(4 * u64::from(pair_capacity)),
            )?,
            sorted_info: ctx.storage_buffer_zeroed(
                "raster.sorted_info",
                f32_bytes(4 * u64::from(pair_capacity)),
            )?,
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

    /// dL/d(render), `5 + P` planes; the loss writes it before the rasterizer's backward pass.
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
    pub(crate) async fn read_face_stats(
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
    /// the forward and backward compositing loops (a pixel evaluates the listed faces whose
    /// coverage mask holds it), and the hits (contributions with α ≥ alpha_min) as the face
    /// statistics recorded them since they were last cleared.
    pub async fn read_work(&self, ctx: &GpuContext, faces: u32) -> GpuResult<WorkCounts> {
        let tiles_x = self.width.div_ceil(TILE);
        let tiles = (tiles_x * self.height.div_ceil(TILE)) as usize;
        let ranges: Vec<u32> = ctx.read_buffer(&self.tile_ranges, 2 * tiles).await?;
        let pairs = self.last_params.num_pairs as usize;
        let info: Vec<u32> = ctx.read_buffer(&self.sorted_info, 4 * pairs).await?;
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
                let (start, end) = (ranges[2 * tile] as usize, ranges[2 * tile + 1] as usize);
                let bit = (y % TILE) * TILE + x % TILE;
                let i = (y * self.width + x) as usize;
                let used = consumed[i] as usize;
                // A saturated pixel stops at its last contributor; the others scan the whole list.
                let saturated = 1.0 - render.plane(4)[i] < t_min;
                for j in start..end.min(pairs) {
                    let word = info[4 * j + 1 + (bit / 32) as usize];
                    if word >> (bit % 32) & 1 == 0 {
                        continue;
                    }
                    let entry = j - start;
                    forward += u64::from(!saturated || entry < used);
                    backward += u64::from(entry < used);
                }
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

    pub(super) fn ensure_faces(&mut self, ctx: &GpuContext, faces: u32) -> GpuResult<()> {
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

    pub(super) fn ensure_pairs(&mut self, ctx: &GpuContext, pairs: u32) -> GpuResult<()> {
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
        self.pair_info = ctx.storage_buffer_zeroed("raster.pair_info", f32_bytes(4 * cap64))?;
        self.sorted_info = ctx.storage_buffer_zeroed("raster.sorted_info", f32_bytes(4 * cap64))?;
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
