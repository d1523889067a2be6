//! Benchmarks (native only): machine-readable timings of GPU kernels on the current adapter.
//! They are not tests: nothing here asserts a speed; `artmesh bench ...` prints the JSON.

use std::time::Instant;

use serde::Serialize;

use crate::gpu::{AdapterReport, GpuContext, GpuResult, RadixSort, key_mask};
use crate::rng::Rng;

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
        times.sort_by(f64::total_cmp);
        let median_ms = times.get(times.len() / 2).copied().unwrap_or(f64::NAN);
        results.push(SortTiming {
            n,
            key_bits,
            repeats,
            median_ms,
            min_ms: times.first().copied().unwrap_or(f64::NAN),
            keys_per_second: f64::from(n) / (median_ms / 1e3),
        });
    }
    Ok(SortBench {
        bench: "radix_sort",
        adapter: ctx.adapter.clone(),
        results,
    })
}

/// Capture throughput of one image size.
#[derive(Debug, Clone, Serialize)]
pub struct CaptureTiming {
    pub width: u32,
    pub height: u32,
    pub object: String,
    pub triangles: usize,
    pub frames: usize,
    /// Wall time of the whole capture: render, readback and PNG encoding of every frame, ground truth.
    pub total_ms: f64,
    pub frames_per_second: f64,
    /// Bytes of the encoded dataset.
    pub bytes: usize,
}

/// `artmesh bench capture` output.
#[derive(Debug, Clone, Serialize)]
pub struct CaptureBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub results: Vec<CaptureTiming>,
}

/// Times `render_dataset` of one procedural object (StorageFurniture, 6 movable parts) at each size, with
/// `views` train views and no test views per state, the files kept in memory.
pub fn capture(ctx: &GpuContext, sizes: &[u32], views: usize) -> Result<CaptureBench, String> {
    use crate::render::{RenderSpec, render_dataset};
    use crate::synth::{Category, SynthParams, generate};
    let object = generate(&SynthParams {
        category: Category::StorageFurniture,
        movable_parts: Some(6),
        seed: 1,
    })?;
    let triangles = (0..object.links.len())
        .flat_map(|l| object.link_meshes(l))
        .map(|m| m.indices.len())
        .sum();
    let mut results = Vec::new();
    for &size in sizes {
        let spec = RenderSpec {
            width: size,
            height: size,
            train_views: views,
            test_views: 0,
            ..RenderSpec::default()
        };
        let mut bytes = 0;
        let start = Instant::now();
        let done = pollster::block_on(render_dataset(
            ctx,
            &object,
            &spec,
            &mut |files| {
                bytes += files.values().map(Vec::len).sum::<usize>();
                Ok(())
            },
            &mut |_| {},
        ))
        .map_err(|e| e.to_string())?;
        let total_ms = start.elapsed().as_secs_f64() * 1e3;
        results.push(CaptureTiming {
            width: size,
            height: size,
            object: object.name.clone(),
            triangles,
            frames: done.frames,
            total_ms,
            frames_per_second: done.frames as f64 / (total_ms / 1e3),
            bytes,
        });
    }
    Ok(CaptureBench {
        bench: "capture",
        adapter: ctx.adapter.clone(),
        results,
    })
}
