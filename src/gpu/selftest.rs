//! GPU self-test: runs the prefix sum and the radix sort on seeded random data and compares
//! them with CPU results. The web page, `artmesh gpu` and the tests (native and browser) all
//! call this, so what a user sees and what CI checks is the same code.

use serde::Serialize;

use super::{GpuContext, GpuResult, PrefixSum, RadixSort, key_mask};
use crate::rng::Rng;

/// Sizes the self-test covers by default: tiny, block edges, non-powers of two, ~1M.
pub const DEFAULT_SIZES: &[u32] = &[1, 2, 3, 255, 256, 1023, 1024, 1025, 4097, 65_537, 1_000_003];

/// Outcome of one primitive on one input size.
#[derive(Debug, Clone, Serialize)]
pub struct PrimitiveCheck {
    pub kernel: &'static str,
    pub n: u32,
    pub key_bits: u32,
    /// Elements that differ from the CPU result (keys and values both count for the sort).
    pub mismatches: usize,
    pub first_mismatch: Option<usize>,
}

impl PrimitiveCheck {
    pub fn passed(&self) -> bool {
        self.mismatches == 0
    }
}

/// The whole self-test: the adapter and each check.
#[derive(Debug, Clone, Serialize)]
pub struct SelfTestReport {
    pub adapter: super::AdapterReport,
    pub checks: Vec<PrimitiveCheck>,
}

impl SelfTestReport {
    pub fn passed(&self) -> bool {
        self.checks.iter().all(PrimitiveCheck::passed)
    }
}

/// Runs both primitives for every size (sort with full 32-bit keys and with 20-bit keys).
pub async fn run(ctx: &GpuContext, sizes: &[u32]) -> GpuResult<SelfTestReport> {
    let mut checks = Vec::new();
    for (i, &n) in sizes.iter().enumerate() {
        let seed = 0x5eed + i as u64;
        checks.push(check_prefix_sum(ctx, n, seed).await?);
        checks.push(check_radix_sort(ctx, n, 32, seed).await?);
        checks.push(check_radix_sort(ctx, n, 20, seed).await?);
    }
    Ok(SelfTestReport {
        adapter: ctx.adapter.clone(),
        checks,
    })
}

/// Exclusive prefix sum of `n` random values in 0..256 against the CPU.
pub async fn check_prefix_sum(ctx: &GpuContext, n: u32, seed: u64) -> GpuResult<PrimitiveCheck> {
    let mut rng = Rng::new(seed);
    let input: Vec<u32> = (0..n).map(|_| rng.below(256)).collect();
    let data = ctx.storage_buffer("selftest.scan", &input)?;
    let scan = PrefixSum::new(ctx, &data, n)?;
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    scan.encode(ctx, &mut encoder, n)?;
    ctx.queue.submit([encoder.finish()]);
    let gpu: Vec<u32> = ctx.read_buffer(&data, n as usize).await?;
    let total: Vec<u32> = ctx.read_buffer(scan.total(), 1).await?;

    let mut expected = Vec::with_capacity(input.len() + 1);
    let mut sum = 0u32;
    for &x in &input {
        expected.push(sum);
        sum = sum.wrapping_add(x);
    }
    let mut got = gpu;
    got.push(total.first().copied().unwrap_or(u32::MAX));
    expected.push(sum);
    Ok(compare("prefix_sum", n, 0, &got, &expected))
}

/// Stable sort of `n` random keys (half of them repeats, to exercise stability) carrying their
/// original index as value, against the CPU's stable sort.
pub async fn check_radix_sort(
    ctx: &GpuContext,
    n: u32,
    key_bits: u32,
    seed: u64,
) -> GpuResult<PrimitiveCheck> {
    let mut rng = Rng::new(seed);
    let mask = key_mask(key_bits);
    let mut keys: Vec<u32> = Vec::with_capacity(n as usize);
    for i in 0..n as usize {
        let key = if i > 0 && rng.below(2) == 0 {
            keys[rng.below(i as u32) as usize]
        } else {
            rng.next_u32() & mask
        };
        keys.push(key);
    }
    let values: Vec<u32> = (0..n).collect();

    let sorter = RadixSort::new(ctx, n)?;
    ctx.queue
        .write_buffer(sorter.keys(), 0, bytemuck::cast_slice(&keys));
    ctx.queue
        .write_buffer(sorter.values(), 0, bytemuck::cast_slice(&values));
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    sorter.encode(ctx, &mut encoder, n, key_bits)?;
    ctx.queue.submit([encoder.finish()]);
    let mut got: Vec<u32> = ctx.read_buffer(sorter.keys(), n as usize).await?;
    got.extend(ctx.read_buffer::<u32>(sorter.values(), n as usize).await?);

    let mut pairs: Vec<(u32, u32)> = keys.into_iter().zip(values).collect();
    pairs.sort_by_key(|&(key, _)| key);
    let mut expected: Vec<u32> = pairs.iter().map(|p| p.0).collect();
    expected.extend(pairs.iter().map(|p| p.1));
    Ok(compare("radix_sort", n, key_bits, &got, &expected))
}

fn compare(
    kernel: &'static str,
    n: u32,
    key_bits: u32,
    got: &[u32],
    expected: &[u32],
) -> PrimitiveCheck {
    let mut mismatches = got.len().abs_diff(expected.len());
    let mut first_mismatch = (mismatches > 0).then_some(got.len().min(expected.len()));
    for (i, (a, b)) in got.iter().zip(expected).enumerate() {
        if a != b {
            mismatches += 1;
            first_mismatch = Some(first_mismatch.map_or(i, |f| f.min(i)));
        }
    }
    PrimitiveCheck {
        kernel,
        n,
        key_bits,
        mismatches,
        first_mismatch,
    }
}
