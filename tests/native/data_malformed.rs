//! Malformed datasets: every case of the shared catalogue must produce its specific error (file + field +
//! message), errors are collected rather than stopping at the first, and nothing panics on broken bytes.
// Native only: the browser runs the same fixture and catalogue from tests/web.rs.

use std::panic::{AssertUnwindSafe, catch_unwind};

use artmesh::data::fixture::{FixtureParams, small_dataset};
use artmesh::data::{
    DataError, Dataset, DatasetErrors, FileSet, PngPixels, Split, State, encode_png,
};
use artmesh::fixtures::malformed::{good_files, malformed_catalogue};

/// Reads without letting a panic escape: a panic is a test failure of its own.
fn read_no_panic(files: &FileSet) -> Result<Result<Dataset, DatasetErrors>, String> {
    catch_unwind(AssertUnwindSafe(|| Dataset::from_files(files))).map_err(|p| {
        p.downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    })
}

#[test]
fn the_base_of_the_catalogue_is_valid() {
    assert!(Dataset::from_files(&good_files()).is_ok());
}

#[test]
fn catalogue_is_large_and_names_are_unique() {
    let cases = malformed_catalogue();
    assert!(cases.len() >= 18, "only {} cases", cases.len());
    let mut names: Vec<_> = cases.iter().map(|c| c.name).collect();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), cases.len());
}

#[test]
fn every_malformed_case_reports_its_specific_error() {
    let mut failures = Vec::new();
    for case in malformed_catalogue() {
        let files = case.files();
        assert_ne!(
            files,
            good_files(),
            "case '{}' did not change anything",
            case.name
        );
        match read_no_panic(&files) {
            Err(panic) => failures.push(format!("{}: PANICKED: {panic}", case.name)),
            Ok(Ok(_)) => failures.push(format!("{}: was accepted", case.name)),
            Ok(Err(errors)) => {
                if !errors.0.iter().any(|e| case.matches(e)) {
                    failures.push(format!(
                        "{}: expected {} / {:?} / \"{}\", got:\n    {}",
                        case.name,
                        case.file,
                        case.field,
                        case.message,
                        errors.to_string().replace('\n', "\n    ")
                    ));
                }
                // Every error names a file and says something.
                assert!(
                    errors
                        .0
                        .iter()
                        .all(|e| !e.file.is_empty() && !e.message.is_empty()),
                    "{}",
                    case.name
                );
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} case(s) failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn all_problems_are_reported_not_just_the_first() {
    let cases = malformed_catalogue();
    let pick = [
        "missing rgba file",
        "8-bit depth PNG",
        "NaN in a transform matrix",
        "trans.json zero-length axis",
        "npy with bad magic",
    ];
    let mut files = good_files();
    for name in pick {
        let case = cases.iter().find(|c| c.name == name).unwrap();
        (case.mutate)(&mut files);
    }
    let errors = Dataset::from_files(&files).unwrap_err();
    for name in pick {
        let case = cases.iter().find(|c| c.name == name).unwrap();
        assert!(
            errors.0.iter().any(|e| case.matches(e)),
            "'{name}' missing from:\n{errors}"
        );
    }
    // Display: one error per line, "file: field: message".
    let text = errors.to_string();
    assert_eq!(text.lines().count(), errors.0.len());
    assert!(
        text.lines()
            .any(|l| l.starts_with("start/train/depth/0000.png: bit depth: expected a 16-bit")),
        "{text}"
    );
}

#[test]
fn without_w_h_sizes_are_compared_with_the_first_image() {
    let ds = small_dataset(FixtureParams::default());
    let mut files = artmesh::data::fixture::artgs_style_files(&ds).unwrap();
    let odd = encode_png("x", 20, 12, PngPixels::Rgba8(&[200; 20 * 12 * 4])).unwrap();
    files.insert("end/train/rgba/0002.png".into(), odd);
    let errors = Dataset::from_files(&files).unwrap_err();
    let e = errors
        .for_file("end/train/rgba/0002.png")
        .find(|e| e.field.as_deref() == Some("size"));
    let e = e.unwrap_or_else(|| panic!("no size error in:\n{errors}"));
    assert!(
        e.message.contains("expected 16x12 (the size of end/train/rgba/0000.png, the first image of this split), found 20x12"),
        "{e}"
    );
    // Its depth and semantic maps no longer match it either.
    assert!(
        errors
            .for_file("end/train/depth/0002.png")
            .any(|e| e.message.contains("expected 20x12"))
    );
    assert!(
        errors
            .for_file("end/train/semantic/0002.npy")
            .any(|e| e.message.contains("expected 20x12"))
    );
}

#[test]
fn error_display_format() {
    let e = DataError::field(
        "transforms_train_start.json",
        "frames[3].transform_matrix",
        "not rigid",
    );
    assert_eq!(
        e.to_string(),
        "transforms_train_start.json: frames[3].transform_matrix: not rigid"
    );
    assert_eq!(
        DataError::file("a.png", "missing").to_string(),
        "a.png: missing"
    );
    let all = DatasetErrors(vec![e.clone(), e]);
    assert_eq!(all.to_string().lines().count(), 2);
    let _: &dyn std::error::Error = &all;
}

/// Truncations and byte flips of every file must give errors or (rarely, for harmless bytes) a dataset,
/// never a panic.
#[test]
fn no_panic_on_truncated_or_corrupted_files() {
    let good = small_dataset(FixtureParams {
        train_views: 1,
        test_views: 0,
        ..Default::default()
    });
    let base = good
        .to_files_with(&artmesh::data::WriteOptions {
            semantic: artmesh::data::SemanticFormat::Npy,
        })
        .unwrap();
    let mut seed: u32 = 12345;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as usize
    };
    let mut runs = 0;
    for (path, bytes) in &base {
        let len = bytes.len();
        let mut variants: Vec<Vec<u8>> = [0, 1, 7, len / 4, len / 2, len.saturating_sub(1)]
            .iter()
            .map(|&cut| bytes[..cut.min(len)].to_vec())
            .collect();
        for _ in 0..8 {
            let mut b = bytes.clone();
            // Corrupt the header region more often: that is where sizes and types live.
            let at = if next() % 2 == 0 {
                next() % len.min(128)
            } else {
                next() % len
            };
            b[at] = (next() & 0xff) as u8;
            variants.push(b);
        }
        for v in variants {
            let mut files = base.clone();
            files.insert(path.clone(), v);
            runs += 1;
            if let Err(panic) = read_no_panic(&files) {
                panic!("reading {path} corrupted panicked: {panic}");
            }
        }
    }
    assert!(runs > 100);
}

#[test]
fn writer_refuses_what_the_reader_would_reject() {
    let good = small_dataset(FixtureParams::default());

    let mut empty = good.clone();
    empty.views[1].frames.clear();
    let e = empty.to_files().unwrap_err();
    assert_eq!(
        (e.file.as_str(), e.field.as_deref()),
        ("transforms_test_start.json", Some("frames"))
    );

    let mut dup = good.clone();
    dup.views[0].frames[1].name = "0000".into();
    assert!(dup.to_files().unwrap_err().message.contains("duplicate"));

    let mut sized = good.clone();
    sized.views[0].frames[0].depth.as_mut().unwrap().width = 3;
    assert_eq!(
        sized.to_files().unwrap_err().file,
        "start/train/depth/0000.png"
    );

    let mut short = good.clone();
    short.views[2].frames[0].rgba.pixels.pop();
    assert_eq!(
        short.to_files().unwrap_err().field.as_deref(),
        Some("pixels")
    );

    let mut parts = good.clone();
    parts.num_parts = 7;
    assert!(parts.to_files().unwrap_err().message.contains("imply 3"));

    let mut no_end = good.clone();
    no_end.views.retain(|v| v.state == State::Start);
    assert_eq!(
        no_end.to_files().unwrap_err().file,
        "transforms_train_end.json"
    );

    let mut partial_depth = good;
    partial_depth.views[0].frames[2].depth = None;
    assert!(
        partial_depth
            .to_files()
            .unwrap_err()
            .message
            .contains("all frames of a split or for none")
    );
    assert!(partial_depth.views(State::Start, Split::Train).is_some());
}
