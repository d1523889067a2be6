//! The one process stream both front ends run, above the export: a dataset (read from a folder,
//! dropped on the page, or the demo's procedural capture, [`demo`]) → its fit, heard by a progress
//! observer → its scores against the dataset's ground truth when there is one → the output folder's
//! files (written to disk by the CLI, offered for download by the page). The CLI and the page only
//! convert at their boundary: arguments and a progress bar, or JS values and events.

pub mod check;
pub mod demo;
pub mod object;
pub mod preview;

use std::fmt;

use crate::data::{DataError, Dataset, FileSet, ReadLimits};
use crate::export::FitFolder;
use crate::fit::object::{FitConfig, ObjectFit, fit_object};
use crate::fit::observer::Observer;
use crate::gpu::{GpuContext, GpuError, now_seconds};

/// The category label of a user's dataset (the demo's objects carry their synthetic category).
pub(crate) const UNKNOWN_CATEGORY: &str = "unknown";

/// Why the pipeline stopped, phrased for the person who ran it.
#[derive(Debug)]
pub enum PipelineError {
    /// The dataset could not be read or is not valid; the message lists every problem found.
    Dataset(String),
    /// The demo's object could not be made or captured; the message names it when known.
    Demo(String),
    /// A user's object (a zipped URDF) could not be read, imported or captured; the message
    /// names the archive and the file at fault.
    Object(String),
    /// The fit of object `id` stopped: a GPU failure, or the observer cancelled it.
    Fit { id: String, source: GpuError },
    /// Scoring or exporting the fit failed; the message names the object and the step.
    Export(String),
    /// Writing the output files failed.
    Write(DataError),
}

impl fmt::Display for PipelineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Dataset(m) | Self::Demo(m) | Self::Object(m) | Self::Export(m) => f.write_str(m),
            Self::Fit { id, source } => write!(f, "{id}: {source}"),
            Self::Write(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for PipelineError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Fit { source, .. } => Some(source),
            Self::Write(e) => Some(e),
            _ => None,
        }
    }
}

/// A dataset ready to fit, with the names its outputs carry.
#[derive(Debug, Clone)]
pub struct FitInput {
    pub dataset: Dataset,
    /// The fit's id in its report and the twin's name.
    pub id: String,
    /// A label in the metrics: the synthetic category, or [`UNKNOWN_CATEGORY`] for user data.
    pub category: String,
}

impl FitInput {
    /// A user's dataset (no known category), named `id`.
    pub fn user(dataset: Dataset, id: String) -> FitInput {
        FitInput {
            dataset,
            id,
            category: UNKNOWN_CATEGORY.into(),
        }
    }
}

/// A finished fit and its output folder.
#[derive(Debug, Clone)]
pub struct FitRun {
    pub fit: ObjectFit,
    /// The report (with the scores when the dataset has ground truth), joints, twin and files.
    pub folder: FitFolder,
    /// How long the fit took (s), as the report says.
    pub seconds: f64,
}

/// Fits `input` with `config` (reconstruction of both states, then articulation; `observer` hears
/// both and may pause or cancel them), then scores the fit against the dataset's ground truth
/// when it has one and builds the output folder ([`FitFolder::build`], and
/// [`preview::PREVIEW_FILE`]).
pub async fn fit_and_export(
    ctx: &GpuContext,
    input: &FitInput,
    config: &FitConfig,
    observer: &mut dyn Observer,
) -> Result<FitRun, PipelineError> {
    let t0 = now_seconds();
    let fit = fit_object(ctx, &input.dataset, config, observer)
        .await
        .map_err(|source| PipelineError::Fit {
            id: input.id.clone(),
            source,
        })?;
    let seconds = now_seconds() - t0;
    let mut folder = FitFolder::build(
        &fit,
        &input.dataset,
        config,
        &input.id,
        &input.category,
        seconds,
    )
    .map_err(|e| PipelineError::Export(e.to_string()))?;
    let png = preview::preview_png(ctx, &input.dataset, &folder.twin).await?;
    folder.files.insert(preview::PREVIEW_FILE.into(), png);
    Ok(FitRun {
        fit,
        folder,
        seconds,
    })
}

/// Reads the dataset folder `root`, named after its last component (`object` when it has none),
/// as [`dataset_from_files`] does; errors start with the folder's name.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_dataset(
    root: &std::path::Path,
    limits: &ReadLimits,
) -> Result<FitInput, PipelineError> {
    let shown = root.display();
    let files =
        crate::data::read_dataset_files(root).map_err(|e| PipelineError::Dataset(e.to_string()))?;
    let id = root
        .file_name()
        .map_or("object".into(), |n| n.to_string_lossy().into_owned());
    dataset_from_files(&files, id, limits)
        .map_err(|e| PipelineError::Dataset(format!("{shown}: {e}")))
}

/// A user's dataset, validated as a file set and then for what a fit needs
/// ([`check::fit_problems`]); the error lists every problem found (the first 50 shown).
pub fn dataset_from_files(
    files: &FileSet,
    id: String,
    limits: &ReadLimits,
) -> Result<FitInput, PipelineError> {
    let dataset = Dataset::from_files_within(files, limits).map_err(|problems| {
        PipelineError::Dataset(format!("{} problem(s):\n{problems}", problems.0.len()))
    })?;
    if let Some(refusal) = check::fit_refusal(&dataset) {
        return Err(PipelineError::Dataset(refusal));
    }
    Ok(FitInput::user(dataset, id))
}

/// Writes `dataset` in the dataset layout under `out` (the demo keeps its capture beside its fit).
#[cfg(not(target_arch = "wasm32"))]
pub fn write_dataset(dataset: &Dataset, out: &std::path::Path) -> Result<(), PipelineError> {
    let files = dataset.to_files().map_err(PipelineError::Write)?;
    crate::data::write_dir(&files, out).map_err(PipelineError::Write)
}

/// Writes the fit folder's files under `out`.
#[cfg(not(target_arch = "wasm32"))]
pub fn write_fit_folder(folder: &FitFolder, out: &std::path::Path) -> Result<(), PipelineError> {
    crate::data::write_dir(&folder.files, out).map_err(PipelineError::Write)
}
