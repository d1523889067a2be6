//! URDF import against the real objects in `../shared/objects/` (habitat-sim test furniture, IsaacGym's Sektion
//! cabinet): structure, parts, meshes, forward kinematics, `package://` resolution and the URDF writer round
//! trip. Bad input (malformed URDFs, bad mesh references, limits, corrupt mesh files) is in
//! `object_import_errors.rs`.

use std::f32::consts::FRAC_PI_2;

use artmesh::object::{ArticulatedObject, Geometry, JointKind};
use glam::{Quat, Vec3};

use crate::common::shared_objects as objects;

fn import(path: &str) -> ArticulatedObject {
    ArticulatedObject::from_urdf(path, objects()).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn kinds(o: &ArticulatedObject) -> [usize; 4] {
    let mut n = [0; 4];
    for j in &o.joints {
        n[match j.kind {
            JointKind::Fixed => 0,
            JointKind::Revolute => 1,
            JointKind::Continuous => 2,
            JointKind::Prismatic => 3,
        }] += 1;
    }
    n
}

/// Counts (links, joints, [fixed, revolute, continuous, prismatic], visuals, collisions, parts), counted from
/// the XML by hand (comments excluded).
struct Expected {
    path: &'static str,
    links: usize,
    joints: usize,
    kinds: [usize; 4],
    visuals: usize,
    collisions: usize,
    parts: usize,
}

const ALL: [Expected; 10] = [
    Expected {
        path: "habitat/cabinet/cabinet.urdf",
        links: 4,
        joints: 3,
        kinds: [1, 0, 0, 2],
        visuals: 3,
        collisions: 7,
        parts: 3,
    },
    Expected {
        path: "habitat/doors/door1.urdf",
        links: 2,
        joints: 1,
        kinds: [0, 1, 0, 0],
        visuals: 1,
        collisions: 1,
        parts: 2,
    },
    Expected {
        path: "habitat/doors/door2.urdf",
        links: 2,
        joints: 1,
        kinds: [0, 1, 0, 0],
        visuals: 1,
        collisions: 1,
        parts: 2,
    },
    Expected {
        path: "habitat/doors/door3.urdf",
        links: 2,
        joints: 1,
        kinds: [0, 1, 0, 0],
        visuals: 1,
        collisions: 1,
        parts: 2,
    },
    Expected {
        path: "habitat/doors/doubledoor.urdf",
        links: 4,
        joints: 3,
        kinds: [1, 2, 0, 0],
        visuals: 2,
        collisions: 2,
        parts: 3,
    },
    Expected {
        path: "habitat/fridge/fridge.urdf",
        links: 4,
        joints: 3,
        kinds: [1, 2, 0, 0],
        visuals: 3,
        collisions: 11,
        parts: 3,
    },
    Expected {
        path: "habitat/fridge/fridge_scaled.urdf",
        links: 4,
        joints: 3,
        kinds: [1, 2, 0, 0],
        visuals: 3,
        collisions: 11,
        parts: 3,
    },
    Expected {
        path: "habitat/kitchen_counter/kitchen_counter.urdf",
        links: 9,
        joints: 8,
        kinds: [1, 0, 0, 7],
        visuals: 8,
        collisions: 46,
        parts: 8,
    },
    Expected {
        path: "sektion/urdf/sektion_cabinet.urdf",
        links: 9,
        joints: 8,
        kinds: [4, 2, 0, 2],
        visuals: 9,
        collisions: 11,
        parts: 5,
    },
    Expected {
        path: "sektion/urdf/sektion_cabinet_2.urdf",
        links: 9,
        joints: 8,
        kinds: [4, 2, 0, 2],
        visuals: 8,
        collisions: 21,
        parts: 5,
    },
];

#[test]
fn object_every_urdf_imports_with_the_counts_of_its_xml() {
    let urdfs: Vec<&String> = objects().keys().filter(|k| k.ends_with(".urdf")).collect();
    // Every URDF in the folder is covered: the ten above plus the malformed fridge_static.urdf.
    assert_eq!(urdfs.len(), ALL.len() + 1, "{urdfs:?}");
    for e in &ALL {
        let o = import(e.path);
        assert_eq!(o.links.len(), e.links, "{} links", e.path);
        assert_eq!(o.joints.len(), e.joints, "{} joints", e.path);
        assert_eq!(kinds(&o), e.kinds, "{} joint kinds", e.path);
        let visuals: usize = o.links.iter().map(|l| l.visuals.len()).sum();
        let collisions: usize = o.links.iter().map(|l| l.collisions.len()).sum();
        assert_eq!(visuals, e.visuals, "{} visuals", e.path);
        assert_eq!(collisions, e.collisions, "{} collisions", e.path);
        let parts = o.parts();
        assert_eq!(parts.parts.len(), e.parts, "{} parts", e.path);
        assert!(parts.merged_joints.is_empty(), "{}", e.path);
        // Every movable joint starts exactly one part; the base has none.
        let mut starters: Vec<usize> = parts.parts.iter().filter_map(|p| p.joint).collect();
        starters.sort_unstable();
        assert_eq!(starters, o.movable_joints(), "{}", e.path);
        assert_eq!(parts.parts[0].joint, None);
        assert_eq!(parts.link_part[o.root], 0);
        assert!(o.warnings.is_empty(), "{}: {:?}", e.path, o.warnings);
        for j in o.joints.iter().filter(|j| j.kind.is_movable()) {
            let (lo, hi) = j.range().unwrap();
            assert!(
                lo <= hi && (hi - lo) > 0.1,
                "{} {}: range {lo}..{hi}",
                e.path,
                j.name
            );
            assert!((j.axis.length() - 1.0).abs() < 1e-6);
        }
    }
}

#[test]
fn object_meshes_are_non_empty_finite_and_consistent() {
    for e in &ALL {
        let o = import(e.path);
        for (l, link) in o.links.iter().enumerate() {
            for v in link.visuals.iter().chain(&link.collisions) {
                if let Geometry::Mesh { meshes, path, .. } = &v.geometry {
                    assert!(meshes.iter().any(|m| !m.indices.is_empty()), "{path}");
                }
            }
            for m in o.link_meshes(l) {
                let n = m.positions.len();
                assert!(n > 0 && !m.indices.is_empty(), "{} {}", e.path, link.name);
                assert_eq!(m.normals.len(), n);
                assert!(m.positions.iter().all(|p| p.is_finite()));
                assert!(m.indices.iter().flatten().all(|&i| (i as usize) < n));
                if let Some(uvs) = &m.uvs {
                    assert_eq!(uvs.len(), n);
                }
            }
        }
    }
    // habitat GLBs carry PNG base-colour textures; Sektion's OBJs colours from their MTL files.
    let fridge = import("habitat/fridge/fridge.urdf");
    let door = fridge.link_meshes(fridge.link_index("top_door").unwrap());
    let tex = door[0]
        .material
        .texture
        .as_ref()
        .expect("top_door.glb is textured");
    assert!(tex.width > 0 && tex.pixels.len() == (tex.width * tex.height * 4) as usize);
    assert!(door[0].uvs.is_some());
    let sektion = import("sektion/urdf/sektion_cabinet.urdf");
    let drawer = sektion.link_meshes(sektion.link_index("drawer_top").unwrap());
    assert_eq!(drawer[0].material.base_color, [0.84, 0.8, 0.64, 1.0]);
    // STL collision meshes have no material of their own.
    let stl = &sektion.links[sektion.link_index("door_left_link").unwrap()].collisions[0];
    let Geometry::Mesh { path, meshes, .. } = &stl.geometry else {
        panic!("mesh expected")
    };
    assert_eq!(path, "sektion/meshes/door_left.stl");
    assert_eq!(meshes[0].material.name, None);
}

#[test]
fn object_mesh_scale_is_applied() {
    let plain = import("habitat/fridge/fridge.urdf");
    let scaled = import("habitat/fridge/fridge_scaled.urdf");
    let extent = |o: &ArticulatedObject, link: &str| {
        let meshes = o.link_meshes(o.link_index(link).unwrap());
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        for p in meshes.iter().flat_map(|m| &m.positions) {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        hi - lo
    };
    let ratio = extent(&scaled, "body") / extent(&plain, "body");
    assert!(
        (ratio - Vec3::splat(1.5)).abs().max_element() < 1e-4,
        "{ratio}"
    );
    let ratio = extent(&scaled, "top_door") / extent(&plain, "top_door");
    assert!(
        (ratio - Vec3::splat(0.75)).abs().max_element() < 1e-4,
        "{ratio}"
    );
}

#[test]
fn object_sektion_parts_and_package_resolution() {
    for path in [
        "sektion/urdf/sektion_cabinet.urdf",
        "sektion/urdf/sektion_cabinet_2.urdf",
    ] {
        let o = import(path);
        assert_eq!(o.name, "cabinet_sektion");
        assert_eq!(o.links[o.root].name, "sektion");
        let parts = o.parts();
        let summary: Vec<(Option<&str>, Vec<&str>)> = parts
            .parts
            .iter()
            .map(|p| {
                (
                    p.joint.map(|j| o.joints[j].name.as_str()),
                    p.links.iter().map(|&l| o.links[l].name.as_str()).collect(),
                )
            })
            .collect();
        assert_eq!(
            summary,
            vec![
                (None, vec!["sektion"]),
                (
                    Some("door_right_joint"),
                    vec!["door_right_link", "door_right_nob_link"]
                ),
                (
                    Some("door_left_joint"),
                    vec!["door_left_link", "door_left_nob_link"]
                ),
                (
                    Some("drawer_top_joint"),
                    vec!["drawer_top", "drawer_handle_top"]
                ),
                (
                    Some("drawer_bottom_joint"),
                    vec!["drawer_bottom", "drawer_handle_bottom"]
                ),
            ],
            "{path}"
        );
    }
    // package://sektion_cabinet_model/... resolves through sektion/package.xml (folder `sektion`).
    let o = import("sektion/urdf/sektion_cabinet.urdf");
    let Geometry::Mesh { path, .. } = &o.links[o.root].visuals[0].geometry else {
        panic!("mesh expected")
    };
    assert_eq!(path, "sektion/meshes/sektion.obj");
    // Without the package.xml, the package cannot be found.
    let mut files = objects().clone();
    files.remove("sektion/package.xml");
    let e = ArticulatedObject::from_urdf("sektion/urdf/sektion_cabinet.urdf", &files).unwrap_err();
    assert!(
        e.message.contains("<name>sektion_cabinet_model</name>"),
        "{e}"
    );
    assert!(
        e.field
            .as_deref()
            .unwrap()
            .ends_with("/geometry/mesh@filename (line 26)"),
        "{e:?}"
    );
}

/// Sektion's original chain (commented out in both files): sektion → fixed anchor → 1.5 cm prismatic shift
/// (mimicking the hinge) → revolute door. The shift is merged; the hinge drives the door part.
#[test]
fn object_chained_shift_joint_is_merged_into_the_base() {
    let chain = r#"
  <link name="door_right_anchor_link"/>
  <link name="door_right_joint_anchor_link"/>
  <joint name="door_right_joint_fixed" type="fixed">
    <parent link="sektion"/><child link="door_right_anchor_link"/>
    <origin xyz="0.3162 0.3757 -0.12973" rpy="0 0 0"/>
  </joint>
  <joint name="door_right_shift_joint" type="prismatic">
    <parent link="door_right_anchor_link"/><child link="door_right_joint_anchor_link"/>
    <axis xyz="0 1 0"/>
    <limit effort="1000.0" lower="-0.015" upper="0" velocity="0.0"/>
    <mimic joint="door_right_joint" multiplier="-0.009554" offset="0" />
  </joint>
  <joint name="door_right_joint" type="revolute">
    <parent link="door_right_joint_anchor_link"/>"#;
    let path = "sektion/urdf/sektion_cabinet.urdf";
    let text = String::from_utf8(objects()[path].clone()).unwrap();
    let original = r#"
  <joint name="door_right_joint" type="revolute">
    <parent link="sektion"/>"#;
    assert!(text.contains(original));
    let mut files = objects().clone();
    files.insert(path.into(), text.replacen(original, chain, 1).into_bytes());
    let o = ArticulatedObject::from_urdf(path, &files).unwrap();
    assert_eq!((o.links.len(), o.joints.len()), (11, 10));
    let shift = o.joint_index("door_right_shift_joint").unwrap();
    let hinge = o.joint_index("door_right_joint").unwrap();
    let m = o.joints[shift].mimic.unwrap();
    assert_eq!(m.joint, hinge);
    assert!((m.multiplier + 0.009554).abs() < 1e-7);
    let parts = o.parts();
    assert_eq!(parts.parts.len(), 5);
    assert_eq!(parts.merged_joints, vec![shift]);
    assert_eq!(parts.parts[1].joint, Some(hinge));
    for name in ["door_right_anchor_link", "door_right_joint_anchor_link"] {
        assert_eq!(parts.link_part[o.link_index(name).unwrap()], 0, "{name}");
    }
    // Part-level state: the hinge at 1 rad, the merged shift at its rest value 0 (clamped into [-0.015, 0]).
    let q = parts.configuration(&o, &[0.0, 1.0, 0.0, 0.2, 0.0]);
    assert_eq!(q[shift], 0.0);
    assert_eq!(q[hinge], 1.0);
    assert_eq!(q[o.joint_index("drawer_top_joint").unwrap()], 0.2);
    // Mimic resolution gives the coupled shift value.
    let coupled = o.apply_mimic(&q);
    assert!((coupled[shift] + 0.009554).abs() < 1e-7);

    // A tiny joint with nothing movable after it is still a part of its own.
    let lone = text.replacen(
        r#"lower="0.0" upper="0.4" velocity="1."/>"#,
        r#"lower="0.0" upper="0.01" velocity="1."/>"#,
        1,
    );
    let mut files = objects().clone();
    files.insert(path.into(), lone.into_bytes());
    let o = ArticulatedObject::from_urdf(path, &files).unwrap();
    assert_eq!(o.parts().parts.len(), 5);
}

#[test]
fn object_forward_kinematics_moves_revolute_and_prismatic_children() {
    // Fridge top door: revolute about the body's z, which the fixed root rotation turns (rpy 1.565 0 0).
    let o = import("habitat/fridge/fridge.urdf");
    let hinge = o.joint_index("top_door_hinge").unwrap();
    let door = o.link_index("top_door").unwrap();
    let theta = 1.2;
    let rest = o.forward_kinematics(&vec![0.0; o.joints.len()]);
    let mut q = vec![0.0; o.joints.len()];
    q[hinge] = theta;
    let moved = o.forward_kinematics(&q);
    let joint_frame = rest[o.joints[hinge].parent] * o.joints[hinge].origin;
    let axis = joint_frame
        .transform_vector3(o.joints[hinge].axis)
        .normalize();
    let pivot = joint_frame.transform_point3(Vec3::ZERO);
    let expected_axis = Quat::from_rotation_x(1.565) * Vec3::Z;
    assert!((axis - expected_axis).length() < 1e-5);
    for p in [Vec3::new(0.0, -0.33, 0.0), Vec3::new(0.1, 0.2, 0.3)] {
        let before = rest[door].transform_point3(p);
        let after = moved[door].transform_point3(p);
        let expected = Quat::from_axis_angle(axis, theta) * (before - pivot) + pivot;
        assert!((after - expected).length() < 1e-5, "{after} vs {expected}");
    }
    // The other door and the body stay put.
    let body = o.link_index("body").unwrap();
    assert!(moved[body].abs_diff_eq(rest[body], 1e-6));
    let bottom = o.link_index("bottom_door").unwrap();
    assert!(moved[bottom].abs_diff_eq(rest[bottom], 1e-6));

    // Sektion top drawer: prismatic along x; its handle (fixed child) follows.
    let o = import("sektion/urdf/sektion_cabinet.urdf");
    let slide = o.joint_index("drawer_top_joint").unwrap();
    let mut q = vec![0.0; o.joints.len()];
    q[slide] = 0.3;
    let rest = o.forward_kinematics(&[]);
    let moved = o.forward_kinematics(&q);
    for name in ["drawer_top", "drawer_handle_top"] {
        let l = o.link_index(name).unwrap();
        let d = moved[l].translation - rest[l].translation;
        assert!(
            (Vec3::from(d) - Vec3::new(0.3, 0.0, 0.0)).length() < 1e-6,
            "{name}: {d}"
        );
        assert!(moved[l].matrix3.abs_diff_eq(rest[l].matrix3, 1e-6));
    }
    let door = o.link_index("door_left_link").unwrap();
    assert!(moved[door].abs_diff_eq(rest[door], 1e-6));

    // Door rotation of Sektion's left door: a quarter turn about z maps the door's +y to -x.
    let hinge = o.joint_index("door_left_joint").unwrap();
    let mut q = vec![0.0; o.joints.len()];
    q[hinge] = -FRAC_PI_2;
    let moved = o.forward_kinematics(&q);
    let y = moved[door].transform_vector3(Vec3::Y);
    assert!((y - Vec3::X).length() < 1e-6, "{y}");
}

/// The URDF writer inverts the importer on real objects: rotated joint frames (rpy), limits, mimics, link
/// poses at any configuration, and the meshes (GLB, OBJ and STL sources, rewritten as OBJ).
#[test]
fn object_urdf_writer_round_trips_the_shared_objects() {
    for path in objects()
        .keys()
        .filter(|k| k.ends_with(".urdf") && !k.ends_with("fridge_static.urdf"))
    {
        let obj = import(path);
        let files = artmesh::export::write_urdf(&obj, "copy/robot.urdf").unwrap();
        let back = ArticulatedObject::from_urdf("copy/robot.urdf", &files)
            .unwrap_or_else(|e| panic!("{path}: {e}"));
        assert_eq!(back.joints.len(), obj.joints.len(), "{path}");
        for (a, b) in obj.joints.iter().zip(&back.joints) {
            assert_eq!(
                (a.kind, a.parent, a.child, a.limit, a.mimic),
                (b.kind, b.parent, b.child, b.limit, b.mimic)
            );
        }
        let mut q: Vec<f32> = obj
            .joints
            .iter()
            .map(|j| j.range().map_or(0.0, |(lo, hi)| 0.3 * lo + 0.7 * hi))
            .collect();
        for config in [obj.rest_configuration(), std::mem::take(&mut q)] {
            let (pa, pb) = (
                obj.forward_kinematics(&config),
                back.forward_kinematics(&config),
            );
            for (link, (a, b)) in pa.iter().zip(&pb).enumerate() {
                for p in [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z] {
                    let d = (a.transform_point3(p) - b.transform_point3(p)).length();
                    assert!(d < 1e-5, "{path}: link {link} pose differs by {d}");
                }
            }
        }
        for link in 0..obj.links.len() {
            let count = |o: &ArticulatedObject| -> usize {
                o.link_meshes(link).iter().map(|m| m.indices.len()).sum()
            };
            assert_eq!(count(&obj), count(&back), "{path}: link {link} triangles");
            let worst = obj
                .link_meshes(link)
                .iter()
                .zip(back.link_meshes(link).iter())
                .flat_map(|(a, b)| {
                    a.positions
                        .iter()
                        .zip(b.positions.iter())
                        .map(|(p, q)| (*p - *q).length())
                })
                .fold(0.0f32, f32::max);
            assert!(
                worst < 1e-5,
                "{path}: link {link} vertices moved by {worst}"
            );
        }
    }
}
