//! Procedural objects of every category: structure checks for every part count, reproducibility, and a
//! contact sheet (`artefacts/synth-contact-sheet.png`) of one object per category at both states.

use artmesh::data::encode_png;
use artmesh::gpu::GpuContext;
use artmesh::object::JointKind;
use artmesh::render::{SheetEntry, contact_sheet, sample_state};
use artmesh::rng::Rng;
use artmesh::synth::{Category, SynthParams, generate};

#[test]
fn every_category_and_part_count_builds_a_sound_object() {
    for category in Category::ALL {
        for parts in category.movable_parts() {
            for seed in 0..3 {
                let params = SynthParams {
                    category,
                    movable_parts: Some(parts),
                    seed,
                };
                let obj = generate(&params).unwrap_or_else(|e| panic!("{params:?}: {e}"));
                let what = format!("{category} {parts} parts seed {seed}");
                let view = obj.parts();
                assert_eq!(view.movable_count(), parts, "{what}");
                assert!(view.merged_joints.is_empty(), "{what}: chained joints");
                for part in &view.parts[1..] {
                    let joint = &obj.joints[part.joint.unwrap()];
                    assert_eq!(
                        joint.parent, obj.root,
                        "{what}: {} hangs on a moving part",
                        joint.name
                    );
                    assert!(
                        matches!(joint.kind, JointKind::Revolute | JointKind::Prismatic),
                        "{what}: {}",
                        joint.name
                    );
                    let (lo, hi) = joint.range().unwrap();
                    assert!(lo < hi, "{what}: {} range {lo}..{hi}", joint.name);
                    assert!((joint.axis.length() - 1.0).abs() < 1e-5, "{what}");
                    let meshes = obj.link_meshes(joint.child);
                    assert!(
                        meshes.iter().any(|m| !m.indices.is_empty()),
                        "{what}: {} has no geometry",
                        joint.name
                    );
                }
                let q = obj.rest_configuration();
                let meshes = artmesh::render::posed_part_meshes(&obj, &q);
                let (lo, hi) = artmesh::render::object_bounds(&meshes).expect("geometry");
                let size = hi - lo;
                assert!(
                    size.max_element() < 3.0 && size.max_element() > 0.02,
                    "{what}: size {size}"
                );
                assert!(
                    lo.z > -0.01,
                    "{what}: sinks below the floor to z = {}",
                    lo.z
                );
                for m in &meshes {
                    assert!(m.mesh.positions.iter().all(|p| p.is_finite()), "{what}");
                    assert!(
                        m.mesh
                            .normals
                            .iter()
                            .all(|n| (n.length() - 1.0).abs() < 1e-3),
                        "{what}"
                    );
                }
                assert_eq!(generate(&params).unwrap(), obj, "{what}: not reproducible");
            }
        }
    }
}

#[test]
fn unsupported_part_counts_are_clear_errors() {
    let err = generate(&SynthParams {
        category: Category::Laptop,
        movable_parts: Some(3),
        seed: 0,
    })
    .unwrap_err()
    .to_string();
    assert!(err.contains("Laptop") && err.contains('3'), "{err}");
}

#[test]
fn contact_sheet_shows_every_category_at_both_states() {
    let ctx = pollster::block_on(GpuContext::new()).expect("GPU adapter (lavapipe)");
    let objects: Vec<_> = Category::ALL
        .iter()
        .map(|&category| {
            let parts = *category.movable_parts().end();
            generate(&SynthParams {
                category,
                movable_parts: Some(parts),
                seed: 1,
            })
            .unwrap()
        })
        .collect();
    let mut rng = Rng::new(5);
    let entries: Vec<SheetEntry> = objects
        .iter()
        .map(|object| SheetEntry {
            object,
            states: [
                sample_state(object, (0.6, 0.8), &mut rng),
                sample_state(object, (0.2, 0.4), &mut rng),
            ],
        })
        .collect();
    let sheet = pollster::block_on(contact_sheet(&ctx, &entries, 160, 4)).unwrap();
    assert_eq!((sheet.width, sheet.height), (160 * 8, 160 * 4));
    // Every tile shows something: some pixel differs from the background.
    for (i, _) in entries.iter().enumerate() {
        for side in 0..2 {
            let (x0, y0) = (((i % 4) * 2 + side) * 160, (i / 4) * 160);
            let covered = (0..160 * 160).any(|k| {
                let (x, y) = (x0 + k % 160, y0 + k / 160);
                sheet.pixels[(y * sheet.width as usize + x) * 4] != 230
            });
            assert!(covered, "{}: tile {side} is empty", objects[i].name);
        }
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("artefacts");
    std::fs::create_dir_all(&dir).unwrap();
    let png = encode_png(
        "synth-contact-sheet.png",
        sheet.width,
        sheet.height,
        artmesh::data::PngPixels::Rgba8(&sheet.pixels),
    )
    .unwrap();
    std::fs::write(dir.join("synth-contact-sheet.png"), png).unwrap();
}

/// `write_urdf` then `from_urdf` gives back the same object: links, joints, limits, meshes, UVs, colours and
/// texture pixels.
#[test]
fn generated_objects_round_trip_through_urdf() {
    for category in Category::ALL {
        let params = SynthParams {
            category,
            movable_parts: Some(*category.movable_parts().end()),
            seed: 11,
        };
        let obj = generate(&params).unwrap();
        let files = artmesh::export::write_urdf(&obj, "object/model.urdf").unwrap();
        let back = artmesh::object::ArticulatedObject::from_urdf("object/model.urdf", &files)
            .unwrap_or_else(|e| panic!("{category}: {e}"));
        assert!(back.warnings.is_empty(), "{category}: {:?}", back.warnings);
        assert_eq!(back.name, obj.name);
        assert_eq!(back.links.len(), obj.links.len(), "{category}");
        assert_eq!(back.joints.len(), obj.joints.len(), "{category}");
        for (a, b) in obj.joints.iter().zip(&back.joints) {
            assert_eq!(
                (&a.name, a.kind, a.parent, a.child),
                (&b.name, b.kind, b.parent, b.child)
            );
            assert_eq!(a.limit, b.limit, "{category}: {}", a.name);
            assert!((a.axis - b.axis).length() < 1e-6, "{category}: {}", a.name);
            let (p, q) = (
                a.origin.transform_point3(glam::Vec3::ONE),
                b.origin.transform_point3(glam::Vec3::ONE),
            );
            assert!(
                (p - q).length() < 1e-5,
                "{category}: {} origin {p} vs {q}",
                a.name
            );
        }
        for link in 0..obj.links.len() {
            let (a, b) = (obj.link_meshes(link), back.link_meshes(link));
            assert_eq!(a.len(), b.len(), "{category}: link {link}");
            for (ma, mb) in a.iter().zip(&b) {
                // The OBJ reader merges vertices identical in position, normal and UV, so compare triangle
                // corners rather than index lists.
                assert_eq!(
                    ma.indices.len(),
                    mb.indices.len(),
                    "{category}: link {link}"
                );
                let (ua, ub) = (ma.uvs.as_ref().unwrap(), mb.uvs.as_ref().unwrap());
                for (ta, tb) in ma.indices.iter().zip(&mb.indices) {
                    for (&i, &j) in ta.iter().zip(tb) {
                        let (i, j) = (i as usize, j as usize);
                        let moved = (ma.positions[i] - mb.positions[j]).length();
                        assert!(
                            moved < 1e-6,
                            "{category}: link {link} corner moved by {moved}"
                        );
                        assert!(
                            (ua[i] - ub[j]).length() < 1e-5,
                            "{category}: link {link} uv"
                        );
                    }
                }
                assert_eq!(ma.material.base_color, mb.material.base_color, "{category}");
                assert_eq!(
                    ma.material.texture, mb.material.texture,
                    "{category}: texture"
                );
            }
        }
        // Movable links carry mass, so physics engines treat them as bodies.
        let text = String::from_utf8(files["object/model.urdf"].clone()).unwrap();
        assert_eq!(
            text.matches("<inertial>").count(),
            obj.links.len(),
            "{category}"
        );
    }
}

/// The full suite's objects are a pure function of the plan: generating them twice gives the same URDF and
/// mesh bytes (rendering determinism is covered by the capture tests).
#[test]
fn full_suite_objects_are_reproducible() {
    let plan = artmesh::synth::suite_plan(false);
    assert_eq!(plan, artmesh::synth::suite_plan(false));
    for entry in &plan {
        let write = || {
            let obj = generate(&entry.params()).unwrap_or_else(|e| panic!("{}: {e}", entry.id()));
            artmesh::export::write_urdf(&obj, "o.urdf").unwrap()
        };
        assert!(write() == write(), "{}", entry.id());
    }
}
