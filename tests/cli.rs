//! The `artmesh` binary as scripts use it: exit codes, JSON on stdout, errors on stderr.
#![cfg(not(target_arch = "wasm32"))]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use artmesh::data::{self, GroundTruth};
use glam::Quat;

fn artmesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_artmesh"))
        .args(args)
        .output()
        .expect("the artmesh binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A fresh folder under the system temp dir, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("artmesh-cli-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        Self(dir)
    }
    fn join(&self, p: &str) -> String {
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
        text(&again.stderr).contains("refusing to overwrite"),
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
    data::write_dir(&pred.to_files(), Path::new(&pred_dir)).unwrap();

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
