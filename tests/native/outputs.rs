//! What the commands write, as a hostile or careless user would test it: nothing replaced, no
//! symlink at an output path followed, no two outputs at one path, nothing left behind by a run
//! that fails (so the rerun is not refused).

use std::path::Path;

use crate::cli::{TempDir, artmesh, text, with_small_capture};

/// Everything in `dir` (names only), to check a refused or failed run left nothing there.
fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    n.sort();
    n
}

/// Runs `args`, expects a failure whose message holds `says`.
fn refused(args: &[&str], says: &str) {
    let out = artmesh(args);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(err.contains(says), "{args:?}: expected '{says}' in: {err}");
}

#[test]
fn export_refuses_one_path_twice_and_symlinks() {
    let tmp = TempDir::new("outputs-export");
    std::fs::create_dir_all(&tmp.0).unwrap();
    let same = tmp.join("twin.out");
    refused(
        &[
            "export",
            &tmp.join("nofit"),
            "--glb",
            &same,
            "--urdf-zip",
            &same,
        ],
        "given as two outputs",
    );
    // The same file spelled two ways.
    let other = format!("{}/./twin.out", tmp.0.display());
    refused(
        &[
            "export",
            &tmp.join("nofit"),
            "--glb",
            &same,
            "--urdf-zip",
            &other,
        ],
        "given as two outputs",
    );
    // A dangling symlink at the output: refused, and its target is not created.
    let link = tmp.join("link.glb");
    std::os::unix::fs::symlink(tmp.join("elsewhere.glb"), &link).unwrap();
    refused(
        &["export", &tmp.join("nofit"), "--glb", &link],
        "is a symlink",
    );
    assert_eq!(names(&tmp.0), ["link.glb"]);
}

#[test]
fn fit_and_learn_refuse_symlinked_outputs() {
    let tmp = TempDir::new("outputs-links");
    std::fs::create_dir_all(tmp.0.join("real")).unwrap();
    let to_folder = tmp.join("to-folder");
    std::os::unix::fs::symlink(tmp.0.join("real"), &to_folder).unwrap();
    let dangling = tmp.join("dangling");
    std::os::unix::fs::symlink(tmp.0.join("gone"), &dangling).unwrap();
    for out in [&to_folder, &dangling] {
        refused(&["fit", &tmp.join("nodata"), "--out", out], "is a symlink");
        refused(&["sample", "--out", out], "is a symlink");
    }
    refused(
        &["learn", "--iterations", "1", "--preview", &dangling],
        "is a symlink",
    );
    assert_eq!(names(&tmp.0), ["dangling", "real", "to-folder"]);
    assert!(names(&tmp.0.join("real")).is_empty());
}

#[test]
fn a_failed_run_leaves_nothing_behind() {
    let tmp = TempDir::new("outputs-failed");
    std::fs::create_dir_all(&tmp.0).unwrap();
    // A dataset that cannot be read, with an output folder two levels down: neither the folder,
    // its parents nor the hidden working folder stay.
    let nested = tmp.join("a/b/fit");
    refused(&["fit", &tmp.join("nodata"), "--out", &nested], "nodata");
    assert!(names(&tmp.0).is_empty(), "{:?}", names(&tmp.0));
    // synth checks the capture only after writing the object: the object goes too, and the same
    // command with a valid range then runs.
    let out = tmp.join("storage");
    let bad = [
        "synth",
        "--category",
        "storage",
        "--start-range",
        "0.9,0.1",
        "--out",
        &out,
    ];
    refused(&with_small_capture(&bad, "0"), "range");
    assert!(names(&tmp.0).is_empty(), "{:?}", names(&tmp.0));
    let good = ["synth", "--category", "storage", "--out", &out];
    let run = artmesh(&with_small_capture(&good, "0"));
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert_eq!(names(&tmp.0), ["storage"]);
    assert!(names(&tmp.0.join("storage")).contains(&"object".to_string()));
    // An existing empty folder is used; a non-empty one is refused untouched.
    std::fs::create_dir_all(tmp.0.join("empty")).unwrap();
    let run = artmesh(&["sample", "--out", &tmp.join("empty"), "--views", "2"]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let before = names(&tmp.0.join("empty"));
    refused(&["sample", "--out", &tmp.join("empty")], "not empty");
    assert_eq!(names(&tmp.0.join("empty")), before);
}

#[test]
fn eval_reads_only_folders_inside_the_suite() {
    let tmp = TempDir::new("outputs-eval");
    let suite = tmp.0.join("suite");
    std::fs::create_dir_all(&suite).unwrap();
    for id in ["../outside", "/etc", "a/b"] {
        let manifest = format!(r#"{{"objects": [{{"id": "{id}", "category": "storage"}}]}}"#);
        std::fs::write(suite.join("suite.json"), manifest).unwrap();
        let s = suite.display().to_string();
        refused(&["eval", &s, &s], "is not a folder name inside the suite");
    }
}

#[test]
fn info_and_fit_name_what_a_fit_would_refuse() {
    let tmp = TempDir::new("outputs-refuse");
    let dir = tmp.join("bg");
    let run = artmesh(&["sample", "--out", &dir, "--views", "2"]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    // Every semantic map background: the depth is fine, the part maps are at fault.
    for state in ["start", "end"] {
        for split in ["train", "test"] {
            let folder = Path::new(&dir).join(format!("{state}/{split}/semantic"));
            for entry in std::fs::read_dir(folder).unwrap() {
                let path = entry.unwrap().path();
                let (w, h) = image::image_dimensions(&path).unwrap();
                let zeros = vec![0u16; (w * h) as usize];
                let name = path.display().to_string();
                let png = artmesh::data::encode_png(
                    &name,
                    w,
                    h,
                    artmesh::data::PngPixels::Gray16(&zeros),
                );
                std::fs::write(&path, png.unwrap()).unwrap();
            }
        }
    }
    let says = "start/train: every semantic map is background";
    refused(&["info", &dir], says);
    refused(
        &["fit", &dir, "--preset", "tiny", "--out", &tmp.join("fit")],
        says,
    );
    assert!(!Path::new(&tmp.join("fit")).exists());
}

#[test]
fn fit_refuses_a_hole_size_it_cannot_fill_in_bounded_memory() {
    let tmp = TempDir::new("outputs-holes");
    let out = tmp.join("fit");
    // Refused before the dataset is read: the folder need not exist.
    refused(
        &[
            "fit",
            &tmp.join("none"),
            "--close-holes",
            "100000",
            "--out",
            &out,
        ],
        "--close-holes: expected at most 256 edges (0: none), found 100000",
    );
    assert!(!Path::new(&out).exists());
}

#[test]
fn render_refuses_links_and_full_folders_and_leaves_nothing_when_it_fails() {
    let tmp = TempDir::new("outputs-render");
    let object = tmp.join("object");
    let run = artmesh(&with_small_capture(
        &["synth", "--category", "storage", "--out", &tmp.join("s")],
        "0",
    ));
    assert!(run.status.success(), "{}", text(&run.stderr));
    std::fs::rename(tmp.0.join("s/object"), &object).unwrap();
    let urdf = std::fs::read_dir(&object)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "urdf"))
        .unwrap()
        .display()
        .to_string();
    let render = |out: &str, range: &str| -> Vec<String> {
        let args = ["render", &urdf, "--start-range", range, "--out", out];
        with_small_capture(&args, "0")
            .into_iter()
            .map(str::to_string)
            .collect()
    };
    let refused_render = |out: &str, range: &str, says: &str| {
        let args = render(out, range);
        refused(&args.iter().map(String::as_str).collect::<Vec<_>>(), says);
    };
    let dangling = tmp.join("dangling");
    std::os::unix::fs::symlink(tmp.0.join("gone"), &dangling).unwrap();
    refused_render(&dangling, "0.6,0.8", "is a symlink");
    std::fs::create_dir_all(tmp.0.join("full")).unwrap();
    std::fs::write(tmp.0.join("full/keep.txt"), "mine").unwrap();
    refused_render(&tmp.join("full"), "0.6,0.8", "not empty");
    assert_eq!(names(&tmp.0.join("full")), ["keep.txt"]);
    // A range outside [0, 1] is refused by the capture; no folder (nor its parents) stays.
    refused_render(&tmp.join("a/b/out"), "0.5,1.5", "range");
    assert!(!tmp.0.join("a").exists(), "{:?}", names(&tmp.0));
    assert!(!tmp.0.join("gone").exists());
}
