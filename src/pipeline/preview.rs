//! `preview.png`: the fitted twin beside the photos (and the ground truth, when the dataset has
//! it), from three of each state's held-out cameras (training cameras when the dataset has no test
//! split), as [`crate::render::preview`] draws it.

use crate::data::{Dataset, PngPixels, Split, State, encode_png};
use crate::export::Twin;
use crate::gpu::GpuContext;
use crate::render::{PreviewTruth, PreviewView, preview};

use super::PipelineError;

/// The preview's name in a fit folder.
pub const PREVIEW_FILE: &str = "preview.png";

/// Cameras per state in the preview.
const VIEWS: usize = 3;

/// Up to [`VIEWS`] frames of `state`, spread over its test split (else its train split).
fn views(dataset: &Dataset, state: State) -> Vec<PreviewView<'_>> {
    let set = [Split::Test, Split::Train].iter().find_map(|&split| {
        dataset
            .views
            .iter()
            .find(|v| v.state == state && v.split == split && !v.frames.is_empty())
    });
    let Some(set) = set else {
        return Vec::new();
    };
    let n = set.frames.len();
    let mut picked: Vec<usize> = (0..VIEWS.min(n)).map(|i| i * n / VIEWS.min(n)).collect();
    picked.dedup();
    picked
        .into_iter()
        .map(|i| PreviewView {
            camera: set.frames[i].camera,
            photo: &set.frames[i].rgba,
        })
        .collect()
}

/// The preview of `twin` fitted to `dataset`, as PNG bytes.
pub async fn preview_png(
    ctx: &GpuContext,
    dataset: &Dataset,
    twin: &Twin,
) -> Result<Vec<u8>, PipelineError> {
    let [start, end] = State::ALL.map(|s| views(dataset, s));
    let truth = match (&dataset.gt_meshes[0], &dataset.gt_joints) {
        (Some(meshes), Some(joints)) if meshes.movable.len() == joints.len() => {
            let twin = Twin::from_truth("truth", meshes, joints);
            Some((twin.visual_object(), twin.end_configuration()))
        }
        _ => None,
    };
    let image = preview(
        ctx,
        &twin.visual_object(),
        &twin.end_configuration(),
        [&start, &end],
        truth
            .as_ref()
            .map(|(object, end)| PreviewTruth { object, end }),
    )
    .await
    .map_err(|e| PipelineError::Export(format!("{PREVIEW_FILE}: {e}")))?;
    encode_png(
        PREVIEW_FILE,
        image.width,
        image.height,
        PngPixels::Rgba8(&image.pixels),
    )
    .map_err(PipelineError::Write)
}
