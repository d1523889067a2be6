//! Unit tests of the geometric joint fit: a door swing, a drawer slide against a far hinge, and a
//! knob turned about its own axis.

use glam::Vec3;

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

#[test]
fn a_door_swing_is_revolute_with_its_hinge_line() {
    let mut rng = Rng::new(3);
    let start = door(&mut rng);
    let truth = PartMotion::revolute(DVec3::Y, DVec3::ZERO, 35f64.to_radians());
    let end = moved_cloud(&door(&mut rng), &truth);
    let g = fit_joint(&start, &end, None).unwrap();
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
    let g = fit_joint(&start, &end, None).unwrap();
    assert_eq!(g.kind, JointKind::Prismatic, "{g:?}");
    assert!((g.prismatic.translation - t).length() < 0.002, "{g:?}");
    // A hinge 1.5 m away turning 10° moves the drawer about as far, but it also turns it.
    let far = PartMotion::revolute(DVec3::Y, DVec3::new(1.5, 0.0, 0.0), 10f64.to_radians());
    let end = moved_cloud(&drawer(&mut rng), &far);
    let g = fit_joint(&start, &end, None).unwrap();
    assert_eq!(g.kind, JointKind::Revolute, "{g:?}");
    assert!(g.settled(), "{g:?}");
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
    let start = knob(&mut rng);
    let turn = PartMotion::revolute(DVec3::Z, DVec3::new(0.3, 0.4, 0.5), 60f64.to_radians());
    let end = moved_cloud(&knob(&mut rng), &turn);
    let g = fit_joint(&start, &end, None).unwrap();
    assert!(!g.observable, "{g:?}");
    assert!(!g.settled());
}
