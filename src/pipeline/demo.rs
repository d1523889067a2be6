//! The demo's dataset: a procedural object of the built-in catalogue, captured in both states
//! as `artmesh demo` and the page's demo do, ready to fit like a user's dataset.

use super::{FitInput, PipelineError};
use crate::fit::object::FitConfig;
use crate::gpu::GpuContext;
use crate::object::ArticulatedObject;
use crate::render::{CaptureError, RenderProgress, RenderSpec, capture_dataset};
use crate::synth::{Category, SynthParams, generate};

// The demo's capture follows the fit's budget but is no part of fitting: it lives here, as
// methods on the budget so both front ends read `config.demo_capture(seed)`.
impl FitConfig {
    /// How a demo captures its procedural object for this budget: square images at the
    /// reconstruction's working size (32 to 512 px) and as many training views per state as it
    /// uses (4 to 100), no test views. The page's demo and the tests' tiny fits use it.
    pub fn demo_capture(&self, seed: u64) -> RenderSpec {
        let size = self.reconstruction.max_size.clamp(32, 512);
        RenderSpec {
            width: size,
            height: size,
            train_views: self.reconstruction.max_views.clamp(4, 100),
            test_views: 0,
            seed,
            ..RenderSpec::default()
        }
    }

    /// How `artmesh demo` captures: as a user's dataset would be, so the fit reads its working
    /// size and its joints come from the full-resolution depth and part maps (at 64² those are
    /// too coarse: the demo cabinet's axes came out 20.9° off) and are judged on test views.
    /// [`FitConfig::demo_capture`] at four times the size (at most 512 px) with 4 test views.
    pub fn full_demo_capture(&self, seed: u64) -> RenderSpec {
        let mut spec = self.demo_capture(seed);
        spec.width = (4 * spec.width).min(512);
        spec.height = spec.width;
        spec.test_views = 4;
        spec
    }
}

/// The procedural `category` object with `movable_parts` movable parts drawn from `seed`.
pub fn demo_object(
    category: Category,
    movable_parts: usize,
    seed: u64,
) -> Result<ArticulatedObject, PipelineError> {
    generate(&SynthParams {
        category,
        movable_parts: Some(movable_parts),
        seed,
    })
    .map_err(|e| PipelineError::Demo(e.to_string()))
}

/// Captures `object` (of `category`) in both states as `spec` says; `on_view` hears the views
/// rendered so far. The dataset is named after the object.
pub async fn capture_demo(
    ctx: &GpuContext,
    object: &ArticulatedObject,
    category: Category,
    spec: &RenderSpec,
    on_view: &mut dyn FnMut(RenderProgress),
) -> Result<FitInput, PipelineError> {
    capture_object(ctx, object, category.name(), spec, on_view)
        .await
        .map_err(|e| PipelineError::Demo(format!("{}: {e}", object.name)))
}

/// Captures `object` in both states as `spec` says, its ground truth (joints, part meshes)
/// included so the fit is scored; the dataset is named after the object and labelled `category`
/// in the metrics. The demo's objects and a user's zipped URDF ([`super::object`]) both come here.
pub async fn capture_object(
    ctx: &GpuContext,
    object: &ArticulatedObject,
    category: &str,
    spec: &RenderSpec,
    on_view: &mut dyn FnMut(RenderProgress),
) -> Result<FitInput, CaptureError> {
    let dataset = capture_dataset(ctx, object, spec, on_view).await?;
    Ok(FitInput {
        dataset,
        id: object.name.clone(),
        category: category.into(),
    })
}
