//! Unit tests of the geometric joint fit: a door swing, a drawer slide against a far hinge, a
//! knob turned about its own axis, slabs that fit both ways round, and joints along or askew to
//! the directions their object is built in.

use glam::{DQuat, Vec3};

use super::*;
use crate::articulation::motion::rotation_axis_angle;
use crate::rng::Rng;

/// A closed box surface (w × h × d m at `origin`) sampled with outward normals.
fn box_cloud(rng: &mut Rng, size: DVec3, origin: DVec3, count: usize) -> PartCloud {
    let mut cloud = PartCloud::default();
    for _ in 0..count {
        let face = rng.below(6) as usize;
        let (axis, side) = (face / 2, (face % 2) as f64);
        let mut p = DVec3::new(
            rng.uniform(0.0, 1.0) as f64,
            rng.uniform(0.0, 1.0) as f64,
            rng.uniform(0.0, 1.0) as f64,
        );
        p[axis] = side;
        let mut n = DVec3::ZERO;
        n[axis] = if side > 0.5 { 1.0 } else { -1.0 };
        cloud.points.push((origin + p * size).as_vec3());
        cloud.normals.push(n.as_vec3());
    }
    cloud
}

fn door(rng: &mut Rng) -> PartCloud {
    box_cloud(
        rng,
        DVec3::new(0.5, 0.8, 0.03),
        DVec3::new(0.0, 0.0, 0.0),
        3000,
    )
}

/// A post beside the door's hinge edge (x = 0): what a cabinet's side is to its door.
fn hinge_post(rng: &mut Rng) -> Vec<Vec3> {
    box_cloud(
        rng,
        DVec3::new(0.02, 0.8, 0.3),
        DVec3::new(-0.025, 0.0, -0.3),
        1500,
    )
    .points
}

/// The residual a correct motion is expected to leave here: these clouds are exact, so only
/// what every capture has, depth rounded to whole millimetres (1/√12 mm RMS).
const ROUNDING_NOISE: Option<f64> = Some(0.000_288_675);

#[test]
fn a_door_swing_is_revolute_with_its_hinge_line() {
    let mut rng = Rng::new(3);
    let start = door(&mut rng);
    let truth = PartMotion::revolute(DVec3::Y, DVec3::ZERO, 35f64.to_radians());
    let end = moved_cloud(&door(&mut rng), &truth);
    let post = hinge_post(&mut rng);
    let anchor = Anchor::new(&post, &post);
    let g = fit_joint(&start, &end, Some(&anchor), ROUNDING_NOISE).unwrap();
    assert_eq!(g.kind, JointKind::Revolute, "{g:?}");
    assert!(g.settled(), "{g:?}");
    let (axis, angle) = rotation_axis_angle(g.revolute.rotation);
    assert!(axis.dot(DVec3::Y).abs() > 0.9995, "{axis}");
    assert!(
        (angle.to_degrees() - 35.0).abs() < 0.3,
        "{}",
        angle.to_degrees()
    );
    let off = g.revolute.pivot - axis * g.revolute.pivot.dot(axis);
    assert!(off.length() < 0.003, "{}", g.revolute.pivot);
    // A degree either way moves the slab's free edge by 9 mm: the depth rules it out at once.
    assert_eq!(g.angle_range, Some([1.0, 1.0]), "{g:?}");
}

/// Whether `m` turns about the line of `truth` by its angle (within 1°, 5 mm).
fn same_hinge(m: &PartMotion, truth: &PartMotion) -> bool {
    let (a, angle) = rotation_axis_angle(m.rotation);
    let (b, truth_angle) = rotation_axis_angle(truth.rotation);
    let (a, angle) = if a.dot(b) < 0.0 {
        (-a, -angle)
    } else {
        (a, angle)
    };
    let off = (m.pivot - truth.pivot).reject_from(b).length();
    a.angle_between(b) < 1f64.to_radians()
        && (angle - truth_angle).abs() < 1f64.to_radians()
        && off < 0.005
}

#[test]
fn a_slab_that_fits_both_ways_round_is_not_settled_and_keeps_both_hinges() {
    // A plain slab with nothing beside it fits as well turned about its hinge as flipped over:
    // the depth cannot tell which, so the joint must not settle, and the true hinge must stay
    // among the hypotheses for the photometric stages.
    let mut rng = Rng::new(3);
    let start = door(&mut rng);
    let truth = PartMotion::revolute(DVec3::Y, DVec3::ZERO, 35f64.to_radians());
    let end = moved_cloud(&door(&mut rng), &truth);
    let g = fit_joint(&start, &end, None, ROUNDING_NOISE).unwrap();
    assert!(!g.settled(), "{g:?}");
    assert!(g.open_rivals().count() > 0, "{g:?}");
    let hypotheses: Vec<PartMotion> = std::iter::once(g.revolute)
        .chain(g.open_rivals().map(|r| r.motion))
        .collect();
    assert!(
        hypotheses.iter().any(|m| same_hinge(m, &truth)),
        "{hypotheses:?}"
    );
}

/// A door with a dark handle strip along its free edge (x > 0.4) on its front face (+z).
fn painted_door(rng: &mut Rng) -> PartCloud {
    let mut d = door(rng);
    d.colors = d
        .points
        .iter()
        .zip(&d.normals)
        .map(|(p, n)| {
            if n.z > 0.5 && p.x > 0.4 {
                Vec3::splat(0.1)
            } else {
                Vec3::splat(0.8)
            }
        })
        .collect();
    d
}

#[test]
fn a_door_whose_slab_fits_both_ways_round_is_decided_by_its_colour() {
    // Swung 110° about its hinge, the slab also fits turned 70° about a line in front of it
    // (flipped over): the smaller turn, which the shape alone would pick. The handle strip's
    // colour tells them apart.
    let mut rng = Rng::new(4);
    let truth = PartMotion::revolute(DVec3::Y, DVec3::ZERO, 110f64.to_radians());
    let start = painted_door(&mut rng);
    let end = moved_cloud(&painted_door(&mut rng), &truth);
    let noise = ROUNDING_NOISE;
    let g = fit_joint(&start, &end, None, noise).unwrap();
    assert!(same_hinge(&g.revolute, &truth), "{g:?}");
    // Colour decided it, not the depth: the flipped hinge stays a rival the depth cannot rule out.
    assert!(!g.settled(), "{g:?}");
    let mut plain = (start.clone(), end.clone());
    plain.0.colors.clear();
    plain.1.colors.clear();
    let g = fit_joint(&plain.0, &plain.1, None, noise).unwrap();
    assert!(!same_hinge(&g.revolute, &truth), "{g:?}");
}

#[test]
fn a_tie_between_the_models_is_not_settled() {
    // Points on a plane that slides within itself: sliding and turning about the plane's normal
    // far away both map it onto itself, so the two models tie.
    let plane = |rng: &mut Rng| {
        let mut c = PartCloud::default();
        for _ in 0..3000 {
            c.points
                .push(Vec3::new(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0), 0.0));
            c.normals.push(Vec3::Z);
        }
        c
    };
    let mut rng = Rng::new(11);
    let start = plane(&mut rng);
    let end = plane(&mut rng);
    let g = fit_joint(&start, &end, None, Some(0.000_5)).unwrap();
    assert!(g.margin < 1.0, "{g:?}");
    assert!(!g.settled(), "{g:?}");
}

#[test]
fn a_drawer_slide_is_prismatic_and_a_far_hinge_is_not() {
    let mut rng = Rng::new(5);
    let drawer = |rng: &mut Rng| {
        box_cloud(
            rng,
            DVec3::new(0.4, 0.15, 0.5),
            DVec3::new(0.0, 0.2, 0.0),
            3000,
        )
    };
    let start = drawer(&mut rng);
    let t = DVec3::new(0.0, 0.0, 0.25);
    let end = moved_cloud(&drawer(&mut rng), &PartMotion::prismatic(t));
    let g = fit_joint(&start, &end, None, None).unwrap();
    assert_eq!(g.kind, JointKind::Prismatic, "{g:?}");
    assert!((g.prismatic.translation - t).length() < 0.002, "{g:?}");
    // A hinge 1.5 m away turning 10° moves the drawer about as far, but it also turns it.
    let far = PartMotion::revolute(DVec3::Y, DVec3::new(1.5, 0.0, 0.0), 10f64.to_radians());
    let end = moved_cloud(&drawer(&mut rng), &far);
    let g = fit_joint(&start, &end, None, None).unwrap();
    assert_eq!(g.kind, JointKind::Revolute, "{g:?}");
    assert!(g.type_evidence >= DECISIVE, "{g:?}");
}

#[test]
fn a_knob_turned_about_its_own_axis_is_not_observable() {
    let mut rng = Rng::new(9);
    // A cylinder of radius 2 cm, 2 cm long, along z.
    let knob = |rng: &mut Rng| {
        let mut c = PartCloud::default();
        for _ in 0..1500 {
            let a = rng.uniform(0.0, std::f32::consts::TAU);
            let z = rng.uniform(0.0, 0.02);
            let n = Vec3::new(a.cos(), a.sin(), 0.0);
            c.points
                .push(Vec3::new(0.3, 0.4, 0.5) + 0.02 * n + Vec3::Z * z);
            c.normals.push(n);
        }
        c
    };
    // Depth rounded to whole millimetres scatters the points (1/√12 mm RMS): without it, the
    // fitted axis's few micrometres off the true one would show in the sampling's own residual.
    let sigma = ROUNDING_NOISE.unwrap() as f32;
    let start = noisy(&knob(&mut rng), sigma, &mut rng);
    let turn = PartMotion::revolute(DVec3::Z, DVec3::new(0.3, 0.4, 0.5), 60f64.to_radians());
    let end = noisy(&moved_cloud(&knob(&mut rng), &turn), sigma, &mut rng);
    let g = fit_joint(&start, &end, None, ROUNDING_NOISE).unwrap();
    assert!(!g.observable, "{g:?}");
    assert!(!g.settled());
    // Nothing in its depth rules out any other angle: the whole half turn each way is open.
    assert_eq!(g.angle_range, Some([180.0, 180.0]), "{g:?}");
}

#[test]
fn the_directions_an_object_is_built_along_come_from_its_faces_alone() {
    // A box turned arbitrarily, with a round handle whose axis is askew to it: the handle's
    // normals form a ring that would tilt the normals' principal axes; the faces' do not.
    let mut rng = Rng::new(21);
    let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.4);
    let faces = box_cloud(&mut rng, DVec3::new(0.6, 0.9, 0.4), DVec3::ZERO, 3000);
    let handle = DQuat::from_rotation_y(30f64.to_radians()) * DVec3::X;
    let (u, v) = handle.any_orthonormal_pair();
    let normals: Vec<Vec3> = faces
        .normals
        .iter()
        .map(|n| n.as_dvec3())
        .chain((0..1000).map(|_| {
            let a = f64::from(rng.uniform(0.0, std::f32::consts::TAU));
            u * a.cos() + v * a.sin()
        }))
        .map(|n| (turn * n).as_vec3())
        .collect();
    let found = build_directions(&normals);
    for axis in [DVec3::X, DVec3::Y, DVec3::Z].map(|a| turn * a) {
        let nearest = found.iter().map(|d| d.dot(axis).abs()).fold(0.0, f64::max);
        let off = nearest.min(1.0).acos().to_degrees();
        assert!(off < 0.05, "{axis}: {off}° off, {found:?}");
    }
}

/// `cloud` with every point moved along its normal by Gaussian noise of `sigma` (m).
fn noisy(cloud: &PartCloud, sigma: f32, rng: &mut Rng) -> PartCloud {
    PartCloud {
        points: cloud
            .points
            .iter()
            .zip(&cloud.normals)
            .map(|(p, n)| *p + *n * sigma * rng.normal())
            .collect(),
        ..cloud.clone()
    }
}

#[test]
fn a_noisy_hinge_built_along_its_object_takes_the_object_s_axis() {
    // A segmenter's wrong blob: a patch of the post beside the hinge's top end labelled as the
    // door in the open state only, and depth noise of 3 mm. The post's faces give the axis the
    // cabinet is built along, which the door's own points, pulled by the blob, miss.
    let mut rng = Rng::new(23);
    let truth = PartMotion::revolute(DVec3::Y, DVec3::ZERO, 35f64.to_radians());
    let post = box_cloud(
        &mut rng,
        DVec3::new(0.02, 0.8, 0.3),
        DVec3::new(-0.025, 0.0, -0.3),
        1500,
    );
    let start = noisy(&door(&mut rng), 0.003, &mut rng);
    let mut end = noisy(&moved_cloud(&door(&mut rng), &truth), 0.003, &mut rng);
    for (p, n) in post.points.iter().zip(&post.normals) {
        if p.y > 0.7 && p.z > -0.1 {
            end.points.push(*p);
            end.normals.push(*n);
        }
    }
    let anchor = Anchor::new(&post.points, &post.points).built_along(&post.normals);
    let g = fit_joint(&start, &end, Some(&anchor), None).unwrap();
    assert_eq!(g.kind, JointKind::Revolute, "{g:?}");
    let (axis, _) = rotation_axis_angle(g.revolute.rotation);
    let off = axis.dot(DVec3::Y).abs().min(1.0).acos().to_degrees();
    assert!(off < 0.05, "{off}° off: {g:?}");
}

#[test]
fn a_hinge_askew_to_its_object_keeps_its_own_axis() {
    // The same door on a hinge tilted 4° from the cabinet's vertical: the points show the tilt
    // far past what aligning to the cabinet would save, so the fit keeps it.
    let mut rng = Rng::new(24);
    let tilted = DQuat::from_rotation_x(4f64.to_radians()) * DVec3::Y;
    let truth = PartMotion::revolute(tilted, DVec3::ZERO, 35f64.to_radians());
    let post = box_cloud(
        &mut rng,
        DVec3::new(0.02, 0.8, 0.3),
        DVec3::new(-0.025, 0.0, -0.3),
        1500,
    );
    let start = door(&mut rng);
    let end = moved_cloud(&door(&mut rng), &truth);
    let anchor = Anchor::new(&post.points, &post.points).built_along(&post.normals);
    let g = fit_joint(&start, &end, Some(&anchor), ROUNDING_NOISE).unwrap();
    let (axis, _) = rotation_axis_angle(g.revolute.rotation);
    let off = axis.dot(tilted).abs().min(1.0).acos().to_degrees();
    assert!(off < 0.3, "{off}° off the tilted hinge: {g:?}");
}
