//! Exclusive prefix sum of u32 on the GPU (kernels in `shaders/scan.wgsl`).
//!
//! Reduce-then-scan: each level scans blocks of 1024 elements in place and writes the block
//! totals into the next level's buffer, until one block remains; the totals are then added back
//! top-down. The levels are planned once for a capacity; `encode` runs any length up to it.

use bytemuck::{Pod, Zeroable};

use super::kernel::{Binding, KernelFamily, compute_pass};
use super::{GpuContext, GpuError, GpuResult};

/// Elements per workgroup (`WG_SIZE * ITEMS` in the shader).
pub(crate) const SCAN_BLOCK: u32 = 1024;

/// Uniform block of `scan.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ScanParams {
    n: u32,
    num_blocks: u32,
    _pad: [u32; 2],
}
const _: () = assert!(size_of::<ScanParams>() == 16);

struct Level {
    params: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

/// An in-place exclusive prefix sum over a storage buffer of u32.
pub struct PrefixSum {
    scan_blocks: wgpu::ComputePipeline,
    add_block_offsets: wgpu::ComputePipeline,
    levels: Vec<Level>,
    /// `sums[l]` holds level l's block totals and is level l+1's data; the last holds the total.
    sums: Vec<wgpu::Buffer>,
    capacity: u32,
}

impl PrefixSum {
    /// Plans a scan over the first `capacity` u32 of `data` (which must hold that many).
    pub fn new(ctx: &GpuContext, data: &wgpu::Buffer, capacity: u32) -> GpuResult<Self> {
        let (family, [scan_blocks, add_block_offsets]) = KernelFamily::new(
            ctx,
            "prefix_sum",
            include_str!("../../shaders/scan.wgsl"),
            &[
                Binding::Uniform,
                Binding::StorageReadWrite,
                Binding::StorageReadWrite,
            ],
            ["scan_blocks", "add_block_offsets"],
        );
        let mut sums: Vec<wgpu::Buffer> = Vec::new();
        let mut levels = Vec::new();
        let mut len = capacity.max(1);
        loop {
            let blocks = len.div_ceil(SCAN_BLOCK);
            let block_sums =
                ctx.storage_buffer_zeroed("prefix_sum.block_sums", u64::from(blocks) * 4)?;
            let params = ctx.uniform_buffer("prefix_sum.params", &ScanParams::zeroed());
            let level_data = sums.last().unwrap_or(data);
            let bind_group = family.bind(ctx, &[&params, level_data, &block_sums]);
            levels.push(Level { params, bind_group });
            sums.push(block_sums);
            if blocks == 1 {
                break;
            }
            len = blocks;
        }
        Ok(Self {
            scan_blocks,
            add_block_offsets,
            levels,
            sums,
            capacity,
        })
    }

    /// The most elements one `encode` can scan.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// A one-element buffer holding the sum of all elements after the scan has run.
    pub fn total(&self) -> &wgpu::Buffer {
        // `new` always creates at least one level.
        &self.sums[self.sums.len() - 1]
    }

    /// Records the scan of the first `n` elements. Parameters go through `queue.write_buffer`,
    /// so encode one scan per plan per submission.
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        n: u32,
    ) -> GpuResult<()> {
        GpuError::check_capacity("prefix sum", n, self.capacity)?;
        let mut blocks = Vec::with_capacity(self.levels.len());
        let mut len = n;
        for level in &self.levels {
            let num_blocks = len.div_ceil(SCAN_BLOCK).max(1);
            let params = ScanParams {
                n: len,
                num_blocks,
                _pad: [0; 2],
            };
            ctx.queue
                .write_buffer(&level.params, 0, bytemuck::bytes_of(&params));
            blocks.push(num_blocks);
            len = num_blocks;
        }
        let mut pass = compute_pass(encoder, "prefix_sum");
        for (level, &num_blocks) in self.levels.iter().zip(&blocks) {
            ctx.dispatch(&mut pass, &self.scan_blocks, &level.bind_group, num_blocks);
        }
        for (level, &num_blocks) in self.levels.iter().zip(&blocks).rev() {
            if num_blocks > 1 {
                ctx.dispatch(
                    &mut pass,
                    &self.add_block_offsets,
                    &level.bind_group,
                    num_blocks,
                );
            }
        }
        Ok(())
    }
}
