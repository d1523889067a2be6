//! Pliers lying flat on the table, jaws towards +x. Two crossing members meet at a pivot (origin in x, y):
//! member A (static base) has the upper jaw (+y) and the lower handle (−y); member B (the one movable part)
//! has the lower jaw and the upper handle, and turns about the vertical pivot axis. At rest (0) the jaws are
//! closed; positive angles open the jaws and spread the handles.
//!
//! The members overlap at the pivot as a lap joint: A's boss fills the lower half of the thickness, B's the
//! upper half, with a rivet on top. Variations: combination or long needle-nose jaws, handle length and
//! spread, steel tone, grip sleeve colour.

use glam::{Affine3A, Vec2, Vec3};

use super::shapes_a::{bezier, prism, tube};
use crate::object::{ArticulatedObject, JointKind, Material};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cylinder, sphere};
use crate::synth::texture::{Finish, random_material, random_plain};

pub(super) fn build(_parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let needle = rng.chance(0.4);
    let jaw_len = if needle {
        rng.uniform(0.05, 0.07)
    } else {
        rng.uniform(0.03, 0.045)
    };
    let jaw_w = rng.uniform(0.007, 0.011); // half-width of both jaws together at their base
    let tip_w = if needle {
        rng.uniform(0.0015, 0.0025)
    } else {
        rng.uniform(0.004, 0.006)
    };
    let handle_len = rng.uniform(0.1, 0.14);
    let rh = rng.uniform(0.0045, 0.006); // steel handle radius
    let rg = rh + rng.uniform(0.001, 0.002); // grip sleeve radius
    let spread = rng.uniform(rg + 0.003, rg + 0.01); // handle-end offset from the axis when closed
    let t = rng.uniform(0.008, 0.011); // thickness of jaws and bosses
    let rb = rng.uniform(0.009, 0.012); // boss radius
    let zc = (t / 2.0).max(rg) + 0.0002;
    let steel = random_material("steel", Finish::Metal, rng);
    let grip = random_material("grip", Finish::Plastic, rng);
    let rivet = random_plain("rivet", Finish::Metal, rng);

    let mut b = ObjectBuilder::new("pliers");
    let base = ObjectBuilder::BASE;
    let open = rng.uniform(0.35, 0.6);
    // About −z: B's jaw (−y side) swings further to −y, its handle (+y side) further to +y.
    let link_b = b.joint(
        "jaw",
        base,
        JointKind::Revolute,
        Vec3::new(0.0, 0.0, zc),
        Vec3::NEG_Z,
        0.0,
        open,
    );
    for (link, side) in [(base, 1.0f32), (link_b, -1.0)] {
        // Jaw on the `side` half, from inside the boss to the tip, with a 0.5 mm gap along the axis.
        let g = 0.0005;
        let outline: Vec<Vec2> = [
            (rb * 0.4, g),
            (jaw_len, g),
            (jaw_len, tip_w),
            (jaw_len * 0.45, jaw_w * 0.85),
            (rb * 0.4, jaw_w),
        ]
        .iter()
        .map(|&(x, y)| Vec2::new(x, side * y))
        .collect();
        b.add(
            link,
            prism(
                &outline,
                zc - t / 2.0,
                zc + t / 2.0,
                Affine3A::IDENTITY,
                &steel,
            ),
        );
        // Boss: lower half for A, upper half for B.
        let (z0, z1) = if side > 0.0 {
            (zc - t / 2.0, zc - 0.0003)
        } else {
            (zc + 0.0003, zc + t / 2.0 + 0.0005)
        };
        b.add(
            link,
            cylinder(Vec3::new(0.0, 0.0, z0), Vec3::new(0.0, 0.0, z1), rb, &steel),
        );
        // Handle on the other half: steel from the boss, then a grip sleeve to a rounded end.
        let s = -side;
        let start = Vec3::new(-rb * 0.5, s * rb * 0.3, zc);
        let end = Vec3::new(-handle_len, s * spread, zc);
        let path = bezier(
            start,
            Vec3::new(-handle_len * 0.3, s * spread * 1.25, zc),
            end,
            10,
        );
        b.add(link, tube(&path, rh * 1.2, rh, 10, &steel));
        add_grip(&mut b, link, &path[3..], rg, &grip);
    }
    b.add(
        base,
        cylinder(
            Vec3::new(0.0, 0.0, zc + t / 2.0 + 0.0003),
            Vec3::new(0.0, 0.0, zc + t / 2.0 + 0.0015),
            rb * 0.4,
            &rivet,
        ),
    );
    b.build()
}

/// Grip sleeve over the outer part of a handle, slightly thicker towards the end, with a rounded end.
fn add_grip(b: &mut ObjectBuilder, link: usize, path: &[Vec3], r: f32, mat: &Material) {
    b.add(link, tube(path, r * 0.95, r, 12, mat));
    if let Some(&end) = path.last() {
        b.add(link, sphere(end, r, mat));
    }
}
