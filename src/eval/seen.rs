//! What the training views measure of the static part, and the CD-s a fit of only that can reach.
//!
//! The Chamfer distance samples the *whole* true surface, including what no view sees: a cabinet's shelves
//! behind a door that opens a little, a table top's underside. A fit that reconstructs only measured surface
//! cannot be closer to those samples than the nearest measured surface is. [`StaticBound`] says how much that
//! costs: the true static part is sampled, each sample is kept when some training view's depth map (either
//! state's: the base does not move) sees it, and the kept samples, as a perfect reconstruction of exactly the
//! measured surface, are scored against the metric's own truth samples. Beside it, the *floor*: a second
//! sample of the whole truth scored the same way, what even a perfect surface scores under 10 000 samples.

use glam::Vec3;
use serde::Serialize;

use super::chamfer::{ChamferOptions, chamfer_points, sample_surface};
use crate::data::{Dataset, Frame, Split, State};

/// How close (metres) a depth map's value must come to a point's depth, at its pixel or a neighbour, for the
/// view to see it: a few millimetres, so that a wall's hidden inner face a board's thickness behind is unseen.
const SEEN_TOLERANCE_M: f32 = 0.005;

/// Candidate samples drawn per metric sample, so that enough remain after the unseen ones are dropped.
const OVERSAMPLING: usize = 6;

/// The static part's CD-s bounds for one dataset (millimetres, the metric's `cd_mm`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StaticBound {
    /// Share of the true static surface some training view sees.
    pub seen_share: f64,
    /// CD-s of a second sample of the whole true surface: the metric's sampling floor.
    pub floor_mm: f64,
    /// CD-s of the seen surface alone: the best a fit of only measured surface can score.
    pub seen_only_mm: f64,
}

/// Which of `points` some frame's depth map sees (within [`SEEN_TOLERANCE_M`] at its pixel or one of the 8
/// around it); frames without depth see nothing.
pub fn seen_by<'a>(points: &[Vec3], frames: impl IntoIterator<Item = &'a Frame>) -> Vec<bool> {
    let mut seen = vec![false; points.len()];
    for frame in frames {
        let Some(depth) = &frame.depth else { continue };
        for (p, s) in points.iter().zip(seen.iter_mut()) {
            if *s {
                continue;
            }
            let Some((pixel, z)) = frame.camera.project(*p) else {
                continue;
            };
            let (x, y) = (pixel.x.floor(), pixel.y.floor());
            *s = (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (px, py) = (x + dx as f32, y + dy as f32);
                    px >= 0.0
                        && py >= 0.0
                        && depth
                            .metres(px as u32, py as u32)
                            .is_some_and(|d| (d - z).abs() < SEEN_TOLERANCE_M)
                })
            });
        }
    }
    seen
}

/// The static part's bounds for `dataset` at `state` under the metric's `options`; `None` when the dataset has
/// no ground-truth static mesh there, no depth, or too little seen surface to sample.
pub fn static_bound(
    dataset: &Dataset,
    state: State,
    options: &ChamferOptions,
) -> Option<StaticBound> {
    let truth = &dataset.gt_meshes_for(state)?.static_part;
    let n = options.samples;
    let metric = sample_surface(truth, n, options.seed).ok()?;
    let second = sample_surface(truth, n, options.seed ^ 0x5eed).ok()?;
    let candidates = sample_surface(truth, OVERSAMPLING * n, options.seed ^ 0xca11).ok()?;
    let frames = State::ALL
        .into_iter()
        .filter_map(|s| dataset.views(s, Split::Train))
        .flat_map(|v| &v.frames);
    let seen = seen_by(&candidates, frames);
    let kept: Vec<Vec3> = candidates
        .iter()
        .zip(&seen)
        .filter_map(|(p, s)| s.then_some(*p))
        .take(n)
        .collect();
    // Fewer than a tenth of the metric's samples would score the sampling, not the surface.
    if kept.len() < n / 10 {
        return None;
    }
    Some(StaticBound {
        seen_share: seen.iter().filter(|&&s| s).count() as f64 / seen.len() as f64,
        floor_mm: chamfer_points(&second, &metric).ok()?.cd_mm,
        seen_only_mm: chamfer_points(&kept, &metric).ok()?.cd_mm,
    })
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::data::fixture::depth_frame;

    /// A frame whose depth map is a wall at z-depth `wall` metres, looking down −z from `eye`.
    fn frame_with_wall(eye: Vec3, wall: f32) -> Frame {
        depth_frame(eye, 32, &|_, _| Some(wall))
    }

    #[test]
    fn a_point_on_the_measured_wall_is_seen_and_one_behind_it_is_not() {
        let frame = frame_with_wall(Vec3::new(0.0, 0.0, 2.0), 1.5);
        let points = [
            Vec3::new(0.0, 0.0, 0.5),   // on the wall (depth 1.5)
            Vec3::new(0.1, -0.1, 0.49), // 1 cm behind it
            Vec3::new(0.0, 0.0, 3.0),   // behind the camera
            Vec3::new(50.0, 0.0, 0.5),  // outside the image
        ];
        assert_eq!(seen_by(&points, [&frame]), [true, false, false, false]);
        assert_eq!(seen_by(&points, []), [false; 4], "no frame sees nothing");
    }
}
