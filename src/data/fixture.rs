//! Sample data: a tiny procedural dataset (the CLI's `demo` sample and the tests' base) and writers for foreign
//! layouts (ArtGS / MPArt-90 / PARIS). The malformed-dataset catalogue built on it lives in the top-level
//! fixtures module.
//!
//! Public so the CLI, native integration tests and browser (wasm) tests share them. Everything is deterministic,
//! needs no file system and no GPU, and runs in milliseconds.

use glam::{Quat, Vec3};
use serde_json::{Value, json};

use super::camera::{Camera, Intrinsics, look_at};
use super::dataset::Dataset;
use super::error::DataError;
use super::frame::Frame;
use super::gt::{self, GtJoint, GtMeshes, JointKind};
use super::image_io::{DepthMap, PartMap, RgbaImage};
use super::npy::encode_npy;
use super::ply::{PlyFormat, TriMesh};
use super::view_set::ViewSet;
use super::{FileSet, GT_TRANS_PATH, Split, State, transforms_file_name};

/// Shape of the generated dataset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FixtureParams {
    /// Image width (default 16; non-square on purpose).
    pub width: u32,
    /// Image height (default 12).
    pub height: u32,
    /// Train views per state (default 3).
    pub train_views: usize,
    /// Test views per state (default 1; 0 = no test split).
    pub test_views: usize,
    /// Movable parts (default 2: one revolute, one prismatic; kinds alternate).
    pub movable_parts: usize,
    /// Generate depth maps.
    pub depth: bool,
    /// Generate semantic maps.
    pub semantic: bool,
    /// Generate `gt/trans.json`.
    pub gt_joints: bool,
    /// Generate GT meshes for both states.
    pub gt_meshes: bool,
}

impl Default for FixtureParams {
    fn default() -> Self {
        FixtureParams {
            width: 16,
            height: 12,
            train_views: 3,
            test_views: 1,
            movable_parts: 2,
            depth: true,
            semantic: true,
            gt_joints: true,
            gt_meshes: true,
        }
    }
}

/// Small deterministic hash for image patterns.
fn hash(a: u32, b: u32, c: u32) -> u32 {
    let mut h =
        a.wrapping_mul(0x9E37_79B1) ^ b.wrapping_mul(0x85EB_CA77) ^ c.wrapping_mul(0xC2B2_AE3D);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^ (h >> 12)
}

/// The fixture's joints: even movable parts revolute about a vertical axis, odd ones prismatic.
pub(crate) fn fixture_joints(movable_parts: usize) -> Vec<GtJoint> {
    (0..movable_parts)
        .map(|k| {
            let kf = k as f32;
            if k % 2 == 0 {
                GtJoint {
                    kind: JointKind::Revolute,
                    origin: Vec3::new(0.3 + 0.1 * kf, -0.2, 0.0),
                    direction: Vec3::Z,
                    start: 0.0,
                    end: 35.0 + 5.0 * kf,
                }
            } else {
                GtJoint {
                    kind: JointKind::Prismatic,
                    origin: Vec3::new(0.0, 0.1 * kf, 0.25),
                    // Not unit length on purpose: values are kept as in the file.
                    direction: Vec3::new(0.0, 2.0, 0.0),
                    start: 0.05,
                    end: 0.25 + 0.01 * kf,
                }
            }
        })
        .collect()
}

/// Axis-aligned box as 8 vertices and 12 outward-facing triangles.
pub fn box_mesh(min: Vec3, max: Vec3) -> TriMesh {
    let positions = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        })
        .collect();
    let triangles = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6], // z-, z+
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7], // y-, y+
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5], // x-, x+
    ];
    TriMesh {
        positions,
        triangles,
    }
}

fn tetrahedron(centre: Vec3, size: f32) -> TriMesh {
    let positions = vec![
        centre + Vec3::new(size, size, size),
        centre + Vec3::new(size, -size, -size),
        centre + Vec3::new(-size, size, -size),
        centre + Vec3::new(-size, -size, size),
    ];
    TriMesh {
        positions,
        triangles: vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
    }
}

/// Applies a joint's motion from start to end to a mesh.
fn move_by(mesh: &TriMesh, joint: &GtJoint) -> TriMesh {
    let axis = joint.unit_direction();
    let positions = mesh
        .positions
        .iter()
        .map(|&p| match joint.kind {
            JointKind::Revolute => {
                Quat::from_axis_angle(axis, joint.motion().to_radians()) * (p - joint.origin)
                    + joint.origin
            }
            JointKind::Prismatic => p + axis * joint.motion(),
        })
        .collect();
    TriMesh {
        positions,
        triangles: mesh.triangles.clone(),
    }
}

fn gt_meshes(joints: &[GtJoint], state: State) -> GtMeshes {
    let movable = joints
        .iter()
        .enumerate()
        .map(|(k, j)| {
            let m = tetrahedron(Vec3::new(0.2 * k as f32, 0.3, 0.5), 0.08);
            if state == State::End {
                move_by(&m, j)
            } else {
                m
            }
        })
        .collect();
    GtMeshes {
        static_part: box_mesh(Vec3::new(-0.5, -0.3, 0.0), Vec3::new(0.5, 0.3, 0.4)),
        movable,
    }
}

fn frame(
    p: &FixtureParams,
    state: State,
    split: Split,
    i: usize,
    count: usize,
    num_parts: usize,
) -> Frame {
    let (w, h) = (p.width, p.height);
    let s = state.index() as u32;
    let seed = (i as u32) + 16 * s + if split == Split::Test { 8 } else { 0 };
    let offset = if split == Split::Test { 0.5 } else { 0.0 } + 0.2 * s as f32;
    let angle = std::f32::consts::TAU * (i as f32 + offset) / count.max(1) as f32;
    let eye = Vec3::new(2.0 * angle.cos(), 2.0 * angle.sin(), 0.6 + 0.1 * s as f32);
    let camera = Camera {
        camera_to_world: look_at(eye, Vec3::new(0.0, 0.0, 0.2), Vec3::Z),
        intrinsics: Intrinsics::from_fov(w, h, 0.9, Some(0.6)),
    };
    let mut pixels = Vec::with_capacity((w * h * 4) as usize);
    let mut millimetres = Vec::with_capacity((w * h) as usize);
    let mut ids = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let r = hash(x, y, seed);
            // Background border at the left and top, a half-transparent stripe, the rest opaque.
            let alpha: u8 = if x < 2 || y < 1 {
                0
            } else if y == h / 2 {
                128
            } else {
                255
            };
            pixels.extend_from_slice(&[
                (x * 16) as u8 ^ (r as u8 & 7),
                (y * 20 + 50 * s) as u8,
                (r >> 8) as u8,
                alpha,
            ]);
            let depth = if alpha == 0 || r.is_multiple_of(11) {
                0
            } else {
                1500 + 10 * x + 7 * y + 3 * seed + (r % 5)
            };
            millimetres.push(depth.min(u32::from(u16::MAX)) as u16);
            // Vertical bands of parts 0..num_parts-1; the right-most band is the last part.
            let id = if alpha == 0 {
                -1
            } else {
                (x as usize * num_parts / w as usize) as i16
            };
            ids.push(id);
        }
    }
    Frame {
        name: format!("{i:04}"),
        camera,
        time: state.default_time(),
        rgba: RgbaImage {
            width: w,
            height: h,
            pixels,
        },
        depth: p.depth.then_some(DepthMap {
            width: w,
            height: h,
            millimetres,
        }),
        parts: p.semantic.then_some(PartMap {
            width: w,
            height: h,
            ids,
        }),
    }
}

/// A tiny synthetic dataset: cameras on a circle looking at the origin, patterned RGBA with partial alpha,
/// depth with invalid pixels, part bands, joints and GT meshes as chosen in `params`.
pub fn small_dataset(params: FixtureParams) -> Dataset {
    let joints = fixture_joints(params.movable_parts);
    let has_parts = params.semantic || params.gt_joints || params.gt_meshes;
    let num_parts = if has_parts {
        params.movable_parts + 1
    } else {
        1
    };
    let mut views = Vec::new();
    for state in State::ALL {
        for (split, count) in [
            (Split::Train, params.train_views),
            (Split::Test, params.test_views),
        ] {
            if count > 0 {
                let frames = (0..count)
                    .map(|i| frame(&params, state, split, i, count, num_parts))
                    .collect();
                views.push(ViewSet {
                    state,
                    split,
                    frames,
                });
            }
        }
    }
    Dataset {
        views,
        num_parts,
        gt_meshes: State::ALL.map(|s| params.gt_meshes.then(|| gt_meshes(&joints, s))),
        gt_joints: params.gt_joints.then_some(joints),
    }
}

/// An MPArt-90-style `.npy` of `<i4` values with shape (h, w).
pub fn write_npy_i32(h: usize, w: usize, data: &[i32]) -> Vec<u8> {
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    encode_npy("<i4", false, &[h, w], &bytes)
}

/// An MPArt-90-style `.npy` of `<i8` values with shape (h, w).
pub fn write_npy_i64(h: usize, w: usize, data: &[i64]) -> Vec<u8> {
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    encode_npy("<i8", false, &[h, w], &bytes)
}

/// A PARIS-style `trans.json` whose `trans_info` is one joint object rather than a list.
pub(crate) fn paris_trans_json(joint: &GtJoint) -> Vec<u8> {
    gt::write_trans_single(joint)
}

/// Writes `ds` the way ArtGS / GaussianArt (MPArt-90) data looks: `camera_angle_x`/`camera_angle_y` only,
/// `file_path` as `./start/train/rgba/0000` (no extension), `<i8` `.npy` semantic maps with -1 background,
/// a PARIS single-object `gt/trans.json` when there is exactly one joint, ascii PLY static meshes and PARIS's
/// `{state}_dynamic_rotate.ply` name for a single movable mesh. Images are written as by [`Dataset::to_files`].
pub fn artgs_style_files(ds: &Dataset) -> Result<FileSet, DataError> {
    let mut files = ds.to_files()?;
    files.retain(|k, _| {
        !k.contains("/semantic/") && !k.starts_with("transforms_") && !k.starts_with("gt/")
    });
    for view in &ds.views {
        let first = view.frames.first().map(|f| f.camera.intrinsics);
        let frames: Vec<Value> = view
            .frames
            .iter()
            .map(|f| {
                let rows = f.camera.camera_to_world.transpose().to_cols_array_2d();
                json!({
                    "file_path": format!("./{}/{}/rgba/{}", view.state.name(), view.split.name(), f.name),
                    "transform_matrix": rows,
                    "time": f.time,
                })
            })
            .collect();
        let k = first.unwrap_or(Intrinsics {
            width: 1,
            height: 1,
            fx: 1.0,
            fy: 1.0,
            cx: 0.5,
            cy: 0.5,
        });
        let doc =
            json!({ "camera_angle_x": k.fov_x(), "camera_angle_y": k.fov_y(), "frames": frames });
        files.insert(
            transforms_file_name(view.split, view.state),
            serde_json::to_vec_pretty(&doc).unwrap_or_default(),
        );
        for f in &view.frames {
            if let Some(m) = &f.parts {
                let ids: Vec<i64> = m.ids.iter().map(|&i| i64::from(i)).collect();
                let path = format!(
                    "{}/{}/semantic/{}.npy",
                    view.state.name(),
                    view.split.name(),
                    f.name
                );
                files.insert(
                    path,
                    write_npy_i64(m.height as usize, m.width as usize, &ids),
                );
            }
        }
    }
    match ds.gt_joints.as_deref() {
        Some([single]) => {
            files.insert(GT_TRANS_PATH.into(), paris_trans_json(single));
        }
        Some(joints) => {
            files.insert(GT_TRANS_PATH.into(), gt::write_trans(joints));
        }
        None => {}
    }
    for state in State::ALL {
        if let Some(m) = ds.gt_meshes_for(state) {
            files.insert(
                gt::static_mesh_path(state),
                m.static_part.to_ply(PlyFormat::Ascii),
            );
            if let [single] = m.movable.as_slice() {
                files.insert(
                    gt::single_movable_mesh_path(state),
                    single.to_ply(PlyFormat::BinaryLittleEndian),
                );
            } else {
                for (i, mesh) in m.movable.iter().enumerate() {
                    files.insert(
                        gt::movable_mesh_path(state, i),
                        mesh.to_ply(PlyFormat::BinaryLittleEndian),
                    );
                }
            }
        }
    }
    Ok(files)
}

/// A `size`² frame seen from `eye` looking down −z (1 rad wide) whose depth is `depth_at(x, y)`
/// metres where that is `Some` (opaque there) and background elsewhere: what depth-evidence tests
/// look through.
pub fn depth_frame(eye: Vec3, size: u32, depth_at: &dyn Fn(u32, u32) -> Option<f32>) -> Frame {
    let pixels = (0..size * size).map(|i| depth_at(i % size, i / size));
    Frame {
        name: "0000".into(),
        camera: Camera::from_fov(look_at(eye, eye - Vec3::Z, Vec3::Y), size, size, 1.0, None),
        time: 0.0,
        rgba: RgbaImage {
            width: size,
            height: size,
            pixels: pixels
                .clone()
                .flat_map(|d| [9, 9, 9, if d.is_some() { 255 } else { 0 }])
                .collect(),
        },
        depth: Some(DepthMap {
            width: size,
            height: size,
            millimetres: pixels
                .map(|d| d.map_or(0, |d| (d * 1000.0) as u16))
                .collect(),
        }),
        parts: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixture_is_deterministic_and_valid() {
        let a = small_dataset(FixtureParams::default());
        assert_eq!(a, small_dataset(FixtureParams::default()));
        assert_eq!(a.views.len(), 4);
        assert_eq!(a.num_parts, 3);
        // Every camera sees the target near the image centre.
        for f in a.frames() {
            let (px, _) = f.camera.project(Vec3::new(0.0, 0.0, 0.2)).unwrap();
            assert!((px - glam::Vec2::new(8.0, 6.0)).length() < 1e-3);
        }
    }
}
