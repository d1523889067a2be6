//! Outputs hold only finite numbers: a dataset, ground truth or export that would carry a NaN, an
//! infinity (written as `null` in JSON) or a value past `f32`'s range is refused, naming the file
//! and the field, and `artmesh export` then writes nothing.

use std::path::Path;

use artmesh::data::fixture::{FixtureParams, small_dataset};
use artmesh::data::{Dataset, GroundTruth};
use artmesh::export::{JOINTS_FILE, Twin, end_configuration, write_glb, write_urdf};
use artmesh::object::ArticulatedObject;
use glam::Vec3;

use crate::cli::{TempDir, artmesh, text};

fn dataset() -> Dataset {
    small_dataset(FixtureParams::default())
}

fn truth_object() -> ArticulatedObject {
    let ds = dataset();
    let start = ds.gt_meshes[0].as_ref().unwrap();
    Twin::from_truth("box", start, ds.gt_joints.as_ref().unwrap()).object()
}

#[test]
fn a_camera_that_is_not_finite_is_not_written() {
    let mut ds = dataset();
    ds.views[0].frames[1].camera.camera_to_world.w_axis.x = f32::NAN;
    let e = ds.to_files().unwrap_err();
    assert_eq!(e.file, "transforms_train_start.json");
    assert_eq!(e.field.as_deref(), Some("frames[1].transform_matrix"));
    assert!(e.message.contains("not a finite number"), "{e}");
    let mut ds = dataset();
    ds.views[0].frames[0].camera.intrinsics.fx = f32::INFINITY;
    assert!(ds.to_files().is_err());
}

#[test]
fn ground_truth_that_is_not_finite_is_not_written() {
    let ds = dataset();
    let mut gt = GroundTruth {
        joints: ds.gt_joints.clone(),
        meshes: ds.gt_meshes.clone(),
    };
    assert!(gt.to_files().is_ok());
    gt.joints.as_mut().unwrap()[1].origin = Vec3::new(0.0, f32::INFINITY, 0.0);
    let e = gt.to_files().unwrap_err();
    assert_eq!(e.file, "gt/trans.json");
    assert_eq!(e.field.as_deref(), Some("trans_info[1]"));
    let mut gt = GroundTruth {
        joints: ds.gt_joints.clone(),
        meshes: ds.gt_meshes.clone(),
    };
    gt.meshes[1].as_mut().unwrap().movable[0].positions[2].z = f32::NAN;
    let e = gt.to_files().unwrap_err();
    assert_eq!(e.file, "gt/end/end_dynamic_0_rotate.ply");
}

#[test]
fn exports_refuse_numbers_that_are_not_finite() {
    let object = truth_object();
    let zero = vec![0.0; object.joints.len()];
    assert!(write_glb(&object, &zero, &zero, "t.glb").is_ok());
    // A motion of 1e300 in joints.json (the issue's example) is past f32's range.
    let joints = format!(
        r#"[{{"joint": "{}", "type": "revolute", "motion": 1e300}}]"#,
        object.joints[0].name
    );
    let e = end_configuration(&object, joints.as_bytes(), JOINTS_FILE).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("[0].motion"));
    // A variant: an end configuration that is itself infinite, and an axis that is not a number.
    let mut end = zero.clone();
    end[0] = f32::INFINITY;
    let e = write_glb(&object, &zero, &end, "t.glb").unwrap_err();
    assert!(e.message.contains("not a finite number"), "{e}");
    let mut bad = object.clone();
    bad.joints[0].axis = Vec3::new(f32::NAN, 0.0, 1.0);
    let e = write_urdf(&bad, "twin.urdf").unwrap_err();
    assert_eq!(e.file, "twin.urdf");
    assert!(
        e.field.as_deref().unwrap().contains(&bad.joints[0].name),
        "{e}"
    );
    assert!(write_glb(&bad, &zero, &zero, "t.glb").is_err());
}

#[test]
fn export_with_an_out_of_range_motion_writes_nothing() {
    let tmp = TempDir::new("outputs-valid-export");
    let fit = tmp.join("fit");
    let object = truth_object();
    let urdf = write_urdf(&object, "urdf/twin.urdf").unwrap();
    artmesh::data::write_dir(&urdf, Path::new(&fit)).unwrap();
    let joints = format!(
        r#"[{{"joint": "{}", "type": "revolute", "motion": 1e300}}]"#,
        object.joints[0].name
    );
    std::fs::write(Path::new(&fit).join("joints.json"), joints).unwrap();
    let glb = tmp.join("twin.glb");
    let out = artmesh(&["export", &fit, "--glb", &glb]);
    assert!(!out.status.success());
    let said = text(&out.stderr);
    assert!(said.contains("motion") && said.contains("finite"), "{said}");
    assert!(!Path::new(&glb).exists(), "a GLB was written");
}
