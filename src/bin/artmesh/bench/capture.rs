//! `artmesh bench capture`: dataset capture throughput (render, readback, PNG encoding).

use std::time::Instant;

use artmesh::gpu::{AdapterReport, GpuContext};
use artmesh::render::{RenderSpec, render_dataset};
use artmesh::synth::{Category, SynthParams, generate};
use serde::Serialize;

use crate::args::{context, to_json};

/// `artmesh bench capture`'s arguments.
#[derive(clap::Args)]
pub struct CaptureBenchArgs {
    /// Square image sizes to time.
    #[arg(long, value_delimiter = ',', default_values_t = [200u32, 800])]
    sizes: Vec<u32>,
    /// Train views per state (frames = 2 x views).
    #[arg(long, default_value_t = 10)]
    views: usize,
}

/// The benchmark's JSON.
pub fn run(args: &CaptureBenchArgs) -> Result<String, String> {
    let ctx = context()?;
    to_json(&capture(&ctx, &args.sizes, args.views)?)
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
    let object = generate(&SynthParams {
        category: Category::StorageFurniture,
        movable_parts: Some(6),
        seed: 1,
    })
    .map_err(|e| e.to_string())?;
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
