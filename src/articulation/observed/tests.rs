//! Unit tests of the observation stage: the depth noise and the plane-fitted samples.

use super::sampling::{MAX_NORMAL_ERROR, frame_samples, view_noise};
use super::*;
use crate::data::{Camera, DepthMap, PartMap, RgbaImage};
use crate::rng::Rng;

/// A `size`² view of a wall facing the camera at `metres`, every pixel of part 0, its depth
/// with Gaussian noise of `sigma_mm` and rounded to the millimetre as a depth PNG holds it.
fn wall(size: u32, metres: f32, sigma_mm: f32, seed: u64) -> Frame {
    let mut rng = Rng::new(seed);
    let n = (size * size) as usize;
    let millimetres = (0..n)
        .map(|_| (1000.0 * metres + sigma_mm * rng.normal()).round() as u16)
        .collect();
    Frame {
        name: "0000".into(),
        camera: Camera::from_fov(glam::Mat4::IDENTITY, size, size, 0.691, None),
        time: 0.0,
        rgba: RgbaImage {
            width: size,
            height: size,
            pixels: vec![200; 4 * n],
        },
        depth: Some(DepthMap {
            width: size,
            height: size,
            millimetres,
        }),
        parts: Some(PartMap {
            width: size,
            height: size,
            ids: vec![0; n],
        }),
    }
}

#[test]
fn the_depth_noise_is_estimated_from_the_map_alone() {
    for (sigma, metres) in [(2.0, 1.0), (8.0, 2.5)] {
        let frame = wall(200, metres, sigma, 7);
        let d = frame.depth.as_ref().unwrap();
        let ids = &frame.parts.as_ref().unwrap().ids;
        let (est, at) = view_noise(&d.millimetres, ids, 200, 200, 1).unwrap();
        // Rounding adds 1/12 mm² of variance.
        let expected = (sigma * sigma + 1.0 / 12.0).sqrt() / 1000.0;
        assert!((est / expected - 1.0).abs() < 0.1, "{est} vs {expected}");
        assert!((at - metres).abs() < 0.01, "{at}");
    }
    // Noise-free depth: only the rounding, and samples from the nearest neighbours.
    let frame = wall(200, 2.0, 0.0, 7);
    let (_, _, noise) = frame_samples(&frame, 1, 4);
    let noise = noise.unwrap();
    assert!(noise.sigma < 0.000_5, "{noise:?}");
    assert_eq!(noise.reach, 1);
}

#[test]
fn noisy_depth_is_averaged_over_a_plane_fit() {
    // 8 mm of noise at 2.5 m with 800 px across 39.6°: a pixel covers 2.3 mm, so the
    // nearest neighbours' normals would be noise; the plane fits must average it away.
    let frame = wall(800, 2.5, 8.0, 3);
    let (samples, _, noise) = frame_samples(&frame, 1, 8);
    let noise = noise.unwrap();
    assert!(noise.reach > 1, "{noise:?}");
    assert!(!samples.is_empty());
    let n = samples.len() as f32;
    let rms_z = (samples
        .iter()
        .map(|s| (s.point.z + 2.5).powi(2))
        .sum::<f32>()
        / n)
        .sqrt();
    // Each sample averages (2R + 1)² pixels: its depth error is σ / (2R + 1) or so.
    assert!(rms_z < 0.008 / 3.0, "{rms_z}");
    // Each normal's error is at most MAX_NORMAL_ERROR per tangent direction (how the reach
    // is chosen), so the RMS tilt is within √2 of it.
    let tilt = (samples
        .iter()
        .map(|s| s.normal.angle_between(Vec3::Z).powi(2))
        .sum::<f32>()
        / n)
        .sqrt();
    assert!(tilt < std::f32::consts::SQRT_2 * MAX_NORMAL_ERROR, "{tilt}");
    assert!(
        samples
            .iter()
            .all(|s| s.variance < (0.008f32).powi(2) / 9.0),
        "per-sample variance"
    );
}
