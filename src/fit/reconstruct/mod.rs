//! The reconstruction phase (paper §3.1, docs/design.md §5), run independently per articulation
//! state:
//!
//! 1. **initialise** a triangle soup from the depth maps ([`super::init`]);
//! 2. **optimise** positions, SH colour, opacity and part logits with the image loss, while
//!    **densifying** (1 → 4 splits of visible faces larger than a few pixels) and **pruning**
//!    (faces that never blend above a small weight, transparent ones, oversized ones) in a
//!    window, and annealing γ and the opacity floor towards hard, opaque triangles;
//! 3. **harden** part labels (argmax), drop the old faces (and with them every cross-part one),
//!    and rebuild connectivity with **part-aware restricted Delaunay** per part
//!    ([`crate::mesh::part_aware_remesh`]; [`RemeshMode::Global`] is the ablation), keeping the
//!    pieces that are not tiny floaters;
//! 4. **recover**: a short fit with the topology fixed, γ and the floor at their final values.
//!
//! Progress is reported as [`Progress`] events; the CLI draws them as a bar, the browser plots them.
//!
//! Files: `config` (settings per preset), `results` (what a state's reconstruction
//! produces), `densify` (densification and pruning), `remesh` (hardening and remeshing),
//! `state` (the stages of one state in order), `both` (natively, the two states at once); this
//! file picks the training views and runs both states.

#[cfg(not(target_arch = "wasm32"))]
mod both;
mod config;
mod densify;
pub mod free_space;
mod remesh;
mod results;
mod state;

pub use config::{
    DensifyConfig, ReconstructionConfig, RemeshMode, SurfaceSource, UNCHECKED_HOLE_EDGES,
};
pub use results::{PhaseTimes, Reconstruction, RemeshStats, StateReconstruction};
pub use state::reconstruct_state;

use std::sync::Arc;

use super::views::downsample_frame;
use crate::articulation::observed::{CloudOptions, ObservedState, observe_dataset};
use crate::data::{Dataset, Frame, Split, State};
use crate::fit::observer::Observer;
use crate::gpu::{GpuContext, GpuError, GpuResult};
use free_space::FreeSpace;

/// A state of the dataset without training views, so there is nothing to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("the dataset has no {} training views", .0.name())]
pub struct NoTrainingViews(pub State);

/// The training views of `state` under `config`: evenly spaced, downsampled.
pub fn training_views(
    dataset: &Dataset,
    state: State,
    config: &ReconstructionConfig,
) -> Result<Vec<Frame>, NoTrainingViews> {
    let frames = dataset
        .views(state, Split::Train)
        .map(|v| &v.frames)
        .filter(|f| !f.is_empty())
        .ok_or(NoTrainingViews(state))?;
    Ok(working_views(frames, config.max_views, config.max_size))
}

/// What one state's reconstruction is given: its views at the working size (those fitted on and
/// those held out), and its parts' surfaces as measured at full resolution, when the config asks
/// for them (see [`SurfaceSource`]).
pub struct StateViews {
    pub train: Vec<Frame>,
    pub held_out: Vec<Frame>,
    /// This state's measured clouds, as the measured joints read them.
    pub measured: Option<ObservedState>,
    /// The clouds its mesh is built over: `measured` with the static base seen in both states.
    pub surface: Option<ObservedState>,
    /// Where both states' training views saw through (shared by the two states' views): hole-fill
    /// faces it sees through are left out.
    pub free_space: Option<Arc<FreeSpace>>,
}

/// The held-out (test) views of `state`, all of them, downsampled as the training views are;
/// empty when the dataset has none.
pub fn test_views(dataset: &Dataset, state: State, config: &ReconstructionConfig) -> Vec<Frame> {
    dataset
        .views(state, Split::Test)
        .map_or(Vec::new(), |v| working_views(&v.frames, 0, config.max_size))
}

/// At most `max_views` of `frames` (0 = all), evenly spaced, downsampled by the integer factor
/// that brings the longer side to `max_size` or under (0 = full size).
fn working_views(frames: &[Frame], max_views: usize, max_size: u32) -> Vec<Frame> {
    let Some(first) = frames.first() else {
        return Vec::new();
    };
    let n = frames.len();
    let take = if max_views == 0 { n } else { max_views.min(n) };
    let longest = first.rgba.width.max(first.rgba.height);
    let factor = if max_size == 0 {
        1
    } else {
        longest.div_ceil(max_size).max(1)
    };
    (0..take)
        .map(|i| downsample_frame(&frames[i * n / take], factor))
        .collect()
}

/// How the measured surfaces are sampled: as the measured joints sample them, so the
/// articulation phase can reuse them.
fn surface_clouds() -> CloudOptions {
    CloudOptions::default()
}

/// Both states' [`StateViews`] of `dataset` under `config`, start state first: what
/// [`reconstruct`] fits.
pub fn state_views(dataset: &Dataset, config: &ReconstructionConfig) -> GpuResult<[StateViews; 2]> {
    // Both states at once: a part's voxel size is the same in both.
    let measured = (config.surface == SurfaceSource::Measured)
        .then(|| observe_dataset(dataset, Split::Train, &surface_clouds()))
        .flatten();
    let mut surface = measured
        .as_ref()
        .map(|[s, e]| [Some(with_both_bases(s, e)), Some(with_both_bases(e, s))])
        .unwrap_or_default();
    let mut measured = measured
        .map(|[s, e]| [Some(s), Some(e)])
        .unwrap_or_default();
    // Over measured surfaces only (what the suites measured; the optimised surfaces of `tiny` and
    // `paper` close holes as before).
    let free_space = (config.surface == SurfaceSource::Measured)
        .then(|| FreeSpace::from_dataset(dataset).map(Arc::new))
        .flatten();
    let mut views = |state: State| -> GpuResult<StateViews> {
        Ok(StateViews {
            train: training_views(dataset, state, config)
                .map_err(|e| GpuError::InvalidInput(e.to_string()))?,
            held_out: test_views(dataset, state, config),
            measured: measured[state.index()].take(),
            surface: surface[state.index()].take(),
            free_space: free_space.clone(),
        })
    };
    Ok([views(State::Start)?, views(State::End)?])
}

/// `own` with its static base (part 0) measured in both states: the base does not move, and
/// what one state hides of it (a cabinet's inside behind closed doors) the other may show.
fn with_both_bases(own: &ObservedState, other: &ObservedState) -> ObservedState {
    let mut out = own.clone();
    if let (Some(base), Some(seen)) = (out.parts.first_mut(), other.parts.first()) {
        *base = base.merged(seen);
    }
    out
}

/// Reconstructs both states of `dataset`: natively at once ([`both`]), in the browser in turn.
pub async fn reconstruct(
    ctx: &GpuContext,
    dataset: &Dataset,
    config: &ReconstructionConfig,
    observer: &mut dyn Observer,
) -> GpuResult<Reconstruction> {
    let views = state_views(dataset, config)?;
    let k = dataset.num_parts;
    #[cfg(not(target_arch = "wasm32"))]
    let states = both::reconstruct_both(ctx, &views, k, config, observer)?.into();
    #[cfg(target_arch = "wasm32")]
    let states = {
        let mut states = Vec::new();
        for (state, v) in State::ALL.into_iter().zip(&views) {
            let rec = reconstruct_state(ctx, state, v, k, config, observer);
            states.push(rec.await?);
        }
        states
    };
    let train_clouds = match views.map(|v| v.measured) {
        [Some(start), Some(end)] => Some((surface_clouds(), [start, end])),
        _ => None,
    };
    Ok(Reconstruction {
        config: *config,
        num_parts: dataset.num_parts,
        states,
        train_clouds,
    })
}
