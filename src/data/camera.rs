//! Pinhole cameras in the OpenGL / NeRF-Blender convention (camera looks down −z, +y up, +x right).
//!
//! Pixel coordinates have their origin at the top-left corner of the image, x to the right and y down, so the
//! centre of pixel (i, j) is (i + 0.5, j + 0.5) and a principal point at (w/2, h/2) is the image centre.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

/// Pinhole intrinsics in pixels.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Intrinsics {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Focal length along x, in pixels.
    pub fx: f32,
    /// Focal length along y, in pixels.
    pub fy: f32,
    /// Principal point x, in pixels from the left edge.
    pub cx: f32,
    /// Principal point y, in pixels from the top edge.
    pub cy: f32,
}

impl Intrinsics {
    /// Intrinsics from horizontal (and optionally vertical) field of view in radians, principal point at the
    /// image centre. Without `fov_y` the pixels are square (`fy = fx`), as in NeRF-Blender files.
    pub fn from_fov(width: u32, height: u32, fov_x: f32, fov_y: Option<f32>) -> Self {
        let (w, h) = (width as f64, height as f64);
        let fx = 0.5 * w / (0.5 * fov_x as f64).tan();
        let fy = fov_y.map_or(fx, |a| 0.5 * h / (0.5 * a as f64).tan());
        Intrinsics {
            width,
            height,
            fx: fx as f32,
            fy: fy as f32,
            cx: (0.5 * w) as f32,
            cy: (0.5 * h) as f32,
        }
    }

    /// Horizontal field of view in radians (`camera_angle_x`).
    pub fn fov_x(&self) -> f32 {
        (2.0 * (0.5 * self.width as f64 / self.fx as f64).atan()) as f32
    }

    /// Vertical field of view in radians (`camera_angle_y`).
    pub(crate) fn fov_y(&self) -> f32 {
        (2.0 * (0.5 * self.height as f64 / self.fy as f64).atan()) as f32
    }

    /// Projects a point in camera coordinates to pixel coordinates; `None` when it is not in front of the camera.
    pub fn project(&self, p_camera: Vec3) -> Option<Vec2> {
        let z = -p_camera.z;
        (z > 0.0).then(|| {
            Vec2::new(
                self.cx + self.fx * p_camera.x / z,
                self.cy - self.fy * p_camera.y / z,
            )
        })
    }

    /// The camera-space point at z-depth `depth` (metres, along −z) seen through `pixel`.
    pub fn unproject(&self, pixel: Vec2, depth: f32) -> Vec3 {
        Vec3::new(
            (pixel.x - self.cx) / self.fx * depth,
            (self.cy - pixel.y) / self.fy * depth,
            -depth,
        )
    }
}

/// A posed pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    /// Camera-to-world rigid transform, OpenGL axes (the `transform_matrix` of the transforms file).
    pub camera_to_world: Mat4,
    /// Pinhole intrinsics.
    pub intrinsics: Intrinsics,
}

impl Camera {
    /// Camera from a pose and a field of view (see [`Intrinsics::from_fov`]).
    pub fn from_fov(
        camera_to_world: Mat4,
        width: u32,
        height: u32,
        fov_x: f32,
        fov_y: Option<f32>,
    ) -> Self {
        Camera {
            camera_to_world,
            intrinsics: Intrinsics::from_fov(width, height, fov_x, fov_y),
        }
    }

    /// World-to-camera transform: the rigid inverse of `camera_to_world` (exact transpose of the rotation).
    pub(crate) fn world_to_camera(&self) -> Mat4 {
        let r = Mat3::from_mat4(self.camera_to_world);
        let t = self.camera_to_world.w_axis.truncate();
        let rt = r.transpose();
        let ti = -(rt * t);
        Mat4::from_cols(
            rt.x_axis.extend(0.0),
            rt.y_axis.extend(0.0),
            rt.z_axis.extend(0.0),
            Vec4::new(ti.x, ti.y, ti.z, 1.0),
        )
    }

    /// Camera centre in world coordinates.
    pub fn position(&self) -> Vec3 {
        self.camera_to_world.w_axis.truncate()
    }

    /// Viewing direction in world coordinates (the camera's −z axis).
    pub fn forward(&self) -> Vec3 {
        -self.camera_to_world.z_axis.truncate()
    }

    /// Projects a world point to (pixel, z-depth in metres); `None` behind the camera.
    pub fn project(&self, world: Vec3) -> Option<(Vec2, f32)> {
        let p = self.world_to_camera().transform_point3(world);
        self.intrinsics.project(p).map(|px| (px, -p.z))
    }

    /// World point at z-depth `depth` (metres) through `pixel`, e.g. to back-project a depth map.
    pub fn unproject(&self, pixel: Vec2, depth: f32) -> Vec3 {
        self.camera_to_world
            .transform_point3(self.intrinsics.unproject(pixel, depth))
    }
}

/// Camera-to-world matrix (OpenGL axes) of a camera at `eye` looking at `target`, with `up` roughly up in the
/// image. Returns the identity rotation at `eye` when `eye == target` or `up` is parallel to the view direction.
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    let back = (eye - target).normalize_or_zero();
    let right = up.cross(back).normalize_or_zero();
    if back == Vec3::ZERO || right == Vec3::ZERO {
        return Mat4::from_translation(eye);
    }
    let true_up = back.cross(right);
    Mat4::from_cols(
        right.extend(0.0),
        true_up.extend(0.0),
        back.extend(0.0),
        eye.extend(1.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_projects_target_to_principal_point() {
        let cam = Camera {
            camera_to_world: look_at(Vec3::new(2.0, -1.0, 0.5), Vec3::ZERO, Vec3::Z),
            intrinsics: Intrinsics::from_fov(16, 12, 0.9, None),
        };
        let (px, depth) = cam.project(Vec3::ZERO).unwrap();
        assert!((px - Vec2::new(8.0, 6.0)).length() < 1e-4, "{px}");
        assert!((depth - Vec3::new(2.0, -1.0, 0.5).length()).abs() < 1e-5);
        // World up projects upwards in the image (smaller y).
        let (up, _) = cam.project(Vec3::new(0.0, 0.0, 0.1)).unwrap();
        assert!(up.y < 6.0);
        let back = cam.unproject(Vec2::new(3.0, 4.0), 1.7);
        let (px2, d2) = cam.project(back).unwrap();
        assert!((px2 - Vec2::new(3.0, 4.0)).length() < 1e-4 && (d2 - 1.7).abs() < 1e-5);
        assert!(
            cam.camera_to_world
                .mul_mat4(&cam.world_to_camera())
                .abs_diff_eq(Mat4::IDENTITY, 1e-6)
        );
    }

    #[test]
    fn fov_round_trip() {
        let k = Intrinsics::from_fov(640, 480, 0.8, Some(0.6));
        assert!((k.fov_x() - 0.8).abs() < 1e-6 && (k.fov_y() - 0.6).abs() < 1e-6);
        assert_eq!((k.cx, k.cy), (320.0, 240.0));
    }
}
