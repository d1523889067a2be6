//! A user's own object as the page takes it, natively on lavapipe: a `.zip` of a URDF with its
//! meshes (written by the crate's URDF exporter from a procedural object, as `artmesh synth
//! --object-only` writes it) is told from a dataset's archive, imported, and captured in both
//! states as the demo captures its objects, with ground truth; broken archives are refused with
//! errors that name the archive, the URDF and the file or element at fault.

use crate::common;

use artmesh::data::{FileLimits, FileSet, Split, State, zip_holds_object};
use artmesh::export::{write_urdf, write_zip};
use artmesh::fit::object::FitConfig;
use artmesh::fit::preset::Preset;
use artmesh::pipeline::demo::capture_demo;
use artmesh::pipeline::object::{capture_zipped, object_from_zip};
use artmesh::synth::{Category, SynthParams, generate};

const SEED: u64 = 7;

/// The procedural laptop's URDF and meshes under `laptop/`, as files and zipped.
fn laptop_files() -> FileSet {
    let object = generate(&SynthParams {
        category: Category::Laptop,
        movable_parts: Some(1),
        seed: SEED,
    })
    .unwrap();
    write_urdf(&object, "laptop.urdf").unwrap()
}

fn zipped(files: &FileSet) -> Vec<u8> {
    write_zip(files, "laptop", "laptop.zip").unwrap()
}

/// The error importing `files` zipped as `laptop.zip`.
fn import_error(files: &FileSet) -> String {
    match object_from_zip("laptop.zip", &zipped(files), &FileLimits::default()) {
        Ok(z) => panic!("{} imported", z.urdf),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_zipped_urdf_is_captured_in_both_states_like_the_demo() {
    let files = laptop_files();
    let bytes = zipped(&files);
    assert!(zip_holds_object(&bytes));
    let zipped = object_from_zip("laptop.zip", &bytes, &FileLimits::default()).unwrap();
    assert_eq!(zipped.urdf, "laptop/laptop.urdf");
    assert_eq!(zipped.object.parts().movable_count(), 1);

    let ctx = common::context();
    let spec = FitConfig::preset(Preset::Tiny).demo_capture(SEED);
    let mut heard = 0;
    let input = pollster::block_on(capture_zipped(&ctx, &zipped, &spec, &mut |p| {
        heard = p.done;
    }))
    .unwrap();
    let ds = &input.dataset;
    assert_eq!(heard, 2 * spec.train_views, "progress heard every view");
    for state in State::ALL {
        let train = ds.views(state, Split::Train).expect("train views");
        assert_eq!(train.frames.len(), spec.train_views, "{state:?}");
        let image = &train.frames[0].rgba;
        assert_eq!((image.width, image.height), (spec.width, spec.height));
        assert!(ds.views(state, Split::Test).is_none(), "no test views");
    }
    // Named after what the user dropped, not the URDF's robot (exporters call it "Scene").
    assert_eq!(input.id, "laptop");
    assert_ne!(zipped.object.name, "laptop");

    // The truth is attached, as for the demo's objects, and is the demo's own: the same object
    // captured directly with the same spec has the same joint.
    let truth = ds.gt_joints.as_ref().expect("ground-truth joints");
    assert_eq!(truth.len(), 1);
    assert!(
        ds.gt_meshes.iter().all(Option::is_some),
        "ground-truth meshes"
    );
    let object = generate(&SynthParams {
        category: Category::Laptop,
        movable_parts: Some(1),
        seed: SEED,
    })
    .unwrap();
    let demo = pollster::block_on(capture_demo(
        &ctx,
        &object,
        Category::Laptop,
        &spec,
        &mut |_| {},
    ))
    .unwrap();
    let direct = &demo.dataset.gt_joints.as_ref().unwrap()[0];
    let (a, b) = (truth[0].unit_direction(), direct.unit_direction());
    assert!(a.dot(b) > 0.9999, "axis {a} vs {b}");
    assert!(
        (truth[0].motion() - direct.motion()).abs() < 1e-3,
        "motion {} vs {}",
        truth[0].motion(),
        direct.motion()
    );
}

#[test]
fn a_zipped_urdf_missing_a_mesh_names_the_mesh_and_the_urdf() {
    let mut files = laptop_files();
    let mesh = files
        .keys()
        .find(|k| k.ends_with(".obj") || k.ends_with(".glb"))
        .cloned()
        .expect("the exporter writes mesh files");
    files.remove(&mesh);
    let e = import_error(&files);
    assert!(e.starts_with("laptop.zip: laptop/laptop.urdf: "), "{e}");
    assert!(e.contains(&format!("laptop/{mesh}")), "{e}");
    assert!(e.contains("not in the"), "{e}");
}

#[test]
fn broken_zipped_urdfs_say_what_was_expected() {
    let urdf = |text: &str| -> FileSet {
        let mut f = FileSet::new();
        f.insert("laptop.urdf".into(), text.as_bytes().to_vec());
        f
    };
    let still = urdf(
        r#"<robot name="still"><link name="a"><visual><geometry><box size="1 1 1"/></geometry></visual></link>
        <link name="b"/><joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint></robot>"#,
    );
    let e = import_error(&still);
    assert!(
        e.starts_with("laptop.zip: laptop/laptop.urdf: ") && e.contains("no movable joint"),
        "{e}"
    );

    let e = import_error(&urdf("<robot name=\"x\"><link"));
    assert!(
        e.starts_with("laptop.zip: laptop/laptop.urdf: ") && e.contains("well-formed XML"),
        "{e}"
    );

    let mut two = laptop_files();
    two.insert("other.urdf".into(), b"<robot/>".to_vec());
    let e = import_error(&two);
    assert!(
        e.contains("2 URDF files") && e.contains("laptop/other.urdf"),
        "{e}"
    );

    let mut none = laptop_files();
    none.retain(|k, _| !k.ends_with(".urdf"));
    assert!(!zip_holds_object(&zipped(&none)));
    assert!(import_error(&none).contains("holds no .urdf file"));
}
