//! `render` reads a URDF's package folder the way `info` reads a dataset folder: only the URDF,
//! its `package.xml` files and what they refer to. A recording beside the meshes is never read;
//! a name that is not UTF-8 or a dangling symlink there is not an error; a URDF named without a
//! folder works; and one node instanced 100 000 times renders in seconds.

use std::os::unix::ffi::OsStrExt;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

use artmesh::data::{FileSource, LazyFolder, write_dir};
use artmesh::fixtures::hostile::inputs;
use artmesh::object::ArticulatedObject;

use crate::cli::{TempDir, text};

const URDF: &str = r#"<robot name="r">
<link name="base"><visual><geometry><mesh filename="meshes/listed.gltf"/></geometry></visual></link>
<link name="lid"><visual><geometry><mesh filename="meshes/shared.obj"/></geometry></visual></link>
<joint name="hinge" type="revolute"><parent link="base"/><child link="lid"/>
<axis xyz="0 0 1"/><limit lower="0" upper="1.5" effort="1" velocity="1"/></joint></robot>"#;

/// A package folder: the URDF, a glTF listing one node 100 000 times, an OBJ with its MTL and
/// texture, and what else a user keeps there.
fn package(tmp: &TempDir) -> &Path {
    let root = tmp.0.as_path();
    let mut files = inputs::gltf_scene_listing_one_node(100_000);
    files.extend(inputs::obj_materials_sharing_one_texture(2, 8));
    let files = files
        .into_iter()
        .map(|(k, v)| (format!("meshes/{}", k.rsplit('/').next().unwrap_or(&k)), v))
        .chain([("robot.urdf".to_string(), URDF.as_bytes().to_vec())])
        .collect();
    write_dir(&files, root).unwrap();
    // A 4 GiB recording (sparse: costs no disk), a dangling link and a name that is not UTF-8.
    let recording = std::fs::File::create(root.join("recording.bag")).unwrap();
    recording.set_len(4 << 30).unwrap();
    std::os::unix::fs::symlink("/nonexistent/target", root.join("meshes/dangling.obj")).unwrap();
    let odd = std::ffi::OsStr::from_bytes(b"notes-\xff.txt");
    std::fs::write(root.join(odd), b"x").unwrap();
    root
}

#[test]
fn only_the_files_the_urdf_names_are_read() {
    let tmp = TempDir::new("urdf-folder-read");
    let root = package(&tmp);
    let folder = LazyFolder::list(root).unwrap();
    assert!(folder.paths().contains(&"recording.bag"));
    let object = ArticulatedObject::from_urdf("robot.urdf", &folder).unwrap();
    assert_eq!(object.links.len(), 2);
    assert_eq!(
        folder.read_so_far(),
        [
            "meshes/listed.gltf",
            "meshes/shared.mtl",
            "meshes/shared.obj",
            "meshes/tex.png",
            "robot.urdf"
        ]
    );
}

#[test]
fn render_takes_a_bare_urdf_name_and_reads_nothing_else() {
    let tmp = TempDir::new("urdf-folder-render");
    let root = package(&tmp);
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_artmesh"))
        .args(["render", "robot.urdf", "--out", "captured"])
        .args([
            "--width",
            "16",
            "--height",
            "16",
            "--train-views",
            "2",
            "--test-views",
            "0",
        ])
        .current_dir(root)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    let secs = start.elapsed().as_secs_f64();
    assert!(secs < 20.0, "render took {secs:.1} s");
    assert!(root.join("captured/transforms_train_end.json").is_file());
}
