//! Metric tests for `artmesh::eval` against hand-computed cases (DESIGN.md §7): the joint metrics,
//! joint matching, surface sampling, k-d tree search and Chamfer distance. Whole-object evaluation
//! and the benchmark tables are in `eval_metrics_objects.rs`.
//!
//! Tolerances: joint metrics are computed in f64 from f32 inputs, so exact cases are checked to 1e-6 (degrees,
//! 0.1 m units, metres); Chamfer values built from exactly corresponding samples to 1e-3 of their unit; sampled
//! Chamfer bounds are derived by hand in each test.

use crate::eval_metrics_common::{cuboid, prismatic, revolute};
use artmesh::data::{GtJoint, JointKind, TriMesh};
use artmesh::eval::{
    ChamferOptions, EvalOptions, Solver, axis_angle_deg, axis_line_distance, axis_pos,
    chamfer_meshes, evaluate_object, match_joints, match_joints_using, motion_error,
    sample_surface,
};
use artmesh::mesh::spatial::KdTree;
use artmesh::rng::Rng;
use glam::Vec3;

const EPS: f64 = 1e-6;

fn close(actual: f64, expected: f64, tol: f64, what: &str) {
    assert!(
        (actual - expected).abs() <= tol,
        "{what}: expected {expected} ± {tol}, got {actual}"
    );
}

/// The unit square [0,1]² in the plane z = `z`.
fn unit_square(z: f32) -> TriMesh {
    TriMesh {
        positions: vec![
            Vec3::new(0.0, 0.0, z),
            Vec3::new(1.0, 0.0, z),
            Vec3::new(1.0, 1.0, z),
            Vec3::new(0.0, 1.0, z),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

#[test]
fn perpendicular_axes_are_90_degrees() {
    close(axis_angle_deg(Vec3::X, Vec3::Y), 90.0, EPS, "X vs Y");
    close(axis_angle_deg(Vec3::Z, -Vec3::Y), 90.0, EPS, "Z vs -Y");
    // Line along X through the origin, line along Y through (0, 0, 0.5): closest points 0.5 m apart.
    let d = axis_line_distance(Vec3::ZERO, Vec3::X, Vec3::new(0.0, 0.0, 0.5), Vec3::Y);
    close(d, 0.5, EPS, "perpendicular line distance (m)");
    let a = revolute(Vec3::ZERO, Vec3::X, 0.0, 10.0);
    let b = revolute(Vec3::new(3.0, 7.0, 0.5), Vec3::Y, 0.0, 10.0);
    close(axis_pos(&a, &b), 5.0, EPS, "Axis Pos (0.1 m units)");
}

#[test]
fn parallel_axes_are_0_degrees_and_their_separation_apart() {
    close(
        axis_angle_deg(Vec3::Z, Vec3::new(0.0, 0.0, 2.0)),
        0.0,
        EPS,
        "Z vs 2Z",
    );
    // Parallel lines 0.3 m apart, origins far apart along the axis: 0.3 m, i.e. 3.0 units (PARIS gives 0).
    let gt = revolute(Vec3::ZERO, Vec3::Z, 0.0, 30.0);
    let pred = revolute(
        Vec3::new(0.3, 0.0, 5.0),
        Vec3::new(0.0, 0.0, 2.0),
        0.0,
        30.0,
    );
    close(axis_pos(&pred, &gt), 3.0, EPS, "parallel Axis Pos");
    // Anti-parallel is parallel too.
    let anti = revolute(Vec3::new(0.0, -0.3, -1.0), -Vec3::Z, 0.0, -30.0);
    close(axis_pos(&anti, &gt), 3.0, EPS, "anti-parallel Axis Pos");
    // Same line: 0.
    let same = revolute(Vec3::new(0.0, 0.0, 9.0), Vec3::Z, 0.0, 30.0);
    close(axis_pos(&same, &gt), 0.0, EPS, "coincident lines");
}

#[test]
fn skew_lines_have_their_closest_distance() {
    // Line a: the X axis. Line b: through (0, 0, 0.25) in the plane z = 0.25, at 30° to X.
    // The common normal is Z, so the distance is 0.25 m whatever the angle; the axis angle is 30°.
    let dir_b = Vec3::new(30f32.to_radians().cos(), 30f32.to_radians().sin(), 0.0);
    let o_b = Vec3::new(0.0, 0.0, 0.25) + 4.0 * dir_b; // any point of line b
    close(
        axis_line_distance(Vec3::ZERO, Vec3::X, o_b, dir_b),
        0.25,
        EPS,
        "skew distance",
    );
    close(axis_angle_deg(Vec3::X, dir_b), 30.0, 1e-5, "skew angle");
    // Line b through (0, 0.2, 0.4) along (0, 1, 1): normal X × (0,1,1)/√2 = (0,-1,1)/√2,
    // distance |(0, 0.2, 0.4) · (0,-1,1)| / √2 = 0.2/√2.
    let d = axis_line_distance(
        Vec3::ZERO,
        Vec3::X,
        Vec3::new(0.0, 0.2, 0.4),
        Vec3::new(0.0, 1.0, 1.0),
    );
    close(d, 0.2 / 2f64.sqrt(), EPS, "skew distance 2");
    // Obtuse angle reads as its supplement: 150° → 30°.
    close(axis_angle_deg(-Vec3::X, dir_b), 30.0, 1e-5, "supplement");
}

#[test]
fn flipped_axis_direction_is_the_same_joint() {
    let gt = revolute(Vec3::new(0.1, 0.2, 0.3), Vec3::Z, 0.0, 60.0);
    // Flipped direction, another point of the same line, negated motion: the same rotation.
    let pred = revolute(Vec3::new(0.1, 0.2, 5.0), -Vec3::Z, 10.0, -50.0);
    close(
        axis_angle_deg(pred.direction, gt.direction),
        0.0,
        EPS,
        "Axis Ang",
    );
    close(axis_pos(&pred, &gt), 0.0, EPS, "Axis Pos");
    close(motion_error(&pred, &gt), 0.0, EPS, "revolute motion");
    // Flipped without negating the motion: rotation by -60° against +60°, 120° apart.
    let wrong = revolute(gt.origin, -Vec3::Z, 0.0, 60.0);
    close(motion_error(&wrong, &gt), 120.0, 1e-4, "unnegated flip");
    // The geodesic wraps: 350° about Z is -10°, which is 30° from 20°.
    let a = revolute(gt.origin, Vec3::Z, 0.0, 350.0);
    let b = revolute(gt.origin, Vec3::Z, 0.0, 20.0);
    close(motion_error(&a, &b), 30.0, 1e-4, "geodesic wrap");
    // Prismatic: flipped direction and negated distance give the same translation.
    let gt_p = prismatic(Vec3::ZERO, Vec3::Y, 0.0, 0.4);
    let pred_p = prismatic(Vec3::ONE, Vec3::new(0.0, -2.0, 0.0), 0.0, -0.4);
    close(motion_error(&pred_p, &gt_p), 0.0, EPS, "prismatic flip");
    let short = prismatic(Vec3::ZERO, Vec3::Y, 0.0, 0.3);
    close(
        motion_error(&short, &gt_p),
        0.1,
        EPS,
        "prismatic 0.1 m short",
    );
    // A prismatic pair has no Axis Pos; a flipped revolute pair matches with zero error.
    let m = match_joints(&[pred, pred_p], &[gt, gt_p]).unwrap();
    assert_eq!(m.index_pairs(), vec![(0, 0), (1, 1)]);
    assert_eq!(m.pairs[1].axis_pos, None);
    close(m.total_error(), 0.0, 1e-5, "matching total");
}

#[test]
fn revolute_vs_prismatic_mismatch_is_matched_flagged_and_costed() {
    // One revolute GT joint, predicted as prismatic on the same axis: matched anyway, a type error, and the
    // whole 45° rotation is missed (a prismatic joint does not rotate).
    let gt = revolute(Vec3::ZERO, Vec3::Z, 0.0, 45.0);
    let pred = prismatic(Vec3::ZERO, Vec3::Z, 0.0, 0.2);
    let m = match_joints(&[pred], &[gt]).unwrap();
    assert_eq!(m.index_pairs(), vec![(0, 0)]);
    assert_eq!(m.type_errors, 1);
    let p = &m.pairs[0];
    assert!(!p.type_correct);
    assert_eq!(
        (p.gt_kind, p.pred_kind),
        (JointKind::Revolute, JointKind::Prismatic)
    );
    close(p.axis_ang, 0.0, EPS, "axis");
    close(p.axis_pos.unwrap(), 0.0, EPS, "pos");
    close(p.part_motion, 45.0, 1e-4, "missed rotation (°)");
    // Prismatic GT predicted as revolute: the whole 0.3 m translation is missed.
    let gt_p = prismatic(Vec3::ZERO, Vec3::X, 0.1, 0.4);
    let pred_r = revolute(Vec3::ZERO, Vec3::X, 0.0, 20.0);
    close(
        motion_error(&pred_r, &gt_p),
        0.3,
        EPS,
        "missed translation (m)",
    );

    // Two GT joints of each type; the cheapest assignment would cross types (near-identical axes), but a
    // type-consistent one exists, so it is chosen.
    let gts = [
        revolute(Vec3::ZERO, Vec3::Z, 0.0, 30.0),
        prismatic(Vec3::ZERO, Vec3::X, 0.0, 0.2),
    ];
    let preds = [
        prismatic(Vec3::ZERO, Vec3::Z, 0.0, 0.0),
        revolute(Vec3::ZERO, Vec3::X, 0.0, 0.0),
    ];
    let m = match_joints(&preds, &gts).unwrap();
    assert_eq!(m.index_pairs(), vec![(1, 0), (0, 1)]);
    assert_eq!(m.type_errors, 0);
    for solver in [Solver::BruteForce, Solver::Hungarian] {
        let s = match_joints_using(&preds, &gts, solver).unwrap();
        assert_eq!(s.index_pairs(), m.index_pairs(), "{solver:?}");
    }

    // More predictions than GT joints: the wrong-type extra one is left unmatched.
    let m = match_joints(&preds, &gts[..1]).unwrap();
    assert_eq!(m.index_pairs(), vec![(1, 0)]);
    assert_eq!(m.unmatched_pred, vec![0]);
    // Fewer: the GT joint without a prediction is reported, and lowers the type accuracy.
    let m = match_joints(&preds[1..], &gts).unwrap();
    assert_eq!(m.index_pairs(), vec![(0, 0)]);
    assert_eq!(m.unmatched_gt, vec![1]);
    let o = evaluate_object("o", "c", &preds[1..], &gts, None, &EvalOptions::default()).unwrap();
    close(o.type_accuracy.unwrap(), 0.5, EPS, "type accuracy");
    assert_eq!(o.joints.len(), 1);
}

#[test]
fn chamfer_of_identical_meshes_is_zero() {
    let cube = cuboid(Vec3::new(0.1, -0.2, 0.3), Vec3::new(0.5, 0.25, 0.1));
    let cd = chamfer_meshes(&cube, &cube, &ChamferOptions::default()).unwrap();
    assert_eq!((cd.cd_peer, cd.cd_mm), (0.0, 0.0));
}

#[test]
fn chamfer_of_unit_offset_square_is_known() {
    // The same square 0.1 m above: with the shared seed each sample's twin lies straight across, at exactly d,
    // and every other sample is farther. cd_peer = (d² + d²)·1000 = 20, cd_mm = d·1000 = 100.
    let d = 0.1_f64;
    let cd = chamfer_meshes(
        &unit_square(0.0),
        &unit_square(d as f32),
        &ChamferOptions::default(),
    )
    .unwrap();
    close(cd.cd_peer, 2.0 * d * d * 1000.0, 1e-3, "cd_peer");
    close(cd.cd_mm, d * 1000.0, 1e-3, "cd_mm (mm)");
}

#[test]
fn chamfer_of_scaled_cube_is_within_hand_bounds() {
    // Unit cube about the origin against the same cube scaled by 1.1. Every point of either surface is at
    // least 0.05 m from the other surface (the faces are 0.05 apart and one cube holds the other), and at most
    // |p|·0.1 ≤ (√3/2)·0.1 ≈ 0.0866 m from its scaled twin. NN among samples are never closer than the surface,
    // and farther by at most about the sample spacing (√(6/10⁴) ≈ 0.025 m), so: cd_mm ∈ [50, 112] mm and
    // cd_peer ∈ [2·0.05²·1000, 2·0.112²·1000] = [5, 25]. Most points sit straight across a face, so the
    // values land near the lower end.
    let small = cuboid(Vec3::ZERO, Vec3::splat(0.5));
    let large = cuboid(Vec3::ZERO, Vec3::splat(0.55));
    let cd = chamfer_meshes(&small, &large, &ChamferOptions::default()).unwrap();
    assert!((50.0..=112.0).contains(&cd.cd_mm), "cd_mm {}", cd.cd_mm);
    assert!((5.0..=25.0).contains(&cd.cd_peer), "cd_peer {}", cd.cd_peer);
    assert!(
        cd.cd_mm < 60.0 && cd.cd_peer < 8.0,
        "near the lower end: {cd:?}"
    );
}

#[test]
fn kd_tree_matches_brute_force() {
    let mut rng = Rng::new(7);
    let pts: Vec<Vec3> = (0..2000)
        .map(|_| Vec3::new(rng.next_f32(), rng.next_f32() * 0.1, rng.next_f32()))
        .collect();
    let tree = KdTree::new(&pts);
    for _ in 0..200 {
        let q = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 1.2 - 0.1;
        let brute = pts
            .iter()
            .map(|p| q.as_dvec3().distance_squared(p.as_dvec3()))
            .fold(f64::INFINITY, f64::min);
        assert_eq!(tree.nearest_distance_squared(q), brute);
    }
}

#[test]
fn sampling_is_deterministic() {
    let cube = cuboid(Vec3::ZERO, Vec3::new(0.5, 0.2, 0.1));
    let a = sample_surface(&cube, 1000, 42).unwrap();
    let b = sample_surface(&cube, 1000, 42).unwrap();
    let c = sample_surface(&cube, 1000, 43).unwrap();
    assert_eq!(a, b);
    assert_ne!(a, c);
    // Samples lie on the surface: one coordinate at its extreme.
    for p in &a {
        let on_face = (p.x.abs() - 0.5).abs() < 1e-6
            || (p.y.abs() - 0.2).abs() < 1e-6
            || (p.z.abs() - 0.1).abs() < 1e-6;
        assert!(on_face, "{p} is off the surface");
    }
    // Area-weighted: the two 1.0 × 0.4 faces (±z) hold 0.8 / 1.28 = 62.5% of the area.
    let on_z = a.iter().filter(|p| (p.z.abs() - 0.1).abs() < 1e-6).count() as f64 / 1000.0;
    close(on_z, 0.625, 0.05, "fraction of samples on the ±z faces");
    let small = cuboid(Vec3::ZERO, Vec3::splat(0.5));
    let large = cuboid(Vec3::ZERO, Vec3::splat(0.55));
    let o = ChamferOptions::default();
    assert_eq!(
        chamfer_meshes(&small, &large, &o).unwrap(),
        chamfer_meshes(&small, &large, &o).unwrap()
    );
}

/// Six joints of mixed types and distinct axes.
fn sample_joints(rng: &mut Rng, n: usize) -> Vec<GtJoint> {
    (0..n)
        .map(|i| {
            let mut v = || rng.next_f32() * 2.0 - 1.0;
            let origin = Vec3::new(v(), v(), v());
            let direction = Vec3::new(v(), v(), v()) + Vec3::X * 0.1;
            if i % 3 == 2 {
                prismatic(origin, direction, 0.0, 0.1 + 0.05 * i as f32)
            } else {
                revolute(origin, direction, 5.0, 20.0 + 7.0 * i as f32)
            }
        })
        .collect()
}

#[test]
fn joint_permutation_is_recovered() {
    let mut rng = Rng::new(3);
    for n in [5usize, 10] {
        // 5 → brute force, 10 → Hungarian.
        let pred = sample_joints(&mut rng, n);
        let perm: Vec<usize> = (0..n).map(|i| (i * 3 + 1) % n).collect(); // gt[i] = pred[perm[i]]
        let gt: Vec<GtJoint> = perm.iter().map(|&p| pred[p]).collect();
        let m = match_joints(&pred, &gt).unwrap();
        let expected: Vec<(usize, usize)> = perm.iter().enumerate().map(|(g, &p)| (p, g)).collect();
        assert_eq!(m.index_pairs(), expected, "n = {n}");
        assert_eq!(m.total_error(), 0.0);
        assert_eq!(m.type_errors, 0);
    }
}

#[test]
fn brute_force_and_hungarian_agree() {
    let mut rng = Rng::new(11);
    for (np, ng) in [(6, 6), (5, 7), (7, 4), (1, 3), (0, 2), (8, 8)] {
        for _ in 0..5 {
            let pred = sample_joints(&mut rng, np);
            let gt = sample_joints(&mut rng, ng);
            let b = match_joints_using(&pred, &gt, Solver::BruteForce).unwrap();
            let h = match_joints_using(&pred, &gt, Solver::Hungarian).unwrap();
            assert_eq!(b.type_errors, h.type_errors);
            close(h.total_error(), b.total_error(), 1e-6, "optimal total");
            assert_eq!(b.pairs.len(), np.min(ng));
            assert_eq!(
                h.unmatched_pred.len() + h.unmatched_gt.len(),
                np.abs_diff(ng)
            );
        }
    }
}
