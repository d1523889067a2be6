//! The viewer's opening camera: among a handful of orbit views, the one from which every movable
//! part shows best. A view is scored by a small CPU depth buffer (no GPU, so it runs before the
//! first frame and in native tests): for each movable part, the share of the pixels it would
//! cover on its own that stay visible in front of the rest, at both observed states; the view's
//! score is the smallest share. The old fixed view is the first candidate and ties keep the
//! earlier one, so the choice only moves when it shows the parts better.

use glam::Vec2;

use super::super::PartMesh;
use crate::data::Camera;

/// Size of the scoring depth buffer: coarse, as it only needs each part's rough coverage.
pub const SCORE_SIZE: (u32, u32) = (64, 48);
/// Fewer pixels than this on its own and a part counts as not shown (seen edge-on, say).
const MIN_PIXELS: u32 = 3;

/// The fixed view the viewer opened with before views were scored (yaw, pitch in radians).
pub const OLD_DEFAULT: (f32, f32) = (-1.05, 0.45);

/// The orbit views tried, the old default first, then around the object from its yaw outward
/// (so ties settle near it) at three heights.
pub fn candidates() -> Vec<(f32, f32)> {
    let mut views = vec![OLD_DEFAULT];
    let turn = std::f32::consts::TAU / 12.0;
    for pitch in [0.45, 0.2, 0.8] {
        for step in 0..12 {
            // 0, +1, −1, +2, −2, … steps of 30° from the default yaw.
            let k = (step + 1) / 2;
            let sign = if step % 2 == 1 { 1.0 } else { -1.0 };
            let yaw = OLD_DEFAULT.0 + sign * k as f32 * turn;
            if (yaw, pitch) != OLD_DEFAULT {
                views.push((yaw, pitch));
            }
        }
    }
    views
}

/// Per part (index = part id): pixels it covers on its own and pixels of it in front.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Coverage {
    pub alone: u32,
    pub visible: u32,
}

impl Coverage {
    /// The visible share of the part, 0 when it covers fewer than a few pixels.
    pub fn fraction(&self) -> f32 {
        if self.alone < MIN_PIXELS {
            0.0
        } else {
            self.visible as f32 / self.alone as f32
        }
    }
}

/// Coverage of each part id `0..parts` in `meshes` seen by `camera` (pixel centres, nearest
/// surface wins); meshes with a negative or larger part id (axis rods) are left out.
pub fn coverage(meshes: &[PartMesh], camera: &Camera, parts: usize) -> Vec<Coverage> {
    let (w, h) = (camera.intrinsics.width, camera.intrinsics.height);
    let n = (w * h) as usize;
    let mut depth = vec![f32::INFINITY; n];
    let mut owner = vec![usize::MAX; n];
    // One coverage mask per part, so a pixel a part covers twice counts once.
    let mut covered = vec![vec![false; n]; parts];
    for m in meshes {
        let Ok(part) = usize::try_from(m.part) else {
            continue;
        };
        if part >= parts {
            continue;
        }
        let projected: Vec<Option<(Vec2, f32)>> = m
            .mesh
            .positions
            .iter()
            .map(|&p| camera.project(p))
            .collect();
        for tri in &m.mesh.indices {
            let corner = |i: usize| projected.get(tri[i] as usize).copied().flatten();
            // A triangle reaching behind the camera is skipped: the orbit keeps the object in
            // front, so only a stray far vertex could do that.
            let (Some(a), Some(b), Some(c)) = (corner(0), corner(1), corner(2)) else {
                continue;
            };
            raster_triangle([a, b, c], (w, h), |pixel, z| {
                covered[part][pixel] = true;
                if z < depth[pixel] {
                    depth[pixel] = z;
                    owner[pixel] = part;
                }
            });
        }
    }
    let mut out = vec![Coverage::default(); parts];
    for (part, mask) in covered.iter().enumerate() {
        out[part].alone = mask.iter().filter(|&&c| c).count() as u32;
    }
    for &o in &owner {
        if o < parts {
            out[o].visible += 1;
        }
    }
    out
}

/// Calls `hit(pixel index, z-depth)` for every pixel centre inside the projected triangle
/// (pixel, z-depth per corner), depth interpolated as 1/z, which is linear on screen.
fn raster_triangle(t: [(Vec2, f32); 3], (w, h): (u32, u32), mut hit: impl FnMut(usize, f32)) {
    let [(a, za), (b, zb), (c, zc)] = t;
    let edge = |p: Vec2, q: Vec2, r: Vec2| (q - p).perp_dot(r - p);
    let area = edge(a, b, c);
    if !area.is_finite() || area.abs() < 1e-12 {
        return;
    }
    let lo = a.min(b).min(c).floor().max(Vec2::ZERO);
    let hi = a.max(b).max(c).ceil().min(Vec2::new(w as f32, h as f32));
    for y in lo.y as u32..hi.y as u32 {
        for x in lo.x as u32..hi.x as u32 {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let (u, v, s) = (
                edge(b, c, p) / area,
                edge(c, a, p) / area,
                edge(a, b, p) / area,
            );
            if u < 0.0 || v < 0.0 || s < 0.0 {
                continue;
            }
            let inv_z = u / za + v / zb + s / zc;
            hit((y * w + x) as usize, 1.0 / inv_z);
        }
    }
}

/// A view's score: the smallest visible share over movable parts `1..parts` and over the posed
/// `states` (each the meshes of one state), seen by `camera`. 1 when there is no movable part.
pub fn view_score(states: &[Vec<PartMesh>], camera: &Camera, parts: usize) -> f32 {
    states
        .iter()
        .flat_map(|meshes| {
            coverage(meshes, camera, parts)
                .into_iter()
                .skip(1)
                .map(|c| c.fraction())
        })
        .fold(1.0, f32::min)
}

/// The chosen view and how it compares with the old default.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OpeningView {
    /// Camera yaw and pitch (radians).
    pub yaw: f32,
    pub pitch: f32,
    /// Its score (smallest visible share of a movable part, both states).
    pub score: f32,
    /// The old default view's score.
    pub old_score: f32,
}

/// Picks the best of [`candidates`] for `states` of an object with `parts` parts, `camera(yaw,
/// pitch)` giving the camera of each. Ties keep the earlier candidate.
pub fn choose(
    states: &[Vec<PartMesh>],
    parts: usize,
    camera: impl Fn(f32, f32) -> Camera,
) -> OpeningView {
    let mut best: Option<OpeningView> = None;
    for (yaw, pitch) in candidates() {
        let score = view_score(states, &camera(yaw, pitch), parts);
        let old_score = best.map_or(score, |b| b.old_score);
        if best.is_none_or(|b| score > b.score) {
            best = Some(OpeningView {
                yaw,
                pitch,
                score,
                old_score,
            });
        }
        if score >= 1.0 {
            break; // every part wholly in sight: nothing can do better
        }
    }
    best.unwrap_or(OpeningView {
        yaw: OLD_DEFAULT.0,
        pitch: OLD_DEFAULT.1,
        score: 0.0,
        old_score: 0.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::look_at;
    use crate::object::{Material, box_mesh};
    use glam::{Affine3A, Vec3};

    fn cube(at: Vec3, size: f32, part: i16) -> PartMesh {
        let mesh = box_mesh(Vec3::splat(size), Material::default())
            .transformed(&Affine3A::from_translation(at));
        PartMesh { mesh, part }
    }

    fn camera_from(eye: Vec3) -> Camera {
        Camera::from_fov(look_at(eye, Vec3::ZERO, Vec3::Z), 64, 48, 0.8, None)
    }

    #[test]
    fn a_part_behind_another_is_hidden_and_one_beside_it_is_not() {
        // Base at the origin, part 1 behind it on +x, part 2 off to the side on +y.
        let meshes = vec![
            cube(Vec3::ZERO, 0.4, 0),
            cube(Vec3::new(0.6, 0.0, 0.0), 0.2, 1),
            cube(Vec3::new(0.0, 0.6, 0.0), 0.2, 2),
        ];
        let from_front = coverage(&meshes, &camera_from(Vec3::new(-3.0, 0.0, 0.0)), 3);
        assert!(from_front[1].alone > 5, "{from_front:?}");
        assert_eq!(from_front[1].visible, 0, "{from_front:?}");
        assert!(from_front[2].fraction() > 0.99, "{from_front:?}");
        let from_side = camera_from(Vec3::new(0.0, -3.0, 0.3));
        let seen = coverage(&meshes, &from_side, 3);
        assert!(seen[1].fraction() > 0.99, "{seen:?}");
        let states = [meshes];
        assert_eq!(
            view_score(&states, &camera_from(Vec3::new(-3.0, 0.0, 0.0)), 3),
            0.0
        );
        assert!(
            view_score(&states, &from_side, 3) < 0.99,
            "part 2 hides behind the base"
        );
    }

    #[test]
    fn the_choice_finds_a_view_where_the_hidden_part_shows() {
        // Part 1 sits right where the old default looks from, behind the base.
        let (yaw, pitch) = OLD_DEFAULT;
        let dir = Vec3::new(
            pitch.cos() * yaw.cos(),
            pitch.cos() * yaw.sin(),
            pitch.sin(),
        );
        let meshes = vec![cube(Vec3::ZERO, 0.5, 0), cube(-dir * 0.45, 0.15, 1)];
        let camera = |yaw: f32, pitch: f32| {
            let d = Vec3::new(
                pitch.cos() * yaw.cos(),
                pitch.cos() * yaw.sin(),
                pitch.sin(),
            );
            camera_from(d * 3.0)
        };
        let chosen = choose(&[meshes], 2, camera);
        assert!(chosen.old_score < 0.2, "{chosen:?}");
        assert!(chosen.score > 0.9, "{chosen:?}");
        assert!(candidates().contains(&(chosen.yaw, chosen.pitch)));
    }
}
