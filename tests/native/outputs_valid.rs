//! `artmesh export` refuses a fit folder whose joints.json would give the GLB non-finite numbers,
//! naming the field, and writes nothing (the refusals themselves are in `fixtures::hostile`).

use std::path::Path;

use artmesh::export::write_urdf;
use artmesh::fixtures::hostile::{joints_json, truth_object};

use crate::cli::{TempDir, artmesh, text};

#[test]
fn export_with_an_out_of_range_motion_writes_nothing() {
    let tmp = TempDir::new("outputs-valid-export");
    let fit = tmp.join("fit");
    let object = truth_object().unwrap();
    let urdf = write_urdf(&object, "urdf/twin.urdf").unwrap();
    artmesh::data::write_dir(&urdf, Path::new(&fit)).unwrap();
    std::fs::write(
        Path::new(&fit).join("joints.json"),
        joints_json(&object, "1e300"),
    )
    .unwrap();
    let glb = tmp.join("twin.glb");
    let out = artmesh(&["export", &fit, "--glb", &glb]);
    assert!(!out.status.success());
    let said = text(&out.stderr);
    assert!(
        said.contains("[0].motion") && said.contains("finite"),
        "{said}"
    );
    assert!(!Path::new(&glb).exists(), "a GLB was written");
    // The same folder with a motion in range exports.
    std::fs::write(
        Path::new(&fit).join("joints.json"),
        joints_json(&object, "30"),
    )
    .unwrap();
    let out = artmesh(&["export", &fit, "--glb", &glb]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(Path::new(&glb).exists());
}
