//! Two-state dataset capture (`render::render_dataset`): real URDF objects and the quick benchmark suite become
//! datasets the reader accepts, whose ground truth describes exactly the motion between the rendered states and
//! scores zero when fed back as a prediction; captures are reproducible; objects the part model cannot describe
//! are refused with clear errors.

use std::sync::OnceLock;

use artmesh::data::{Dataset, FileSet, GtJoint, JointKind as GtKind, State};
use artmesh::eval::{EvalOptions, evaluate_object};
use artmesh::gpu::GpuContext;
use artmesh::object::{ArticulatedObject, JointKind, Material};
use artmesh::render::{
    DatasetRenderError, ObjectProblem, RenderSpec, RenderedDataset, render_dataset,
};
use artmesh::synth::builder::{ObjectBuilder, cuboid};
use artmesh::synth::{generate, suite_plan};
use glam::{Quat, Vec3};
use pollster::block_on;

fn context() -> &'static GpuContext {
    static CTX: OnceLock<GpuContext> = OnceLock::new();
    CTX.get_or_init(|| block_on(GpuContext::new()).expect("a GPU adapter (lavapipe in CI)"))
}

use crate::common::shared_objects as objects;

fn small_spec(seed: u64, train_views: usize) -> RenderSpec {
    RenderSpec {
        width: 40,
        height: 40,
        train_views,
        test_views: 1,
        seed,
        ..RenderSpec::default()
    }
}

/// Captures `obj`, collecting the files in memory.
fn capture(
    obj: &ArticulatedObject,
    spec: &RenderSpec,
) -> Result<(FileSet, RenderedDataset), DatasetRenderError> {
    let mut files = FileSet::new();
    let mut frames_seen = 0;
    let rendered = block_on(render_dataset(
        context(),
        obj,
        spec,
        &mut |batch| {
            files.extend(batch);
            Ok(())
        },
        &mut |p| frames_seen = p.done,
    ))?;
    assert_eq!(frames_seen, rendered.frames);
    Ok((files, rendered))
}

/// The end-state GT mesh of every movable part is its start-state mesh moved by the GT joint (rotation by
/// `r − l` degrees about the line `(o, d)`, or translation by `r − l` metres along `d`), vertex for vertex.
fn assert_truth_moves_meshes(what: &str, dataset: &Dataset) {
    let joints = dataset.gt_joints.as_ref().expect("joints");
    let start = dataset.gt_meshes_for(State::Start).expect("start meshes");
    let end = dataset.gt_meshes_for(State::End).expect("end meshes");
    assert_eq!(start.static_part, end.static_part, "{what}: the base moved");
    for (i, joint) in joints.iter().enumerate() {
        let moved = |p: Vec3| motion(joint, p);
        let (a, b) = (&start.movable[i], &end.movable[i]);
        assert_eq!(a.positions.len(), b.positions.len(), "{what}: part {i}");
        let worst = a
            .positions
            .iter()
            .zip(&b.positions)
            .map(|(p, q)| (moved(*p) - *q).length())
            .fold(0.0f32, f32::max);
        assert!(
            worst < 2e-4,
            "{what}: part {i} is {worst} m off its GT motion"
        );
    }
}

fn motion(joint: &GtJoint, p: Vec3) -> Vec3 {
    let d = joint.unit_direction();
    match joint.kind {
        GtKind::Revolute => {
            let q = Quat::from_axis_angle(d, joint.motion().to_radians());
            joint.origin + q * (p - joint.origin)
        }
        GtKind::Prismatic => p + d * joint.motion(),
    }
}

/// GT fed back as the prediction: every metric is exactly zero.
fn assert_self_evaluation_is_zero(what: &str, dataset: &Dataset) {
    let joints = dataset.gt_joints.as_ref().unwrap();
    let meshes = dataset.gt_meshes_for(State::Start).unwrap();
    let m = evaluate_object(
        what,
        "test",
        joints,
        joints,
        Some((meshes, meshes)),
        &EvalOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(m.type_accuracy, Some(1.0), "{what}");
    for (name, v) in [
        ("axis_ang", m.axis_ang),
        ("axis_pos", m.axis_pos),
        ("part_motion", m.part_motion),
    ] {
        assert!(v.is_none_or(|v| v == 0.0), "{what}: {name} = {v:?}");
    }
    for cd in [m.cd_s, m.cd_m].into_iter().flatten() {
        assert_eq!((cd.cd_peer, cd.cd_mm), (0.0, 0.0), "{what}");
    }
    assert!(m.cd_m.is_some(), "{what}: no CD-m");
}

#[test]
fn shared_objects_capture_as_valid_datasets_with_consistent_truth() {
    let urdfs: Vec<&String> = objects()
        .keys()
        .filter(|k| k.ends_with(".urdf") && !k.ends_with("fridge_static.urdf"))
        .collect();
    assert!(
        urdfs.len() >= 10,
        "expected the shared objects, found {urdfs:?}"
    );
    for path in urdfs {
        let obj =
            ArticulatedObject::from_urdf(path, objects()).unwrap_or_else(|e| panic!("{path}: {e}"));
        let (files, rendered) =
            capture(&obj, &small_spec(1, 6)).unwrap_or_else(|e| panic!("{path}: {e}"));
        let dataset = Dataset::from_files(&files).unwrap_or_else(|e| panic!("{path}:\n{e}"));
        let parts = obj.parts();
        assert_eq!(dataset.num_parts, parts.parts.len(), "{path}");
        assert_eq!(rendered.num_parts, parts.parts.len(), "{path}");
        // GT joint types follow the URDF joints of the parts.
        for (k, gt) in dataset.gt_joints.as_ref().unwrap().iter().enumerate() {
            let joint = &obj.joints[parts.parts[k + 1].joint.unwrap()];
            let expected = if joint.kind == JointKind::Prismatic {
                GtKind::Prismatic
            } else {
                GtKind::Revolute
            };
            assert_eq!(gt.kind, expected, "{path}: joint {}", joint.name);
            // States lie at [0.6, 0.8] and [0.2, 0.4] of the joint's range.
            let (lo, hi) = joint.range().unwrap();
            let scale = if expected == GtKind::Revolute {
                180.0 / std::f32::consts::PI
            } else {
                1.0
            };
            let fraction = |v: f32| (v / scale - lo) / (hi - lo);
            assert!(
                (0.6 - 1e-4..=0.8 + 1e-4).contains(&fraction(gt.start)),
                "{path}: {gt:?}"
            );
            assert!(
                (0.2 - 1e-4..=0.4 + 1e-4).contains(&fraction(gt.end)),
                "{path}: {gt:?}"
            );
        }
        // Part ids in the maps follow the part view: every id is a part, the movable ones show up somewhere.
        let mut seen = vec![false; dataset.num_parts];
        for frame in dataset.frames() {
            for &id in &frame.parts.as_ref().unwrap().ids {
                if id >= 0 {
                    seen[id as usize] = true;
                }
            }
        }
        assert!(
            seen[1..].iter().all(|&s| s),
            "{path}: parts never seen: {seen:?}"
        );
        assert_truth_moves_meshes(path, &dataset);
        assert_self_evaluation_is_zero(path, &dataset);
    }
}

#[test]
fn quick_suite_ground_truth_scores_zero_as_prediction() {
    for entry in suite_plan(true) {
        let obj = generate(&entry.params()).unwrap_or_else(|e| panic!("{}: {e}", entry.id()));
        let (files, _) = capture(&obj, &small_spec(entry.seed, 2))
            .unwrap_or_else(|e| panic!("{}: {e}", entry.id()));
        let dataset =
            Dataset::from_files(&files).unwrap_or_else(|e| panic!("{}:\n{e}", entry.id()));
        assert_eq!(dataset.num_movable(), entry.movable_parts, "{}", entry.id());
        assert_truth_moves_meshes(&entry.id(), &dataset);
        assert_self_evaluation_is_zero(&entry.id(), &dataset);
    }
}

#[test]
fn the_same_seed_gives_the_same_bytes() {
    let obj = ArticulatedObject::from_urdf("sektion/urdf/sektion_cabinet.urdf", objects()).unwrap();
    let (a, _) = capture(&obj, &small_spec(7, 2)).unwrap();
    let (b, _) = capture(&obj, &small_spec(7, 2)).unwrap();
    assert!(a == b, "two captures with the same seed differ");
    let (c, _) = capture(&obj, &small_spec(8, 2)).unwrap();
    assert!(a != c, "a different seed gave the same capture");
}

/// A 1 m box with one door of `door_size` on a joint of `kind` with limits `lower..upper`.
fn door_object(door_size: Vec3, lower: f32, upper: f32, kind: JointKind) -> ArticulatedObject {
    let mat = Material::default();
    let mut b = ObjectBuilder::new("test");
    b.add(
        ObjectBuilder::BASE,
        cuboid(Vec3::new(0.0, 0.0, 0.5), Vec3::ONE, &mat),
    );
    let door = b.joint(
        "door",
        ObjectBuilder::BASE,
        kind,
        Vec3::new(0.5, -0.5, 0.5),
        Vec3::Z,
        lower,
        upper,
    );
    b.add(door, cuboid(Vec3::new(0.0, -0.51, 0.5), door_size, &mat));
    b.build()
}

fn problem(obj: &ArticulatedObject) -> ObjectProblem {
    match capture(obj, &small_spec(0, 1)) {
        Err(DatasetRenderError::Object(p)) => p,
        Err(e) => panic!("expected an object problem, got {e}"),
        Ok(_) => panic!("expected an object problem, got a dataset"),
    }
}

#[test]
fn objects_outside_the_part_model_are_clear_errors() {
    let door = Vec3::new(1.0, 0.02, 1.0);
    // Empty joint range: start and end would coincide.
    let p = problem(&door_object(door, 0.3, 0.3, JointKind::Revolute));
    assert!(matches!(p, ObjectProblem::EmptyRange { .. }), "{p}");
    assert!(p.to_string().contains("door_joint"), "{p}");
    // A door without surface (zero thickness and width: a line).
    let p = problem(&door_object(
        Vec3::new(0.0, 0.0, 1.0),
        0.0,
        1.0,
        JointKind::Revolute,
    ));
    assert!(matches!(p, ObjectProblem::NoSurface { part: 1, .. }), "{p}");
    assert!(p.to_string().contains("door"), "{p}");
    // Nothing moves.
    let mut b = ObjectBuilder::new("static");
    b.add(
        ObjectBuilder::BASE,
        cuboid(Vec3::ZERO, Vec3::ONE, &Material::default()),
    );
    let p = problem(&b.build());
    assert!(matches!(p, ObjectProblem::NothingMoves(_)), "{p}");
    // Zero volume: everything inside a tenth of a millimetre.
    let mut b = ObjectBuilder::new("speck");
    let tiny = Vec3::splat(1e-4);
    b.add(
        ObjectBuilder::BASE,
        cuboid(Vec3::ZERO, tiny, &Material::default()),
    );
    let lid = b.joint(
        "lid",
        ObjectBuilder::BASE,
        JointKind::Revolute,
        Vec3::ZERO,
        Vec3::X,
        0.0,
        1.0,
    );
    b.add(
        lid,
        cuboid(Vec3::new(0.0, 0.0, 1e-4), tiny, &Material::default()),
    );
    let p = problem(&b.build());
    assert!(matches!(p, ObjectProblem::ZeroVolume { .. }), "{p}");
    assert!(p.to_string().contains("zero volume"), "{p}");
    // Too large for the depth maps (a mesh in millimetres read as metres), or a vertex at 3e38.
    for (name, far) in [("stadium", 1e3f32), ("overflow", 3e38)] {
        let mut b = ObjectBuilder::new(name);
        b.add(
            ObjectBuilder::BASE,
            cuboid(Vec3::ZERO, Vec3::ONE, &Material::default()),
        );
        let lid = b.joint(
            "lid",
            ObjectBuilder::BASE,
            JointKind::Revolute,
            Vec3::ZERO,
            Vec3::X,
            0.0,
            1.0,
        );
        b.add(
            lid,
            cuboid(Vec3::splat(far), Vec3::ONE, &Material::default()),
        );
        let p = problem(&b.build());
        assert!(matches!(p, ObjectProblem::TooLarge { .. }), "{name}: {p}");
        assert!(p.to_string().contains("at most 25 m"), "{p}");
    }
    // A part hanging on another movable part.
    let mut nested = door_object(door, 0.0, 1.0, JointKind::Revolute);
    let knob_parent = nested.joints[0].child;
    let mut b = ObjectBuilder::new("knob");
    let knob = b.joint(
        "knob",
        ObjectBuilder::BASE,
        JointKind::Revolute,
        Vec3::ZERO,
        Vec3::Y,
        0.0,
        1.0,
    );
    b.add(
        knob,
        cuboid(Vec3::ZERO, Vec3::splat(0.05), &Material::default()),
    );
    let mut extra = b.build();
    let mut joint = extra.joints.remove(0);
    joint.parent = knob_parent;
    joint.child = nested.links.len();
    nested.links.push(extra.links.remove(knob));
    nested.joints.push(joint);
    let p = problem(&nested);
    assert!(
        matches!(
            p,
            ObjectProblem::NestedPart {
                part: 2,
                parent: 1,
                ..
            }
        ),
        "{p}"
    );
    // A bad state interval.
    let spec = RenderSpec {
        start_range: (0.8, 0.6),
        ..small_spec(0, 1)
    };
    let err = capture(&door_object(door, 0.0, 1.0, JointKind::Revolute), &spec)
        .err()
        .unwrap();
    assert!(err.to_string().contains("start state range"), "{err}");
}

#[test]
fn continuous_joints_sample_the_documented_full_turn() {
    let obj = door_object(Vec3::new(1.0, 0.02, 1.0), 0.0, 0.0, JointKind::Continuous);
    let (files, _) = capture(&obj, &small_spec(3, 1)).unwrap();
    let dataset = Dataset::from_files(&files).unwrap();
    let joint = dataset.gt_joints.as_ref().unwrap()[0];
    // [0.6, 0.8] and [0.2, 0.4] of [−180°, 180°].
    assert!((36.0..=108.0).contains(&joint.start), "{joint:?}");
    assert!((-108.0..=-36.0).contains(&joint.end), "{joint:?}");
    assert_truth_moves_meshes("continuous", &dataset);
}
