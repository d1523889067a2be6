//! The measured joints (ours, [`GeometryUse`]): both states' part surfaces sampled from the
//! training views' full-resolution depth and part maps, and per movable part the joint that
//! best moves one onto the other. They seed the photometric stages, and the joints they settle
//! skip them.

use super::config::{ArticulationConfig, GeometryUse};
use crate::articulation::geometric::{GeometricJoint, JointMeasurer};
use crate::articulation::observed::{CloudOptions, ObservedState, observe_dataset};
use crate::data::{Dataset, Split, State};
use crate::fit::observer::{Observer, Phase, Progress, checkpoint};
use crate::gpu::{GpuError, GpuResult, now_seconds};

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
/// `observer` hears a [`Phase::Measure`] event before each movable part (and may pause or cancel
/// there): a part's measurement takes seconds, and in the browser the page turns between them.
pub(super) async fn measure(
    dataset: &Dataset,
    config: &ArticulationConfig,
    k: usize,
    sampled: Option<&(CloudOptions, [ObservedState; 2])>,
    warnings: &mut Vec<String>,
    observer: &mut dyn Observer,
) -> GpuResult<Measured> {
    let t0 = now_seconds();
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
    }
    let joints = measure_joints_of(k, train_clouds.as_ref(), observer, t0).await?;
    let settled: Vec<bool> = joints
        .iter()
        .map(|g| config.geometry == GeometryUse::Settle && g.is_some_and(|g| g.settled()))
        .collect();
    Ok(Measured {
        train_clouds,
        joints,
        settled,
    })
}

/// Names the measured parts whose joints the depth and part maps could not settle, with the
/// noise the depth showed: a capture too noisy to decide gets told so, not a confident guess.
/// Those the photometric stages train (`trainable`) are decided there; the others (no
/// reconstructed surface to train) keep the way their depth leans.
pub(super) fn unsettled_warning(
    measured: &Measured,
    trainable: &[bool],
    warnings: &mut Vec<String>,
) {
    let Some(clouds) = &measured.train_clouds else {
        return;
    };
    let parts = |train: bool| -> Vec<String> {
        (0..measured.joints.len())
            .filter(|&p| measured.joints[p].is_some_and(|g| !g.settled()))
            .filter(|&p| trainable.get(p).copied().unwrap_or(false) == train)
            .map(|p| p.to_string())
            .collect()
    };
    let (photometric, leaning) = (parts(true), parts(false));
    if photometric.is_empty() && leaning.is_empty() {
        return;
    }
    let noise = clouds[0].noise.map_or(String::new(), |n| {
        format!(
            " (depth noise about {:.1} mm at {:.1} m)",
            1000.0 * n.sigma,
            n.depth
        )
    });
    let measured_count = measured.joints.iter().flatten().count();
    let what = if photometric.len() + leaning.len() == measured_count {
        "the depth and part maps settle none of the joints"
    } else {
        "the depth and part maps do not settle every joint"
    };
    let mut how = Vec::new();
    if !photometric.is_empty() {
        how.push(format!(
            "part(s) {} are decided by the photometric stages among the hypotheses the depth left open",
            photometric.join(", ")
        ));
    }
    if !leaning.is_empty() {
        how.push(format!(
            "part(s) {} have no reconstructed surface to train and keep the joint their depth leans to",
            leaning.join(", ")
        ));
    }
    warnings.push(format!(
        "{what}{noise}: {}; check any flagged below",
        how.join("; ")
    ));
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
/// base and for a part not measured in both states), a [`Phase::Measure`] event before each.
async fn measure_joints_of(
    k: usize,
    train: Option<&[ObservedState; 2]>,
    observer: &mut dyn Observer,
    t0: f64,
) -> GpuResult<Vec<Option<GeometricJoint>>> {
    let mut joints = Vec::with_capacity(k);
    if let Some(clouds) = train {
        let measurer = JointMeasurer::new(clouds);
        let movable = measurer.parts().saturating_sub(1) as u32;
        // Open so far: measured movable parts without a settled joint.
        let open = |joints: &[Option<GeometricJoint>]| -> u32 {
            let unsettled = joints
                .iter()
                .skip(1)
                .filter(|g| !g.is_some_and(|g| g.settled()));
            unsettled.count() as u32
        };
        for part in 0..measurer.parts() {
            if part > 0 {
                let at = measuring((part as u32 - 1, movable), open(&joints), t0);
                checkpoint(observer, &at).await?;
            }
            joints.push(measurer.measure(part));
        }
        checkpoint(observer, &measuring((movable, movable), open(&joints), t0)).await?;
    }
    joints.resize(k, None);
    Ok(joints)
}

/// The event of the joint measurement with `done` of `parts` movable parts measured, `open` of
/// them left open.
fn measuring((done, parts): (u32, u32), open: u32, t0: f64) -> Progress {
    Progress {
        state: State::End,
        phase: Phase::Measure,
        iteration: done,
        iterations: parts,
        open,
        loss: None,
        psnr: None,
        vertices: 0,
        faces: 0,
        elapsed_s: now_seconds() - t0,
        candidate: None,
    }
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
