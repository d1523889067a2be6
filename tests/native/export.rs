//! The exports, checked by the programs that consume them: the Khronos glTF validator (npm
//! `gltf-validator`), MuJoCo and PyBullet (PyPI), and our own URDF reader with the ground-truth
//! renderer. `scripts/setup.sh` installs the tools; a missing one fails the test and says so.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

use artmesh::data::{Camera, FileSet, Intrinsics, write_dir};
use artmesh::export::twin::{joint_transform, moved_link_frames};
use artmesh::export::{Twin, export_twin, write_glb, write_urdf};
use artmesh::object::ArticulatedObject;
use artmesh::render::{
    GtRenderer, capture_truth, object_bounds, posed_part_meshes, sample_state, sample_views,
};
use artmesh::rng::Rng;
use artmesh::synth::{Category, SynthParams, generate};
use glam::{Affine3A, Mat4};
use pollster::block_on;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh scratch folder under `target/`.
fn scratch(name: &str) -> PathBuf {
    let dir = repo().join("target/test-export").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs the glTF validator on `glbs`; one report per file.
fn validate(glbs: &[PathBuf]) -> Vec<serde_json::Value> {
    let web = repo().join("web");
    assert!(
        web.join("node_modules/gltf-validator").exists(),
        "the glTF validator is not installed: run scripts/setup.sh (npm ci in web/)"
    );
    let out = Command::new("node")
        .arg("test/validate_gltf.mjs")
        .args(glbs)
        .current_dir(&web)
        .output()
        .expect("node runs (scripts/setup.sh installs it)");
    let reports: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(
        reports.len(),
        glbs.len(),
        "validator: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    reports
}

fn assert_valid(glbs: &[PathBuf]) {
    for r in validate(glbs) {
        eprintln!("validator: {r}");
        assert_eq!(r["errors"], 0, "{r}");
    }
}

/// Runs `tests/sim/<script>` with `args` in the venv `scripts/setup.sh` makes (MuJoCo and
/// PyBullet); fails with `trouble`, the output and the errors unless it passes. Returns its JSON
/// report.
fn run_simulator_check(script: &str, args: &[&Path], trouble: &str) -> serde_json::Value {
    let python = std::env::var_os("ARTMESH_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("target/pyenv/bin/python"));
    assert!(
        python.exists(),
        "{} is missing: run scripts/setup.sh (it makes a venv with MuJoCo and PyBullet)",
        python.display()
    );
    let out = Command::new(&python)
        .arg(repo().join("tests/sim").join(script))
        .args(args)
        .output()
        .expect("the venv's python runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    eprintln!("{script}: {stdout}");
    assert!(
        out.status.success(),
        "{}: {trouble}:\n{stdout}\n{}",
        args[0].display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&stdout).unwrap_or_default()
}

/// Loads `urdf` in MuJoCo and PyBullet with contacts on (`tests/sim/check_contacts.py`): at rest no
/// movable link overlaps another by more than 5 mm, and driven one at a time each joint covers at
/// least 90 % of its range both ways. Returns the checker's report.
fn check_contacts(urdf: &Path) -> serde_json::Value {
    run_simulator_check(
        "check_contacts.py",
        &[urdf],
        "the twin jams or overlaps in a simulator",
    )
}

/// Loads `urdf` in MuJoCo and PyBullet, sets every joint to `values`, and compares each link frame
/// with `expected` (< 1 mm, < 0.1°); also checks limits and that the joints move.
fn check_in_simulators(
    urdf: &Path,
    object: &ArticulatedObject,
    values: &[f32],
    expected: &[Affine3A],
) -> serde_json::Value {
    let joints: Vec<_> = object
        .joints
        .iter()
        .zip(values)
        .map(|(j, &value)| {
            use artmesh::object::JointKind;
            let kind = match j.kind {
                JointKind::Prismatic => "prismatic",
                JointKind::Fixed => "fixed",
                JointKind::Revolute | JointKind::Continuous => "revolute",
            };
            let limit = j.limit.unwrap_or(artmesh::object::Limit {
                lower: 0.0,
                upper: 0.0,
                effort: 0.0,
                velocity: 0.0,
            });
            serde_json::json!({
                "name": j.name, "type": kind,
                "value": value, "lower": limit.lower, "upper": limit.upper,
            })
        })
        .collect();
    let links: Vec<_> = object
        .links
        .iter()
        .zip(expected)
        .map(|(l, pose)| {
            let (_, r, t) = pose.to_scale_rotation_translation();
            serde_json::json!({
                "name": l.name, "position": t.to_array(), "quaternion_xyzw": r.to_array(),
            })
        })
        .collect();
    let expect = serde_json::json!({
        "joints": joints,
        "links": links,
        "tolerance": { "position_m": 0.001, "angle_deg": 0.1 },
    });
    let expect_path = urdf.with_file_name("expect.json");
    std::fs::write(&expect_path, expect.to_string()).unwrap();
    run_simulator_check(
        "check_urdf.py",
        &[urdf, &expect_path],
        "the simulators disagree",
    )
}

/// A procedural object's two sampled states.
fn states(obj: &ArticulatedObject, seed: u64) -> [Vec<f32>; 2] {
    let mut rng = Rng::new(seed);
    [
        sample_state(obj, (0.6, 0.8), &mut rng),
        sample_state(obj, (0.2, 0.4), &mut rng),
    ]
}

/// The ground-truth twin of a procedural object: its start-state part meshes and joints, the
/// shape a fit's twin has.
fn truth_twin(category: Category, parts: usize, seed: u64) -> (ArticulatedObject, Twin) {
    let obj = generate(&SynthParams {
        category,
        movable_parts: Some(parts),
        seed,
    })
    .unwrap();
    let truth = capture_truth(&obj, states(&obj, seed)).unwrap();
    let twin = Twin::from_truth(&obj.name, &truth.meshes[0], &truth.joints);
    (obj, twin)
}

/// The GLB's node tree as (name, children names) pairs, walking from the scene's root.
fn node_tree(doc: &gltf::Document) -> Vec<(String, Vec<String>)> {
    let scene = doc.default_scene().expect("a default scene");
    let mut out = Vec::new();
    let mut stack: Vec<gltf::Node> = scene.nodes().collect();
    while let Some(n) = stack.pop() {
        let name = |n: &gltf::Node| n.name().unwrap_or_default().to_string();
        out.push((name(&n), n.children().map(|c| name(&c)).collect()));
        stack.extend(n.children());
    }
    out.sort();
    out
}

/// Ground-truth twins (a 7-part cabinet, a 4-part oven, a 3-part table, odd names) as GLB and URDF:
/// the validator finds no error (collision extras included), the GLB reads back with the twin's
/// hierarchy, MuJoCo and PyBullet put every link where the joints say, and with contacts on the
/// links neither overlap nor jam.
#[test]
fn truth_twins_export_valid_glbs_and_urdfs_the_simulators_follow() {
    let dir = scratch("truth");
    let mut glbs = Vec::new();
    for (category, parts, seed) in [
        (Category::StorageFurniture, 6, 3),
        (Category::Oven, 3, 5),
        (Category::Table, 2, 1),
    ] {
        let (_, mut twin) = truth_twin(category, parts, seed);
        if category == Category::Table {
            twin.name = "Tür <&> \"table\" ü/..".into();
        }
        let object = twin.object();
        let end = twin.end_configuration();
        let files = export_twin(&object, &end, b"[]").unwrap();
        let here = dir.join(category.slug());
        std::fs::create_dir_all(&here).unwrap();
        let glb = here.join("twin.glb");
        std::fs::write(&glb, &files.glb).unwrap();
        glbs.push(glb);

        // The GLB reads back: base at the root, every part under it with its joint in extras, one
        // animation channel per joint that moves.
        let gltf = gltf::Gltf::from_slice(&files.glb).unwrap();
        let want: Vec<String> = (1..=parts).map(artmesh::export::twin::part_link).collect();
        let tree = node_tree(&gltf.document);
        let base = tree.iter().find(|(n, _)| n == "base").expect("a base node");
        assert_eq!(base.1.len(), parts, "{category}: {tree:?}");
        for part in &want {
            assert!(base.1.contains(part), "{category}: {part} not under base");
        }
        for node in gltf.document.nodes().filter(|n| n.name() != Some("base")) {
            let extras: serde_json::Value =
                serde_json::from_str(node.extras().as_ref().unwrap().get()).unwrap();
            let joint = &extras["joint"];
            assert_eq!(joint["child"], node.name().unwrap(), "{category}");
            assert!(
                joint["limit"]["upper"].as_f64().unwrap()
                    >= joint["limit"]["lower"].as_f64().unwrap()
            );
        }
        let moving = end.iter().filter(|v| v.abs() > 1e-6).count();
        let channels: usize = gltf
            .document
            .animations()
            .map(|a| a.channels().count())
            .sum();
        assert_eq!(channels, moving, "{category}");

        // Every link's node carries its convex collision pieces in extras.
        for node in gltf.document.nodes() {
            let extras = node.extras().as_ref().map(|r| r.get()).unwrap_or("{}");
            let extras: serde_json::Value = serde_json::from_str(extras).unwrap();
            let pieces = extras["collision"].as_array().map_or(0, Vec::len);
            assert!(pieces > 0, "{category}: node {:?}: {extras}", node.name());
        }

        // The URDF in both simulators, every joint at its end value.
        write_dir(&files.urdf, &here.join("urdf")).unwrap();
        let motions: Vec<Affine3A> = twin.joints.iter().map(joint_transform).collect();
        let expected = moved_link_frames(&twin, &motions);
        let report = check_in_simulators(&here.join("urdf/twin.urdf"), &object, &end, &expected);
        assert!(report.is_object(), "{category}: {report}");
        // With contacts on, the convex pieces neither overlap at rest nor jam a joint.
        let contacts = check_contacts(&here.join("urdf/twin.urdf"));
        assert_eq!(contacts["ok"], true, "{category}: {contacts}");

        // Names: escaped in the URDF (our reader gives them back), sanitised as the zip's folder.
        let back = ArticulatedObject::from_urdf("twin.urdf", &files.urdf).unwrap();
        assert_eq!(back.name, twin.name);
        let mut zip = zip::ZipArchive::new(std::io::Cursor::new(files.zip.clone())).unwrap();
        for i in 0..zip.len() {
            let entry = zip.by_index(i).unwrap();
            let name = entry.name().unwrap().to_string();
            assert!(entry.enclosed_name().is_some(), "{name}");
            let folder = name.split('/').next().unwrap().to_string();
            assert!(
                folder
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-'),
                "{folder}"
            );
        }
    }
    // The procedural objects themselves (textures, fixed joints, links in chains) as GLB too.
    for (category, parts, seed) in [(Category::Faucet, 3, 2), (Category::Window, 4, 8)] {
        let obj = generate(&SynthParams {
            category,
            movable_parts: Some(parts),
            seed,
        })
        .unwrap();
        let [start, end] = states(&obj, seed);
        let glb = dir.join(format!("{}-object.glb", category.slug()));
        std::fs::write(&glb, write_glb(&obj, &start, &end, "object.glb").unwrap()).unwrap();
        glbs.push(glb);
    }
    assert_valid(&glbs);
}

/// A tiny fit of a two-door cabinet, exported: the validator passes its GLB, and both simulators
/// put each link where the fitted start → end motion (`joints.json`'s `end_transform`) puts it.
#[test]
fn fitted_twin_exports_follow_the_fitted_motions_in_the_simulators() {
    let ctx = common::context();
    let (_, fit) = block_on(artmesh::fixtures::object::tiny_fit(
        &ctx,
        Category::StorageFurniture,
        2,
        4,
        &|_| {},
        &|_| {},
        &artmesh::fit::object::FitConfig::preset(artmesh::fit::preset::Preset::Tiny),
    ))
    .unwrap();
    let twin = Twin::from_fit(&fit, "cabinet").unwrap();
    assert!(twin.parts.iter().all(|p| p.colors.is_some()));
    let records = artmesh::export::joint_records(&fit);
    let json = serde_json::to_vec(&records).unwrap();
    let object = twin.object();
    let end = artmesh::export::end_configuration(&object, &json, "joints.json").unwrap();
    assert_eq!(end, twin.end_configuration());
    let files = export_twin(&object, &end, &json).unwrap();
    let dir = scratch("fit");
    let glb = dir.join("twin.glb");
    std::fs::write(&glb, &files.glb).unwrap();
    // Decimated toward a quarter of its faces, the twin keeps a colour per vertex and exports a
    // valid GLB. (A tiny fit's parts are small islands with long rims, which stop some collapses
    // short of their share.)
    let faces = |t: &Twin| {
        t.parts
            .iter()
            .map(|p| p.mesh.triangles.len())
            .sum::<usize>()
    };
    let small = twin.with_visual_budget(faces(&twin) / 4);
    assert!(
        faces(&small) <= faces(&twin) / 3 && faces(&small) > 0,
        "{} → {}",
        faces(&twin),
        faces(&small)
    );
    for p in &small.parts {
        assert_eq!(
            p.colors.as_ref().map(Vec::len),
            Some(p.mesh.positions.len())
        );
    }
    let small_glb = dir.join("small.glb");
    std::fs::write(
        &small_glb,
        export_twin(&small.object(), &end, &json).unwrap().glb,
    )
    .unwrap();
    assert_valid(&[glb, small_glb]);
    write_dir(&files.urdf, &dir.join("urdf")).unwrap();
    let motions: Vec<Affine3A> = records
        .iter()
        .map(|r| {
            let m = r.end_transform;
            Affine3A::from_mat4(
                Mat4::from_cols_array_2d(&m.map(|row| row.map(|v| v as f32))).transpose(),
            )
        })
        .collect();
    let expected = moved_link_frames(&twin, &motions);
    check_in_simulators(&dir.join("urdf/twin.urdf"), &object, &end, &expected);
    let contacts = check_contacts(&dir.join("urdf/twin.urdf"));
    assert_eq!(contacts["ok"], true, "{contacts}");
}

/// Rendering a procedural object and its URDF export (read back with our importer) gives identical
/// images: colour, depth and part ids, at two states and three views.
#[test]
fn synth_urdf_round_trip_renders_identically() {
    let ctx = common::context();
    let (w, h) = (48, 40);
    let renderer = GtRenderer::new(&ctx, w, h).unwrap();
    for (category, parts, seed) in [
        (Category::StorageFurniture, 3, 6),
        (Category::Faucet, 2, 1),
        (Category::Suitcase, 2, 9),
    ] {
        let obj = generate(&SynthParams {
            category,
            movable_parts: Some(parts),
            seed,
        })
        .unwrap();
        let files: FileSet = write_urdf(&obj, "copy/model.urdf").unwrap();
        let back = ArticulatedObject::from_urdf("copy/model.urdf", &files).unwrap();
        for q in states(&obj, seed) {
            let (a, b) = (posed_part_meshes(&obj, &q), posed_part_meshes(&back, &q));
            let (lo, hi) = object_bounds(&a).unwrap();
            let centre = (lo + hi) * 0.5;
            for pose in sample_views(3, centre, (hi - lo).length() * 1.2, seed, true) {
                let camera = Camera {
                    camera_to_world: pose,
                    intrinsics: Intrinsics {
                        width: w,
                        height: h,
                        fx: 50.0,
                        fy: 50.0,
                        cx: w as f32 / 2.0,
                        cy: h as f32 / 2.0,
                    },
                };
                let va = block_on(renderer.render_view(&ctx, &a, &camera)).unwrap();
                let vb = block_on(renderer.render_view(&ctx, &b, &camera)).unwrap();
                let covered = va.parts.ids.iter().filter(|&&p| p >= 0).count();
                assert!(
                    covered > 50,
                    "{category}: only {covered} pixels show the object"
                );
                assert!(va.rgba == vb.rgba, "{category}: colours differ");
                assert!(va.depth == vb.depth, "{category}: depths differ");
                assert!(va.parts == vb.parts, "{category}: part ids differ");
            }
        }
    }
}
