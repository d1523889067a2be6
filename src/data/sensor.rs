//! The sensor model of a capture: which camera the rendered frames are made to look as if they
//! came from. [`SensorModel::Ideal`] keeps the exact renders (the benchmark protocol);
//! [`SensorModel::Consumer`] degrades each frame as a consumer RGB-D camera and a learned
//! part segmenter would (depth in `depth`, part maps in `parts`); [`SensorModel::ConsumerTracked`]
//! also writes camera poses with the error of SLAM / AR tracking. Colour and the alpha mask stay
//! as rendered. Every parameter is a named constant with its source (docs/method.md, "Sensor
//! model"). A frame is degraded from its own seed ([`frame_seed`]), so it comes out the same
//! however many views were rendered before it.

pub mod depth;
pub mod parts;
mod pixels;
#[cfg(test)]
mod tests;

pub use pixels::REFERENCE_WIDTH;

use glam::{Mat4, Quat, Vec3};

use super::camera::Camera;
use super::frame::Frame;
use super::{Split, State};
use crate::rng::Rng;

/// Camera-pose rotation error σ (degrees, about each camera axis; about 0.43° in all) of
/// [`SensorModel::ConsumerTracked`]. An engineering choice matching the 0.2–0.5° for
/// SLAM / ARKit tracking over an object-sized capture.
pub const POSE_ROTATION_SIGMA_DEG: f32 = 0.25;

/// Camera-position error σ (mm, along each camera axis; about 8.7 mm in all) of
/// [`SensorModel::ConsumerTracked`]: the size of RGB-D SLAM's absolute trajectory error on
/// desk-sized scenes, 4–16 mm RMSE for ORB-SLAM2 on the TUM RGB-D fr1/fr2 desk and xyz
/// sequences (Mur-Artal & Tardós 2017, "ORB-SLAM2", IEEE T-RO, Table 3; benchmark: Sturm et al.
/// 2012, IROS). The issue asks for 5–10 mm.
pub const POSE_TRANSLATION_SIGMA_MM: f32 = 5.0;

/// Which camera a capture's frames look as if they came from (see the module docs).
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum SensorModel {
    /// Exact renders: depth to the millimetre, exact part maps (the benchmark protocol).
    #[default]
    Ideal,
    /// A consumer RGB-D camera's depth (noise growing with depth squared, edge errors, flying
    /// pixels, dropouts, holes, nothing at grazing incidence) and a learned segmenter's part
    /// maps (boundaries 1–2 px off, now and then a wrong blob); exact camera poses.
    Consumer,
    /// [`SensorModel::Consumer`], with camera poses off by SLAM / AR tracking's error
    /// ([`POSE_ROTATION_SIGMA_DEG`], [`POSE_TRANSLATION_SIGMA_MM`]) in the written dataset (the
    /// images are rendered from the true poses).
    ConsumerTracked,
}

/// A sensor name that is none of [`SensorModel::ALL`]'s.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown sensor model '{0}': expected ideal, consumer or consumer-tracked")]
pub struct UnknownSensor(pub String);

impl SensorModel {
    /// Every model, in the order front ends list them.
    pub const ALL: [SensorModel; 3] = [
        SensorModel::Ideal,
        SensorModel::Consumer,
        SensorModel::ConsumerTracked,
    ];

    /// The name the CLI, the page and JSON use: `"ideal"`, `"consumer"`, `"consumer-tracked"`.
    pub fn name(self) -> &'static str {
        match self {
            SensorModel::Ideal => "ideal",
            SensorModel::Consumer => "consumer",
            SensorModel::ConsumerTracked => "consumer-tracked",
        }
    }

    /// A short description for a person choosing one.
    pub fn label(self) -> &'static str {
        match self {
            SensorModel::Ideal => "ideal (exact renders)",
            SensorModel::Consumer => "consumer depth camera",
            SensorModel::ConsumerTracked => "consumer depth camera, tracked poses",
        }
    }

    /// Degrades `frame` in place as this sensor would have captured it, reproducibly for `seed`
    /// (see [`frame_seed`]). Ideal leaves it untouched. Images whose size disagrees with their
    /// pixel count are left as they are.
    pub fn degrade(self, frame: &mut Frame, seed: u64) {
        if self == SensorModel::Ideal {
            return;
        }
        // One stream per image, so a change to one model leaves the others' draws alone.
        let mut streams = Rng::new(seed);
        let (depth_seed, parts_seed, pose_seed) =
            (streams.next_u64(), streams.next_u64(), streams.next_u64());
        if let Some(map) = frame.depth.as_mut() {
            depth::degrade_depth(map, &frame.camera.intrinsics, &mut Rng::new(depth_seed));
        }
        if let Some(map) = frame.parts.as_mut() {
            parts::degrade_parts(map, &frame.rgba, &mut Rng::new(parts_seed));
        }
        if self == SensorModel::ConsumerTracked {
            perturb_pose(&mut frame.camera, &mut Rng::new(pose_seed));
        }
    }
}

impl std::fmt::Display for SensorModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SensorModel {
    type Err = UnknownSensor;

    /// One of the names of [`SensorModel::name`], any case, surrounding blanks ignored.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let wanted = text.trim();
        SensorModel::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(wanted))
            .ok_or_else(|| UnknownSensor(wanted.chars().take(40).collect()))
    }
}

/// The seed that degrades view `view` of `split` in `state` of a capture drawn with
/// `capture_seed`: a hash of all four, so it does not depend on the views rendered before.
pub fn frame_seed(capture_seed: u64, state: State, split: Split, view: usize) -> u64 {
    // A fixed salt keeps the sensor's draws apart from the capture's own use of its seed.
    let base = Rng::new(capture_seed ^ 0x5e45_0a11_d3e7_c0de).next_u64();
    let split_bit = match split {
        Split::Train => 0,
        Split::Test => 1,
    };
    let key = (view as u64)
        .wrapping_mul(4)
        .wrapping_add(2 * state.index() as u64 + split_bit);
    Rng::new(base ^ key).next_u64()
}

/// Moves the written camera by a small rigid error: a rotation about and a shift along the
/// camera's own axes (the images stay as rendered from the true pose).
fn perturb_pose(camera: &mut Camera, rng: &mut Rng) {
    let mut draw = |sigma: f32| Vec3::new(rng.normal(), rng.normal(), rng.normal()) * sigma;
    let rotation = Quat::from_scaled_axis(draw(POSE_ROTATION_SIGMA_DEG.to_radians()));
    let shift = draw(POSE_TRANSLATION_SIGMA_MM / 1000.0);
    camera.camera_to_world *= Mat4::from_rotation_translation(rotation, shift);
}
