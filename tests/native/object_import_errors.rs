//! URDF import of bad input, starting from the real objects in `../shared/objects/`: a malformed URDF, bad
//! mesh references, joint-limit rules, and corrupt mesh files (errors or meshes, never panics).

use artmesh::data::FileSet;
use artmesh::object::{ArticulatedObject, JointKind};

use crate::common::shared_objects as objects;

/// A copy of the objects with `path` edited by `edit` (text replacement in a URDF).
fn edited(path: &str, from: &str, to: &str) -> FileSet {
    let mut files = objects().clone();
    let text = String::from_utf8(files[path].clone()).unwrap();
    assert!(text.contains(from), "{path} does not contain {from:?}");
    files.insert(path.to_string(), text.replacen(from, to, 1).into_bytes());
    files
}

#[test]
fn object_malformed_fridge_static_is_a_clear_error() {
    let e =
        ArticulatedObject::from_urdf("habitat/fridge/fridge_static.urdf", objects()).unwrap_err();
    assert_eq!(e.file, "habitat/fridge/fridge_static.urdf");
    assert_eq!(
        e.field.as_deref(),
        Some("robot/link[name=bottom_door]/visual[0]/origin@xyz (line 122)")
    );
    assert!(
        e.message
            .contains("expected three finite numbers separated by spaces"),
        "{e}"
    );
    assert!(e.message.contains("\"0.01, -0.33, 0\""), "{e}");
}

#[test]
fn object_bad_mesh_references_are_clear_errors() {
    let urdf = "habitat/fridge/fridge.urdf";
    let missing = edited(urdf, "top_door.glb", "no_such_door.glb");
    let e = ArticulatedObject::from_urdf(urdf, &missing).unwrap_err();
    assert_eq!(e.file, urdf);
    assert_eq!(
        e.field.as_deref(),
        Some("robot/link[name=top_door]/visual[0]/geometry/mesh@filename (line 96)")
    );
    assert!(
        e.message.contains("'habitat/fridge/no_such_door.glb'")
            && e.message.contains("not in the dataset"),
        "{e}"
    );

    let dae = edited(urdf, "top_door.glb", "top_door.dae");
    let e = ArticulatedObject::from_urdf(urdf, &dae).unwrap_err();
    assert!(e.message.contains("unsupported mesh format '.dae'"), "{e}");

    let bad_scale = edited(urdf, r#"scale="1.0 1.0 1.0""#, r#"scale="1.0 1.0 x""#);
    let e = ArticulatedObject::from_urdf(urdf, &bad_scale).unwrap_err();
    assert_eq!(
        e.field.as_deref(),
        Some("robot/link[name=body]/visual[0]/geometry/mesh@scale (line 20)")
    );
    assert!(e.message.contains("expected three finite numbers"), "{e}");
    let short_scale = edited(urdf, r#"scale="1.0 1.0 1.0""#, r#"scale="1.0 1.0""#);
    assert!(ArticulatedObject::from_urdf(urdf, &short_scale).is_err());

    let escape = edited(urdf, "top_door.glb", "../../../../etc/top_door.glb");
    let e = ArticulatedObject::from_urdf(urdf, &escape).unwrap_err();
    assert!(e.message.contains("leaves the dataset"), "{e}");

    let corrupt = {
        let mut f = objects().clone();
        f.insert(
            "habitat/fridge/top_door.glb".into(),
            b"glTF\x02\0\0\0garbage".to_vec(),
        );
        f
    };
    let e = ArticulatedObject::from_urdf(urdf, &corrupt).unwrap_err();
    assert_eq!(e.file, "habitat/fridge/top_door.glb");
    assert!(e.message.contains("mesh of habitat/fridge/fridge.urdf at robot/link[name=top_door]/visual[0]/geometry/mesh, line 96"), "{e}");

    let corrupt_obj = {
        let mut f = objects().clone();
        f.insert(
            "sektion/meshes/drawer.obj".into(),
            b"v 0 0 0\nf 1 7 9\n".to_vec(),
        );
        f
    };
    let e = ArticulatedObject::from_urdf("sektion/urdf/sektion_cabinet.urdf", &corrupt_obj)
        .unwrap_err();
    assert_eq!(e.file, "sektion/meshes/drawer.obj");
}

#[test]
fn object_joint_limits_rules() {
    let urdf = "habitat/fridge/fridge.urdf";
    // Revolute without <limit>: URDF requires one.
    let no_limit = edited(
        urdf,
        r#"<limit effort="44.4" lower="0.0" upper="2.3" velocity="40"/>"#,
        "",
    );
    let e = ArticulatedObject::from_urdf(urdf, &no_limit).unwrap_err();
    assert_eq!(
        e.field.as_deref(),
        Some("robot/joint[name=top_door_hinge] (line 78)")
    );
    assert!(e.message.contains("<limit"), "{e}");
    // Inverted limits.
    let inverted = edited(
        urdf,
        r#"lower="0.0" upper="2.3""#,
        r#"lower="2.3" upper="0.0""#,
    );
    let e = ArticulatedObject::from_urdf(urdf, &inverted).unwrap_err();
    assert!(
        e.field
            .as_deref()
            .unwrap()
            .starts_with("robot/joint[name=top_door_hinge]/limit@lower"),
        "{e}"
    );
    // Continuous: no limit needed; sampling range is [-π, π].
    let continuous = edited(
        urdf,
        r#"name="top_door_hinge" type="revolute""#,
        r#"name="top_door_hinge" type="continuous""#,
    );
    let o = ArticulatedObject::from_urdf(urdf, &continuous).unwrap();
    let j = &o.joints[o.joint_index("top_door_hinge").unwrap()];
    assert_eq!(j.kind, JointKind::Continuous);
    assert_eq!(
        j.range(),
        Some((-std::f32::consts::PI, std::f32::consts::PI))
    );
    assert_eq!(o.parts().parts.len(), 3);
}

/// Truncated and bit-flipped mesh files give errors or meshes, never panics.
#[test]
fn object_corrupt_mesh_files_never_panic() {
    use artmesh::object::load_mesh;
    let sources = [
        "habitat/doors/door1.glb",
        "sektion/meshes/door_left.obj",
        "sektion/meshes/door_left.stl",
        "sektion/meshes/drawer_convexdecomposition0.obj",
    ];
    for src in sources {
        let bytes = &objects()[src];
        let mut cases: Vec<Vec<u8>> = [
            0,
            1,
            12,
            20,
            84,
            100,
            1000,
            bytes.len() / 2,
            bytes.len() - 1,
        ]
        .iter()
        .filter(|&&n| n < bytes.len())
        .map(|&n| bytes[..n].to_vec())
        .collect();
        // Flip bytes in the header region (GLB chunk lengths, JSON, STL counts, OBJ indices).
        for at in [8, 12, 16, 24, 40, 81, 83, 200, 400] {
            if at < bytes.len() {
                let mut b = bytes.clone();
                b[at] ^= 0xA5;
                cases.push(b);
            }
        }
        for case in cases {
            let mut files = FileSet::new();
            let len = case.len();
            files.insert(src.to_string(), case);
            let result = load_mesh(src, &files, &mut Vec::new());
            if let Ok(meshes) = result {
                for m in meshes {
                    let n = m.positions.len();
                    assert!(
                        m.indices.iter().flatten().all(|&i| (i as usize) < n),
                        "{src} @ {len}"
                    );
                }
            }
        }
    }
}
