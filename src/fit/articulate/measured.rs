//! The measured joints (ours, [`GeometryUse`]): both states' part surfaces sampled from the
//! training views' full-resolution depth and part maps, and per movable part the joint that
//! best moves one onto the other. They seed the photometric stages, and the joints they settle
//! skip them.

use super::config::{ArticulationConfig, GeometryUse};
use crate::articulation::geometric::{Anchor, GeometricJoint, fit_joint};
use crate::articulation::observed::{CloudOptions, ObservedState, observe_dataset};
use crate::data::{Dataset, Split, State};
use crate::gpu::{GpuError, GpuResult};

/// Points of the rest of the object a measured joint's axis is checked against.
const ANCHOR_POINTS: usize = 20_000;

/// What the training views measure.
pub(super) struct Measured {
    /// Both states' clouds of the training views (`None`: the geometry is off, or no views).
    pub(super) train_clouds: Option<[ObservedState; 2]>,
    /// The measured joint per part (`None` for the base and for a part not measured in both
    /// states).
    pub(super) joints: Vec<Option<GeometricJoint>>,
    /// Per part, whether the measurements settle its joint (taken as measured, no photometry).
    pub(super) settled: Vec<bool>,
}

/// Measures the joints of `k` parts from the training views, adding what a user should know
/// to `warnings`.
/// `sampled`: both states' training clouds if the reconstruction already sampled them, with the
/// options it sampled them with (reused when those are `config`'s).
pub(super) fn measure(
    dataset: &Dataset,
    config: &ArticulationConfig,
    k: usize,
    sampled: Option<&(CloudOptions, [ObservedState; 2])>,
    warnings: &mut Vec<String>,
) -> GpuResult<Measured> {
    let train_clouds = match sampled {
        Some((options, clouds))
            if *options == config.clouds && config.geometry != GeometryUse::Off =>
        {
            Some(clouds.clone())
        }
        _ => observe(dataset, config, Split::Train),
    };
    if let Some(clouds) = &train_clouds {
        measurement_warnings(clouds, warnings)?;
        let has_test_views = [State::Start, State::End]
            .iter()
            .all(|&s| dataset.views(s, Split::Test).is_some());
        if !has_test_views {
            warnings.push(
                "the dataset has no test views: refined joints are judged against their measured seeds on the training views' points".into(),
            );
        }
    }
    let joints = measure_joints(k, train_clouds.as_ref());
    let settled = joints
        .iter()
        .map(|g| config.geometry == GeometryUse::Settle && g.is_some_and(|g| g.settled()))
        .collect();
    Ok(Measured {
        train_clouds,
        joints,
        settled,
    })
}

/// Both states' clouds of a split, or `None` (no views of it, or the geometry is off).
pub(super) fn observe(
    dataset: &Dataset,
    config: &ArticulationConfig,
    split: Split,
) -> Option<[ObservedState; 2]> {
    (config.geometry != GeometryUse::Off)
        .then(|| observe_dataset(dataset, split, &config.clouds))
        .flatten()
}

/// The joints the training views' depth and part maps measure, one per part (`None` for the
/// base and for a part not measured in both states).
fn measure_joints(k: usize, train: Option<&[ObservedState; 2]>) -> Vec<Option<GeometricJoint>> {
    (0..k)
        .map(|part| {
            let [s, e] = train.filter(|_| part > 0)?;
            let anchor = Anchor::new(
                &s.others(part, ANCHOR_POINTS),
                &e.others(part, ANCHOR_POINTS),
            );
            fit_joint(&s.parts[part], &e.parts[part], Some(&anchor))
        })
        .collect()
}

/// What a user should know about the measurements: views without depth or part maps. A movable
/// part that no training view of either state shows (not one pixel labelled with it) is an
/// error: there is nothing to fit it to.
fn measurement_warnings(clouds: &[ObservedState; 2], warnings: &mut Vec<String>) -> GpuResult<()> {
    for (state, c) in [State::Start, State::End].iter().zip(clouds) {
        if c.views_with_depth < c.views {
            warnings.push(format!(
                "{} of the {} {} training views have no depth or part map of the colour image's size: the joints are measured from the other {}",
                c.views - c.views_with_depth,
                c.views,
                state.name(),
                c.views_with_depth
            ));
        }
    }
    let unseen: Vec<String> = (1..clouds[0].parts.len())
        .filter(|&p| clouds.iter().all(|c| c.parts[p].labelled == 0))
        .map(|p| p.to_string())
        .collect();
    if !unseen.is_empty() && clouds.iter().all(|c| c.views_with_depth > 0) {
        return Err(GpuError::InvalidInput(format!(
            "movable part(s) {} appear in no training view's part map (with depth) in either state: nothing to fit their joints to; check the semantic maps' ids (0 = background, k + 1 = part k)",
            unseen.join(", ")
        )));
    }
    Ok(())
}
