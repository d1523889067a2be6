//! `artmesh eval`: predicted joints and part meshes scored against ground truth, one object or a
//! whole suite with the paper's tables.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use artmesh::data::{self, GroundTruth, State};
use artmesh::eval;

use crate::args::to_json;
use crate::suite::read_suite_listing;

/// `artmesh eval`'s arguments.
#[derive(clap::Args)]
pub struct EvalArgs {
    /// Prediction: a folder laid out like a dataset's gt/ folder (trans.json,
    /// {start,end}/{state}_static_rotate.ply, {state}_dynamic_{i}_rotate.ply), or one that contains gt/;
    /// for a suite, a folder with one such folder per object id.
    pred: PathBuf,
    /// Ground truth: a dataset folder (its gt/ is used) or a gt/ folder; or a suite folder.
    gt: PathBuf,
    /// For a suite: print the two tables as Markdown instead of JSON.
    #[arg(long)]
    markdown: bool,
    /// State whose part meshes are compared (the paper reports the start state).
    #[arg(long, default_value = "start", value_parser = ["start", "end"])]
    state: String,
    /// Object name written in the report (default: the ground-truth folder's name).
    #[arg(long)]
    id: Option<String>,
    /// Object category written in the report.
    #[arg(long, default_value = "unknown")]
    category: String,
    /// Area-weighted surface samples per mesh for the Chamfer distances.
    #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    samples: u32,
}

/// `artmesh eval`: one object's report, or (GT holds suite.json) the whole suite's.
pub fn run(args: EvalArgs) -> Result<ExitCode, String> {
    let EvalArgs {
        pred,
        gt,
        markdown,
        state,
        id,
        category,
        samples,
    } = args;
    let state = if state == "end" {
        State::End
    } else {
        State::Start
    };
    if gt.join("suite.json").is_file() {
        return evaluate_suite(&pred, &gt, state, samples, markdown);
    }
    let id = id.unwrap_or_else(|| folder_name(&gt));
    let report = evaluate(&pred, &gt, state, &id, &category, samples)?;
    out!("{}", to_json(&report)?);
    Ok(ExitCode::SUCCESS)
}

/// Reads a gt/-style folder (or a folder containing gt/) as [`GroundTruth`].
fn read_ground_truth(root: &Path) -> Result<GroundTruth, String> {
    let files = data::read_dir(root).map_err(|e| e.to_string())?;
    let files = if files.keys().any(|k| k.starts_with("gt/")) {
        files
    } else {
        files
            .into_iter()
            .map(|(k, v)| (format!("gt/{k}"), v))
            .collect()
    };
    GroundTruth::from_files(&files).map_err(|e| format!("{}:\n{e}", root.display()))
}

/// Scores one prediction folder against one ground-truth folder.
fn evaluate(
    pred: &Path,
    gt: &Path,
    state: State,
    id: &str,
    category: &str,
    samples: u32,
) -> Result<eval::ObjectMetrics, String> {
    let (pred, gt_data) = (read_ground_truth(pred)?, read_ground_truth(gt)?);
    let (Some(pred_joints), Some(gt_joints)) = (&pred.joints, &gt_data.joints) else {
        return Err("both the prediction and the ground truth need joints (trans.json)".into());
    };
    let meshes = match (&pred.meshes[state.index()], &gt_data.meshes[state.index()]) {
        (Some(p), Some(g)) => Some((p, g)),
        _ => {
            eprintln!("artmesh: no {state} part meshes on both sides: joint metrics only");
            None
        }
    };
    let options = eval::EvalOptions {
        chamfer: eval::ChamferOptions {
            samples: samples as usize,
            ..Default::default()
        },
    };
    eval::evaluate_object(id, category, pred_joints, gt_joints, meshes, &options)
        .map_err(|e| e.to_string())
}

/// Scores every object of a suite and prints the per-object reports and both benchmark tables.
fn evaluate_suite(
    pred: &Path,
    gt: &Path,
    state: State,
    samples: u32,
    markdown: bool,
) -> Result<ExitCode, String> {
    let listing = read_suite_listing(gt)?;
    let mut reports = Vec::with_capacity(listing.objects.len());
    for (id, category) in &listing.objects {
        let report = evaluate(&pred.join(id), &gt.join(id), state, id, category, samples)
            .map_err(|e| format!("{id}: {e}"))?;
        reports.push(report);
    }
    let by_parts = eval::BenchmarkTable::by_part_count(&reports);
    let by_category = eval::BenchmarkTable::by_category(&reports);
    if markdown {
        out!(
            "By part count (the paper's Table 1)\n\n{}",
            by_parts.to_markdown()
        );
        out!(
            "By category (the paper's appendix table)\n\n{}",
            by_category.to_markdown()
        );
    } else {
        let json = serde_json::json!({
            "objects": reports,
            "by_part_count": by_parts,
            "by_category": by_category,
        });
        out!("{}", to_json(&json)?);
    }
    Ok(ExitCode::SUCCESS)
}

/// The last component of `path` (the whole path when it has none).
fn folder_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}
