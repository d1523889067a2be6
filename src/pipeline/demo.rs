//! The demo's dataset: a procedural object of the built-in catalogue, captured in both states
//! as `artmesh demo` and the page's demo do, ready to fit like a user's dataset.

use super::{FitInput, PipelineError};
use crate::fit::object::FitConfig;
use crate::fit::preset::Preset;
use crate::gpu::GpuContext;
use crate::object::ArticulatedObject;
use crate::render::{CaptureError, RenderProgress, RenderSpec, capture_dataset};
use crate::synth::{Category, SynthParams, generate};

// The demo's capture follows the fit's budget (never below `fast`'s) but is no part of fitting:
// it lives here, as methods on the budget so both front ends read `config.full_demo_capture(seed)`.
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

    /// How `artmesh demo` and the page photograph an object (the demo's or a dropped URDF), as
    /// a user's dataset would be: the joints are measured from its full-resolution depth and part
    /// maps and judged on its test views, while the fit reads it at its own working size. Four
    /// times the working size (at most 512 px; full-resolution budgets get 512) with 4 test views,
    /// and never less than the `fast` preset's capture (256², 12 training views per state),
    /// whatever the preset: at `tiny`'s own 128² and 4 views the depth could not measure a
    /// dropped object (habitat's kitchen counter's seven drawers came out hinges, sektion's door
    /// 68° off), where at 256² and 12 views all three shared objects come out right within 0.4°
    /// (`docs/results.md`, 2026-12-07); at 64² the demo cabinet's door came out 20.9° off.
    pub fn full_demo_capture(&self, seed: u64) -> RenderSpec {
        let least = FitConfig::preset(Preset::Fast).demo_capture(seed);
        let own = self.demo_capture(seed);
        let size = match self.reconstruction.max_size {
            0 => FULL_CAPTURE_MAX,
            _ => (4 * own.width.max(least.width)).min(FULL_CAPTURE_MAX),
        };
        RenderSpec {
            width: size,
            height: size,
            train_views: own.train_views.max(least.train_views),
            test_views: 4,
            ..own
        }
    }
}

/// The largest side (px) a demo captures: a 512² view (colour, depth, part map) is 2 MB
/// decoded, so 16 views per state are about 70 MB, which a browser tab holds easily.
const FULL_CAPTURE_MAX: u32 = 512;

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
