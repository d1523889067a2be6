//! `artmesh bench sort`: radix-sort throughput (keys/s) on the current adapter.

use std::time::Instant;

use artmesh::gpu::{AdapterReport, GpuContext, GpuResult, RadixSort, key_mask};
use artmesh::rng::Rng;
use serde::Serialize;

use crate::args::{context, to_json};

/// `artmesh bench sort`'s arguments.
#[derive(clap::Args)]
pub struct SortArgs {
    /// Key counts to time.
    #[arg(long, value_delimiter = ',', default_values_t = [1_000_000u32, 4_194_304])]
    sizes: Vec<u32>,
    /// Significant key bits (passes = ceil(bits / 8)).
    #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..=32))]
    key_bits: u32,
    /// Timed runs per size (after one warm-up run).
    #[arg(long, default_value_t = 5)]
    repeats: usize,
}

/// The benchmark's JSON.
pub fn run(args: &SortArgs) -> Result<String, String> {
    let ctx = context()?;
    let report = sort(&ctx, &args.sizes, args.key_bits, args.repeats).map_err(|e| e.to_string())?;
    to_json(&report)
}

/// Throughput of one sort size.
#[derive(Debug, Clone, Serialize)]
pub struct SortTiming {
    pub n: u32,
    pub key_bits: u32,
    pub repeats: usize,
    /// Median wall time of encode + submit + wait, excluding the upload of the keys.
    pub median_ms: f64,
    pub min_ms: f64,
    pub keys_per_second: f64,
}

/// `artmesh bench sort` output.
#[derive(Debug, Clone, Serialize)]
pub struct SortBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub results: Vec<SortTiming>,
}

/// Times the radix sort on random 32-bit keys for each size (one warm-up run each).
pub fn sort(
    ctx: &GpuContext,
    sizes: &[u32],
    key_bits: u32,
    repeats: usize,
) -> GpuResult<SortBench> {
    let mut results = Vec::new();
    for &n in sizes {
        let mut rng = Rng::new(u64::from(n));
        let mask = key_mask(key_bits);
        let keys: Vec<u32> = (0..n).map(|_| rng.next_u32() & mask).collect();
        let values: Vec<u32> = (0..n).collect();
        let sorter = RadixSort::new(ctx, n)?;
        let mut times = Vec::with_capacity(repeats);
        for run in 0..=repeats {
            ctx.queue
                .write_buffer(sorter.keys(), 0, bytemuck::cast_slice(&keys));
            ctx.queue
                .write_buffer(sorter.values(), 0, bytemuck::cast_slice(&values));
            ctx.queue.submit([]);
            ctx.poll_wait()?;
            let start = Instant::now();
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            sorter.encode(ctx, &mut encoder, n, key_bits)?;
            ctx.queue.submit([encoder.finish()]);
            ctx.poll_wait()?;
            ctx.check()?;
            if run > 0 {
                times.push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        let (median_ms, min_ms) = super::median_min(&mut times);
        results.push(SortTiming {
            n,
            key_bits,
            repeats,
            median_ms,
            min_ms,
            keys_per_second: f64::from(n) / (median_ms / 1e3),
        });
    }
    Ok(SortBench {
        bench: "radix_sort",
        adapter: ctx.adapter.clone(),
        results,
    })
}
