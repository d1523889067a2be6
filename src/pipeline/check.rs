//! What a fit would refuse in a dataset that reads fine, found before any GPU work, in the
//! dataset's terms: `artmesh info` lists these beside the reader's problems, and
//! [`super::read_dataset`] (behind the CLI's `fit`) refuses with the same words, instead of the
//! fit failing later with a message about vertices or buffers.

use crate::data::{Dataset, Frame, Split, State, transforms_file_name};
use crate::raster::MAX_PARTS;

/// Narrowest and widest horizontal field of view a fit accepts, in degrees.
const FOV_DEGREES: (f32, f32) = (0.5, 175.0);

/// Every reason a fit of `dataset` would stop before fitting anything; empty when there is none.
pub fn fit_problems(dataset: &Dataset) -> Vec<String> {
    let mut problems = Vec::new();
    if dataset.num_parts > MAX_PARTS {
        let from = match &dataset.gt_joints {
            Some(j) => format!("gt/trans.json lists {} joints", j.len()),
            None => "the largest id in the semantic maps".to_string(),
        };
        problems.push(format!(
            "{} parts ({from}): a fit handles 1 to {MAX_PARTS} (the static base and up to {} movable parts)",
            dataset.num_parts,
            MAX_PARTS - 1
        ));
    }
    for view in &dataset.views {
        let (lo, hi) = FOV_DEGREES;
        let fov = |f: &Frame| f.camera.intrinsics.fov_x().to_degrees();
        if let Some((i, f)) = view
            .frames
            .iter()
            .enumerate()
            .find(|(_, f)| !(lo..=hi).contains(&fov(f)))
        {
            problems.push(format!(
                "{}: frames[{i}]: a focal length of {} px on a {} px wide image is a horizontal field of view of {}°: expected {lo}° to {hi}°",
                transforms_file_name(view.split, view.state),
                f.camera.intrinsics.fx,
                f.camera.intrinsics.width,
                fov(f)
            ));
        }
    }
    for state in State::ALL {
        if let Some(train) = dataset.views(state, Split::Train)
            && let Some(why) = no_start(&train.frames)
        {
            problems.push(format!(
                "{}/train: {why}: the reconstruction starts from the foreground pixels' depth",
                state.name()
            ));
        }
    }
    problems
}

/// [`fit_problems`] as one message, the way `info`, `fit` and the page say it; `None` when a
/// fit can start.
pub fn fit_refusal(dataset: &Dataset) -> Option<String> {
    let problems = fit_problems(dataset);
    (!problems.is_empty()).then(|| {
        format!(
            "the dataset reads, but a fit would stop on {} problem(s):\n{}",
            problems.len(),
            problems.join("\n")
        )
    })
}

/// Why no frame has a pixel the reconstruction can start from (foreground, valid depth, a
/// part id), naming the map at fault; `None` when some frame has one.
fn no_start(frames: &[Frame]) -> Option<&'static str> {
    let (mut depth, mut opaque, mut labelled) = (false, false, false);
    for f in frames {
        let Some(d) = &f.depth else { continue };
        for (i, &mm) in d.millimetres.iter().enumerate() {
            let valid = mm > 0;
            let fg = f.rgba.pixels.get(4 * i + 3).is_some_and(|&a| a >= 128);
            let part = f
                .parts
                .as_ref()
                .is_none_or(|p| p.ids.get(i).is_some_and(|&id| id >= 0));
            depth |= valid;
            opaque |= valid && fg;
            labelled |= part;
            if valid && fg && part {
                return None;
            }
        }
    }
    Some(if !depth {
        "no frame has a depth map with a valid (non-zero) pixel"
    } else if !opaque {
        "no pixel with valid depth is foreground (alpha ≥ 128) in any frame"
    } else if !labelled {
        "every semantic map is background (0 in a PNG, -1 in a .npy)"
    } else {
        "no foreground pixel with valid depth has a part id (its semantic map says background there)"
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::fixture::{FixtureParams, small_dataset};

    fn problems_after(change: impl Fn(&mut Dataset)) -> Vec<String> {
        let mut dataset = small_dataset(FixtureParams::default());
        change(&mut dataset);
        fit_problems(&dataset)
    }

    #[test]
    fn a_fittable_dataset_has_no_problem() {
        assert_eq!(problems_after(|_| {}), Vec::<String>::new());
    }

    // Each refusal's words are checked on data written and read back, natively and in the
    // browser: `fixtures::hostile`, "what a fit would refuse".
}
