//! `artmesh bench reconstruct`: the reconstruction phase on the quick suite's objects, captured in
//! memory: time per phase and state, mesh quality per part.

use std::time::Instant;

use artmesh::data::SensorModel;
use artmesh::eval::{ChamferOptions, ReconstructionReport, reconstruction_report};
use artmesh::fit::observer::Unobserved;
use artmesh::fit::reconstruct::{PhaseTimes, ReconstructionConfig, reconstruct};
use artmesh::gpu::{AdapterReport, GpuContext};
use artmesh::synth::suite_plan;
use serde::Serialize;

use super::source::capture_entry;
use crate::args::{SuiteObjects, context, reconstruction_config, to_json};
use crate::suite::CaptureSettings;

/// `artmesh bench reconstruct`'s arguments.
#[derive(clap::Args)]
pub struct ReconstructBenchArgs {
    #[command(flatten)]
    suite: SuiteObjects,
    /// part-aware or global remeshing.
    #[arg(long, default_value = "part-aware", value_parser = ["part-aware", "global"])]
    remesh: String,
}

/// The benchmark's JSON; a line per object on stderr.
pub fn run(args: &ReconstructBenchArgs) -> Result<String, String> {
    let s = &args.suite;
    let config = reconstruction_config(&s.preset, &args.remesh)?;
    let ctx = context()?;
    let report = reconstruct_suite(&ctx, &config, &s.objects, s.size, s.views, &mut log_object)?;
    to_json(&report)
}

/// One object's phases and parts, on stderr.
fn log_object(o: &ReconstructObject) {
    let parts: Vec<String> = o
        .report
        .states
        .iter()
        .map(|s| {
            let pieces: Vec<String> = s
                .parts
                .iter()
                .map(|p| {
                    format!(
                        "{}:{}f/{}c/cd {:.1}mm",
                        p.part,
                        p.faces,
                        p.components,
                        p.chamfer.map_or(f64::NAN, |c| c.cd_mm)
                    )
                })
                .collect();
            format!(
                "{} {:.1} dB cross {} [{}]",
                s.state.name(),
                s.psnr_recovered,
                s.cross_part_faces,
                pieces.join(" ")
            )
        })
        .collect();
    eprintln!(
        "bench reconstruct: {} ({} parts) {:.1} s  {}",
        o.id,
        o.parts,
        o.seconds,
        parts.join("  ")
    );
}

/// One object of `artmesh bench reconstruct`.
#[derive(Debug, Clone, Serialize)]
pub struct ReconstructObject {
    pub id: String,
    pub category: &'static str,
    pub parts: usize,
    pub seconds: f64,
    pub report: ReconstructionReport,
}

/// Time per phase summed over all objects and both states.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct PhaseTotals {
    pub seconds: PhaseTimes,
    /// The phase with the largest share, and that share.
    pub dominant: &'static str,
    pub dominant_share: f64,
}

/// `artmesh bench reconstruct` output.
#[derive(Debug, Clone, Serialize)]
pub struct ReconstructBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub preset: ReconstructionConfig,
    pub capture: CaptureSettings,
    pub phases: PhaseTotals,
    pub objects: Vec<ReconstructObject>,
}

/// Reconstructs the quick-suite objects (all, or those whose id contains one of `only`), each
/// captured in memory at `size`² with `views` training views per state, and times every phase.
pub fn reconstruct_suite(
    ctx: &GpuContext,
    config: &ReconstructionConfig,
    only: &[String],
    size: u32,
    views: usize,
    log: &mut dyn FnMut(&ReconstructObject),
) -> Result<ReconstructBench, String> {
    let mut objects = Vec::new();
    let mut totals = PhaseTotals::default();
    for entry in suite_plan(true) {
        let id = entry.id();
        if !super::selected(only, &id) {
            continue;
        }
        let dataset = capture_entry(ctx, &entry, size, views, 0)?;
        let start = Instant::now();
        let reconstruction =
            pollster::block_on(reconstruct(ctx, &dataset, config, &mut Unobserved))
                .map_err(|e| format!("{id}: {e}"))?;
        let seconds = start.elapsed().as_secs_f64();
        let report = reconstruction_report(
            &reconstruction,
            &dataset.gt_meshes,
            &ChamferOptions::default(),
        );
        for s in &report.states {
            totals.seconds.accumulate(&s.times);
        }
        let done = ReconstructObject {
            id,
            category: entry.category,
            parts: dataset.num_parts,
            seconds,
            report,
        };
        log(&done);
        objects.push(done);
    }
    (totals.dominant, totals.dominant_share) = totals.seconds.dominant();
    Ok(ReconstructBench {
        bench: "reconstruct",
        adapter: ctx.adapter.clone(),
        preset: *config,
        capture: CaptureSettings {
            size,
            train_views: views,
            sensor: SensorModel::Ideal,
        },
        phases: totals,
        objects,
    })
}
