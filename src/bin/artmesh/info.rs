//! `artmesh info`, `gpu` and `sample`: look at a dataset or the GPU, or write the sample dataset.

use std::path::PathBuf;
use std::process::ExitCode;

use artmesh::data::{self, Dataset, fixture};
use artmesh::gpu::selftest;

use crate::args::{ReadArgs, context, to_json};
use crate::output::NewFolder;

/// `artmesh info`'s arguments.
#[derive(clap::Args)]
pub struct InfoArgs {
    /// Dataset folder in the ArtGS / MPArt-90 / PARIS layout (transforms_*_{start,end}.json, ...).
    dataset: PathBuf,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    read: ReadArgs,
}

/// `artmesh gpu`'s arguments.
#[derive(clap::Args)]
pub struct GpuArgs {
    /// Largest input size for the self-test.
    #[arg(long, default_value_t = 1_000_003)]
    max_size: u32,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// `artmesh sample`'s arguments.
#[derive(clap::Args)]
pub struct SampleArgs {
    /// Folder to create; existing files are never overwritten.
    #[arg(long)]
    out: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(8..=4096))]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 48, value_parser = clap::value_parser!(u32).range(8..=4096))]
    height: u32,
    /// Train views per state.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u16).range(1..=1000))]
    views: u16,
    /// Movable parts (revolute and prismatic alternate).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=15))]
    parts: u8,
}

/// `artmesh info`: the dataset's summary, or every problem found (and failure).
pub fn info(args: &InfoArgs) -> Result<ExitCode, String> {
    let root = &args.dataset;
    let files = data::read_dataset_files(root).map_err(|e| e.to_string())?;
    match Dataset::from_files_within(&files, &args.read.limits()) {
        Ok(dataset) => {
            if let Some(refusal) = artmesh::pipeline::check::fit_refusal(&dataset) {
                eprintln!("{}: {refusal}", root.display());
                return Ok(ExitCode::FAILURE);
            }
            let summary = dataset.summary();
            if args.json {
                out!("{}", to_json(&summary)?);
            } else {
                out!("{}\n{summary}", root.display());
            }
            Ok(ExitCode::SUCCESS)
        }
        Err(problems) => {
            eprintln!("{}: {} problem(s) found:", root.display(), problems.0.len());
            eprintln!("{problems}");
            Ok(ExitCode::FAILURE)
        }
    }
}

/// `artmesh gpu`: the adapter and the self-test of the GPU primitives (failure on a mismatch).
pub fn gpu(args: &GpuArgs) -> Result<ExitCode, String> {
    let ctx = context()?;
    let sizes: Vec<u32> = selftest::DEFAULT_SIZES
        .iter()
        .copied()
        .filter(|&n| n <= args.max_size)
        .collect();
    let report = pollster::block_on(selftest::run(&ctx, &sizes)).map_err(|e| e.to_string())?;
    if args.json {
        out!("{}", to_json(&report)?);
    } else {
        let a = &report.adapter;
        out!(
            "adapter: {} ({}, {}, driver {})",
            a.name,
            a.backend,
            a.device_type,
            a.driver
        );
        out!(
            "limits: storage binding {} MiB, {} workgroups per dimension",
            a.max_storage_buffer_binding_size >> 20,
            a.max_compute_workgroups_per_dimension
        );
        for c in &report.checks {
            let verdict = if c.passed() { "ok" } else { "MISMATCH" };
            let bits = if c.key_bits > 0 {
                format!("{}-bit keys", c.key_bits)
            } else {
                String::new()
            };
            out!("{:>10}  n = {:<9} {bits:<12} {verdict}", c.kernel, c.n);
        }
    }
    Ok(if report.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// `artmesh sample`: the built-in sample dataset into a new folder.
pub fn sample(args: &SampleArgs) -> Result<ExitCode, String> {
    let params = fixture::FixtureParams {
        width: args.width,
        height: args.height,
        train_views: args.views.into(),
        test_views: usize::from(args.views).div_ceil(4),
        movable_parts: args.parts.into(),
        ..Default::default()
    };
    let files = fixture::small_dataset(params)
        .to_files()
        .map_err(|e| e.to_string())?;
    let folder = NewFolder::create(&args.out)?;
    data::write_dir(&files, folder.path()).map_err(|e| e.to_string())?;
    let out = folder.finish()?;
    out!("wrote {} files to {}", files.len(), out.display());
    Ok(ExitCode::SUCCESS)
}
