//! Dataset reader/writer round trips, foreign layouts (ArtGS / MPArt-90 / PARIS), PLY variants and summaries.
// Native only: the browser runs the same fixture and catalogue from tests/web.rs.

use artmesh::data::fixture::{
    self, FixtureParams, artgs_style_files, small_dataset, write_npy_i32, write_npy_i64,
};
use artmesh::data::{
    Dataset, FileSet, JointKind, PlyFormat, SemanticFormat, Split, State, TriMesh, WriteOptions,
    encode_png, rebase_on_dataset_root,
};
use glam::Vec3;
use serde_json::{Value, json};

fn read(files: &FileSet) -> Dataset {
    match Dataset::from_files(files) {
        Ok(ds) => ds,
        Err(e) => panic!("expected a valid dataset, got:\n{e}"),
    }
}

fn edit_json(files: &mut FileSet, path: &str, f: impl FnOnce(&mut Value)) {
    let mut v: Value = serde_json::from_slice(&files[path]).unwrap();
    f(&mut v);
    files.insert(path.into(), serde_json::to_vec(&v).unwrap());
}

#[test]
fn writer_then_reader_is_the_identity() {
    let ds = small_dataset(FixtureParams::default());
    let files = ds.to_files().unwrap();
    assert_eq!(read(&files), ds);
    // Writing what was read gives the same bytes.
    assert_eq!(read(&files).to_files().unwrap(), files);
}

#[test]
fn writer_produces_exactly_the_documented_layout() {
    let files = small_dataset(FixtureParams::default()).to_files().unwrap();
    let mut expected = vec![
        "gt/trans.json".to_string(),
        "transforms_test_end.json".into(),
        "transforms_test_start.json".into(),
        "transforms_train_end.json".into(),
        "transforms_train_start.json".into(),
    ];
    for state in ["start", "end"] {
        expected.push(format!("gt/{state}/{state}_static_rotate.ply"));
        for i in 0..2 {
            expected.push(format!("gt/{state}/{state}_dynamic_{i}_rotate.ply"));
        }
        for (split, n) in [("train", 3), ("test", 1)] {
            for i in 0..n {
                for kind in ["rgba", "depth", "semantic"] {
                    expected.push(format!("{state}/{split}/{kind}/{i:04}.png"));
                }
            }
        }
    }
    expected.sort();
    assert_eq!(files.keys().cloned().collect::<Vec<_>>(), expected);

    // Both intrinsics conventions are written, and file_path has the extension.
    let t: Value = serde_json::from_slice(&files["transforms_train_start.json"]).unwrap();
    for key in [
        "camera_angle_x",
        "camera_angle_y",
        "fl_x",
        "fl_y",
        "cx",
        "cy",
    ] {
        assert!(t[key].as_f64().unwrap() > 0.0, "{key}");
    }
    assert_eq!((t["w"].as_u64(), t["h"].as_u64()), (Some(16), Some(12)));
    assert_eq!(t["frames"][1]["file_path"], "start/train/rgba/0001.png");
    assert_eq!(t["frames"][1]["time"], 0.0);
    // f32 values are written short, not widened to f64 digits.
    let text = String::from_utf8(files["transforms_train_start.json"].clone()).unwrap();
    assert!(!text.contains("0000000"), "{text}");
}

#[test]
fn round_trips_across_fixture_options() {
    let variants = [
        FixtureParams {
            depth: false,
            ..Default::default()
        },
        FixtureParams {
            semantic: false,
            ..Default::default()
        },
        FixtureParams {
            gt_joints: false,
            ..Default::default()
        },
        FixtureParams {
            gt_meshes: false,
            gt_joints: false,
            semantic: false,
            ..Default::default()
        },
        FixtureParams {
            movable_parts: 1,
            test_views: 0,
            ..Default::default()
        },
        FixtureParams {
            movable_parts: 5,
            width: 24,
            height: 9,
            train_views: 5,
            test_views: 2,
            ..Default::default()
        },
        FixtureParams {
            movable_parts: 0,
            ..Default::default()
        },
    ];
    for p in variants {
        let ds = small_dataset(p);
        assert_eq!(read(&ds.to_files().unwrap()), ds, "{p:?}");
        let npy = ds
            .to_files_with(&WriteOptions {
                semantic: SemanticFormat::Npy,
            })
            .unwrap();
        assert_eq!(npy.keys().any(|k| k.ends_with(".npy")), p.semantic, "{p:?}");
        assert_eq!(read(&npy), ds, "{p:?} with .npy semantics");
    }
    let bare = small_dataset(FixtureParams {
        gt_meshes: false,
        gt_joints: false,
        semantic: false,
        ..Default::default()
    });
    assert_eq!(bare.num_parts, 1);
    assert!(bare.gt_joints.is_none() && bare.gt_meshes_for(State::Start).is_none());
}

#[test]
fn artgs_mpart90_paris_layout_reads_with_the_right_values() {
    let ds = small_dataset(FixtureParams {
        movable_parts: 1,
        ..Default::default()
    });
    let files = artgs_style_files(&ds).unwrap();

    // The files really are in the foreign style.
    let t: Value = serde_json::from_slice(&files["transforms_train_end.json"]).unwrap();
    assert!(t.get("fl_x").is_none() && t.get("w").is_none() && t["camera_angle_y"].is_number());
    assert_eq!(t["frames"][0]["file_path"], "./end/train/rgba/0000");
    assert!(
        files.contains_key("end/train/semantic/0000.npy")
            && !files.contains_key("end/train/semantic/0000.png")
    );
    assert_eq!(
        &files["end/train/semantic/0000.npy"][..10],
        b"\x93NUMPY\x01\x00v\x00"
    );
    assert!(
        String::from_utf8_lossy(&files["end/train/semantic/0000.npy"]).contains("'descr': '<i8'")
    );
    let trans: Value = serde_json::from_slice(&files["gt/trans.json"]).unwrap();
    assert!(trans["trans_info"].is_object(), "PARIS writes one object");
    assert!(files["gt/start/start_static_rotate.ply"].starts_with(b"ply\nformat ascii 1.0"));
    assert!(files.contains_key("gt/end/end_dynamic_rotate.ply"));

    let got = read(&files);
    assert_eq!(got.views.len(), ds.views.len());
    assert_eq!(got.num_parts, 2);
    assert_eq!(got.gt_joints, ds.gt_joints);
    assert_eq!(got.gt_joints.as_ref().unwrap()[0].kind, JointKind::Revolute);
    assert_eq!(got.gt_meshes, ds.gt_meshes);
    for (gv, ev) in got.views.iter().zip(&ds.views) {
        assert_eq!((gv.state, gv.split), (ev.state, ev.split));
        for (g, e) in gv.frames.iter().zip(&ev.frames) {
            assert_eq!(g.name, e.name);
            assert_eq!(g.camera.camera_to_world, e.camera.camera_to_world);
            assert_eq!(g.time, e.time);
            assert_eq!(
                (g.rgba.clone(), g.depth.clone()),
                (e.rgba.clone(), e.depth.clone())
            );
            assert_eq!(
                g.parts, e.parts,
                "ids with -1 background survive the .npy route"
            );
            let (gk, ek) = (g.camera.intrinsics, e.camera.intrinsics);
            assert_eq!((gk.width, gk.height, gk.cx, gk.cy), (16, 12, 8.0, 6.0));
            assert!(
                (gk.fx - ek.fx).abs() < 1e-4 * ek.fx && (gk.fy - ek.fy).abs() < 1e-4 * ek.fy,
                "{gk:?} vs {ek:?}"
            );
            assert!(
                (gk.fx - gk.fy).abs() > 1.0,
                "camera_angle_y is honoured (fy != fx)"
            );
        }
    }
}

#[test]
fn dropped_folder_is_rebased_on_the_dataset_root() {
    let ds = small_dataset(FixtureParams::default());
    let mut dropped: FileSet = ds
        .to_files()
        .unwrap()
        .into_iter()
        .map(|(k, v)| (format!("chair/{k}"), v))
        .collect();
    dropped.insert("chair/.DS_Store".into(), b"junk".to_vec());
    dropped.insert("README.txt".into(), b"outside the dataset".to_vec());
    assert_eq!(read(&rebase_on_dataset_root(dropped)), ds);
}

#[test]
fn blender_intrinsics_formulas_and_defaults() {
    let mut files = small_dataset(FixtureParams {
        test_views: 0,
        ..Default::default()
    })
    .to_files()
    .unwrap();
    for name in ["transforms_train_start.json", "transforms_train_end.json"] {
        edit_json(&mut files, name, |v| {
            let o = v.as_object_mut().unwrap();
            for k in ["fl_x", "fl_y", "cx", "cy", "w", "h", "camera_angle_y"] {
                o.remove(k);
            }
            o.insert("camera_angle_x".into(), json!(0.6911112070083618));
            for f in o["frames"].as_array_mut().unwrap() {
                f.as_object_mut().unwrap().remove("time");
            }
        });
    }
    let ds = read(&files);
    let k = ds.views(State::Start, Split::Train).unwrap().frames[0]
        .camera
        .intrinsics;
    let fx = (0.5 * 16.0 / (0.5f64 * 0.6911112070083618).tan()) as f32;
    assert_eq!((k.fx, k.fy, k.cx, k.cy), (fx, fx, 8.0, 6.0));
    // Missing `time` defaults from the state.
    assert!(
        ds.views(State::Start, Split::Train)
            .unwrap()
            .frames
            .iter()
            .all(|f| f.time == 0.0)
    );
    assert!(
        ds.views(State::End, Split::Train)
            .unwrap()
            .frames
            .iter()
            .all(|f| f.time == 1.0)
    );
    assert!(
        ds.views(State::Start, Split::Test).is_none(),
        "test split is optional"
    );
}

#[test]
fn nerfstudio_intrinsics_win_and_can_be_per_frame() {
    let mut files = small_dataset(FixtureParams::default()).to_files().unwrap();
    edit_json(&mut files, "transforms_train_start.json", |v| {
        v["camera_angle_x"] = json!(1.5); // inconsistent on purpose: fl_x takes precedence
        v["fl_x"] = json!(20.5);
        v.as_object_mut().unwrap().remove("cy"); // defaults to the image centre
        v["frames"][2]["fl_y"] = json!(33.25);
        v["frames"][2]["cx"] = json!(7.5);
    });
    let ds = read(&files);
    let frames = &ds.views(State::Start, Split::Train).unwrap().frames;
    let k0 = frames[0].camera.intrinsics;
    assert_eq!((k0.fx, k0.cy), (20.5, 6.0));
    let k2 = frames[2].camera.intrinsics;
    assert_eq!((k2.fx, k2.fy, k2.cx), (20.5, 33.25, 7.5));
    // Per-frame intrinsics survive our own writer too.
    assert_eq!(read(&ds.to_files().unwrap()), ds);
}

#[test]
fn file_path_spellings_and_rgb_images() {
    let mut files = small_dataset(FixtureParams::default()).to_files().unwrap();
    edit_json(&mut files, "transforms_train_start.json", |v| {
        v["frames"][0]["file_path"] = json!("./start/train/rgba/0000");
        v["frames"][1]["file_path"] = json!("start\\train\\rgba\\0001.png");
        v["frames"][2]["file_path"] = json!("start/./train/x/../rgba/0002.PNG");
    });
    // Upper-case extension used as given; an RGB image reads as opaque RGBA.
    let png = files.remove("start/train/rgba/0002.png").unwrap();
    files.insert("start/train/rgba/0002.PNG".into(), png);
    let rgb = encode_png(
        "x",
        16,
        12,
        artmesh::data::PngPixels::Rgb8(&[9; 16 * 12 * 3]),
    )
    .unwrap();
    files.insert("start/train/rgba/0001.png".into(), rgb);
    let ds = read(&files);
    let frames = &ds.views(State::Start, Split::Train).unwrap().frames;
    assert_eq!(
        frames.iter().map(|f| f.name.as_str()).collect::<Vec<_>>(),
        ["0000", "0001", "0002"]
    );
    assert!(frames[1].rgba.pixels.chunks(4).all(|p| p == [9, 9, 9, 255]));
    assert!(
        frames[2].depth.is_some() && frames[2].parts.is_some(),
        "siblings found next to an upper-case .PNG"
    );
}

#[test]
fn semantic_maps_from_hand_written_npy_files() {
    let ds = small_dataset(FixtureParams {
        test_views: 0,
        ..Default::default()
    });
    let mut files = ds.to_files().unwrap();
    for state in [State::Start, State::End] {
        for (i, f) in ds
            .views(state, Split::Train)
            .unwrap()
            .frames
            .iter()
            .enumerate()
        {
            let ids = &f.parts.as_ref().unwrap().ids;
            let base = format!("{}/train/semantic/{i:04}", state.name());
            files.remove(&format!("{base}.png"));
            let npy = if i % 2 == 0 {
                write_npy_i32(
                    12,
                    16,
                    &ids.iter().map(|&v| i32::from(v)).collect::<Vec<_>>(),
                )
            } else {
                write_npy_i64(
                    12,
                    16,
                    &ids.iter().map(|&v| i64::from(v)).collect::<Vec<_>>(),
                )
            };
            files.insert(format!("{base}.npy"), npy);
        }
    }
    assert_eq!(read(&files), ds);
}

#[test]
fn ply_ascii_and_binary_meshes() {
    let mesh = fixture::box_mesh(Vec3::new(-1.0, -0.5, 0.0), Vec3::new(0.1, 0.2, 0.3));
    for format in [PlyFormat::Ascii, PlyFormat::BinaryLittleEndian] {
        assert_eq!(
            TriMesh::from_ply("m.ply", &mesh.to_ply(format)).unwrap(),
            mesh
        );
    }
    // Hand-written ascii: CRLF, comments, extra vertex properties, a quad (fan-triangulated), vertex_index.
    let ascii = "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nelement vertex 4\r\nproperty double x\r\n\
                 property double y\r\nproperty double z\r\nproperty float nx\r\nproperty uchar red\r\n\
                 element face 1\r\nproperty list uchar uint vertex_index\r\nelement edge 1\r\n\
                 property int vertex1\r\nproperty int vertex2\r\nend_header\r\n\
                 0 0 0 0.5 1\r\n1 0 0 0.5 2\r\n1 1 0 0.5 3\r\n0 1 0.25 0.5 4\r\n4 0 1 2 3\r\n0 1\r\n";
    let m = TriMesh::from_ply("hand.ply", ascii.as_bytes()).unwrap();
    assert_eq!(m.positions[3], Vec3::new(0.0, 1.0, 0.25));
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);

    // Binary little endian with int16 list counts and int32 indices.
    let mut bin = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                    property float z\nelement face 1\nproperty list short int vertex_indices\nend_header\n"
        .to_vec();
    for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        v.iter()
            .for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    bin.extend_from_slice(&3i16.to_le_bytes());
    [2i32, 1, 0]
        .iter()
        .for_each(|i| bin.extend_from_slice(&i.to_le_bytes()));
    assert_eq!(
        TriMesh::from_ply("b.ply", &bin).unwrap().triangles,
        vec![[2, 1, 0]]
    );
}

#[test]
fn summary_reports_views_parts_depth_and_ground_truth() {
    let ds = small_dataset(FixtureParams::default());
    let s = ds.summary();
    let counts: Vec<_> = s
        .views
        .iter()
        .map(|v| (v.state, v.split, v.frames, v.width, v.height))
        .collect();
    assert_eq!(
        counts,
        [
            (State::Start, Split::Train, 3, 16, 12),
            (State::Start, Split::Test, 1, 16, 12),
            (State::End, Split::Train, 3, 16, 12),
            (State::End, Split::Test, 1, 16, 12),
        ]
    );
    assert_eq!(s.num_parts, 3);
    let valid: Vec<u16> = ds
        .frames()
        .flat_map(|f| f.depth.as_ref().unwrap().millimetres.iter().copied())
        .filter(|&d| d > 0)
        .collect();
    let (lo, hi) = (*valid.iter().min().unwrap(), *valid.iter().max().unwrap());
    assert_eq!(
        s.depth_range_m,
        Some([f32::from(lo) / 1000.0, f32::from(hi) / 1000.0])
    );
    assert!(s.has_depth && s.has_semantic && s.has_gt_joints && s.has_gt_meshes);
    assert_eq!(
        s.gt_joint_kinds,
        [JointKind::Revolute, JointKind::Prismatic]
    );

    let text = s.to_string();
    assert!(
        text.contains("start/train: 3 views, 16x12, depth + semantic"),
        "{text}"
    );
    assert!(text.contains("end/test: 1 view, 16x12"), "{text}");
    assert!(
        text.contains("parts: 3 (static base + 2 movable)"),
        "{text}"
    );
    assert!(text.contains(&format!(
        "depth: {:.3} m to {:.3} m",
        f32::from(lo) / 1000.0,
        f32::from(hi) / 1000.0
    )));
    assert!(
        text.contains("GT joints: 2 (revolute, prismatic)")
            && text.contains("GT meshes: start, end"),
        "{text}"
    );

    let json = serde_json::to_value(&s).unwrap();
    assert_eq!(json["views"][0]["state"], "start");
    assert_eq!(json["views"][0]["split"], "train");
    assert_eq!(json["gt_joint_kinds"], json!(["revolute", "prismatic"]));

    let bare = small_dataset(FixtureParams {
        depth: false,
        semantic: false,
        gt_joints: false,
        gt_meshes: false,
        test_views: 0,
        ..Default::default()
    })
    .summary();
    assert_eq!(
        (bare.depth_range_m, bare.has_depth, bare.has_semantic),
        (None, false, false)
    );
    assert!(
        !bare.has_gt_joints && !bare.has_gt_meshes && bare.views.len() == 2 && bare.num_parts == 1
    );
    let text = bare.to_string();
    assert!(
        text.contains("depth: none")
            && text.contains("GT joints: none")
            && text.contains("GT meshes: none")
    );
}

#[cfg(not(target_arch = "wasm32"))]
#[test]
fn folders_read_and_write_without_overwriting() {
    use artmesh::data::{read_dir, write_dir};
    let root = std::env::temp_dir().join(format!("artmesh-data-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let files = small_dataset(FixtureParams::default()).to_files().unwrap();
    write_dir(&files, &root).unwrap();
    std::fs::write(root.join(".DS_Store"), b"junk").unwrap();
    std::fs::create_dir_all(root.join(".git")).unwrap();
    std::fs::write(root.join(".git/config"), b"junk").unwrap();
    assert_eq!(read_dir(&root).unwrap(), files, "hidden files are skipped");

    let e = write_dir(&files, &root).unwrap_err();
    assert!(
        files.contains_key(&e.file) && e.message.contains("refusing to overwrite"),
        "{e}"
    );
    let mut escaping = FileSet::new();
    escaping.insert("../evil.txt".into(), vec![1]);
    assert!(
        write_dir(&escaping, &root)
            .unwrap_err()
            .message
            .contains("relative path")
    );

    let missing = read_dir(&root.join("nope")).unwrap_err();
    assert!(
        missing.message.contains("cannot open the dataset folder"),
        "{missing}"
    );
    let not_dir = read_dir(&root.join("gt/trans.json")).unwrap_err();
    assert!(
        not_dir
            .message
            .contains("expected a dataset folder, found a file"),
        "{not_dir}"
    );
    std::fs::remove_dir_all(&root).unwrap();
}
