//! Where the training views saw *through*: the evidence that keeps remeshing from closing a real
//! opening.
//!
//! A short boundary loop is usually a gap the depth maps left in a surface, and closing it is right;
//! but the mouth of a drawer's slot, the space between a table's rails or a window's frame are
//! loops too. The difference is in the data: where a view's depth lies well behind a point (or the
//! view saw background there), the ray passed through that point without meeting anything, so no
//! surface can be there. [`FreeSpace`] keeps every training view's depth, min-pooled to a few
//! hundred pixels (a block counts as far only where all of it is far), and a fill face whose
//! points the views see through is left out.

use glam::Vec3;

use crate::data::{Camera, Dataset, Frame, Split, State};

/// Longest side of a pooled depth map (pixels).
const MAX_SIDE: u32 = 256;

/// A view's depth at a point within this many of the part's median edges of the point's own
/// depth measures a surface there; farther behind, the view saw through the point …
const MARGIN_EDGES: f32 = 0.5;
/// … or within this share of the depth, where that is larger (depth noise grows with distance).
const MARGIN_SHARE: f32 = 0.01;

/// A point is free when at least this many views see through it, and they outnumber the views
/// that measure a surface at it: a fill that sticks out past a thin part's rim is seen through
/// only by views that graze the rim; most see the part there.
const MIN_VIEWS: usize = 2;

/// A fill face is refused when at least this many of its four sample points are free.
const MIN_FREE_SAMPLES: usize = 2;

/// Pooled depth of one view: metres to the nearest surface in each block, `f32::INFINITY` where
/// the block is all background, 0 where any pixel of it has no depth (no evidence); and the part
/// that nearest surface belongs to (-1 where the view has no part map).
struct PooledView {
    camera: Camera,
    factor: u32,
    width: u32,
    height: u32,
    depth: Vec<f32>,
    part: Vec<i16>,
}

/// Both states' training views as free-space evidence.
pub struct FreeSpace {
    views: [Vec<PooledView>; 2],
}

impl FreeSpace {
    /// The evidence in `dataset`'s training views; `None` when no view has depth.
    pub fn from_dataset(dataset: &Dataset) -> Option<FreeSpace> {
        let pooled = |state: State| -> Vec<PooledView> {
            dataset
                .views(state, Split::Train)
                .map_or(Vec::new(), |v| v.frames.iter().filter_map(pool).collect())
        };
        let views = [pooled(State::Start), pooled(State::End)];
        (views.iter().any(|v| !v.is_empty())).then_some(FreeSpace { views })
    }

    /// Whether views of `states` see through `p` (see [`MIN_VIEWS`]), on part `part` whose
    /// median edge is `spacing` (metres).
    pub fn is_free(&self, states: &[State], p: Vec3, part: usize, spacing: f32) -> bool {
        let (mut through, mut surface) = (0, 0);
        for view in states.iter().flat_map(|s| &self.views[s.index()]) {
            match view.evidence(p, part, spacing) {
                Some(Evidence::Through) => through += 1,
                Some(Evidence::Surface) => surface += 1,
                None => {}
            }
        }
        through >= MIN_VIEWS && through > surface
    }

    /// Whether `face` (over `positions`, of part `part`) spans space the views of `states` saw
    /// through: its centroid and the points halfway from it to each corner are tested.
    pub fn refuses(
        &self,
        states: &[State],
        positions: &[Vec3],
        face: &[u32; 3],
        part: usize,
        spacing: f32,
    ) -> bool {
        let [a, b, c] = face.map(|i| positions[i as usize]);
        let centroid = (a + b + c) / 3.0;
        let samples = [
            centroid,
            (centroid + a) / 2.0,
            (centroid + b) / 2.0,
            (centroid + c) / 2.0,
        ];
        let free = samples
            .iter()
            .filter(|&&p| self.is_free(states, p, part, spacing))
            .count();
        free >= MIN_FREE_SAMPLES
    }
}

/// What one view says of a point.
enum Evidence {
    /// Its depth there lies well behind the point: the ray passed through it.
    Through,
    /// Its depth there is the point's own, on the point's part (or the view has no part map): a
    /// surface was measured at it. A drawer's front just behind a fill across the cabinet's slot
    /// for it is not the cabinet's surface.
    Surface,
}

impl PooledView {
    /// What this view says of `p` on part `part`; `None` outside the image, where something in
    /// front hides it, or where another part's surface is at it.
    fn evidence(&self, p: Vec3, part: usize, spacing: f32) -> Option<Evidence> {
        let (pixel, z) = self.camera.project(p)?;
        let f = self.factor as f32;
        let (x, y) = ((pixel.x / f).floor(), (pixel.y / f).floor());
        if x < 0.0 || y < 0.0 || x >= self.width as f32 || y >= self.height as f32 {
            return None;
        }
        let i = (y as u32 * self.width + x as u32) as usize;
        let d = self.depth[i];
        let margin = (MARGIN_EDGES * spacing).max(MARGIN_SHARE * z);
        if d == 0.0 {
            None
        } else if d > z + margin {
            Some(Evidence::Through)
        } else if d >= z - margin && (self.part[i] < 0 || self.part[i] as usize == part) {
            Some(Evidence::Surface)
        } else {
            None
        }
    }
}

/// The states whose views show part `part` where a state-`state` reconstruction has it: the static
/// base does not move, so both; a movable part only in its own.
pub fn evidence_states(part: usize, state: State) -> Vec<State> {
    if part == 0 {
        State::ALL.to_vec()
    } else {
        vec![state]
    }
}

/// `frame`'s depth min-pooled to at most [`MAX_SIDE`] pixels a side; `None` without depth.
fn pool(frame: &Frame) -> Option<PooledView> {
    let depth = frame.depth.as_ref()?;
    let factor = depth.width.max(depth.height).div_ceil(MAX_SIDE).max(1);
    let (width, height) = (depth.width.div_ceil(factor), depth.height.div_ceil(factor));
    let mut pooled = vec![f32::INFINITY; (width * height) as usize];
    let mut part = vec![-1i16; pooled.len()];
    for y in 0..depth.height {
        for x in 0..depth.width {
            let i = ((y / factor) * width + x / factor) as usize;
            let background = frame.rgba.pixel(x, y).is_some_and(|p| p[3] == 0);
            let d = match depth.metres(x, y) {
                Some(d) => d,
                None if background => f32::INFINITY,
                None => 0.0,
            };
            if d < pooled[i] {
                pooled[i] = d;
                part[i] = frame.parts.as_ref().and_then(|m| m.id(x, y)).unwrap_or(-1);
            }
        }
    }
    Some(PooledView {
        camera: frame.camera,
        factor,
        width,
        height,
        depth: pooled,
        part,
    })
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::data::fixture::depth_frame;

    /// A view from `eye` down −z whose depth sees a wall at `wall` metres on its left half and
    /// background on its right half.
    fn half_wall(eye: Vec3, wall: f32) -> PooledView {
        pool(&depth_frame(eye, 64, &|x, _| (x < 32).then_some(wall))).unwrap()
    }

    #[test]
    fn points_in_front_of_the_wall_or_over_background_are_free_and_on_it_are_not() {
        let eye = Vec3::new(0.0, 0.0, 2.0);
        let space = FreeSpace {
            views: [vec![half_wall(eye, 1.5), half_wall(eye, 1.5)], Vec::new()],
        };
        let start = [State::Start];
        let free = |states: &[State], p: Vec3| space.is_free(states, p, 0, 0.01);
        assert!(!free(&start, Vec3::new(-0.2, 0.0, 0.5)), "on the wall");
        assert!(!free(&start, Vec3::new(-0.2, 0.0, 0.2)), "behind it");
        assert!(free(&start, Vec3::new(-0.2, 0.0, 1.0)), "well in front");
        assert!(free(&start, Vec3::new(0.2, 0.0, 0.5)), "over background");
        assert!(
            !free(&[State::End], Vec3::new(0.2, 0.0, 0.5)),
            "no end views"
        );

        // A face over the background half is refused; one lying on the wall is kept.
        let positions = [
            Vec3::new(0.1, -0.1, 0.5),
            Vec3::new(0.3, -0.1, 0.5),
            Vec3::new(0.2, 0.1, 0.5),
            Vec3::new(-0.3, -0.1, 0.5),
            Vec3::new(-0.1, -0.1, 0.5),
            Vec3::new(-0.2, 0.1, 0.5),
        ];
        assert!(space.refuses(&start, &positions, &[0, 1, 2], 0, 0.01));
        assert!(!space.refuses(&start, &positions, &[3, 4, 5], 0, 0.01));
    }

    #[test]
    fn only_the_static_base_takes_evidence_from_both_states() {
        assert_eq!(evidence_states(0, State::End), State::ALL.to_vec());
        assert_eq!(evidence_states(2, State::End), vec![State::End]);
    }
}
