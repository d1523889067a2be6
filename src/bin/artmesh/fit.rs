//! `artmesh fit`: the whole fit of a dataset (reconstruction and articulation), written as a fit
//! folder (joints, part meshes, report, the twin); `demo` writes its fit the same way.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use artmesh::data;
use artmesh::export::FitFolder;
use artmesh::fit::articulate::{Ablation, GeometryUse};
use artmesh::fit::object::FitConfig;
use artmesh::fit::observer::Progress;
use artmesh::fit::reconstruct::RemeshMode;
use artmesh::pipeline::{self, FitInput};

use crate::args::{BudgetArgs, ReadArgs, context, to_json};
use crate::output::NewFolder;
use crate::progress;

/// `artmesh fit`'s arguments.
#[derive(clap::Args)]
pub struct FitArgs {
    /// Dataset folder (ArtGS / MPArt-90 / PARIS layout, with depth and semantic maps).
    dataset: PathBuf,
    /// New folder to write.
    #[arg(long)]
    out: PathBuf,
    /// Budget: tiny (tests, seconds), fast (CPU demo, minutes), paper (the paper's 20k + 20k iterations).
    #[arg(long, default_value = "fast", value_parser = ["tiny", "fast", "paper"])]
    preset: String,
    /// Articulation ablation: full, no-vertex-color, no-vertex-opacity or no-backward.
    #[arg(long, default_value = "full", value_parser = ["full", "no-vertex-color", "no-vertex-opacity", "no-backward"])]
    ablation: String,
    /// part-aware (the paper) or global remeshing (ablation).
    #[arg(long, default_value = "part-aware", value_parser = ["part-aware", "global"])]
    remesh: String,
    /// How the joints use the dataset's full-resolution depth and part maps: settle (joints
    /// the measurements settle skip the photometric stages), seed (they seed every part's
    /// photometric stages), off (the paper's method) [default: settle; off for paper].
    #[arg(long, value_parser = ["off", "seed", "settle"])]
    geometry: Option<String>,
    #[command(flatten)]
    budget: BudgetArgs,
    #[command(flatten)]
    read: ReadArgs,
}

/// `artmesh fit`: the preset with the options, fitted to the dataset into a fresh folder.
pub fn run(args: FitArgs) -> Result<ExitCode, String> {
    let mut config = args.budget.fit_config(&args.preset)?;
    if args.remesh == "global" {
        config.reconstruction.remesh = RemeshMode::Global;
    }
    config.articulation.ablation = Ablation::parse(&args.ablation).map_err(|e| e.to_string())?;
    if let Some(g) = args.geometry {
        config.articulation.geometry = GeometryUse::parse(&g).map_err(|e| e.to_string())?;
    }
    let folder = NewFolder::create(&args.out)?;
    let input =
        pipeline::read_dataset(&args.dataset, &args.read.limits()).map_err(|e| e.to_string())?;
    let report = fit_and_write(&input, &config, folder.path(), &args.out)?;
    folder.finish()?;
    out!("{}", to_json(&report)?);
    Ok(ExitCode::SUCCESS)
}

/// Fits `dataset` with a progress bar on stderr, writes joints.json, gt/ and report.json
/// under `out` (a fresh folder, which will be `shown` when the command finishes), prints the
/// joints and metrics, and returns the report.
pub fn fit_and_write(
    input: &FitInput,
    config: &FitConfig,
    out: &Path,
    shown: &Path,
) -> Result<serde_json::Value, String> {
    let ctx = context()?;
    let mut bar = progress::Bar::new("fit");
    let run = pollster::block_on(pipeline::fit_and_export(
        &ctx,
        input,
        config,
        &mut |p: &Progress| bar.show(p),
    ))
    .map_err(|e| e.to_string())?;
    bar.finish();
    for w in &run.fit.articulation.warnings {
        eprintln!("fit: warning: {w}");
    }
    let (folder, seconds) = (run.folder, run.seconds);
    log_folder(&folder);
    let meshes = folder.files.keys().filter(|p| p.ends_with(".ply")).count();
    pipeline::write_fit_folder(&folder, out).map_err(|e| e.to_string())?;
    eprintln!(
        "fit: {seconds:.0} s; wrote joints.json, report.json, gt/ ({meshes} part meshes), the twin as {} \
         (+ meshes), {} and {} (all of it for download) to {}",
        artmesh::export::URDF_FILE,
        artmesh::export::GLB_FILE,
        artmesh::export::ZIP_FILE,
        shown.display()
    );
    Ok(folder.report)
}

/// The fitted joints and, with ground truth, the paper's metrics, on stderr.
fn log_folder(folder: &FitFolder) {
    for j in &folder.joints {
        let unit = if j.kind == data::JointKind::Revolute {
            "°"
        } else {
            " m"
        };
        let registered = match j.axis_registration {
            Some(r) if r.applied => {
                format!(", registered along the axis from {:.3}{unit}", r.fitted)
            }
            _ => String::new(),
        };
        eprintln!(
            "fit: part {}: {:?} joint, axis {:.3?} through {:.3?}, motion {:.3}{unit}{registered} (bake-off losses {:.4?})",
            j.part, j.kind, j.direction, j.origin, j.motion, j.bake_off
        );
    }
    if let Some(m) = &folder.metrics {
        let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
        eprintln!(
            "fit: against the ground truth: Axis Ang {} °, Axis Pos {} (0.1 m), Part Motion {}, CD-s {} ({} mm), CD-m {} ({} mm), joint types {}/{} right",
            f(m.axis_ang),
            f(m.axis_pos),
            f(m.part_motion),
            f(m.cd_s.map(|c| c.cd_peer)),
            f(m.cd_s.map(|c| c.cd_mm)),
            f(m.cd_m.map(|c| c.cd_peer)),
            f(m.cd_m.map(|c| c.cd_mm)),
            m.joints.len() - m.type_errors,
            m.joints.len() + m.unmatched_gt.len()
        );
    }
}
