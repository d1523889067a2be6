//! Unit tests of the vertex-wise motion consistency loss: agreement of identical surfaces, the
//! validity threshold, part-restricted matching, and the analytic gradient against finite differences.

use super::*;
use crate::rng::Rng;

/// An n × n grid patch on [0, size]² with a smooth bump, all vertices of one part; colour and
/// opacity smooth functions of position.
fn bumpy_patch(n: usize, size: f32, part: u32, num_parts: usize) -> StateSurface {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            let z = 0.004 * (3.0 * u).sin() * (2.5 * v + 0.3).cos();
            positions.push(Vec3::new(u * size, v * size, z));
        }
    }
    let mut faces = Vec::new();
    let row = n as u32 + 1;
    for j in 0..n as u32 {
        for i in 0..n as u32 {
            let v = j * row + i;
            faces.push([v, v + 1, v + row + 1]);
            faces.push([v, v + row + 1, v + row]);
        }
    }
    let colors = positions
        .iter()
        .map(|p| {
            Vec3::new(
                0.5 + 2.0 * p.x,
                0.3 + 1.5 * p.y,
                0.4 + (20.0 * p.x * p.y).sin() * 0.3,
            )
        })
        .collect();
    let opacity = positions
        .iter()
        .map(|p| 0.6 + 0.3 * (8.0 * p.x + 5.0 * p.y).sin())
        .collect();
    let parts = vec![part; positions.len()];
    StateSurface::new(positions, faces, parts, colors, opacity, num_parts).unwrap()
}

fn identity_motions(num_parts: usize) -> Vec<(DMat3, DVec3)> {
    vec![(DMat3::IDENTITY, DVec3::ZERO); num_parts]
}

/// The loss with default weights when no part moves (identity motions for all `num_parts`).
fn loss_at_rest(
    source: &StateSurface,
    target: &StateSurface,
    num_parts: usize,
) -> VertexMotionLoss {
    vertex_motion_loss(
        source,
        target,
        &identity_motions(num_parts),
        &VertexMotionWeights::default(),
    )
    .unwrap()
}

/// A rotation by `angle` about `axis` then a translation.
fn rigid(axis: DVec3, angle: f64, t: DVec3) -> (DMat3, DVec3) {
    (DMat3::from_axis_angle(axis.normalize(), angle), t)
}

#[test]
fn identical_surfaces_under_identity_agree() {
    let s = bumpy_patch(6, 0.1, 1, 2);
    let out = loss_at_rest(&s, &s, 2);
    assert_eq!(out.considered, s.num_vertices());
    assert_eq!(out.valid, s.num_vertices());
    assert!(out.loss.abs() < 1e-12, "{}", out.loss);
    assert_eq!(out.per_part.len(), 2);
    assert_eq!(out.per_part[1].count as usize, s.num_vertices());
    assert!(out.per_part[1].g.length() < 1e-9);
}

#[test]
fn far_away_motion_matches_nothing() {
    let s = bumpy_patch(4, 0.1, 1, 2);
    let mut motions = identity_motions(2);
    motions[1].1 = DVec3::new(0.0, 0.0, 0.5);
    let out = vertex_motion_loss(&s, &s, &motions, &VertexMotionWeights::default()).unwrap();
    assert_eq!(out.considered, s.num_vertices());
    assert_eq!(out.valid, 0);
    assert_eq!(out.loss, 0.0);
    assert_eq!(out.per_part[1], PartSums::default());
}

#[test]
fn static_base_and_missing_parts_are_skipped() {
    // Part 0 (base) vertices never move or match; part 2 has no target faces.
    let base = bumpy_patch(3, 0.1, 0, 3);
    let out = loss_at_rest(&base, &base, 3);
    assert_eq!((out.considered, out.valid, out.loss), (0, 0, 0.0));
    let moving = bumpy_patch(3, 0.1, 2, 3);
    let target = bumpy_patch(3, 0.1, 1, 3);
    let out = loss_at_rest(&moving, &target, 3);
    assert_eq!((out.considered, out.valid), (0, 0));
}

/// Source points off a target surface: chosen on target faces (barycentrics in [lo, 1 − 2 lo]
/// of a random face, or pushed outward past a boundary edge when `past_edge`), lifted along
/// the normal by `lift`, and carried back by the inverse of `motion` so the motion returns
/// them there. Colours and opacities differ from the target's.
fn source_near(
    target: &StateSurface,
    motion: (DMat3, DVec3),
    count: usize,
    past_edge: f32,
    lift: f32,
    seed: u64,
) -> StateSurface {
    let mut rng = Rng::new(seed);
    let (a_inv, b_inv) = (motion.0.inverse(), -motion.0.inverse() * motion.1);
    let mut positions = Vec::new();
    for _ in 0..count {
        let f = rng.below(target.faces.len() as u32) as usize;
        let [a, b, c] = target.faces[f].map(|v| target.positions[v as usize]);
        let (mut u, mut v) = (rng.uniform(0.15, 0.7), rng.uniform(0.15, 0.7));
        if u + v > 0.85 {
            (u, v) = (0.85 - v, 0.85 - u);
        }
        let n = (b - a).cross(c - a).normalize();
        let on = a + (b - a) * u + (c - a) * v;
        // Past the edge ab (opposite c), in the plane: an edge region of a lone triangle.
        let out = if past_edge > 0.0 {
            let e = (b - a).normalize();
            let away = e.cross(n).normalize();
            let towards_c = (c - a).dot(away);
            a + e * (b - a).length() * rng.uniform(0.2, 0.8) - away * towards_c.signum() * past_edge
        } else {
            on
        };
        let p = (out + n * lift * rng.uniform(0.5, 1.0)).as_dvec3();
        positions.push((a_inv * p + b_inv).as_vec3());
    }
    let colors = positions
        .iter()
        .map(|_| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()))
        .collect();
    let opacity = positions.iter().map(|_| rng.next_f32()).collect();
    let parts = vec![1; count];
    StateSurface::new(
        positions,
        Vec::new(),
        parts,
        colors,
        opacity,
        target.num_parts,
    )
    .unwrap()
}

/// Central differences of L over the 12 entries of part 1's (A, b) against the analytic
/// Σ gᵢ xᵢᵀ and Σ gᵢ, after checking that no vertex changes face, region or validity.
fn check_gradient(
    source: &StateSurface,
    target: &StateSurface,
    motion: (DMat3, DVec3),
    weights: &VertexMotionWeights,
) {
    let h = 1e-4;
    let run = |m: (DMat3, DVec3)| {
        let mut motions = identity_motions(source.num_parts);
        motions[1] = m;
        vertex_motion_loss(source, target, &motions, weights).unwrap()
    };
    let matches = |m: (DMat3, DVec3)| -> Vec<Option<([u32; 3], Region)>> {
        source
            .positions
            .iter()
            .map(|x| {
                let moved = m.0 * x.as_dvec3() + m.1;
                closest_on_part(target, 1, moved)
                    .filter(|hit| hit.distance_squared <= f64::from(weights.max_distance).powi(2))
                    .map(|hit| (hit.corners, hit.region))
            })
            .collect()
    };
    let base = run(motion);
    let base_matches = matches(motion);
    assert!(base.valid > 0 && base.loss > 0.0);
    let analytic = base.per_part[1];
    let scale = analytic
        .gx
        .to_cols_array()
        .iter()
        .chain(analytic.g.to_array().iter())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    for entry in 0..12 {
        let shifted = |s: f64| {
            let (mut a, mut b) = motion;
            if entry < 9 {
                a.col_mut(entry / 3)[entry % 3] += s;
            } else {
                b[entry - 9] += s;
            }
            (a, b)
        };
        for s in [h, -h] {
            assert_eq!(
                matches(shifted(s)),
                base_matches,
                "entry {entry} moves a vertex across a region"
            );
        }
        let numeric = (run(shifted(h)).loss - run(shifted(-h)).loss) / (2.0 * h);
        let exact = if entry < 9 {
            analytic.gx.col(entry / 3)[entry % 3]
        } else {
            analytic.g[entry - 9]
        };
        assert!(
            (numeric - exact).abs() <= 1e-6 * scale,
            "entry {entry}: numeric {numeric} vs analytic {exact} (scale {scale})"
        );
    }
}

#[test]
fn gradient_matches_finite_differences_in_face_regions() {
    let target = bumpy_patch(8, 0.2, 1, 2);
    let truth = rigid(
        DVec3::new(0.3, -0.5, 1.0),
        0.4,
        DVec3::new(0.05, -0.02, 0.1),
    );
    let source = source_near(&target, truth, 300, 0.0, 0.002, 11);
    // A slightly wrong motion, as during optimisation.
    let nudge = rigid(
        DVec3::new(1.0, 0.2, 0.1),
        0.002,
        DVec3::new(0.0003, -0.0002, 0.0001),
    );
    let motion = (nudge.0 * truth.0, nudge.0 * truth.1 + nudge.1);
    let weights = VertexMotionWeights {
        color: 0.7,
        opacity: 1.3,
        max_distance: 0.02,
    };
    let out = vertex_motion_loss(&source, &target, &[truth, motion], &weights).unwrap();
    assert_eq!(out.valid, 300);
    check_gradient(&source, &target, motion, &weights);
}

#[test]
fn gradient_matches_finite_differences_in_edge_regions() {
    // One lone triangle: points past its edge ab land in that edge's region.
    let target = StateSurface::new(
        vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.05, 0.01, 0.006),
            Vec3::new(0.01, 0.04, 0.01),
        ],
        vec![[0, 1, 2]],
        vec![1; 3],
        vec![
            Vec3::new(1.0, 0.2, 0.0),
            Vec3::new(0.0, 0.9, 0.3),
            Vec3::new(0.2, 0.1, 0.8),
        ],
        vec![0.9, 0.2, 0.5],
        2,
    )
    .unwrap();
    let truth = rigid(
        DVec3::new(-0.2, 1.0, 0.4),
        -0.3,
        DVec3::new(-0.03, 0.01, 0.02),
    );
    let source = source_near(&target, truth, 50, 0.004, 0.002, 5);
    let nudge = rigid(
        DVec3::new(0.0, 0.3, 1.0),
        0.001,
        DVec3::new(0.0001, 0.0002, -0.0001),
    );
    let motion = (nudge.0 * truth.0, nudge.0 * truth.1 + nudge.1);
    let weights = VertexMotionWeights::default();
    let mut motions = identity_motions(2);
    motions[1] = motion;
    for x in &source.positions {
        let hit = closest_on_part(&target, 1, motion.0 * x.as_dvec3() + motion.1).unwrap();
        assert_eq!(hit.region, Region::Edge(0, 1));
    }
    check_gradient(&source, &target, motion, &weights);
}

#[test]
fn matches_stay_within_the_same_part() {
    // A part-1 triangle 1 cm below the source vertex, a part-2 triangle 1 mm below it.
    let red = Vec3::new(1.0, 0.0, 0.0);
    let green = Vec3::new(0.0, 1.0, 0.0);
    let tri = |z: f32| {
        [
            Vec3::new(-0.05, -0.05, z),
            Vec3::new(0.05, -0.05, z),
            Vec3::new(0.0, 0.05, z),
        ]
    };
    // One red vertex at the origin, labelled `part`, of a three-part surface.
    let lone_red_vertex = |part: u32| {
        StateSurface::new(
            vec![Vec3::ZERO],
            Vec::new(),
            vec![part],
            vec![red],
            vec![1.0],
            3,
        )
        .unwrap()
    };
    let positions: Vec<Vec3> = tri(-0.01).into_iter().chain(tri(-0.001)).collect();
    let target = StateSurface::new(
        positions,
        vec![[0, 1, 2], [3, 4, 5]],
        vec![1, 1, 1, 2, 2, 2],
        vec![red, red, red, green, green, green],
        vec![1.0; 6],
        3,
    )
    .unwrap();
    let source = lone_red_vertex(1);
    let out = loss_at_rest(&source, &target, 3);
    assert_eq!(out.valid, 1);
    assert!(
        out.loss.abs() < 1e-12,
        "matched the wrong part: loss {}",
        out.loss
    );
    let hit = closest_on_part(&target, 1, DVec3::ZERO).unwrap();
    assert_eq!(hit.corners, [0, 1, 2]);
    assert!((hit.distance_squared.sqrt() - 0.01).abs() < 1e-6);
    // The same vertex labelled 2 matches the green triangle instead.
    let source2 = lone_red_vertex(2);
    let out = loss_at_rest(&source2, &target, 3);
    assert!((out.loss - 2.0).abs() < 1e-6, "{}", out.loss);
    assert_eq!(out.per_part[1], PartSums::default());
}

#[test]
fn cross_part_faces_are_left_out() {
    let s = StateSurface::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE],
        vec![[0, 1, 2], [1, 3, 2]],
        vec![1, 1, 1, 2],
        vec![Vec3::ZERO; 4],
        vec![0.5; 4],
        3,
    )
    .unwrap();
    assert_eq!(s.cross_part_faces(), 1);
    assert_eq!(
        (
            s.part_face_count(1),
            s.part_face_count(2),
            s.part_face_count(9)
        ),
        (1, 0, 0)
    );
}

#[test]
fn bad_input_is_an_error() {
    let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let make = |positions: Vec<Vec3>,
                faces: Vec<[u32; 3]>,
                parts: Vec<u32>,
                colors: usize,
                opacity: Vec<f32>,
                k: usize| {
        StateSurface::new(
            positions,
            faces,
            parts,
            vec![Vec3::ZERO; colors],
            opacity,
            k,
        )
    };
    let ok = || make(p.clone(), vec![[0, 1, 2]], vec![1; 3], 3, vec![0.5; 3], 2);
    assert!(ok().is_ok());
    for bad in [
        make(p.clone(), vec![[0, 1, 2]], vec![1; 2], 3, vec![0.5; 3], 2),
        make(p.clone(), vec![[0, 1, 2]], vec![1; 3], 4, vec![0.5; 3], 2),
        make(p.clone(), vec![[0, 1, 2]], vec![1; 3], 3, vec![0.5; 1], 2),
        make(p.clone(), vec![[0, 1, 3]], vec![1; 3], 3, vec![0.5; 3], 2),
        make(
            p.clone(),
            vec![[0, 1, 2]],
            vec![1, 2, 1],
            3,
            vec![0.5; 3],
            2,
        ),
        make(p.clone(), vec![[0, 1, 2]], vec![0; 3], 3, vec![0.5; 3], 0),
        make(
            p.clone(),
            vec![[0, 1, 2]],
            vec![1; 3],
            3,
            vec![0.5, 1.5, 0.5],
            2,
        ),
        make(
            vec![Vec3::ZERO, Vec3::NAN, Vec3::Y],
            vec![[0, 1, 2]],
            vec![1; 3],
            3,
            vec![0.5; 3],
            2,
        ),
    ] {
        let err = bad.unwrap_err();
        assert!(!err.to_string().is_empty());
    }
    let s = ok().unwrap();
    let w = VertexMotionWeights::default();
    assert!(
        vertex_motion_loss(&s, &s, &identity_motions(1), &w)
            .unwrap_err()
            .to_string()
            .contains("motions")
    );
    assert!(vertex_motion_loss(&s, &s, &[], &w).is_err());
    let other = make(p.clone(), vec![[0, 1, 2]], vec![1; 3], 3, vec![0.5; 3], 3).unwrap();
    assert!(vertex_motion_loss(&s, &other, &identity_motions(3), &w).is_err());
    let mut nan_motion = identity_motions(2);
    nan_motion[1].1.x = f64::NAN;
    assert!(vertex_motion_loss(&s, &s, &nan_motion, &w).is_err());
    let bad_weights = VertexMotionWeights {
        max_distance: -1.0,
        ..w
    };
    assert!(vertex_motion_loss(&s, &s, &identity_motions(2), &bad_weights).is_err());
    // A field with inconsistent arrays is refused too.
    let mut field = MeshField::new(p.clone(), vec![[0, 1, 2]], 2, 0.0);
    field.opacity.pop();
    assert!(StateSurface::from_field(&field).is_err());
}

#[test]
fn from_field_reads_colour_opacity_and_parts() {
    let mut field = MeshField::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]], 3, 0.0);
    field.set_color(1, Vec3::new(0.2, 0.6, 0.9));
    field.opacity[2] = 2.0;
    field.part_logits[3 + 2] = 1.0; // vertex 1's logit of part 2
    let s = StateSurface::from_field(&field).unwrap();
    assert_eq!(s.parts(), &[0, 2, 0]);
    assert!((s.colors()[1] - Vec3::new(0.2, 0.6, 0.9)).length() < 1e-6);
    assert!((s.colors()[0] - Vec3::splat(0.5)).length() < 1e-6);
    assert!((s.opacity()[0] - 0.5).abs() < 1e-6);
    assert!((s.opacity()[2] - 1.0 / (1.0 + (-2.0f32).exp())).abs() < 1e-6);
    assert_eq!(s.cross_part_faces(), 1);
}
