//! The `artmesh` binary as scripts use it: exit codes, JSON on stdout, errors on stderr.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use artmesh::data::{self, GroundTruth};
use glam::Quat;

pub(crate) fn artmesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_artmesh"))
        .args(args)
        .output()
        .expect("the artmesh binary runs")
}

pub(crate) fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A fresh folder under the system temp dir, removed when dropped.
pub(crate) struct TempDir(pub(crate) PathBuf);

impl TempDir {
    pub(crate) fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("artmesh-cli-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        Self(dir)
    }
    pub(crate) fn join(&self, p: &str) -> String {
        self.0.join(p).display().to_string()
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "stderr: {}", text(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}

#[test]
fn sample_then_info_then_refuse_to_overwrite() {
    let tmp = TempDir::new("info");
    let dir = tmp.join("obj");
    let out = artmesh(&["sample", "--out", &dir, "--parts", "3", "--views", "4"]);
    assert!(out.status.success(), "{}", text(&out.stderr));

    let info = artmesh(&["info", &dir]);
    assert!(info.status.success(), "{}", text(&info.stderr));
    let shown = text(&info.stdout);
    assert!(
        shown.contains("start/train: 4 views") && shown.contains("parts: 4"),
        "{shown}"
    );
    let summary = json(&artmesh(&["info", &dir, "--json"]));
    assert_eq!(summary["num_parts"], 4);

    let again = artmesh(&["sample", "--out", &dir]);
    assert_eq!(again.status.code(), Some(1));
    assert!(
        text(&again.stderr).contains("already exists and is not empty"),
        "{}",
        text(&again.stderr)
    );
}

#[test]
fn info_lists_problems_and_fails() {
    let tmp = TempDir::new("bad");
    let dir = tmp.join("obj");
    assert!(artmesh(&["sample", "--out", &dir]).status.success());
    let png = Path::new(&dir).join("end/train/depth/0002.png");
    let bytes = std::fs::read(&png).unwrap();
    std::fs::write(&png, &bytes[..bytes.len() / 2]).unwrap();
    let out = artmesh(&["info", &dir]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains("1 problem(s) found") && err.contains("end/train/depth/0002.png"),
        "{err}"
    );
}

#[test]
fn eval_scores_ground_truth_as_zero_and_a_tilted_axis_by_its_angle() {
    let tmp = TempDir::new("eval");
    let gt_dir = tmp.join("gt_object");
    assert!(
        artmesh(&["sample", "--out", &gt_dir, "--parts", "2"])
            .status
            .success()
    );

    let perfect = json(&artmesh(&["eval", &gt_dir, &gt_dir, "--samples", "2000"]));
    for joint in perfect["joints"].as_array().unwrap() {
        assert_eq!(joint["axis_ang"], 0.0, "{joint}");
        assert_eq!(joint["part_motion"], 0.0, "{joint}");
    }
    assert_eq!(perfect["cd_s"]["cd_peer"], 0.0);
    assert_eq!(perfect["cd_m"]["cd_mm"], 0.0);

    // Prediction = ground truth with joint 0's axis tilted by 10 degrees, written as a gt/ folder.
    let files = data::read_dir(Path::new(&gt_dir)).unwrap();
    let mut pred = GroundTruth::from_files(&files).unwrap();
    let joint = &mut pred.joints.as_mut().unwrap()[0];
    let tilt_axis = joint.direction.any_orthonormal_vector();
    joint.direction = Quat::from_axis_angle(tilt_axis, 10f32.to_radians()) * joint.direction;
    let pred_dir = tmp.join("prediction");
    data::write_dir(&pred.to_files().unwrap(), Path::new(&pred_dir)).unwrap();

    let scored = json(&artmesh(&["eval", &pred_dir, &gt_dir, "--samples", "2000"]));
    let axis_ang = scored["joints"][0]["axis_ang"].as_f64().unwrap();
    assert!((axis_ang - 10.0).abs() < 1e-3, "axis error {axis_ang}");
    assert_eq!(scored["joints"][1]["axis_ang"], 0.0);
}

#[test]
fn eval_without_joints_is_a_clear_error() {
    let tmp = TempDir::new("eval-missing");
    let gt_dir = tmp.join("obj");
    assert!(artmesh(&["sample", "--out", &gt_dir]).status.success());
    std::fs::create_dir_all(tmp.join("empty")).unwrap();
    let out = artmesh(&["eval", &tmp.join("empty"), &gt_dir]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("found neither joints nor part meshes"),
        "{}",
        text(&out.stderr)
    );
}

/// Every file below `root` with its bytes, keyed by relative path.
fn tree(root: &str) -> data::FileSet {
    data::read_dir(Path::new(root)).expect("readable output")
}

/// `args` followed by capture options for tiny, fast datasets.
pub(crate) fn with_small_capture<'a>(args: &[&'a str], test_views: &'a str) -> Vec<&'a str> {
    let mut all = args.to_vec();
    all.extend([
        "--width",
        "24",
        "--height",
        "24",
        "--train-views",
        "2",
        "--test-views",
        test_views,
    ]);
    all
}

#[test]
fn quick_suite_is_valid_reproducible_and_scores_zero_against_itself() {
    let tmp = TempDir::new("suite");
    let (a, b) = (tmp.join("a"), tmp.join("b"));
    for dir in [&a, &b] {
        let out = artmesh(&with_small_capture(
            &["suite", "--quick", "--out", dir],
            "1",
        ));
        assert!(out.status.success(), "{}", text(&out.stderr));
    }
    let files = tree(&a);
    assert!(files == tree(&b), "two runs of the quick suite differ");
    let manifest: serde_json::Value = serde_json::from_slice(&files["suite.json"]).unwrap();
    let objects = manifest["objects"].as_array().unwrap();
    assert_eq!(objects.len(), 16);
    assert!(files.contains_key("contact-sheet.png"));
    for o in objects {
        let id = o["id"].as_str().unwrap();
        let info = json(&artmesh(&["info", &format!("{a}/{id}"), "--json"]));
        assert_eq!(info["num_parts"], o["parts"], "{id}: {info}");
        let urdf = format!("{id}/object/{}.urdf", o["name"].as_str().unwrap());
        assert!(files.contains_key(&urdf), "{urdf} missing");
    }
    // Ground truth fed as the prediction: zero error everywhere, in both tables.
    let report = json(&artmesh(&["eval", &a, &a, "--samples", "500"]));
    for table in ["by_part_count", "by_category"] {
        for column in report[table]["columns"].as_array().unwrap() {
            for metric in ["axis_ang", "axis_pos", "part_motion"] {
                let v = &column[metric];
                assert!(
                    v.is_null() || v.as_f64() == Some(0.0),
                    "{table} {}: {metric} = {v}",
                    column["label"]
                );
            }
        }
    }
    let all = report["by_part_count"]["columns"]
        .as_array()
        .unwrap()
        .last()
        .unwrap()
        .clone();
    assert_eq!(all["label"], "All");
    assert_eq!(all["objects"], 16);
    let md = artmesh(&["eval", &a, &a, "--samples", "200", "--markdown"]);
    let md = text(&md.stdout);
    assert!(
        md.contains("| Metric |") && md.contains("StorageFurniture") && md.contains("6+ Parts"),
        "{md}"
    );
}

#[test]
fn synth_and_render_write_datasets_and_refuse_bad_input() {
    let tmp = TempDir::new("synth");
    let dir = tmp.join("storage");
    let synth = [
        "synth",
        "--category",
        "storage",
        "--parts",
        "5",
        "--seed",
        "7",
        "--out",
        &dir,
    ];
    let out = artmesh(&with_small_capture(&synth, "0"));
    assert!(out.status.success(), "{}", text(&out.stderr));
    let info = json(&artmesh(&["info", &dir, "--json"]));
    assert_eq!(info["num_parts"], 6, "{info}");
    // The written object renders again through `artmesh render`.
    let urdf = tmp.join("storage/object/storagefurniture_5p_s7.urdf");
    let again = tmp.join("again");
    let out = artmesh(&with_small_capture(
        &["render", &urdf, "--out", &again],
        "0",
    ));
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(json(&artmesh(&["info", &again, "--json"]))["num_parts"], 6);
    // Refusals: non-empty output folder, unknown category, impossible part count, missing URDF, bad mesh.
    let before = tree(&dir);
    let out = artmesh(&["synth", "--category", "storage", "--out", &dir]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("not empty"),
        "{}",
        text(&out.stderr)
    );
    assert!(tree(&dir) == before, "a refused run changed the folder");
    let out = artmesh(&["synth", "--category", "sofa", "--out", &tmp.join("x")]);
    assert!(
        text(&out.stderr).contains("unknown category 'sofa'"),
        "{}",
        text(&out.stderr)
    );
    let out = artmesh(&[
        "synth",
        "--category",
        "laptop",
        "--parts",
        "4",
        "--out",
        &tmp.join("x"),
    ]);
    assert!(
        text(&out.stderr).contains("Laptop objects have 1..=1 movable parts"),
        "{}",
        text(&out.stderr)
    );
    let out = artmesh(&["render", &tmp.join("none.urdf"), "--out", &tmp.join("x")]);
    assert!(
        text(&out.stderr).contains("none.urdf: no such file"),
        "{}",
        text(&out.stderr)
    );
    let broken = tmp.join("broken");
    std::fs::create_dir_all(&broken).unwrap();
    for (name, mesh) in [("missing", "gone.obj"), ("format", "door.fbx")] {
        let path = format!("{broken}/{name}.urdf");
        std::fs::write(&path, format!(
            r#"<robot name="r"><link name="a"/><link name="b"><visual><geometry><mesh filename="{mesh}"/></geometry></visual></link>
            <joint name="j" type="revolute"><parent link="a"/><child link="b"/><limit lower="0" upper="1"/></joint></robot>"#
        ))
        .unwrap();
        if name == "format" {
            std::fs::write(format!("{broken}/door.fbx"), b"Kaydara FBX Binary").unwrap();
        }
        let out = artmesh(&["render", &path, "--out", &tmp.join(name)]);
        let err = text(&out.stderr);
        assert!(!out.status.success() && err.contains(mesh), "{name}: {err}");
        assert!(
            !Path::new(&tmp.join(name)).exists(),
            "{name}: output written despite the error"
        );
    }
}

#[test]
fn learn_and_bench_raster_print_json() {
    let tmp = TempDir::new("learn");
    std::fs::create_dir_all(&tmp.0).unwrap();
    let preview = tmp.join("preview.png");
    let args = [
        "learn",
        "--size",
        "32",
        "--views",
        "3",
        "--iterations",
        "8",
        "--edge-pixels",
        "4",
        "--preview",
        &preview,
    ];
    let report = json(&artmesh(&args));
    assert_eq!(report["size"], 32);
    assert!(report["psnr_start"].as_f64().unwrap() > 5.0);
    assert!(report["curve"].as_array().unwrap().len() >= 2);
    let png = image::load_from_memory(&std::fs::read(&preview).unwrap()).unwrap();
    assert_eq!((png.width(), png.height()), (96, 96));
    // The preview is never overwritten.
    let again = artmesh(&args);
    assert!(!again.status.success() && text(&again.stderr).contains("already exists"));

    let bench = json(&artmesh(&[
        "bench",
        "raster",
        "--cases",
        "32x300",
        "--repeats",
        "1",
    ]));
    let case = &bench["results"][0];
    assert_eq!(case["width"], 32);
    assert!(case["median_ms"].as_f64().unwrap() > 0.0);
    assert!(case["work"]["forward_evaluations"].as_u64().unwrap() > 0);
    assert!(bench["fma_peak"]["gflops"].as_f64().unwrap() > 0.0);
    let bad = artmesh(&["bench", "raster", "--cases", "32by300"]);
    assert!(
        !bad.status.success() && text(&bad.stderr).contains("SIZExFACES"),
        "{}",
        text(&bad.stderr)
    );
}

#[test]
fn reconstruct_writes_part_meshes_and_a_report_and_refuses_bad_input() {
    let tmp = TempDir::new("reconstruct");
    let dir = tmp.join("obj");
    let out = artmesh(&[
        "synth",
        "--category",
        "laptop",
        "--parts",
        "1",
        "--seed",
        "1005",
        "--out",
        &dir,
        "--width",
        "32",
        "--height",
        "32",
        "--train-views",
        "4",
        "--test-views",
        "0",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let before = tree(&dir);
    let result = tmp.join("result");
    let run = artmesh(&[
        "reconstruct",
        &dir,
        "--out",
        &result,
        "--preset",
        "tiny",
        "--iterations",
        "30",
    ]);
    let report = json(&run);
    // Progress went to stderr, phase by phase.
    let progress = text(&run.stderr);
    for phase in ["initialise", "optimise", "remesh", "recover", "done"] {
        assert!(progress.contains(phase), "no '{phase}' in:\n{progress}");
    }
    assert_eq!(report["preset"], "tiny");
    assert_eq!(report["remesh"], "part-aware");
    for state in report["states"].as_array().unwrap() {
        assert_eq!(state["cross_part_faces"], 0);
        assert_eq!(state["parts"].as_array().unwrap().len(), 2);
        assert!(state["parts"][1]["chamfer"]["cd_mm"].as_f64().unwrap() > 0.0);
    }
    // The meshes are in the gt/ layout, readable as ground truth, with the report beside them.
    let written = tree(&result);
    let gt = GroundTruth::from_files(&written).unwrap();
    for state in [data::State::Start, data::State::End] {
        let meshes = gt.meshes[state.index()].as_ref().unwrap();
        assert!(!meshes.static_part.triangles.is_empty() && meshes.movable.len() == 1);
    }
    assert!(written.contains_key("report.json"));
    // The dataset is untouched; the output folder is never overwritten.
    assert_eq!(tree(&dir), before);
    let again = artmesh(&["reconstruct", &dir, "--out", &result, "--preset", "tiny"]);
    assert!(!again.status.success() && text(&again.stderr).contains("not empty"));

    // A dataset without depth maps: a clear error, nothing written.
    std::fs::remove_dir_all(format!("{dir}/start/train/depth")).unwrap();
    std::fs::remove_dir_all(format!("{dir}/end/train/depth")).unwrap();
    let no_depth = tmp.join("no-depth");
    let out = artmesh(&["reconstruct", &dir, "--out", &no_depth, "--preset", "tiny"]);
    let err = text(&out.stderr);
    assert!(!out.status.success() && err.contains("depth"), "{err}");
    assert!(!Path::new(&no_depth).exists());
    let bad = artmesh(&["reconstruct", &dir, "--out", &no_depth, "--preset", "huge"]);
    assert!(!bad.status.success() && text(&bad.stderr).contains("tiny"));

    // The benchmark: one quick-suite object, seconds per phase and the dominant phase.
    let bench = json(&artmesh(&[
        "bench",
        "reconstruct",
        "--preset",
        "tiny",
        "--objects",
        "pen",
        "--size",
        "32",
        "--views",
        "3",
    ]));
    assert_eq!(bench["objects"].as_array().unwrap().len(), 1);
    assert!(bench["phases"]["seconds"]["optimise_s"].as_f64().unwrap() > 0.0);
    assert!(bench["phases"]["dominant"].is_string());
}

/// `demo` ends with the twin's exports and preview (two states × three cameras × photo, ground
/// truth and twin, each tile showing the object) in its fit folder; `export` writes them again from that folder
/// (the same node tree, the same archive entries), refuses to overwrite, and names what is missing.
#[test]
fn demo_writes_the_twin_and_export_rewrites_it() {
    let tmp = TempDir::new("export");
    let demo = tmp.join("demo");
    let out = artmesh(&["demo", "--preset", "tiny", "--out", &demo]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let fit = format!("{demo}/fit");
    for f in ["joints.json", "urdf/twin.urdf", "twin.glb", "twin.zip"] {
        assert!(Path::new(&fit).join(f).is_file(), "{f} missing");
    }
    let preview = image::open(format!("{fit}/preview.png"))
        .unwrap()
        .to_rgba8();
    let (w, h, t) = (preview.width(), preview.height(), preview.height() / 2);
    assert_eq!(2 * w, 9 * h, "{w}×{h}");
    for (row, col) in (0..2).flat_map(|r| (0..9).map(move |c| (r, c))) {
        let pixel = |i: u32| preview.get_pixel(col * t + i % t, row * t + i / t).0;
        let covered = (0..t * t).filter(|&i| pixel(i)[..3] != [235; 3]).count();
        assert!(covered * 50 > (t * t) as usize, "tile {row},{col} is empty");
    }
    let joints: serde_json::Value =
        serde_json::from_slice(&std::fs::read(format!("{fit}/joints.json")).unwrap()).unwrap();
    assert_eq!(joints[0]["joint"], "joint_1");
    assert_eq!(
        joints[0]["end_transform"][3],
        serde_json::json!([0.0, 0.0, 0.0, 1.0])
    );

    let (glb, zip) = (tmp.join("again.glb"), tmp.join("again.zip"));
    let out = artmesh(&["export", &fit, "--glb", &glb, "--urdf-zip", &zip]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let names = |bytes: Vec<u8>| {
        let doc = gltf::Gltf::from_slice(&bytes).unwrap().document;
        let mut n: Vec<(String, usize)> = doc
            .nodes()
            .map(|n| {
                (
                    n.name().unwrap_or_default().to_string(),
                    n.children().count(),
                )
            })
            .collect();
        n.sort();
        n
    };
    let original = names(std::fs::read(format!("{fit}/twin.glb")).unwrap());
    assert_eq!(names(std::fs::read(&glb).unwrap()), original);
    assert_eq!(original[0], ("base".to_string(), 2));
    let entries = |path: &str| {
        let mut z = zip::ZipArchive::new(std::fs::File::open(path).unwrap()).unwrap();
        let mut n: Vec<String> = z.file_names().map(|f| f.unwrap().to_string()).collect();
        n.sort();
        let mut urdf = String::new();
        let urdf_name = n.iter().find(|f| f.ends_with("twin.urdf")).unwrap().clone();
        std::io::Read::read_to_string(&mut z.by_name(&urdf_name).unwrap(), &mut urdf).unwrap();
        (n, urdf.contains("<limit lower="))
    };
    let (want, limits) = entries(&format!("{fit}/twin.zip"));
    assert!(limits);
    assert_eq!(entries(&zip).0, want);
    assert!(
        want.iter().any(|f| f.ends_with("/joints.json"))
            && want.iter().any(|f| f.ends_with(".stl"))
    );

    let again = artmesh(&["export", &fit, "--glb", &glb]);
    assert_eq!(again.status.code(), Some(1));
    assert!(
        text(&again.stderr).contains("already exists"),
        "{}",
        text(&again.stderr)
    );
    let nothing = artmesh(&["export", &fit]);
    assert!(
        text(&nothing.stderr).contains("--glb"),
        "{}",
        text(&nothing.stderr)
    );
    let wrong = artmesh(&["export", &demo, "--glb", &tmp.join("x.glb")]);
    assert_eq!(wrong.status.code(), Some(1));
    assert!(
        text(&wrong.stderr).contains("urdf/twin.urdf: missing"),
        "{}",
        text(&wrong.stderr)
    );
    assert!(!Path::new(&tmp.join("x.glb")).exists());

    // The spread benchmark on the demo's dataset: two fits, the second one's shift per joint.
    let dataset = format!("{demo}/dataset");
    let spread = json(&artmesh(&["bench", "spread", &dataset, "--runs", "2"]));
    assert_eq!(spread["fits"].as_array().unwrap().len(), 2);
    assert_eq!(spread["fits"][1]["ssim_factor"].as_f64(), Some(1.000001));
    let shifts = spread["shifts"][0].as_array().unwrap();
    assert_eq!(shifts.len(), joints.as_array().unwrap().len());
    let worst = spread["max_axis_deg"].as_f64().unwrap();
    assert!((0.0..=90.0).contains(&worst), "{spread}");
    // The demo has ground truth: every fit is scored against it, and the unchanged fit is the
    // demo's own fit, so it scores what the demo's report says.
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(format!("{fit}/report.json")).unwrap()).unwrap();
    let scored = report["metrics"]["joints"].as_array().unwrap();
    for run in spread["fits"].as_array().unwrap() {
        assert_eq!(
            run["gt_errors"].as_array().map(Vec::len),
            Some(scored.len()),
            "{run}"
        );
        assert_eq!(
            run["seed_gt_errors"].as_array().map(Vec::len),
            Some(scored.len()),
            "{run}"
        );
    }
    for (fitted, demo) in spread["fits"][0]["gt_errors"]
        .as_array()
        .unwrap()
        .iter()
        .zip(scored)
    {
        for metric in ["axis_ang", "part_motion"] {
            let (a, b) = (
                fitted[metric].as_f64().unwrap(),
                demo[metric].as_f64().unwrap(),
            );
            assert!((a - b).abs() < 1e-9, "{metric}: spread {a}, demo {b}");
        }
    }
    // Changing only the view order shares one reconstruction: same meshes, so the same
    // registration seeds, and another articulation seed.
    let order = json(&artmesh(&[
        "bench",
        "spread",
        &dataset,
        "--runs",
        "2",
        "--vary",
        "view-order",
    ]));
    assert_eq!(order["change"], "view-order");
    let fits = order["fits"].as_array().unwrap();
    assert_eq!(
        fits[0]["remeshed_faces"], fits[1]["remeshed_faces"],
        "{order}"
    );
    assert_eq!(
        fits[0]["psnr_optimised"], fits[1]["psnr_optimised"],
        "{order}"
    );
    assert_ne!(fits[0]["articulation_seed"], fits[1]["articulation_seed"]);
    for shift in order["shifts"][0].as_array().unwrap() {
        assert_eq!(shift["seed_axis_deg"].as_f64(), Some(0.0), "{order}");
    }
    let missing = artmesh(&["bench", "spread", &tmp.join("nowhere")]);
    assert_eq!(missing.status.code(), Some(1));
    assert!(
        text(&missing.stderr).contains("nowhere"),
        "{}",
        text(&missing.stderr)
    );
}
