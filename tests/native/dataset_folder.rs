//! Reading a dataset folder reads the dataset and nothing beside it: the transforms files, `gt/`
//! and the frames they name. What else a user keeps there (a recording, a stray link, a file
//! named in another encoding) is neither read nor an error. A dataset whose images would decode
//! past the budget is refused before any is decoded.

use std::os::unix::ffi::OsStrExt;

use artmesh::data::{self, fixture};

#[test]
fn only_the_referenced_files_are_read() {
    let dir = std::env::temp_dir().join(format!("artmesh-dataset-folder-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let params = fixture::FixtureParams::default();
    let files = fixture::small_dataset(params).to_files().unwrap();
    data::write_dir(&files, &dir).unwrap();
    let expected = data::read_dataset(&dir).unwrap();

    // A 4 GiB recording (sparse: no disk used, but reading it would take 4 GiB of memory), one
    // beside the frames too, a dangling symlink, a name that is not UTF-8, and a FIFO.
    for at in ["capture.mp4", "start/train/rgba/take2.mp4"] {
        let f = std::fs::File::create(dir.join(at)).unwrap();
        f.set_len(4 << 30).unwrap();
    }
    std::os::unix::fs::symlink(dir.join("gone"), dir.join("start/train/rgba/old.png")).unwrap();
    std::fs::write(
        dir.join(std::ffi::OsStr::from_bytes(b"notes-\xff.txt")),
        b"x",
    )
    .unwrap();
    let made = std::process::Command::new("mkfifo")
        .arg(dir.join("pipe"))
        .status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo");

    let read = data::read_dataset_files(&dir).unwrap();
    let mut want: Vec<&String> = files.keys().collect();
    want.sort();
    assert_eq!(
        read.keys().collect::<Vec<_>>(),
        want,
        "read exactly the dataset's files"
    );
    assert_eq!(data::read_dataset(&dir).unwrap(), expected);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_budget_is_a_flag() {
    let dir = std::env::temp_dir().join(format!("artmesh-dataset-budget-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // 400×300, 8 frames: 7.7 MB decoded.
    let params = fixture::FixtureParams {
        width: 400,
        height: 300,
        ..Default::default()
    };
    let files = fixture::small_dataset(params).to_files().unwrap();
    data::write_dir(&files, &dir).unwrap();
    let info = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_artmesh"))
            .arg("info")
            .arg(&dir)
            .args(extra)
            .output()
            .unwrap()
    };
    let ok = info(&[]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let tight = info(&["--max-decoded-mb", "1"]);
    let err = String::from_utf8_lossy(&tight.stderr);
    assert!(
        !tight.status.success() && err.contains("over the budget of 1 MB"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
