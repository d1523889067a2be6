//! Whole-object evaluation tests for `artmesh::eval` (DESIGN.md §7): an object scored against its own
//! ground truth (also reordered), input errors, and the benchmark tables by part count and category.

use crate::eval_metrics_common::{cuboid, prismatic, revolute};
use artmesh::data::{GtJoint, GtMeshes, TriMesh};
use artmesh::eval::{
    BenchmarkTable, ChamferOptions, EvalError, EvalOptions, ObjectMetrics, PartBucket,
    chamfer_meshes, evaluate_object,
};
use glam::Vec3;

/// Three movable parts (two doors and a drawer) on a box, with their joints.
fn sample_object() -> (Vec<GtJoint>, GtMeshes) {
    let joints = vec![
        revolute(Vec3::new(0.5, 0.0, 0.0), Vec3::Y, 0.0, 80.0),
        prismatic(Vec3::ZERO, Vec3::Z, 0.0, 0.3),
        revolute(Vec3::new(-0.5, 0.0, 0.2), -Vec3::Y, 10.0, 40.0),
    ];
    let meshes = GtMeshes {
        static_part: cuboid(Vec3::ZERO, Vec3::new(0.5, 0.4, 0.3)),
        movable: vec![
            cuboid(Vec3::new(0.25, 0.0, 0.35), Vec3::new(0.25, 0.4, 0.02)),
            cuboid(Vec3::new(0.0, 0.0, -0.2), Vec3::new(0.4, 0.3, 0.05)),
            cuboid(Vec3::new(-0.25, 0.0, 0.35), Vec3::new(0.25, 0.4, 0.02)),
        ],
    };
    (joints, meshes)
}

/// `evaluate_object` of a storage-furniture object with the default options.
fn evaluate_cabinet(
    joints: &[GtJoint],
    meshes: &GtMeshes,
    gt_joints: &[GtJoint],
    gt_meshes: &GtMeshes,
) -> ObjectMetrics {
    evaluate_object(
        "obj",
        "StorageFurniture",
        joints,
        gt_joints,
        Some((meshes, gt_meshes)),
        &EvalOptions::default(),
    )
    .unwrap()
}

#[test]
fn ground_truth_as_prediction_scores_zero() {
    let (joints, meshes) = sample_object();
    let o = evaluate_cabinet(&joints, &meshes, &joints, &meshes);
    assert_eq!(o.part_count, 4);
    assert_eq!(o.axis_ang, Some(0.0));
    assert_eq!(o.axis_pos, Some(0.0));
    assert_eq!(o.part_motion, Some(0.0));
    assert_eq!(o.part_motion_revolute, Some(0.0));
    assert_eq!(o.part_motion_prismatic, Some(0.0));
    assert_eq!(o.type_accuracy, Some(1.0));
    assert_eq!(
        (o.type_errors, o.unmatched_gt.len(), o.unmatched_pred.len()),
        (0, 0, 0)
    );
    let cd_s = o.cd_s.unwrap();
    let cd_m = o.cd_m.unwrap();
    assert_eq!(
        [cd_s.cd_peer, cd_s.cd_mm, cd_m.cd_peer, cd_m.cd_mm],
        [0.0; 4]
    );
    assert_eq!(o.cd_m_parts.len(), 3);

    // Shuffled GT order: the matching pairs each movable mesh with its own, still all zero.
    let order = [2usize, 0, 1];
    let gt_joints: Vec<GtJoint> = order.iter().map(|&i| joints[i]).collect();
    let gt_meshes = GtMeshes {
        static_part: meshes.static_part.clone(),
        movable: order.iter().map(|&i| meshes.movable[i].clone()).collect(),
    };
    let o = evaluate_cabinet(&joints, &meshes, &gt_joints, &gt_meshes);
    assert_eq!(o.cd_m.unwrap().cd_peer, 0.0);
    assert_eq!(o.axis_ang, Some(0.0));
    let pairs: Vec<(usize, usize)> = o.cd_m_parts.iter().map(|p| (p.pred, p.gt)).collect();
    assert_eq!(pairs, vec![(2, 0), (0, 1), (1, 2)]);

    // The per-object JSON round-trips and holds no NaN.
    let json = serde_json::to_string(&o).unwrap();
    assert!(!json.contains("NaN"));
    let back: ObjectMetrics = serde_json::from_str(&json).unwrap();
    assert_eq!(back, o);
}

#[test]
fn bad_inputs_are_clear_errors() {
    let (joints, meshes) = sample_object();
    let o = EvalOptions::default();
    let mut nan = joints.clone();
    nan[1].end = f32::NAN;
    let e = evaluate_object("o", "c", &nan, &joints, None, &o).unwrap_err();
    assert!(
        matches!(
            e,
            EvalError::InvalidJoint {
                side: "predicted",
                index: 1,
                ..
            }
        ),
        "{e}"
    );
    let mut zero = joints.clone();
    zero[0].direction = Vec3::ZERO;
    let e = evaluate_object("o", "c", &joints, &zero, None, &o).unwrap_err();
    assert!(
        matches!(
            e,
            EvalError::InvalidJoint {
                side: "ground-truth",
                index: 0,
                ..
            }
        ),
        "{e}"
    );

    let mut empty = meshes.clone();
    empty.movable[2] = TriMesh::default();
    // A predicted part the fit found no surface for: its joint is scored, its CD-m is not.
    let scored = evaluate_object("o", "c", &joints, &joints, Some((&empty, &meshes)), &o).unwrap();
    assert_eq!(scored.unsurfaced_pred, vec![2]);
    assert_eq!(scored.cd_m_parts.len(), joints.len() - 1);
    assert!(scored.cd_m_parts.iter().all(|p| p.pred != 2));
    assert_eq!(scored.joints.len(), joints.len());
    // The same hole in the ground truth is an error: there is nothing to score against.
    let e = evaluate_object("o", "c", &joints, &joints, Some((&meshes, &empty)), &o).unwrap_err();
    assert_eq!(
        e.to_string(),
        "ground-truth movable part 2: mesh has no triangles"
    );
    let mut flat = meshes.clone();
    flat.static_part = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
        triangles: vec![[0, 1, 2]],
    };
    let e = evaluate_object("o", "c", &joints, &joints, Some((&meshes, &flat)), &o).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("ground-truth static part: mesh has no surface"),
        "{e}"
    );
    let mut bad_index = meshes.clone();
    bad_index.static_part.triangles.push([0, 1, 99]);
    assert!(matches!(
        evaluate_object("o", "c", &joints, &joints, Some((&bad_index, &meshes)), &o),
        Err(EvalError::InvalidMesh { .. })
    ));
    let mut missing = meshes.clone();
    missing.movable.pop();
    assert!(matches!(
        evaluate_object("o", "c", &joints, &joints, Some((&missing, &meshes)), &o),
        Err(EvalError::Inconsistent(_))
    ));
    let none = ChamferOptions {
        samples: 0,
        seed: 1,
    };
    assert!(chamfer_meshes(&meshes.static_part, &meshes.static_part, &none).is_err());
    // No joints at all is fine: nothing to average.
    let o = evaluate_object("o", "c", &[], &[], None, &o).unwrap();
    assert_eq!((o.part_count, o.axis_ang, o.type_accuracy), (1, None, None));
}

fn object(id: &str, category: &str, parts: usize, axis_ang: f64) -> ObjectMetrics {
    let mut o = evaluate_object(id, category, &[], &[], None, &EvalOptions::default()).unwrap();
    o.part_count = parts;
    o.axis_ang = Some(axis_ang);
    o
}

#[test]
fn table_buckets_objects_by_part_count() {
    assert_eq!(PartBucket::of(1), None);
    let buckets: Vec<_> = [2, 3, 4, 5, 7]
        .iter()
        .map(|&n| PartBucket::of(n).unwrap())
        .collect();
    use PartBucket::*;
    assert_eq!(buckets, [Two, Three, FourToFive, FourToFive, SixPlus]);

    let objects = vec![
        object("a", "Table", 2, 1.0),
        object("b", "Table", 3, 2.0),
        object("c", "StorageFurniture", 4, 3.0),
        object("d", "StorageFurniture", 5, 5.0),
        object("e", "Box", 7, 9.0),
    ];
    let t = BenchmarkTable::by_part_count(&objects);
    let labels: Vec<(&str, usize)> = t
        .columns
        .iter()
        .map(|c| (c.label.as_str(), c.objects))
        .collect();
    assert_eq!(
        labels,
        [
            ("2 Parts", 1),
            ("3 Parts", 1),
            ("4-5 Parts", 2),
            ("6+ Parts", 1),
            ("All", 5)
        ]
    );
    assert_eq!(t.column("4-5 Parts").unwrap().axis_ang, Some(4.0));
    // All = object-weighted mean of the buckets, as in the paper: (1 + 2 + 3 + 5 + 9) / 5.
    assert_eq!(t.column("All").unwrap().axis_ang, Some(4.0));
    assert_eq!(t.column("All").unwrap().axis_pos, None);

    let c = BenchmarkTable::by_category(&objects);
    let labels: Vec<(&str, usize)> = c
        .columns
        .iter()
        .map(|c| (c.label.as_str(), c.objects))
        .collect();
    assert_eq!(
        labels,
        [
            ("Box", 1),
            ("StorageFurniture", 2),
            ("Table", 2),
            ("All", 5)
        ]
    );
    assert_eq!(c.column("Table").unwrap().axis_ang, Some(1.5));
    let json = serde_json::to_string(&t).unwrap();
    assert!(!json.contains("NaN"));
}

#[test]
fn markdown_table_has_the_paper_layout() {
    let objects = vec![
        object("a", "Table", 2, 1.0),
        object("b", "Table", 3, 2.0),
        object("c", "StorageFurniture", 4, 3.0),
        object("d", "StorageFurniture", 5, 5.0),
        object("e", "Box", 7, 9.0),
    ];
    let md = BenchmarkTable::by_part_count(&objects).to_markdown();
    let lines: Vec<&str> = md.lines().collect();
    assert_eq!(
        lines[..4],
        [
            "| Metric | 2 Parts (1) | 3 Parts (1) | 4-5 Parts (2) | 6+ Parts (1) | All (5) |",
            "| --- | ---: | ---: | ---: | ---: | ---: |",
            "| Axis Ang ↓ (°) | 1.00 | 2.00 | 4.00 | 9.00 | 4.00 |",
            "| Axis Pos ↓ (0.1 m) | - | - | - | - | - |",
        ]
    );
    let names: Vec<&str> = lines[2..]
        .iter()
        .map(|l| l.split('|').nth(1).unwrap().trim())
        .collect();
    assert_eq!(
        names,
        [
            "Axis Ang ↓ (°)",
            "Axis Pos ↓ (0.1 m)",
            "Part Motion ↓ (° / m)",
            "CD-s ↓",
            "CD-m ↓",
            "Part Motion rev. ↓ (°)",
            "Part Motion pris. ↓ (m)",
            "CD-s ↓ (mm)",
            "CD-m ↓ (mm)",
            "Type Acc ↑ (%)",
            "Missed / extra joints",
        ]
    );
    for l in &lines {
        assert_eq!(l.matches('|').count(), 7, "{l}");
    }
    assert_eq!(
        lines.last().unwrap(),
        &"| Missed / extra joints | 0 / 0 | 0 / 0 | 0 / 0 | 0 / 0 | 0 / 0 |"
    );
}
