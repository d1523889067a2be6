//! Procedural objects of every category: structure checks for every part count, reproducibility, and a
//! contact sheet (`artefacts/synth-contact-sheet.png`) of one object per category at both states.
#![cfg(not(target_arch = "wasm32"))]

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
    .unwrap_err();
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
