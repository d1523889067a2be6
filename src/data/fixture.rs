//! Test fixtures: a tiny procedural dataset, writers for foreign layouts (ArtGS / MPArt-90 / PARIS), and a
//! catalogue of malformed datasets with the error each must produce.
//!
//! Public so native integration tests and browser (wasm) tests share them. Everything is deterministic,
//! needs no file system and no GPU, and runs in milliseconds.

use glam::{Quat, Vec3};
use serde_json::{Value, json};

use super::camera::{Camera, Intrinsics, look_at};
use super::dataset::{Dataset, Frame, ViewSet};
use super::error::DataError;
use super::gt::{self, GtJoint, GtMeshes, JointKind};
use super::image_io::{DepthMap, PartMap, PngPixels, RgbaImage, encode_png};
use super::npy::encode_npy;
use super::ply::{PlyFormat, TriMesh};
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
pub fn fixture_joints(movable_parts: usize) -> Vec<GtJoint> {
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

/// The default fixture written in our layout: the base of the malformed catalogue.
pub fn good_files() -> FileSet {
    // The fixture is valid by construction; an empty set here would make every test fail loudly.
    small_dataset(FixtureParams::default())
        .to_files()
        .unwrap_or_default()
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
pub fn paris_trans_json(joint: &GtJoint) -> Vec<u8> {
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

/// One malformed dataset: how to break [`good_files`] and the error the reader must report.
#[derive(Debug, Clone, Copy)]
pub struct MalformedCase {
    /// Short identifier.
    pub name: &'static str,
    /// Breaks a copy of [`good_files`].
    pub mutate: fn(&mut FileSet),
    /// Expected [`DataError::file`].
    pub file: &'static str,
    /// Expected [`DataError::field`] (exact), when the case pins it.
    pub field: Option<&'static str>,
    /// Text the error message must contain.
    pub message: &'static str,
}

impl MalformedCase {
    /// The broken file set.
    pub fn files(&self) -> FileSet {
        let mut files = good_files();
        (self.mutate)(&mut files);
        files
    }

    /// Whether `e` is the error this case expects.
    pub fn matches(&self, e: &DataError) -> bool {
        e.file == self.file
            && self.field.is_none_or(|f| e.field.as_deref() == Some(f))
            && e.message.contains(self.message)
    }
}

/// Parses a JSON file of the set, lets `f` edit it, writes it back (pretty-printed).
fn edit_json(files: &mut FileSet, path: &str, f: impl FnOnce(&mut Value)) {
    if let Some(mut v) = files
        .get(path)
        .and_then(|b| serde_json::from_slice::<Value>(b).ok())
    {
        f(&mut v);
        files.insert(
            path.into(),
            serde_json::to_vec_pretty(&v).unwrap_or_default(),
        );
    }
}

/// Replaces the text `"__SENTINEL__"` (quotes included) in a file by `raw`, e.g. to inject a bare `NaN`.
fn replace_sentinel(files: &mut FileSet, path: &str, raw: &str) {
    if let Some(b) = files.get_mut(path) {
        *b = String::from_utf8_lossy(b)
            .replace("\"__SENTINEL__\"", raw)
            .into_bytes();
    }
}

fn matrix_row(v: &mut Value, frame: usize, row: usize) -> Option<&mut Vec<Value>> {
    v.get_mut("frames")?
        .get_mut(frame)?
        .get_mut("transform_matrix")?
        .get_mut(row)?
        .as_array_mut()
}

fn gray16(w: u32, h: u32, value: u16) -> Vec<u8> {
    encode_png(
        "fixture",
        w,
        h,
        PngPixels::Gray16(&vec![value; (w * h) as usize]),
    )
    .unwrap_or_default()
}

/// 16x12 semantic map, all part 0 except `id` at pixel (5, 5).
fn ids_with(id: i32) -> Vec<i32> {
    let mut ids = vec![0; 16 * 12];
    if let Some(p) = ids.get_mut(5 * 16 + 5) {
        *p = id;
    }
    ids
}

fn set_npy_semantic(files: &mut FileSet, frame: &str, bytes: Vec<u8>) {
    files.remove(&format!("{frame}.png"));
    files.insert(format!("{frame}.npy"), bytes);
}

fn edit_trans(files: &mut FileSet, f: impl FnOnce(&mut Value)) {
    edit_json(files, GT_TRANS_PATH, f);
}

/// Malformed datasets, each made by one mutation of [`good_files`], with the error it must produce.
pub fn malformed_catalogue() -> Vec<MalformedCase> {
    const TS: &str = "transforms_train_start.json";
    const TE: &str = "transforms_train_end.json";
    let case = |name, mutate, file, field, message| MalformedCase {
        name,
        mutate,
        file,
        field,
        message,
    };
    vec![
        case(
            "missing rgba file",
            |f| {
                f.remove("start/train/rgba/0001.png");
            },
            TS,
            Some("frames[1].file_path"),
            "refers to start/train/rgba/0001.png, which is not in the dataset",
        ),
        case(
            "truncated rgba PNG",
            |f| {
                if let Some(b) = f.get_mut("start/train/rgba/0000.png") {
                    b.truncate(b.len() / 2);
                }
            },
            "start/train/rgba/0000.png",
            None,
            "could not decode PNG",
        ),
        case(
            "not a PNG at all",
            |f| {
                f.insert("end/test/rgba/0000.png".into(), b"GIF89a".to_vec());
            },
            "end/test/rgba/0000.png",
            None,
            "could not decode PNG",
        ),
        case(
            "16-bit rgba PNG",
            |f| {
                let px = vec![1000u16; 16 * 12 * 4];
                f.insert(
                    "start/train/rgba/0002.png".into(),
                    encode_png("x", 16, 12, PngPixels::Rgba16(&px)).unwrap_or_default(),
                );
            },
            "start/train/rgba/0002.png",
            Some("bit depth"),
            "expected an 8-bit RGBA or RGB PNG, found 16-bit RGBA",
        ),
        case(
            "8-bit depth PNG",
            |f| {
                f.insert(
                    "start/train/depth/0000.png".into(),
                    encode_png("x", 16, 12, PngPixels::Gray8(&[7; 192])).unwrap_or_default(),
                );
            },
            "start/train/depth/0000.png",
            Some("bit depth"),
            "expected a 16-bit single-channel PNG, found 8-bit single-channel",
        ),
        case(
            "8-bit RGB depth PNG",
            |f| {
                f.insert(
                    "end/train/depth/0001.png".into(),
                    encode_png("x", 16, 12, PngPixels::Rgb8(&[7; 576])).unwrap_or_default(),
                );
            },
            "end/train/depth/0001.png",
            Some("bit depth"),
            "expected a 16-bit single-channel PNG, found 8-bit RGB",
        ),
        case(
            "16-bit RGB depth PNG",
            |f| {
                f.insert(
                    "end/train/depth/0002.png".into(),
                    encode_png("x", 16, 12, PngPixels::Rgb16(&[7; 576])).unwrap_or_default(),
                );
            },
            "end/train/depth/0002.png",
            Some("channels"),
            "expected a 16-bit single-channel PNG, found 16-bit RGB",
        ),
        case(
            "depth size mismatch",
            |f| {
                f.insert("start/train/depth/0002.png".into(), gray16(16, 10, 1500));
            },
            "start/train/depth/0002.png",
            Some("size"),
            "expected 16x12 (the size of start/train/rgba/0002.png), found 16x10",
        ),
        case(
            "semantic size mismatch",
            |f| {
                f.insert("end/test/semantic/0000.png".into(), gray16(12, 12, 1));
            },
            "end/test/semantic/0000.png",
            Some("size"),
            "expected 16x12 (the size of end/test/rgba/0000.png), found 12x12",
        ),
        case(
            "depth missing for one frame",
            |f| {
                f.remove("end/train/depth/0002.png");
            },
            "end/train/depth/0002.png",
            None,
            "other frames of end/train have depth maps",
        ),
        case(
            "NaN in a transform matrix",
            |f| {
                edit_json(f, TE, |v| {
                    if let Some(x) = matrix_row(v, 0, 1).and_then(|row| row.get_mut(2)) {
                        *x = json!("__SENTINEL__");
                    }
                });
                replace_sentinel(f, TE, "NaN");
            },
            TE,
            Some("frames[0].transform_matrix[1][2]"),
            "expected a finite number, found NaN",
        ),
        case(
            "scaled (non-rigid) transform matrix",
            |f| {
                edit_json(f, TS, |v| {
                    for r in 0..3 {
                        if let Some(row) = matrix_row(v, 2, r) {
                            for x in row.iter_mut().take(3) {
                                *x = json!(x.as_f64().unwrap_or(0.0) * 1.5);
                            }
                        }
                    }
                });
            },
            TS,
            Some("frames[2].transform_matrix"),
            "not rigid: columns not orthonormal (max deviation 1.25",
        ),
        case(
            "mirrored transform matrix",
            |f| {
                edit_json(f, TS, |v| {
                    for r in 0..3 {
                        if let Some(x) = matrix_row(v, 1, r).and_then(|row| row.first_mut()) {
                            *x = json!(-x.as_f64().unwrap_or(0.0));
                        }
                    }
                });
            },
            TS,
            Some("frames[1].transform_matrix"),
            "not rigid: rotation determinant is -1.0000, expected +1",
        ),
        case(
            "bad last matrix row",
            |f| {
                edit_json(f, TS, |v| {
                    if let Some(row) = matrix_row(v, 0, 3) {
                        *row = vec![json!(0), json!(0), json!(1), json!(1)];
                    }
                });
            },
            TS,
            Some("frames[0].transform_matrix"),
            "expected the last row to be [0, 0, 0, 1], found [0.0, 0.0, 1.0, 1.0]",
        ),
        case(
            "3x4 matrix",
            |f| {
                edit_json(f, TS, |v| {
                    if let Some(m) = v
                        .pointer_mut("/frames/0/transform_matrix")
                        .and_then(Value::as_array_mut)
                    {
                        m.pop();
                    }
                });
            },
            TS,
            Some("frames[0].transform_matrix"),
            "expected a 4x4 matrix (4 rows of 4 numbers), found 3 rows",
        ),
        case(
            "part id out of range in PNG",
            |f| {
                let mut raw = vec![1u16; 192];
                raw[40] = 10; // part 9 of 3
                f.insert(
                    "start/train/semantic/0001.png".into(),
                    encode_png("x", 16, 12, PngPixels::Gray16(&raw)).unwrap_or_default(),
                );
            },
            "start/train/semantic/0001.png",
            Some("part id"),
            "part id 9 at pixel (8, 2) is out of range: expected -1 (background) to 2",
        ),
        case(
            "part id out of range in npy",
            |f| {
                set_npy_semantic(
                    f,
                    "start/test/semantic/0000",
                    write_npy_i32(12, 16, &ids_with(5)),
                );
            },
            "start/test/semantic/0000.npy",
            Some("part id"),
            "part id 5 at pixel (5, 5) is out of range",
        ),
        case(
            "part id below -1 in npy",
            |f| {
                set_npy_semantic(
                    f,
                    "start/test/semantic/0000",
                    write_npy_i64(
                        12,
                        16,
                        &ids_with(-3).into_iter().map(i64::from).collect::<Vec<_>>(),
                    ),
                );
            },
            "start/test/semantic/0000.npy",
            Some("part id"),
            "found -3 at pixel (5, 5)",
        ),
        case(
            "npy with bad magic",
            |f| {
                let mut b = write_npy_i32(12, 16, &ids_with(0));
                b[1] = b'X';
                set_npy_semantic(f, "end/train/semantic/0000", b);
            },
            "end/train/semantic/0000.npy",
            Some("magic"),
            "expected a .npy file starting with \\x93NUMPY",
        ),
        case(
            "npy header claiming a huge shape",
            |f| {
                let b = encode_npy("<i8", false, &[1_000_000, 1_000_000], &[0; 64]);
                set_npy_semantic(f, "end/train/semantic/0001", b);
            },
            "end/train/semantic/0001.npy",
            Some("shape"),
            "header claims shape (1000000, 1000000) of <i8 (8000000000000 bytes)",
        ),
        case(
            "npy of booleans",
            |f| {
                set_npy_semantic(
                    f,
                    "end/train/semantic/0002",
                    encode_npy("|b1", false, &[12, 16], &[0; 192]),
                );
            },
            "end/train/semantic/0002.npy",
            Some("descr"),
            "booleans are not part ids",
        ),
        case(
            "empty frames list",
            |f| {
                edit_json(f, "transforms_test_start.json", |v| v["frames"] = json!([]));
            },
            "transforms_test_start.json",
            Some("frames"),
            "expected at least one frame, found an empty list",
        ),
        case(
            "missing end state",
            |f| {
                f.remove(TE);
            },
            TE,
            None,
            "the train views of both states are required",
        ),
        case(
            "missing frames key",
            |f| {
                edit_json(f, TS, |v| {
                    if let Some(o) = v.as_object_mut() {
                        o.remove("frames");
                    }
                });
            },
            TS,
            Some("frames"),
            "missing (expected a list of frames)",
        ),
        case(
            "string where a number is expected",
            |f| {
                edit_json(f, TS, |v| v["camera_angle_x"] = json!("0.69"));
            },
            TS,
            Some("camera_angle_x"),
            "expected a number, found a string \"0.69\"",
        ),
        case(
            "invalid JSON syntax",
            |f| {
                if let Some(b) = f.get_mut(TE) {
                    b.truncate(b.len() / 3);
                }
            },
            TE,
            None,
            "invalid JSON: EOF while parsing",
        ),
        case(
            "camera_angle_x not positive",
            |f| {
                edit_json(f, TS, |v| v["camera_angle_x"] = json!(0.0));
            },
            TS,
            Some("camera_angle_x"),
            "expected an angle in radians in (0, π), found 0",
        ),
        case(
            "negative focal length",
            |f| {
                edit_json(f, "transforms_test_end.json", |v| v["fl_y"] = json!(-20.0));
            },
            "transforms_test_end.json",
            Some("fl_y"),
            "expected a positive focal length in pixels, found -20",
        ),
        case(
            "no focal length at all",
            |f| {
                edit_json(f, TS, |v| {
                    if let Some(o) = v.as_object_mut() {
                        o.remove("camera_angle_x");
                        o.remove("fl_x");
                    }
                });
            },
            TS,
            Some("camera_angle_x"),
            "missing (expected camera_angle_x, or fl_x",
        ),
        case(
            "infinite time",
            |f| {
                edit_json(f, TS, |v| v["frames"][1]["time"] = json!("__SENTINEL__"));
                replace_sentinel(f, TS, "Infinity");
            },
            TS,
            Some("frames[1].time"),
            "expected a finite number, found inf",
        ),
        case(
            "file_path escaping the dataset folder",
            |f| {
                edit_json(f, TS, |v| v["frames"][0]["file_path"] = json!("../x.png"));
            },
            TS,
            Some("frames[0].file_path"),
            "\"../x.png\" points outside the dataset folder",
        ),
        case(
            "absolute file_path",
            |f| {
                edit_json(f, TS, |v| {
                    v["frames"][2]["file_path"] = json!("/etc/passwd")
                });
            },
            TS,
            Some("frames[2].file_path"),
            "expected a path relative to the dataset folder",
        ),
        case(
            "images of different sizes within a split",
            |f| {
                f.insert(
                    "start/train/rgba/0001.png".into(),
                    encode_png("x", 20, 12, PngPixels::Rgba8(&[200; 960])).unwrap_or_default(),
                );
                f.insert("start/train/depth/0001.png".into(), gray16(20, 12, 1500));
                f.insert("start/train/semantic/0001.png".into(), gray16(20, 12, 1));
            },
            "start/train/rgba/0001.png",
            Some("size"),
            "expected 16x12 (w/h in transforms_train_start.json), found 20x12",
        ),
        case(
            "trans.json with an unknown joint type",
            |f| {
                edit_trans(f, |v| v["trans_info"][1]["type"] = json!("screw"));
            },
            GT_TRANS_PATH,
            Some("trans_info[1].type"),
            "expected \"rotate\" or \"translate\", found \"screw\"",
        ),
        case(
            "trans.json entry without its motion key",
            |f| {
                edit_trans(f, |v| {
                    if let Some(o) = v["trans_info"][0].as_object_mut() {
                        o.remove("rotate");
                    }
                });
            },
            GT_TRANS_PATH,
            Some("trans_info[0].rotate"),
            "missing (expected the motion {\"l\": start, \"r\": end} of a \"rotate\" joint)",
        ),
        case(
            "trans.json zero-length axis",
            |f| {
                edit_trans(f, |v| v["trans_info"][1]["axis"]["d"] = json!([0, 0, 0]));
            },
            GT_TRANS_PATH,
            Some("trans_info[1].axis.d"),
            "expected a non-zero, finite axis direction",
        ),
        case(
            "trans.json trans_info of the wrong type",
            |f| {
                edit_trans(f, |v| v["trans_info"] = json!(5));
            },
            GT_TRANS_PATH,
            Some("trans_info"),
            "expected a list of joints or a joint object, found the number 5",
        ),
        case(
            "truncated PLY",
            |f| {
                if let Some(b) = f.get_mut("gt/start/start_static_rotate.ply") {
                    b.truncate(b.len() - 20);
                }
            },
            "gt/start/start_static_rotate.ply",
            Some("element face"),
            "truncated or malformed: could not read entry 10 of 12",
        ),
        case(
            "PLY face index out of range",
            |f| {
                let mesh = TriMesh {
                    positions: vec![Vec3::ZERO; 3],
                    triangles: vec![[0, 1, 7]],
                };
                f.insert(
                    "gt/end/end_dynamic_0_rotate.ply".into(),
                    mesh.to_ply(PlyFormat::Ascii),
                );
            },
            "gt/end/end_dynamic_0_rotate.ply",
            Some("element face"),
            "triangle 0 refers to vertex 7, but there are 3 vertices",
        ),
        case(
            "GT mesh missing for a part",
            |f| {
                f.remove("gt/end/end_dynamic_1_rotate.ply");
            },
            "gt/end/end_dynamic_1_rotate.ply",
            None,
            "missing: gt/trans.json has 2 joints",
        ),
    ]
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
