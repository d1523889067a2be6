//! What a fit will do, counted before it starts: the quantities its time grows with (pixels the
//! depth measurements read, working-size pixels and views, steps of each stage). A front end
//! turns them into a time estimate with rates measured on its adapter (the page's
//! `web/estimate.js`); the counts themselves come from the fit's own config, so they cannot
//! drift from what the fit does.

use serde::{Deserialize, Serialize};

use super::articulate::GeometryUse;
use super::object::FitConfig;
use super::reconstruct::SurfaceSource;
use crate::data::{Dataset, Split, State};

/// The capture a fit will read: its training views' size and count per state, and its parts.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Capture {
    pub width: u32,
    pub height: u32,
    /// Training views per state.
    pub views: usize,
    /// Movable parts (the base not counted).
    pub movable_parts: usize,
    /// Whether the views have depth maps (without, nothing is measured).
    pub depth: bool,
    /// Per movable part, the pixels the part maps label it with over both states' training
    /// views (empty without part maps, or not known yet): what its measurement has to match.
    #[serde(default)]
    pub part_pixels: Vec<u64>,
}

impl Capture {
    /// The capture of `dataset` (its start state's training views; `None` without any).
    pub fn of(dataset: &Dataset) -> Option<Self> {
        let frames = &dataset.views(State::Start, Split::Train)?.frames;
        let first = frames.first()?;
        let movable = dataset.num_parts.saturating_sub(1);
        let mut part_pixels = vec![0u64; movable];
        let maps = State::ALL
            .into_iter()
            .filter_map(|state| dataset.views(state, Split::Train))
            .flat_map(|v| &v.frames)
            .filter_map(|f| f.parts.as_ref());
        for map in maps {
            // Part 0 is the base, negative ids the background.
            for &id in &map.ids {
                if let Some(n) = usize::try_from(id)
                    .ok()
                    .filter(|&i| i > 0)
                    .and_then(|i| part_pixels.get_mut(i - 1))
                {
                    *n += 1;
                }
            }
        }
        if first.parts.is_none() {
            part_pixels.clear();
        }
        Some(Self {
            width: first.rgba.width,
            height: first.rgba.height,
            views: frames.len(),
            movable_parts: movable,
            depth: first.depth.is_some(),
            part_pixels,
        })
    }
}

/// A fit's work, stage by stage (see the module comment).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitWork {
    /// Full-resolution training pixels over both states, when the depth maps are measured
    /// (measured surfaces or measured joints); 0 when they are not.
    pub depth_pixels: u64,
    pub movable_parts: usize,
    /// The capture's [`Capture::part_pixels`] where the joints are measured (empty otherwise).
    pub part_pixels: Vec<u64>,
    /// Pixels of one training view at the working size, and training views per state.
    pub working_pixels: u64,
    pub views: usize,
    /// Steps of each state's surface optimisation (0: its surfaces are measured from depth).
    pub surface_steps: u32,
    /// Steps of each state's recovery after remeshing.
    pub recovery_steps: u32,
    /// Steps of the joint candidates and of the refinement, when the photometric stages run
    /// (they do only for a joint the depth maps leave open, or with the geometry off).
    pub candidate_steps: u32,
    pub refine_steps: u32,
    /// Renders per refinement step.
    pub refine_renders: usize,
    /// The refinement checks whether its objective is flat every `refine_check_every` steps and
    /// can stop at the second check: `refine_min_steps` is the least it runs.
    pub refine_check_every: u32,
    pub refine_min_steps: u32,
    /// Whether the photometric stages run whatever the depth maps say (geometry off or seed).
    pub photometric_always: bool,
}

impl FitWork {
    /// The work of fitting `capture` with `config`.
    pub fn of(config: &FitConfig, capture: &Capture) -> Self {
        let rec = &config.reconstruction;
        let art = &config.articulation;
        let longest = capture.width.max(capture.height).max(1);
        // As the working views are made (`downsample_frame`): an integer factor.
        let factor = match rec.max_size {
            0 => 1,
            n => longest.div_ceil(n).max(1),
        };
        let working_pixels = u64::from((capture.width / factor).max(1))
            * u64::from((capture.height / factor).max(1));
        let views = match rec.max_views {
            0 => capture.views,
            n => n.min(capture.views),
        };
        // Without depth maps the surfaces are optimised and nothing is measured.
        let measured_surfaces = capture.depth && rec.surface == SurfaceSource::Measured;
        let measures_depth =
            capture.depth && (measured_surfaces || art.geometry != GeometryUse::Off);
        let depth_pixels = if measures_depth {
            2 * capture.views as u64 * u64::from(capture.width) * u64::from(capture.height)
        } else {
            0
        };
        let decide = art.decision_step();
        Self {
            depth_pixels,
            movable_parts: capture.movable_parts,
            part_pixels: if measures_depth && art.geometry != GeometryUse::Off {
                capture.part_pixels.clone()
            } else {
                Vec::new()
            },
            working_pixels,
            views,
            surface_steps: if measured_surfaces {
                0
            } else {
                rec.fit.iterations
            },
            recovery_steps: rec.recovery_iterations,
            candidate_steps: decide,
            refine_steps: art.iterations - decide,
            refine_renders: art.refine_renders(views),
            refine_check_every: art.report_every.max(1),
            refine_min_steps: (2 * art.report_every.max(1)).min(art.iterations - decide),
            photometric_always: art.geometry != GeometryUse::Settle,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::preset::Preset;

    const CAPTURE: Capture = Capture {
        width: 256,
        height: 256,
        views: 12,
        movable_parts: 2,
        depth: true,
        part_pixels: Vec::new(),
    };

    #[test]
    fn fast_reads_the_depth_and_trains_at_its_working_size() {
        let w = FitWork::of(&FitConfig::preset(Preset::Fast), &CAPTURE);
        assert_eq!(w.depth_pixels, 2 * 12 * 256 * 256);
        assert_eq!((w.working_pixels, w.views), (64 * 64, 12));
        assert_eq!(w.surface_steps, 0, "fast measures its surfaces");
        assert_eq!(w.candidate_steps + w.refine_steps, 300);
        assert_eq!(w.refine_renders, 24);
        assert_eq!((w.refine_check_every, w.refine_min_steps), (20, 40));
        assert!(!w.photometric_always);
    }

    #[test]
    fn a_capture_counts_each_movable_parts_labelled_pixels_in_both_states() {
        use crate::data::fixture::{FixtureParams, small_dataset};
        let dataset = small_dataset(FixtureParams::default());
        let capture = Capture::of(&dataset).unwrap();
        assert_eq!((capture.width, capture.height, capture.views), (16, 12, 3));
        assert_eq!(capture.movable_parts, 2);
        let labelled = |part: i16| -> u64 {
            let train = State::ALL.map(|s| dataset.views(s, Split::Train).unwrap());
            let frames = train.iter().flat_map(|v| &v.frames);
            let maps = frames.map(|f| f.parts.as_ref().unwrap());
            maps.map(|m| m.ids.iter().filter(|&&id| id == part).count() as u64)
                .sum()
        };
        assert_eq!(capture.part_pixels, [labelled(1), labelled(2)]);
        assert!(capture.part_pixels.iter().all(|&n| n > 0));
        let unlabelled = small_dataset(FixtureParams {
            semantic: false,
            ..FixtureParams::default()
        });
        assert!(Capture::of(&unlabelled).unwrap().part_pixels.is_empty());
    }

    #[test]
    fn tiny_optimises_its_surfaces_and_paper_measures_no_depth() {
        let tiny = FitWork::of(&FitConfig::preset(Preset::Tiny), &CAPTURE);
        assert_eq!(tiny.working_pixels, 32 * 32);
        assert!(tiny.surface_steps > 0);
        let paper = FitWork::of(&FitConfig::preset(Preset::Paper), &CAPTURE);
        assert_eq!(paper.depth_pixels, 0);
        assert!(paper.photometric_always);
        let no_depth = Capture {
            depth: false,
            ..CAPTURE
        };
        let fast = FitWork::of(&FitConfig::preset(Preset::Fast), &no_depth);
        assert_eq!(fast.depth_pixels, 0);
        assert!(
            fast.surface_steps > 0,
            "without depth, fast optimises its surfaces"
        );
    }
}
