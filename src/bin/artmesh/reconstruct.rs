//! `artmesh reconstruct`: the reconstruction phase alone, part meshes and a report written out.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use artmesh::data;
use artmesh::eval;
use artmesh::fit::observer::Progress;
use artmesh::fit::reconstruct::ReconstructionConfig;

use crate::args::{context, reconstruction_config, to_json};
use crate::output::NewFolder;
use crate::progress;

/// `artmesh reconstruct`'s arguments.
#[derive(clap::Args)]
pub struct ReconstructArgs {
    /// Dataset folder (ArtGS / MPArt-90 / PARIS layout, with depth and semantic maps).
    dataset: PathBuf,
    /// New folder to write.
    #[arg(long)]
    out: PathBuf,
    /// Budget: tiny (tests, seconds), fast (CPU demo, minutes), paper (20k iterations at full resolution).
    #[arg(long, default_value = "fast", value_parser = ["tiny", "fast", "paper"])]
    preset: String,
    /// part-aware (the paper) or global (ablation: one restricted Delaunay over all parts;
    /// the report counts the faces that cross parts).
    #[arg(long, default_value = "part-aware", value_parser = ["part-aware", "global"])]
    remesh: String,
    /// Override the preset's optimisation iterations per state.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    iterations: Option<u32>,
    /// Override the preset's largest image side (frames are downsampled by an integer factor; 0 = full size).
    #[arg(long)]
    max_size: Option<u32>,
    /// Override the preset's views per state (0 = all).
    #[arg(long)]
    max_views: Option<usize>,
}

/// `artmesh reconstruct`: the preset with the overrides, run on the dataset into a fresh folder.
pub fn run(args: &ReconstructArgs) -> Result<ExitCode, String> {
    let mut config = reconstruction_config(&args.preset, &args.remesh)?;
    if let Some(n) = args.iterations {
        config.fit.iterations = n;
    }
    config.max_size = args.max_size.unwrap_or(config.max_size);
    config.max_views = args.max_views.unwrap_or(config.max_views);
    let folder = NewFolder::create(&args.out)?;
    let report = reconstruct(&args.dataset, folder.path(), &config)?;
    let out = folder.finish()?;
    eprintln!("reconstruct: in {}", out.display());
    out!("{}", to_json(&report)?);
    Ok(ExitCode::SUCCESS)
}

/// Loads `root`, reconstructs it with `config` (a progress bar on stderr), writes the part
/// meshes and report.json under `out` and returns the report.
fn reconstruct(
    root: &Path,
    out: &Path,
    config: &ReconstructionConfig,
) -> Result<eval::ReconstructionReport, String> {
    let dataset = data::read_dataset(root).map_err(|e| e.to_string())?;
    let ctx = context()?;
    let mut bar = progress::Bar::new("reconstruct");
    let reconstruction = pollster::block_on(artmesh::fit::reconstruct::reconstruct(
        &ctx,
        &dataset,
        config,
        &mut |p: &Progress| bar.show(p),
    ))
    .map_err(|e| format!("{}: {e}", root.display()))?;
    bar.finish();
    let report = eval::reconstruction_report(
        &reconstruction,
        &dataset.gt_meshes,
        &eval::ChamferOptions::default(),
    );
    let mut files = reconstruction
        .as_ground_truth()
        .to_files()
        .map_err(|e| e.to_string())?;
    files.insert("report.json".into(), to_json(&report)?.into_bytes());
    data::write_dir(&files, out).map_err(|e| e.to_string())?;
    log_report(&report);
    eprintln!(
        "reconstruct: wrote {} files to {}",
        files.len(),
        out.display()
    );
    Ok(report)
}

/// Per state and part, what the report says, on stderr.
fn log_report(report: &eval::ReconstructionReport) {
    for s in &report.states {
        eprintln!(
            "reconstruct: {} state: PSNR {:.2} dB (optimised {:.2}, remeshed {:.2}), {} cross-part faces, {:.0} s",
            s.state.name(),
            s.psnr_recovered,
            s.psnr_optimised,
            s.psnr_remeshed,
            s.cross_part_faces,
            s.times.total_s
        );
        for p in &s.parts {
            let gt = p
                .gt_components
                .map(|n| format!(" (ground truth {n})"))
                .unwrap_or_default();
            let cd = p
                .chamfer
                .map(|c| format!(", Chamfer {:.1} mm / {:.3} peer", c.cd_mm, c.cd_peer))
                .unwrap_or_default();
            eprintln!(
                "reconstruct:   part {}: {} faces, {} piece(s){gt}, {} boundary / {} non-manifold edges{cd}",
                p.part, p.faces, p.components, p.boundary_edges, p.non_manifold_edges
            );
        }
    }
}
