//! The result viewer's scene, independent of where it is drawn: an articulated object at
//! adjustable joint values, coloured by its own colours or by part, with each joint's axis as a
//! thin rod, seen by an orbiting camera. The page draws it on a WebGPU canvas
//! ([`super::GtRenderer::draw`]); tests render it off-screen.

use glam::{Affine3A, Quat, Vec3};

use super::{PartMesh, object_bounds, posed_part_meshes};
use crate::data::{Camera, look_at};
use crate::object::{ArticulatedObject, JointKind, Material, box_mesh};

/// Part colours when colouring by part (linear RGB; part 0, the base, is grey).
const PALETTE: [[f32; 3]; 8] = [
    [0.55, 0.55, 0.55],
    [0.85, 0.25, 0.15],
    [0.15, 0.45, 0.85],
    [0.20, 0.65, 0.25],
    [0.85, 0.65, 0.10],
    [0.55, 0.25, 0.75],
    [0.10, 0.65, 0.70],
    [0.85, 0.40, 0.60],
];
/// Axis rod colours: revolute orange, prismatic blue.
const REVOLUTE_ROD: [f32; 3] = [1.0, 0.45, 0.0];
const PRISMATIC_ROD: [f32; 3] = [0.0, 0.35, 1.0];
/// The true axes' colour, when the truth is known: near black, apart from the fitted ones.
pub const TRUTH_ROD: [f32; 3] = [0.05, 0.05, 0.05];
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
            centre: (lo + hi) * 0.5,
            radius: ((hi - lo).length() * 0.5).max(1e-3),
            yaw: -1.05,
            pitch: 0.45,
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
        self.values[j.index] = value.clamp(lo, hi) / j.scale();
        true
    }

    /// Puts every joint at the start (`false`) or end (`true`) state.
    pub fn set_state(&mut self, end: bool) {
        self.values = if end { &self.end } else { &self.start }.clone();
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
        let direction = Vec3::new(
            self.pitch.cos() * self.yaw.cos(),
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
        );
        let aspect = width.max(1) as f32 / height.max(1) as f32;
        let half = (FOV_Y * 0.5).tan() * aspect.min(1.0);
        let distance = self.radius / half.atan().sin() * 1.1 * self.zoom;
        let pose = look_at(self.centre + direction * distance, self.centre, Vec3::Z);
        let fov_x = 2.0 * ((FOV_Y * 0.5).tan() * aspect).atan();
        Camera::from_fov(pose, width.max(1), height.max(1), fov_x, None)
    }

    /// The meshes to draw: the posed parts, then the joint axes.
    pub fn meshes(&self) -> Vec<PartMesh> {
        let mut meshes = posed_part_meshes(&self.object, &self.values);
        if self.colour_by_part {
            for m in &mut meshes {
                let c = PALETTE[m.part.max(0) as usize % PALETTE.len()];
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{GtJoint, GtMeshes, JointKind as GtKind, TriMesh};
    use crate::export::Twin;

    fn cube(at: Vec3) -> TriMesh {
        let m = box_mesh(Vec3::splat(0.2), Material::default());
        TriMesh {
            positions: m.positions.iter().map(|p| *p + at).collect(),
            triangles: m.indices,
        }
    }

    fn scene() -> TwinScene {
        let start = GtMeshes {
            static_part: cube(Vec3::ZERO),
            movable: vec![
                cube(Vec3::new(0.3, 0.0, 0.0)),
                cube(Vec3::new(0.0, 0.3, 0.0)),
            ],
        };
        let joints = [
            GtJoint {
                kind: GtKind::Revolute,
                origin: Vec3::new(0.2, 0.0, 0.0),
                direction: Vec3::Z,
                start: 0.0,
                end: 60.0,
            },
            GtJoint {
                kind: GtKind::Prismatic,
                origin: Vec3::new(0.0, 0.3, 0.0),
                direction: Vec3::Y,
                start: 0.0,
                end: 0.1,
            },
        ];
        let twin = Twin::from_truth("two", &start, &joints);
        TwinScene::new(twin.visual_object(), twin.end_configuration())
    }

    #[test]
    fn sliders_are_in_degrees_and_metres_and_clamp() {
        let mut s = scene();
        let j = s.joints().to_vec();
        assert_eq!(j.len(), 2);
        assert_eq!((j[0].kind, j[0].unit), ("revolute", "°"));
        assert!(
            (j[0].upper - 60.0).abs() < 1e-3 && j[0].lower == 0.0,
            "{j:?}"
        );
        assert!((j[1].end - 0.1).abs() < 1e-6 && j[1].unit == "m");
        assert_eq!(s.slider_values(), vec![0.0, 0.0]);
        assert!(s.set_joint(0, 200.0) && s.set_joint(1, 0.05));
        let v = s.slider_values();
        assert!(
            (v[0] - 60.0).abs() < 1e-3 && (v[1] - 0.05).abs() < 1e-6,
            "{v:?}"
        );
        assert!(!s.set_joint(2, 1.0) && !s.set_joint(0, f32::NAN));
        s.set_state(true);
        let v = s.slider_values();
        assert!(
            (v[0] - 60.0).abs() < 1e-3 && (v[1] - 0.1).abs() < 1e-6,
            "{v:?}"
        );
        s.set_state(false);
        assert_eq!(s.slider_values(), vec![0.0, 0.0]);
    }

    #[test]
    fn moving_a_slider_moves_only_its_part_and_axes_are_drawn() {
        let mut s = scene();
        let before = s.meshes();
        assert_eq!(before.len(), 3 + 2, "three parts and two axis rods");
        s.set_joint(1, 0.1);
        let after = s.meshes();
        for (a, b) in before.iter().zip(&after) {
            let moved = a.mesh.positions != b.mesh.positions;
            assert_eq!(moved, a.part == 2, "part {} moved: {moved}", a.part);
        }
        let shifted = after[2].mesh.positions[0] - before[2].mesh.positions[0];
        assert!(
            (shifted - Vec3::new(0.0, 0.1, 0.0)).length() < 1e-5,
            "{shifted}"
        );
        s.show_axes = false;
        s.colour_by_part = true;
        let plain = s.meshes();
        assert_eq!(plain.len(), 3);
        assert_eq!(plain[1].mesh.colors.as_ref().unwrap()[0], PALETTE[1]);
        // The true axes are drawn, in their own colour, while asked for.
        s.truth_axes = vec![(Vec3::ZERO, Vec3::Z)];
        let with_truth = s.meshes();
        assert_eq!(with_truth.len(), 4);
        assert_eq!(with_truth[3].mesh.colors.as_ref().unwrap()[0], TRUTH_ROD);
        s.show_truth = false;
        assert_eq!(s.meshes().len(), 3);
    }

    #[test]
    fn the_camera_frames_the_object_and_orbits() {
        let mut s = scene();
        let cam = s.camera(200, 100);
        let (px, _) = cam.project(s.centre).unwrap();
        assert!((px - glam::Vec2::new(100.0, 50.0)).length() < 1e-2, "{px}");
        let p0 = cam.position();
        s.orbit(50.0, 0.0);
        s.zoom(2.0);
        let p1 = s.camera(200, 100).position();
        assert!((p1 - s.centre).length() < (p0 - s.centre).length() * 0.6);
        s.orbit(0.0, 1e6);
        assert!(s.camera(10, 10).position().z > s.centre.z);
    }
}
