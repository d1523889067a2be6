//! Ground-truth renderer: a plain wgpu render pipeline (not the differentiable rasterizer) that turns posed
//! meshes and a [`Camera`] into the three images a dataset frame holds: RGBA (alpha = coverage mask), z-depth
//! and part ids.
//!
//! Conventions:
//! - The projection comes from the pinhole [`Intrinsics`]: a world point lands exactly where
//!   [`Camera::project`] puts it, with pixel centres at `+0.5`.
//! - Depth is the camera-space z-depth in metres (distance along the viewing axis, not ray length, not NDC),
//!   interpolated perspective-correctly from the vertices, so it is exact on planar faces up to `f32` rounding.
//!   [`RenderedView::depth`] holds it in millimetres, rounded, 0 where nothing is covered; depths of 65.535 m
//!   and more are **clamped** to 65 535 mm. [`RenderedView::depth_metres`] keeps the unrounded values.
//! - The depth buffer uses reversed z (`Depth32Float`, near → 1, far → 0, compare `Greater`) with near/far
//!   fitted to the scene's vertices for every view; it only decides visibility.
//! - Shading is deterministic: base colour (the mesh's vertex colours when it has them, else its material's;
//!   × texture, bilinear, repeat) × (0.3 ambient + 0.7 two-sided Lambert
//!   from a headlight at the camera), written sRGB-encoded to `Rgba8Unorm`. Material alpha is ignored: every
//!   surface is opaque. Background is transparent black, part id −1.
//! - No back-face culling: imported meshes do not always wind consistently.
//!
//! The module is async and I/O-free, so it runs natively and in the browser.

mod dataset;
mod pipeline;
mod preview;
mod sheet;
mod view;
pub mod viewer;

pub use dataset::{
    CaptureError, CaptureTruth, DatasetRenderError, MIN_OBJECT_SIZE, ObjectProblem, RenderProgress,
    RenderSpec, RenderedDataset, capture_dataset, capture_truth, render_dataset,
};
pub use pipeline::GtRenderer;
pub use preview::{PreviewTruth, PreviewView, preview};
pub use sheet::{SheetEntry, contact_sheet, overview_camera};

use glam::{Mat4, Vec3};

use crate::data::{DepthMap, PartMap, RgbaImage, look_at};
use crate::object::{ArticulatedObject, RenderMesh};
use crate::rng::Rng;

/// A world-space mesh tagged with the part it belongs to.
#[derive(Debug, Clone, PartialEq)]
pub struct PartMesh {
    /// Geometry and material in world coordinates.
    pub mesh: RenderMesh,
    /// Part id written to the part map (0 = static base, k = movable part k).
    pub part: i16,
}

/// The three images of one rendered view.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderedView {
    /// Shaded colour (sRGB-encoded), alpha 255 where a surface covers the pixel centre, else transparent black.
    pub rgba: RgbaImage,
    /// z-depth in millimetres, rounded; 0 where not covered; clamped to 65 535 (65.535 m).
    pub depth: DepthMap,
    /// Part id of the visible surface, −1 for background.
    pub parts: PartMap,
    /// Unrounded z-depth in metres, row-major, 0 where not covered.
    pub depth_metres: Vec<f32>,
}

/// World-space meshes of `obj` at joint values `q` (see [`ArticulatedObject::forward_kinematics`]), each
/// tagged with its link's part from [`ArticulatedObject::parts`].
pub fn posed_part_meshes(obj: &ArticulatedObject, q: &[f32]) -> Vec<PartMesh> {
    let poses = obj.forward_kinematics(q);
    let parts = obj.parts();
    poses
        .iter()
        .enumerate()
        .flat_map(|(link, pose)| {
            let part = parts.link_part.get(link).copied().unwrap_or(0);
            let part = i16::try_from(part).unwrap_or(i16::MAX);
            obj.link_meshes(link).into_iter().map(move |m| PartMesh {
                mesh: m.transformed(pose),
                part,
            })
        })
        .collect()
}

/// `n` camera-to-world poses (OpenGL axes) on a sphere of `radius` around `centre`, each looking at `centre`
/// with world +z up in the image. Directions are uniform on the sphere, or on its upper half (`z ≥ centre.z`,
/// the z-up convention of the datasets) when `upper_hemisphere` is set. The same seed gives the same poses.
/// Directions within ~0.5° of the poles use +y as the up hint so the pose stays well defined.
pub fn sample_views(
    n: usize,
    centre: Vec3,
    radius: f32,
    seed: u64,
    upper_hemisphere: bool,
) -> Vec<Mat4> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            // Uniform on the sphere: z uniform in [−1, 1] (or [0, 1]), azimuth uniform.
            let u = rng.next_f32();
            let z = if upper_hemisphere { u } else { 2.0 * u - 1.0 };
            let phi = std::f32::consts::TAU * rng.next_f32();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let dir = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let up = if z.abs() > 0.99996 { Vec3::Y } else { Vec3::Z };
            look_at(centre + dir * radius, centre, up)
        })
        .collect()
}

/// Axis-aligned bounds of the finite vertices of `meshes`; `None` when there are none.
pub fn object_bounds(meshes: &[PartMesh]) -> Option<(Vec3, Vec3)> {
    crate::object::mesh_bounds(meshes.iter().map(|m| &m.mesh))
}

/// Joint values for one state: every part's joint at `lower + f · (upper − lower)` of its range with `f` drawn
/// uniformly from `fraction` (Articulate-100 draws the start state from [0.6, 0.8] and the end state from
/// [0.2, 0.4]); every other joint, merged chain joints included, at its rest value. One value per joint.
pub fn sample_state(obj: &ArticulatedObject, fraction: (f32, f32), rng: &mut Rng) -> Vec<f32> {
    let parts = obj.parts();
    let values: Vec<f32> = parts
        .parts
        .iter()
        .map(|part| {
            let f = fraction.0 + (fraction.1 - fraction.0) * rng.next_f32();
            part.joint
                .and_then(|j| obj.joints[j].range())
                .map_or(0.0, |(lo, hi)| lo + f * (hi - lo))
        })
        .collect();
    parts.configuration(obj, &values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{Camera, Intrinsics};

    #[test]
    fn sampled_views_look_at_the_centre_from_the_sphere() {
        let centre = Vec3::new(0.2, -0.1, 0.4);
        for upper in [false, true] {
            let poses = sample_views(64, centre, 2.5, 9, upper);
            assert_eq!(poses, sample_views(64, centre, 2.5, 9, upper));
            assert_ne!(poses, sample_views(64, centre, 2.5, 10, upper));
            let mut below = 0;
            for pose in &poses {
                let cam = Camera {
                    camera_to_world: *pose,
                    intrinsics: Intrinsics::from_fov(16, 12, 1.0, None),
                };
                assert!(((cam.position() - centre).length() - 2.5).abs() < 1e-4);
                let (px, depth) = cam.project(centre).unwrap();
                assert!((px - glam::Vec2::new(8.0, 6.0)).length() < 1e-3, "{px}");
                assert!((depth - 2.5).abs() < 1e-4);
                below += usize::from(cam.position().z < centre.z);
            }
            assert_eq!(below == 0, upper, "{below} of 64 below the centre");
        }
    }
}
