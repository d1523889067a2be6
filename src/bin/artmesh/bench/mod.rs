//! `artmesh bench ...`: benchmarks that print machine-readable JSON (timings of GPU kernels on the
//! current adapter, and the fit's accuracy over a suite). They are not tests: nothing here asserts
//! a speed. One module per benchmark: its arguments, its measurement and its JSON report.

mod capture;
mod fit;
mod joints;
mod raster;
mod reconstruct;
mod sort;
mod source;
mod spread;

use std::process::ExitCode;

// The variants' doc comments are the benchmarks' help text. One is parsed per run, so the size
// difference between the variants costs nothing.
#[derive(clap::Subcommand)]
#[allow(clippy::large_enum_variant)]
pub enum Bench {
    /// Dataset capture throughput (frames/s: render, readback, PNG encoding) of a 7-part
    /// procedural cabinet.
    Capture(capture::CaptureBenchArgs),
    /// Rasterizer training iterations (forward + loss + backward + Adam) on a benchmark mesh:
    /// ms per iteration, pixel-face evaluations/s, model FLOP rate against an FMA peak probe.
    Raster(raster::RasterArgs),
    /// The reconstruction phase on the quick suite's objects (captured in memory): time per
    /// phase and state, mesh quality per part (pieces, boundary/non-manifold edges, cross-part
    /// faces, Chamfer to ground truth). Progress per object on stderr.
    Reconstruct(reconstruct::ReconstructBenchArgs),
    /// The whole fit (reconstruction + articulation) over a suite, scored against ground
    /// truth: per-object metrics and wall time, the paper-style tables by part count and by
    /// category (JSON on stdout; Markdown with --markdown), and with --ablations the paper's
    /// Table 4. The objects come from a suite folder (--suite-dir, as users hand datasets
    /// over) or, for CI-sized runs, are captured in memory at --size with --views.
    Fit(fit::FitBenchArgs),
    /// How far rounding-level changes move a fit's joints: the dataset fitted RUNS times, fit k
    /// with the reconstruction's SSIM weight scaled by 1 + k x STEP, each fit's joints against
    /// the unchanged fit's (axis angle, axis-line distance, motion). The yardstick for comparing
    /// fits on backends that round differently (native vs browser). Progress on stderr.
    Spread(spread::SpreadArgs),
    /// The joints the suite's full-resolution depth and part maps measure on their own (no
    /// reconstruction, no photometry), scored against ground truth (JSON; a line per object on
    /// stderr): what the fit's geometric stage starts from, in seconds per object.
    Joints(joints::JointsArgs),
    /// Radix-sort throughput (keys/s) on the current adapter.
    Sort(sort::SortArgs),
}

/// Runs one benchmark and prints its JSON report.
pub fn run(which: Bench) -> Result<ExitCode, String> {
    let json = match which {
        Bench::Capture(a) => capture::run(&a)?,
        Bench::Raster(a) => raster::run(&a)?,
        Bench::Reconstruct(a) => reconstruct::run(&a)?,
        Bench::Fit(a) => fit::run(&a)?,
        Bench::Spread(a) => spread::run(&a)?,
        Bench::Joints(a) => joints::run(&a)?,
        Bench::Sort(a) => sort::run(&a)?,
    };
    out!("{json}");
    Ok(ExitCode::SUCCESS)
}

/// Whether an object passes an `--objects` filter (empty: every object).
fn selected(only: &[String], id: &str) -> bool {
    only.is_empty() || only.iter().any(|o| id.contains(o.as_str()))
}

/// Median and minimum of `times` (NaN when empty); sorts them.
fn median_min(times: &mut [f64]) -> (f64, f64) {
    times.sort_by(f64::total_cmp);
    let median = times.get(times.len() / 2).copied().unwrap_or(f64::NAN);
    (median, times.first().copied().unwrap_or(f64::NAN))
}
