//! Stable key–value radix sort of u32 pairs on the GPU (kernels in `shaders/radix_sort.wgsl`).
//!
//! Eight bits per pass; `key_bits` skips the passes a caller's keys cannot need (the rasterizer
//! packs (tile, depth) keys into fewer than 32 bits). Each pass counts digits per 1024-key block,
//! scans the digit-major histogram with [`PrefixSum`], and scatters stably. The sorter owns its
//! key and value buffers: producers write into [`RadixSort::keys`]/[`RadixSort::values`] and the
//! sorted result is found there again.

use bytemuck::{Pod, Zeroable};

use super::kernel::{Binding, KernelFamily, compute_pass};
use super::scan::PrefixSum;
use super::{GpuContext, GpuError, GpuResult};

const RADIX_BITS: u32 = 8;
const RADIX: u32 = 1 << RADIX_BITS;
const MAX_PASSES: usize = (32 / RADIX_BITS) as usize;
/// Keys per workgroup in `radix_sort.wgsl` (`BLOCK` = 256 invocations × 16 keys).
const SORT_BLOCK: u32 = 4096;

/// Uniform block of `radix_sort.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct SortParams {
    n: u32,
    num_blocks: u32,
    shift: u32,
    _pad: u32,
}
const _: () = assert!(size_of::<SortParams>() == 16);

/// The bits a key may use when sorted with `key_bits` significant bits (1..=32).
pub fn key_mask(key_bits: u32) -> u32 {
    u32::MAX >> (32 - key_bits.clamp(1, 32))
}

/// A GPU radix sorter for up to `capacity` (key, value) pairs.
pub struct RadixSort {
    count_digits: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    keys: [wgpu::Buffer; 2],
    values: [wgpu::Buffer; 2],
    scan: PrefixSum,
    params: Vec<wgpu::Buffer>,
    /// Pass p reads buffer p % 2 and writes the other one.
    bind_groups: Vec<wgpu::BindGroup>,
    capacity: u32,
}

impl RadixSort {
    /// Allocates buffers for `capacity` pairs; errors if they exceed the adapter's binding limit.
    pub fn new(ctx: &GpuContext, capacity: u32) -> GpuResult<Self> {
        let capacity = capacity.max(1);
        let bytes = u64::from(capacity) * 4;
        let keys = [
            ctx.storage_buffer_zeroed("radix_sort.keys", bytes)?,
            ctx.storage_buffer_zeroed("radix_sort.keys_alt", bytes)?,
        ];
        let values = [
            ctx.storage_buffer_zeroed("radix_sort.values", bytes)?,
            ctx.storage_buffer_zeroed("radix_sort.values_alt", bytes)?,
        ];
        let histogram_len = RADIX * capacity.div_ceil(SORT_BLOCK);
        let histogram =
            ctx.storage_buffer_zeroed("radix_sort.histogram", u64::from(histogram_len) * 4)?;
        let scan = PrefixSum::new(ctx, &histogram, histogram_len)?;

        let (family, [count_digits, scatter]) = KernelFamily::new(
            ctx,
            "radix_sort",
            include_str!("../../shaders/radix_sort.wgsl"),
            &[
                Binding::Uniform,
                Binding::StorageRead,
                Binding::StorageRead,
                Binding::StorageReadWrite,
                Binding::StorageReadWrite,
                Binding::StorageReadWrite,
            ],
            ["count_digits", "scatter"],
        );
        let params: Vec<_> = (0..MAX_PASSES)
            .map(|_| ctx.uniform_buffer("radix_sort.params", &SortParams::zeroed()))
            .collect();
        let bind_groups = params
            .iter()
            .enumerate()
            .map(|(pass, params)| {
                let (src, dst) = (pass % 2, 1 - pass % 2);
                family.bind(
                    ctx,
                    &[
                        params,
                        &keys[src],
                        &values[src],
                        &keys[dst],
                        &values[dst],
                        &histogram,
                    ],
                )
            })
            .collect();
        Ok(Self {
            count_digits,
            scatter,
            keys,
            values,
            scan,
            params,
            bind_groups,
            capacity,
        })
    }

    /// Keys to sort (u32 each); holds the sorted keys after [`RadixSort::encode`] has run.
    pub fn keys(&self) -> &wgpu::Buffer {
        &self.keys[0]
    }

    /// Values travelling with the keys; permuted alongside them.
    pub fn values(&self) -> &wgpu::Buffer {
        &self.values[0]
    }

    /// The most pairs one sort can take.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Records a stable sort of the first `n` pairs by the low `key_bits` bits of their keys
    /// (higher bits must be zero). Encode one sort per sorter per submission: parameters are
    /// written with `queue.write_buffer`.
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        n: u32,
        key_bits: u32,
    ) -> GpuResult<()> {
        GpuError::check_capacity("radix sort", n, self.capacity)?;
        if n <= 1 {
            return Ok(());
        }
        let passes = key_bits.clamp(1, 32).div_ceil(RADIX_BITS) as usize;
        let num_blocks = n.div_ceil(SORT_BLOCK);
        for pass in 0..passes {
            let params = SortParams {
                n,
                num_blocks,
                shift: pass as u32 * RADIX_BITS,
                _pad: 0,
            };
            ctx.queue
                .write_buffer(&self.params[pass], 0, bytemuck::bytes_of(&params));
            let bind_group = &self.bind_groups[pass];
            ctx.dispatch(
                &mut compute_pass(encoder, "radix_sort.count"),
                &self.count_digits,
                bind_group,
                num_blocks,
            );
            self.scan.encode(ctx, encoder, RADIX * num_blocks)?;
            ctx.dispatch(
                &mut compute_pass(encoder, "radix_sort.scatter"),
                &self.scatter,
                bind_group,
                num_blocks,
            );
        }
        // An odd number of passes leaves the result in the alternate buffers.
        if passes % 2 == 1 {
            let bytes = u64::from(n) * 4;
            encoder.copy_buffer_to_buffer(&self.keys[1], 0, &self.keys[0], 0, bytes);
            encoder.copy_buffer_to_buffer(&self.values[1], 0, &self.values[0], 0, bytes);
        }
        Ok(())
    }
}
