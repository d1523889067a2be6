//! The result viewer's scene, independent of where it is drawn: an articulated object at
//! adjustable joint values, coloured by its own colours or by part, with each joint's axis as a
//! thin rod, seen by an orbiting camera; when the truth is known, the true parts as a ghost
//! ([`ghost_over`]) articulated along with the fitted ones. The page draws it on a WebGPU canvas
//! ([`super::GtRenderer::render_view`]); tests render it off-screen.

mod opening;
pub mod palette;

use glam::{Affine3A, Quat, Vec3};

use super::{PartMesh, RenderedView, object_bounds, posed_part_meshes};
use crate::data::{Camera, RgbaImage, look_at};
use crate::object::{ArticulatedObject, JointKind, Material, box_mesh};
pub use opening::{Coverage, OLD_DEFAULT, OpeningView, SCORE_SIZE, coverage, view_score};
use palette::{PRISMATIC_ROD, REVOLUTE_ROD, TRUTH_PART, TRUTH_ROD, part_colour, part_css};

/// Vertical field of view of the viewer's camera (radians).
const FOV_Y: f32 = 0.7;

/// One movable joint as the viewer's sliders show it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ViewJoint {
    /// Index into the object's joints.
    pub index: usize,
    pub name: String,
    #[serde(rename = "type")]
    pub kind: &'static str,
    /// Slider range and the two observed states, in degrees (revolute) or metres (prismatic).
    pub lower: f32,
    pub upper: f32,
    pub start: f32,
    pub end: f32,
    pub unit: &'static str,
}

impl ViewJoint {
    /// Slider units per joint unit (degrees per radian for revolute joints).
    fn scale(&self) -> f32 {
        if self.kind == "revolute" {
            1f32.to_degrees()
        } else {
            1.0
        }
    }
}

/// The viewer's state: object, joint values and camera.
#[derive(Debug, Clone)]
pub struct TwinScene {
    object: ArticulatedObject,
    joints: Vec<ViewJoint>,
    /// One value per joint of the object (radians / metres).
    values: Vec<f32>,
    start: Vec<f32>,
    end: Vec<f32>,
    pub colour_by_part: bool,
    pub show_axes: bool,
    /// The true joint axes (a point on each and its unit direction, world frame, fixed: every
    /// part hangs from the base), drawn in [`TRUTH_ROD`] while `show_truth` is on.
    pub truth_axes: Vec<(Vec3, Vec3)>,
    pub show_truth: bool,
    /// The true object, when known, drawn as a ghost while `show_truth_parts` is on.
    truth: Option<TruthParts>,
    pub show_truth_parts: bool,
    centre: Vec3,
    radius: f32,
    /// Camera azimuth and elevation (radians) and distance as a multiple of the framing distance.
    yaw: f32,
    pitch: f32,
    zoom: f32,
}

impl TwinScene {
    /// The scene of `object` at its start state (every joint at 0), with `end` the end state's
    /// joint values; framed on both states.
    pub fn new(object: ArticulatedObject, end: Vec<f32>) -> TwinScene {
        let start = vec![0.0; object.joints.len()];
        let mut end = end;
        end.resize(object.joints.len(), 0.0);
        let joints = object
            .joints
            .iter()
            .enumerate()
            .filter_map(|(index, j)| {
                let kind = match j.kind {
                    JointKind::Revolute | JointKind::Continuous => "revolute",
                    JointKind::Prismatic => "prismatic",
                    JointKind::Fixed => return None,
                };
                let (lo, hi) = j.range()?;
                let mut joint = ViewJoint {
                    index,
                    name: j.name.clone(),
                    kind,
                    lower: lo,
                    upper: hi,
                    start: 0.0,
                    end: end[index],
                    unit: if kind == "revolute" { "°" } else { "m" },
                };
                let s = joint.scale();
                (joint.lower, joint.upper, joint.end) = (lo * s, hi * s, end[index] * s);
                Some(joint)
            })
            .collect();
        let both: Vec<PartMesh> = [&start, &end]
            .into_iter()
            .flat_map(|q| posed_part_meshes(&object, q))
            .collect();
        let (lo, hi) = object_bounds(&both).unwrap_or((Vec3::splat(-0.5), Vec3::splat(0.5)));
        TwinScene {
            values: start.clone(),
            object,
            joints,
            start,
            end,
            colour_by_part: false,
            show_axes: true,
            truth_axes: Vec::new(),
            show_truth: true,
            truth: None,
            show_truth_parts: false,
            centre: (lo + hi) * 0.5,
            radius: ((hi - lo).length() * 0.5).max(1e-3),
            yaw: OLD_DEFAULT.0,
            pitch: OLD_DEFAULT.1,
            zoom: 1.0,
        }
    }

    /// The movable joints, in slider order.
    pub fn joints(&self) -> &[ViewJoint] {
        &self.joints
    }

    /// The current value of each slider (degrees / metres).
    pub fn slider_values(&self) -> Vec<f32> {
        self.joints
            .iter()
            .map(|j| self.values[j.index] * j.scale())
            .collect()
    }

    /// Sets slider `i` to `value` (degrees / metres), clamped to its range; `false` when there is
    /// no such slider or the value is not a number.
    pub fn set_joint(&mut self, i: usize, value: f32) -> bool {
        let Some(j) = self.joints.get(i) else {
            return false;
        };
        if !value.is_finite() {
            return false;
        }
        let (lo, hi) = (j.lower.min(j.upper), j.lower.max(j.upper));
        let index = j.index;
        self.values[index] = value.clamp(lo, hi) / j.scale();
        if let Some(truth) = &mut self.truth {
            truth.follow(index, self.values[index]);
        }
        true
    }

    /// Puts every joint at the start (`false`) or end (`true`) state, the true parts too.
    pub fn set_state(&mut self, end: bool) {
        self.set_phase(if end { 1.0 } else { 0.0 });
    }

    /// Puts every joint `t` of the way from the start state (0) to the end state (1), the true
    /// parts too (each along its own motion): what the play button animates.
    pub fn set_phase(&mut self, t: f32) {
        let t = if t.is_finite() { t } else { 0.0 };
        let lerp = |a: &[f32], b: &[f32]| a.iter().zip(b).map(|(a, b)| a + (b - a) * t).collect();
        self.values = lerp(&self.start, &self.end);
        if let Some(truth) = &mut self.truth {
            truth.values = lerp(&truth.start, &truth.end);
        }
    }

    /// Adds the true object, `end` its end state's joint values (start: all 0). `pairs` says
    /// which true joint each fitted joint is (indices into the two objects' joints): those
    /// follow the sliders — at the same value when the kinds agree (turned to the fitted axis's
    /// sense), else at the same share of their motion; the others move with the state buttons
    /// and the play button only.
    pub fn set_truth(
        &mut self,
        object: ArticulatedObject,
        end: Vec<f32>,
        pairs: &[(usize, usize)],
    ) {
        let mut end = end;
        end.resize(object.joints.len(), 0.0);
        let mut follow = vec![None; self.object.joints.len()];
        for &(fitted, truth) in pairs {
            let (Some(f), Some(t)) = (self.object.joints.get(fitted), object.joints.get(truth))
            else {
                continue;
            };
            let gain = if f.kind == t.kind {
                // An axis and its opposite with the opposite motion are the same joint.
                if f.axis.dot(t.axis) < 0.0 { -1.0 } else { 1.0 }
            } else if self.end[fitted] != 0.0 {
                end[truth] / self.end[fitted]
            } else {
                0.0
            };
            follow[fitted] = Some((truth, gain));
        }
        let start = vec![0.0; object.joints.len()];
        let mut truth = TruthParts {
            object,
            values: start.clone(),
            start,
            end,
            follow,
        };
        for (i, &v) in self.values.iter().enumerate() {
            truth.follow(i, v);
        }
        self.truth = Some(truth);
    }

    /// Whether the true parts are known.
    pub fn has_truth_parts(&self) -> bool {
        self.truth.is_some()
    }

    /// The legend of "Colour by part": one entry per part of the fitted object.
    pub fn legend(&self) -> Vec<LegendEntry> {
        let parts = self.object.parts();
        parts
            .parts
            .iter()
            .enumerate()
            .map(|(k, part)| {
                let link = part
                    .links
                    .first()
                    .and_then(|&l| self.object.links.get(l))
                    .map_or_else(String::new, |l| l.name.clone());
                let joint = part.joint.and_then(|j| self.object.joints.get(j));
                let kind = joint.map(|j| match j.kind {
                    JointKind::Prismatic => "slide",
                    JointKind::Fixed => "fixed",
                    JointKind::Revolute | JointKind::Continuous => "hinge",
                });
                // "part_2" reads as "part 2", the joints table's numbering.
                let shown = link.replace('_', " ");
                let name = match kind {
                    None if k == 0 => "base".to_string(),
                    None => shown,
                    Some(kind) => format!("{shown} ({kind})"),
                };
                LegendEntry {
                    part: k,
                    name,
                    link,
                    colour: part_css(k),
                }
            })
            .collect()
    }

    /// The camera's yaw and pitch (radians).
    pub fn view(&self) -> (f32, f32) {
        (self.yaw, self.pitch)
    }

    /// Chooses the opening view (see [`opening`]): the orbit view from which the movable parts
    /// show best at both states; turns the camera there and returns the choice.
    pub fn choose_opening_view(&mut self) -> OpeningView {
        let states = [&self.start, &self.end].map(|q| posed_part_meshes(&self.object, q));
        let parts = self.object.parts().parts.len();
        let (w, h) = SCORE_SIZE;
        let choice = opening::choose(&states, parts, |yaw, pitch| {
            self.camera_at(yaw, pitch, self.zoom, w, h)
        });
        (self.yaw, self.pitch) = (choice.yaw, choice.pitch);
        choice
    }

    /// Turns the camera by `dx`, `dy` pixels of a drag (a full canvas width is about half a turn).
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        if dx.is_finite() && dy.is_finite() {
            self.yaw -= dx * 0.01;
            self.pitch = (self.pitch + dy * 0.01).clamp(-1.5, 1.5);
        }
    }

    /// Moves the camera closer (`factor` > 1) or further away.
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.zoom = (self.zoom / factor).clamp(0.2, 5.0);
        }
    }

    /// The camera for a `width` × `height` image.
    pub fn camera(&self, width: u32, height: u32) -> Camera {
        self.camera_at(self.yaw, self.pitch, self.zoom, width, height)
    }

    /// The camera at `yaw`, `pitch` and `zoom` for a `width` × `height` image.
    fn camera_at(&self, yaw: f32, pitch: f32, zoom: f32, width: u32, height: u32) -> Camera {
        let direction = Vec3::new(
            pitch.cos() * yaw.cos(),
            pitch.cos() * yaw.sin(),
            pitch.sin(),
        );
        let aspect = width.max(1) as f32 / height.max(1) as f32;
        let half = (FOV_Y * 0.5).tan() * aspect.min(1.0);
        let distance = self.radius / half.atan().sin() * 1.1 * zoom;
        let pose = look_at(self.centre + direction * distance, self.centre, Vec3::Z);
        let fov_x = 2.0 * ((FOV_Y * 0.5).tan() * aspect).atan();
        Camera::from_fov(pose, width.max(1), height.max(1), fov_x, None)
    }

    /// The meshes to draw: the posed parts, then the joint axes.
    pub fn meshes(&self) -> Vec<PartMesh> {
        let mut meshes = posed_part_meshes(&self.object, &self.values);
        if self.colour_by_part {
            for m in &mut meshes {
                let c = part_colour(m.part.max(0) as usize);
                m.mesh.colors = Some(vec![c; m.mesh.positions.len()]);
                m.mesh.material.texture = None;
            }
        }
        if self.show_axes {
            let poses = self.object.forward_kinematics(&self.values);
            for j in &self.joints {
                let joint = &self.object.joints[j.index];
                let frame = poses[joint.parent] * joint.origin;
                let axis = frame.transform_vector3(joint.axis).normalize_or(Vec3::X);
                let at = frame.transform_point3(Vec3::ZERO);
                let color = if j.kind == "revolute" {
                    REVOLUTE_ROD
                } else {
                    PRISMATIC_ROD
                };
                meshes.push(self.rod(at, axis, color));
            }
        }
        if self.show_truth {
            for &(at, axis) in &self.truth_axes {
                meshes.push(self.rod(at, axis.normalize_or(Vec3::X), TRUTH_ROD));
            }
        }
        meshes
    }

    /// The true parts to draw as a ghost over [`TwinScene::meshes`] ([`ghost_over`]): empty
    /// unless the truth is known and `show_truth_parts` is on.
    pub fn truth_meshes(&self) -> Vec<PartMesh> {
        let Some(truth) = self.truth.as_ref().filter(|_| self.show_truth_parts) else {
            return Vec::new();
        };
        let mut meshes = posed_part_meshes(&truth.object, &truth.values);
        for m in &mut meshes {
            m.mesh.colors = Some(vec![TRUTH_PART; m.mesh.positions.len()]);
            m.mesh.material.texture = None;
        }
        meshes
    }

    /// A thin rod of `color` through `at` along unit `axis`, a little longer than the object.
    fn rod(&self, at: Vec3, axis: Vec3, color: [f32; 3]) -> PartMesh {
        let rod = self.radius * 1.1;
        let mut mesh = box_mesh(
            Vec3::new(2.0 * rod, rod * 0.02, rod * 0.02),
            Material::default(),
        );
        mesh.colors = Some(vec![color; mesh.positions.len()]);
        let place = Affine3A::from_rotation_translation(Quat::from_rotation_arc(Vec3::X, axis), at);
        PartMesh {
            mesh: mesh.transformed(&place),
            part: -1,
        }
    }
}

/// One entry of the part-colour legend.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LegendEntry {
    /// The part's id (0: the base), as the renderer's part map has it.
    pub part: usize,
    /// What the legend says, e.g. "base" or "part 1 (hinge)".
    pub name: String,
    /// The part's first link, e.g. "part_1", as the URDF names it.
    pub link: String,
    /// Its colour as CSS text (`#rrggbb`).
    pub colour: String,
}

/// The true object beside the fitted one, at its own joint values.
#[derive(Debug, Clone)]
struct TruthParts {
    object: ArticulatedObject,
    values: Vec<f32>,
    start: Vec<f32>,
    end: Vec<f32>,
    /// Per fitted joint: the true joint that follows it and the gain from fitted to true value.
    follow: Vec<Option<(usize, f32)>>,
}

impl TruthParts {
    /// Moves the true joint paired with fitted joint `fitted`, now at `value`.
    fn follow(&mut self, fitted: usize, value: f32) {
        if let Some(&Some((truth, gain))) = self.follow.get(fitted)
            && let Some(slot) = self.values.get_mut(truth)
        {
            *slot = gain * value;
        }
    }
}

/// How much of the true parts' ghost shows: a hatched see-through fill, and an outline round
/// each true part (where its part id changes) so its shape reads over any colour; each fainter
/// where the fitted surface is in front, so a hidden true part still reads without hiding the fit.
const GHOST_FILL: [f32; 2] = [0.6, 0.3];
const GHOST_OUTLINE: [f32; 2] = [1.0, 0.5];

/// The fill is hatched: diagonal stripes this many pixels wide, every other one ghosted. A dark
/// see-through fill alone reads as shading on a grey object (issue 47: the ghost could not be
/// told apart on grey objects); stripes read as the ghost over a surface of any colour, and the
/// fitted surface shows between them.
const HATCH_PX: usize = 3;

/// Lays the true parts' render `truth` over the fitted twin's `fitted` (same camera and size):
/// the truth's colour at [`GHOST_FILL`] inside a part and [`GHOST_OUTLINE`] on its outline, the
/// first value where the truth is nearer (or alone: there as alpha, so the canvas background
/// shows through), the second where it is behind the fitted surface.
pub fn ghost_over(fitted: &RenderedView, truth: &RenderedView) -> RgbaImage {
    let mut out = fitted.rgba.clone();
    let (w, h) = (truth.parts.width as usize, truth.parts.height as usize);
    let ids = &truth.parts.ids;
    // On the outline: a covered pixel with a 4-neighbour of another part (or none, or the edge).
    let outline = |i: usize| {
        let (x, y) = (i % w, i / w);
        let other = |j: usize| ids.get(j).is_none_or(|&id| id != ids[i]);
        x == 0
            || y == 0
            || x + 1 >= w
            || y + 1 >= h
            || other(i - 1)
            || other(i + 1)
            || other(i - w)
            || other(i + w)
    };
    let n = ids.len();
    let same_size = [out.pixels.len(), truth.rgba.pixels.len()] == [4 * n; 2]
        && [fitted.depth_metres.len(), truth.depth_metres.len()] == [n; 2];
    if n != w * h || !same_size {
        return out; // not two renders of one view: nothing to lay over
    }
    for (i, px) in out.pixels.chunks_exact_mut(4).enumerate() {
        let ghost = &truth.rgba.pixels[4 * i..4 * i + 4];
        if ghost[3] == 0 {
            continue;
        }
        let empty = px[3] == 0;
        let behind = !empty && truth.depth_metres[i] > fitted.depth_metres[i];
        let shares = if outline(i) {
            GHOST_OUTLINE
        } else if ((i % w + i / w) / HATCH_PX).is_multiple_of(2) {
            GHOST_FILL
        } else {
            continue;
        };
        let a = shares[usize::from(behind)];
        for c in 0..3 {
            let under = if empty { ghost[c] } else { px[c] } as f32;
            px[c] = (under + (ghost[c] as f32 - under) * a).round() as u8;
        }
        if empty {
            px[3] = (255.0 * a).round() as u8;
        }
    }
    out
}

#[cfg(test)]
mod tests;
