//! Everything one fit leaves behind, as files: what `artmesh fit` writes to its folder and what
//! the page offers for download. One builder serves both, so the two always agree.

use serde::Serialize;

use super::joints::{JointRecord, joint_records};
use super::twin::NoStartState;
use super::{JOINTS_FILE, Twin, export_twin};
use crate::data::{DataError, Dataset, FileSet};
use crate::eval::{
    ChamferOptions, EvalError, EvalOptions, ObjectMetrics, evaluate_fit, reconstruction_report,
};
use crate::fit::object::{FitConfig, ObjectFit};

/// The fit report's path in a fit folder.
pub const REPORT_FILE: &str = "report.json";

/// A fit's results and its folder's files.
#[derive(Debug, Clone)]
pub struct FitFolder {
    /// `report.json`: the configuration, joints, warnings, curves, reconstruction quality and,
    /// with ground truth, the metrics and the true joints (`truth`).
    pub report: serde_json::Value,
    pub joints: Vec<JointRecord>,
    /// The scores against the dataset's ground truth, when it has GT joints.
    pub metrics: Option<ObjectMetrics>,
    /// `joints.json`, `report.json`, the predicted `gt/` folder and the twin's exports
    /// ([`super::TwinFiles::into_fit_folder`]).
    pub files: FileSet,
    /// The twin the exports were written from.
    pub twin: Twin,
    /// The dataset's true joints, when it has them (the page draws their axes).
    pub truth: Option<Vec<crate::data::GtJoint>>,
    /// The dataset's true part meshes at the start state, when it has them (the page's viewer
    /// draws them over the fitted twin).
    pub truth_meshes: Option<crate::data::GtMeshes>,
}

/// Which step of [`FitFolder::build`] failed, for which object (`id`) or file (`what`).
#[derive(Debug, thiserror::Error)]
pub enum FolderError {
    /// The fit could not be scored against the dataset's ground truth.
    #[error("{id}: scoring against the ground truth: {source}")]
    Score {
        /// The fit's id.
        id: String,
        /// Why.
        source: EvalError,
    },
    /// A file's JSON could not be written.
    #[error("{what}: cannot serialise: {source}")]
    Serialise {
        /// The file.
        what: &'static str,
        /// Why.
        source: serde_json::Error,
    },
    /// The fit has no twin.
    #[error("{id}: {source}")]
    Twin {
        /// The fit's id.
        id: String,
        /// Why.
        source: NoStartState,
    },
    /// The twin's URDF, GLB or archive could not be written.
    #[error("{id}: exporting: {source}")]
    Export {
        /// The fit's id.
        id: String,
        /// Why.
        source: DataError,
    },
}

/// The dataset's true joints, when it has them, in `joints.json`'s units (degrees or metres) and
/// field names, for the page's fitted-beside-true table.
fn truth_records(dataset: &Dataset) -> Option<Vec<serde_json::Value>> {
    let joints = dataset.gt_joints.as_ref()?;
    Some(
        joints
            .iter()
            .enumerate()
            .map(|(i, j)| {
                serde_json::json!({
                    "part": i + 1,
                    "type": j.kind,
                    "direction": j.unit_direction().to_array(),
                    "origin": j.origin.to_array(),
                    "motion": j.motion(),
                })
            })
            .collect(),
    )
}

fn json(value: &impl Serialize, what: &'static str) -> Result<String, FolderError> {
    serde_json::to_string_pretty(value).map_err(|source| FolderError::Serialise { what, source })
}

impl FitFolder {
    /// Scores and exports `fit` of `dataset` (object `id` of `category`), which took `seconds`.
    /// Errors say which step failed.
    pub fn build(
        fit: &ObjectFit,
        dataset: &Dataset,
        config: &FitConfig,
        id: &str,
        category: &str,
        seconds: f64,
    ) -> Result<FitFolder, FolderError> {
        let quality = reconstruction_report(
            &fit.reconstruction,
            &dataset.gt_meshes,
            &ChamferOptions::default(),
        );
        let metrics = evaluate_fit(fit, dataset, id, category, &EvalOptions::default())
            .transpose()
            .map_err(|source| FolderError::Score {
                id: id.to_string(),
                source,
            })?;
        let joints = joint_records(fit);
        let report = serde_json::json!({
            "id": id,
            "seconds": seconds,
            "config": config,
            "joints": joints,
            "warnings": fit.articulation.warnings,
            "articulation": {
                "times": fit.articulation.times,
                "curve": fit.articulation.curve,
                "fitted": fit.articulation.joints,
            },
            "reconstruction": quality,
            "metrics": metrics,
            "truth": truth_records(dataset),
        });
        let joints_json = json(&joints, JOINTS_FILE)?.into_bytes();
        let twin = Twin::from_fit(fit, id)
            .map_err(|source| FolderError::Twin {
                id: id.to_string(),
                source,
            })?
            .with_visual_budget(config.max_visual_faces);
        let exports = export_twin(&twin.object(), &twin.end_configuration(), &joints_json)
            .map_err(|source| FolderError::Export {
                id: id.to_string(),
                source,
            })?;
        let mut files = fit
            .as_ground_truth()
            .to_files()
            .map_err(|source| FolderError::Export {
                id: id.to_string(),
                source,
            })?;
        files.insert(JOINTS_FILE.into(), joints_json);
        files.insert(REPORT_FILE.into(), json(&report, REPORT_FILE)?.into_bytes());
        files.extend(exports.into_fit_folder());
        Ok(FitFolder {
            report,
            joints,
            metrics,
            files,
            twin,
            truth: dataset.gt_joints.clone(),
            truth_meshes: dataset.gt_meshes[0].clone(),
        })
    }
}
