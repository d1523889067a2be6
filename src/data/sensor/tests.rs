//! Tests of the sensor model: reproducibility, the depth noise against Nguyen et al.'s σ_z, the
//! dropout rate, grazing incidence, depth edges, where part maps may change, and bad sizes.

use std::collections::BTreeSet;

use glam::{Mat3, Mat4};

use super::depth::{DROPOUT_RATE, axial_sigma_mm};
use super::parts::{add_wrong_blob, foreground_of, shift_boundaries};
use super::*;
use crate::data::{DepthMap, Intrinsics, PartMap, RgbaImage};

/// A `w`×`h` frame (39.6° field of view) with the given depth and part ids; alpha is 255 where
/// the part id is a part.
fn frame(
    w: usize,
    h: usize,
    depth: impl Fn(usize, usize) -> u16,
    part: impl Fn(usize, usize) -> i16,
) -> Frame {
    let ids = grid(w, h, part);
    let rgba = ids
        .iter()
        .flat_map(|&id| [90, 120, 150, if id >= 0 { 255 } else { 0 }])
        .collect();
    let (w32, h32) = (w as u32, h as u32);
    Frame {
        name: "0000".into(),
        camera: Camera::from_fov(Mat4::IDENTITY, w32, h32, 0.691_111, None),
        time: 0.0,
        rgba: RgbaImage {
            width: w32,
            height: h32,
            pixels: rgba,
        },
        depth: Some(DepthMap {
            width: w32,
            height: h32,
            millimetres: grid(w, h, depth),
        }),
        parts: Some(PartMap {
            width: w32,
            height: h32,
            ids,
        }),
    }
}

/// `f` at every pixel of a `w`×`h` image, row-major.
fn grid<T>(w: usize, h: usize, f: impl Fn(usize, usize) -> T) -> Vec<T> {
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| f(x, y))
        .collect()
}

/// A 160² cabinet-like view: a foreground square of three parts side by side (the middle one
/// 10 cm nearer) on an empty background.
fn scene() -> Frame {
    let inside = |x: usize, y: usize| (30..130).contains(&x) && (30..130).contains(&y);
    let part = move |x: usize, y: usize| match (inside(x, y), x) {
        (false, _) => -1,
        (true, ..70) => 0,
        (true, ..100) => 1,
        _ => 2,
    };
    frame(
        160,
        160,
        move |x, y| match part(x, y) {
            -1 => 0,
            1 => 1100,
            _ => 1200,
        },
        part,
    )
}

fn flat(size: usize, mm: u16) -> Frame {
    frame(size, size, |_, _| mm, |_, _| 0)
}

fn depth_of(frame: &Frame) -> &[u16] {
    &frame.depth.as_ref().unwrap().millimetres
}

fn ids_of(frame: &Frame) -> &[i16] {
    &frame.parts.as_ref().unwrap().ids
}

fn degraded(mut frame: Frame, model: SensorModel, seed: u64) -> Frame {
    model.degrade(&mut frame, seed);
    frame
}

#[test]
fn ideal_leaves_the_frame_unchanged() {
    for seed in [0, 7, u64::MAX] {
        assert_eq!(degraded(scene(), SensorModel::Ideal, seed), scene());
    }
}

#[test]
fn a_seed_gives_the_same_bytes_and_another_seed_others() {
    for model in [SensorModel::Consumer, SensorModel::ConsumerTracked] {
        let a = degraded(scene(), model, 11);
        assert_eq!(a, degraded(scene(), model, 11), "{model}");
        let b = degraded(scene(), model, 12);
        assert_ne!(depth_of(&a), depth_of(&b), "{model}");
        assert_ne!(ids_of(&a), ids_of(&b), "{model}");
        // Colour and the mask stay as rendered.
        assert_eq!(a.rgba, scene().rgba);
    }
}

#[test]
fn depth_noise_matches_nguyen_at_1_m_and_2_5_m() {
    // The published curve: about 1.9 mm at 1 m and 8–10 mm at 2.5 m.
    assert!((axial_sigma_mm(1.0, 0.0) - 1.884).abs() < 1e-3);
    assert!((8.0..10.0).contains(&axial_sigma_mm(2.5, 0.0)));
    for mm in [1000u16, 2500] {
        let out = degraded(flat(256, mm), SensorModel::Consumer, 3);
        let errors: Vec<f64> = depth_of(&out)
            .iter()
            .filter(|&&d| d != 0)
            .map(|&d| f64::from(d) - f64::from(mm))
            .collect();
        let n = errors.len() as f64;
        let mean = errors.iter().sum::<f64>() / n;
        let std = (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / n).sqrt();
        let expected = f64::from(axial_sigma_mm(f32::from(mm) / 1000.0, 0.0));
        assert!(
            (std / expected - 1.0).abs() < 0.15,
            "{mm} mm: measured σ {std:.3} mm, model {expected:.3} mm"
        );
        assert!(mean.abs() < 0.1 * expected, "{mm} mm: bias {mean:.3} mm");
    }
}

#[test]
fn dropouts_come_at_the_stated_rate() {
    let out = degraded(flat(400, 1500), SensorModel::Consumer, 5);
    let dropped = depth_of(&out).iter().filter(|&&d| d == 0).count();
    let rate = dropped as f32 / (400.0 * 400.0);
    // The i.i.d. rate plus a few holes of at most 3 px radius at this width.
    assert!(
        rate > 0.85 * DROPOUT_RATE && rate < 1.25 * DROPOUT_RATE,
        "dropped {rate:.4}"
    );
}

/// A 64² view through a narrow lens of a plane turned `degrees` away from the camera.
fn tilted_plane(degrees: f32) -> Frame {
    let slope = degrees.to_radians().tan();
    let mut f = frame(
        64,
        64,
        move |x, _| {
            let a = (x as f32 + 0.5 - 32.0) / 2000.0;
            (1000.0 / (1.0 - slope * a)).round() as u16
        },
        |_, _| 0,
    );
    f.camera.intrinsics = Intrinsics {
        width: 64,
        height: 64,
        fx: 2000.0,
        fy: 2000.0,
        cx: 32.0,
        cy: 32.0,
    };
    f
}

#[test]
fn grazing_surfaces_lose_their_depth() {
    let zero_share = |frame: &Frame| {
        depth_of(frame).iter().filter(|&&d| d == 0).count() as f32 / depth_of(frame).len() as f32
    };
    let steep = degraded(tilted_plane(85.0), SensorModel::Consumer, 1);
    assert!(zero_share(&steep) > 0.95, "85°: {}", zero_share(&steep));
    let slanted = degraded(tilted_plane(60.0), SensorModel::Consumer, 1);
    assert!(zero_share(&slanted) < 0.05, "60°: {}", zero_share(&slanted));
}

#[test]
fn depth_edges_are_shifted_dropped_or_mixed_near_the_edge_only() {
    // Left half at 1 m, right half at 1.5 m: one vertical edge between x = 99 and 100.
    let step = |x: usize| if x < 100 { 1000 } else { 1500 };
    let (mut shifted, mut mixed, mut dropped) = (0, 0, 0);
    for seed in 0..4 {
        let out = degraded(
            frame(200, 200, |x, _| step(x), |_, _| 0),
            SensorModel::Consumer,
            seed,
        );
        for (i, &d) in depth_of(&out).iter().enumerate() {
            let x = i % 200;
            let near_edge = (97..103).contains(&x);
            let ideal = step(x);
            let noise_ok = f32::from(d.abs_diff(ideal)) < 6.0 * axial_sigma_mm(1.5, 0.0);
            if !near_edge {
                assert!(d == 0 || noise_ok, "x {x}: {d} mm far from the edge");
                continue;
            }
            match d {
                0 => dropped += 1,
                _ if noise_ok => {}
                _ if f32::from(d.abs_diff(step(199 - x))) < 30.0 => shifted += 1,
                _ => mixed += 1,
            }
        }
    }
    assert!(
        shifted > 50 && mixed > 50 && dropped > 50,
        "{shifted} {mixed} {dropped}"
    );
}

/// The Chebyshev distance from pixel `i` to the nearest pixel of `ideal` labelled `label`
/// (up to 3; 4 when none is that close).
fn distance_to_label(ideal: &[i16], w: usize, i: usize, label: i16) -> usize {
    let (x, y) = ((i % w) as i64, (i / w) as i64);
    let h = (ideal.len() / w) as i64;
    (0..=3)
        .find(|&r| {
            (-r..=r).any(|dy| {
                (-r..=r).any(|dx| {
                    let (sx, sy) = (x + dx, y + dy);
                    (0..w as i64).contains(&sx)
                        && (0..h).contains(&sy)
                        && ideal[(sy * w as i64 + sx) as usize] == label
                })
            })
        })
        .map_or(4, |r| r as usize)
}

#[test]
fn part_changes_stay_within_two_pixels_of_a_boundary() {
    let f = scene();
    let ideal = ids_of(&f).to_vec();
    let parts = f.parts.as_ref().unwrap();
    let foreground = foreground_of(parts, &f.rgba);
    let mut far = 0;
    let mut changed = 0;
    for seed in 0..8 {
        let mut ids = ideal.clone();
        shift_boundaries(
            &mut ids,
            &ideal,
            &foreground,
            (160, 160),
            &mut Rng::new(seed),
        );
        for (i, (&new, &old)) in ids.iter().zip(&ideal).enumerate() {
            if new == old {
                continue;
            }
            changed += 1;
            let distance = distance_to_label(&ideal, 160, i, new);
            assert!(
                distance <= 2,
                "pixel {i}: {old} → {new}, {distance} px away"
            );
            far += usize::from(distance == 2);
        }
    }
    // Boundaries do move, some of them by the full 2 px.
    assert!(
        changed > 8 * 100 && far > 0,
        "{changed} changed, {far} by 2 px"
    );
}

#[test]
fn no_part_label_outside_the_foreground() {
    for seed in 0..16 {
        let out = degraded(scene(), SensorModel::Consumer, seed);
        for (id, px) in ids_of(&out).iter().zip(out.rgba.pixels.chunks_exact(4)) {
            assert!(
                px[3] > 0 || *id == -1,
                "seed {seed}: label {id} on the background"
            );
        }
    }
}

#[test]
fn a_wrong_blob_is_another_visible_label_inside_the_foreground() {
    // At 800 px the blob is 3–8 px in radius.
    let f = frame(
        800,
        800,
        |_, _| 1000,
        |x, y| match (x, y) {
            (..100, _) | (_, ..100) => -1,
            (..400, _) => 0,
            _ => 3,
        },
    );
    let ideal = ids_of(&f).to_vec();
    let foreground = foreground_of(f.parts.as_ref().unwrap(), &f.rgba);
    for seed in 0..10 {
        let mut ids = ideal.clone();
        add_wrong_blob(
            &mut ids,
            &ideal,
            &foreground,
            (800, 800),
            &mut Rng::new(seed),
        );
        let changed: Vec<usize> = (0..ids.len()).filter(|&i| ids[i] != ideal[i]).collect();
        assert!(!changed.is_empty(), "seed {seed}: no blob");
        let labels: BTreeSet<i16> = changed.iter().map(|&i| ids[i]).collect();
        assert!(labels.len() == 1 && (labels.contains(&0) || labels.contains(&3)));
        assert!(changed.iter().all(|&i| foreground[i]));
        let xs = changed.iter().map(|&i| i % 800);
        let ys = changed.iter().map(|&i| i / 800);
        let span = |v: Vec<usize>| v.iter().max().unwrap() - v.iter().min().unwrap();
        assert!(span(xs.collect()) <= 16 && span(ys.collect()) <= 16);
    }
}

#[test]
fn frame_seeds_differ_by_state_split_and_view() {
    let mut seen = BTreeSet::new();
    for state in State::ALL {
        for split in Split::ALL {
            for view in 0..200 {
                assert!(seen.insert(frame_seed(5, state, split, view)));
            }
        }
    }
    assert_ne!(
        frame_seed(5, State::Start, Split::Train, 0),
        frame_seed(6, State::Start, Split::Train, 0)
    );
}

#[test]
fn names_parse_and_round_trip() {
    for model in SensorModel::ALL {
        assert_eq!(model.name().parse::<SensorModel>(), Ok(model));
        let json = serde_json::to_string(&model).unwrap();
        assert_eq!(json, format!("\"{}\"", model.name()));
        assert_eq!(serde_json::from_str::<SensorModel>(&json).unwrap(), model);
    }
    assert_eq!(" Consumer ".parse(), Ok(SensorModel::Consumer));
    assert_eq!(SensorModel::default(), SensorModel::Ideal);
    let err = "kinect".parse::<SensorModel>().unwrap_err();
    assert!(
        err.to_string()
            .contains("ideal, consumer or consumer-tracked")
    );
}

#[test]
fn pose_error_is_small_rigid_and_only_when_tracked() {
    let truth = scene().camera.camera_to_world;
    assert_eq!(
        degraded(scene(), SensorModel::Consumer, 2)
            .camera
            .camera_to_world,
        truth
    );
    let mut squared_mm = 0.0;
    for seed in 0..64 {
        let pose = degraded(scene(), SensorModel::ConsumerTracked, seed)
            .camera
            .camera_to_world;
        let r = Mat3::from_mat4(pose);
        assert!((r.transpose() * r).abs_diff_eq(Mat3::IDENTITY, 1e-5));
        assert!((r.determinant() - 1.0).abs() < 1e-5);
        let angle = (((r.x_axis.x + r.y_axis.y + r.z_axis.z - 1.0) / 2.0).clamp(-1.0, 1.0))
            .acos()
            .to_degrees();
        assert!(angle < 3.0, "seed {seed}: turned {angle}°");
        squared_mm += (pose.w_axis.truncate().length() * 1000.0).powi(2);
    }
    let rms_mm = (squared_mm / 64.0).sqrt();
    let expected = POSE_TRANSLATION_SIGMA_MM * 3f32.sqrt();
    assert!((rms_mm / expected - 1.0).abs() < 0.3, "rms {rms_mm} mm");
}

#[test]
fn mismatched_sizes_are_left_alone() {
    let mut f = scene();
    f.depth.as_mut().unwrap().millimetres.pop();
    f.parts.as_mut().unwrap().ids.push(1);
    let before = f.clone();
    SensorModel::Consumer.degrade(&mut f, 1);
    assert_eq!(f, before);
    // A colour image of another size: the part map's own labels are the foreground.
    let mut f = scene();
    f.rgba.width = 7;
    SensorModel::ConsumerTracked.degrade(&mut f, 1);
    for (id, old) in ids_of(&f).iter().zip(ids_of(&scene())) {
        assert!(*old >= 0 || *id == -1);
    }
    // Empty images.
    let mut empty = frame(0, 0, |_, _| 0, |_, _| 0);
    SensorModel::Consumer.degrade(&mut empty, 1);
    let mut one = frame(1, 1, |_, _| 500, |_, _| 0);
    SensorModel::Consumer.degrade(&mut one, 1);
}
