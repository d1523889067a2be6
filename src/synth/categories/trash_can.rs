//! Trash can, in four styles. Pedal bin (round or square): a lid hinged at the back (revolute, lifting the
//! front) and a foot pedal at the front bottom (revolute, tip pressed down). Butterfly bin: two half lids
//! hinged at the left and right edges swinging up and apart, plus an optional pedal. Swing bin: a tall body
//! with a hood whose front flap swings both ways about a horizontal axis (rest in the middle of its range).
//! Recycling bin: two or three compartments, each with its own back-hinged lid, plus an optional pedal.

use glam::Vec3;

use super::shapes_b::{GAP, Open, open_box, slab};
use crate::object::{ArticulatedObject, JointKind, Material};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cylinder, frustum, torus};
use crate::synth::texture::{Finish, plain, random_material};

/// A foot pedal sticking out of the front (y = `front`) at the bottom; positive angles press its tip down.
fn pedal(b: &mut ObjectBuilder, name: &str, x: f32, front: f32, width: f32, material: &Material) {
    let z = 0.045;
    let pivot = Vec3::new(x, front - GAP, z);
    let link = b.joint(
        name,
        ObjectBuilder::BASE,
        JointKind::Revolute,
        pivot,
        Vec3::X,
        0.0,
        0.3,
    );
    b.add(
        link,
        slab(
            Vec3::new(x - width / 2.0, front - GAP - 0.075, z - 0.006),
            Vec3::new(x + width / 2.0, front - GAP, z + 0.006),
            material,
        ),
    );
}

/// A rectangular open-topped body `w` × `d` × `h` standing centred on z = 0, with a dark false floor inside
/// at height `floor`.
fn square_body(
    b: &mut ObjectBuilder,
    w: f32,
    d: f32,
    h: f32,
    floor: f32,
    body: &Material,
    dark: &Material,
) {
    let base = ObjectBuilder::BASE;
    open_box(
        b,
        base,
        Vec3::new(-w / 2.0, -d / 2.0, 0.0),
        Vec3::new(w / 2.0, d / 2.0, h),
        0.01,
        Open::Top,
        body,
    );
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0 + 0.01, -d / 2.0 + 0.01, floor),
            Vec3::new(w / 2.0 - 0.01, d / 2.0 - 0.01, floor + 0.003),
            dark,
        ),
    );
}

/// The bin's materials.
struct Materials {
    body: Material,
    lid: Material,
    /// The dark inside.
    dark: Material,
    pedal: Material,
}

/// Pedal bin, round or square: lid (+ pedal when two parts).
fn pedal_bin(b: &mut ObjectBuilder, parts: usize, lid_upper: f32, m: &Materials, rng: &mut Rng) {
    let base = ObjectBuilder::BASE;
    let h = rng.uniform(0.3, 0.7);
    let top = h;
    if rng.chance(0.5) {
        let r = rng.uniform(0.12, 0.18);
        let rb = r * rng.uniform(0.88, 0.97);
        b.add(
            base,
            frustum(Vec3::ZERO, Vec3::Z * (top - 0.01), rb, r, &m.body),
        );
        b.add(
            base,
            cylinder(Vec3::Z * (top - 0.01), Vec3::Z * top, r * 0.92, &m.dark),
        );
        b.add(
            base,
            torus(Vec3::Z * (top - 0.006), Vec3::Z, r - 0.004, 0.006, &m.body),
        );
        let lid = b.joint(
            "lid",
            base,
            JointKind::Revolute,
            Vec3::new(0.0, r + 0.008, top + GAP),
            Vec3::NEG_X,
            0.0,
            lid_upper,
        );
        b.add(
            lid,
            frustum(
                Vec3::Z * (top + GAP),
                Vec3::Z * (top + GAP + rng.uniform(0.02, 0.05)),
                r + 0.006,
                r * 0.85,
                &m.lid,
            ),
        );
        b.add(
            base,
            slab(
                Vec3::new(-0.03, r - 0.01, top - 0.04),
                Vec3::new(0.03, r + 0.016, top - 0.005),
                &m.pedal,
            ),
        );
        if parts >= 2 {
            pedal(b, "pedal", 0.0, -rb, r * 0.8, &m.pedal);
        }
    } else {
        let (w, d) = (rng.uniform(0.25, 0.4), rng.uniform(0.22, 0.35));
        square_body(b, w, d, top, top * 0.4, &m.body, &m.dark);
        let lid = b.joint(
            "lid",
            base,
            JointKind::Revolute,
            Vec3::new(0.0, d / 2.0 + 0.004, top + GAP),
            Vec3::NEG_X,
            0.0,
            lid_upper,
        );
        b.add(
            lid,
            slab(
                Vec3::new(-w / 2.0 - 0.004, -d / 2.0 - 0.004, top + GAP),
                Vec3::new(w / 2.0 + 0.004, d / 2.0 + 0.004, top + GAP + 0.025),
                &m.lid,
            ),
        );
        if parts >= 2 {
            pedal(b, "pedal", 0.0, -d / 2.0, w * 0.5, &m.pedal);
        }
    }
}

/// Butterfly bin: two half lids hinged at the sides (+ pedal when three parts).
fn butterfly_bin(
    b: &mut ObjectBuilder,
    parts: usize,
    lid_upper: f32,
    m: &Materials,
    rng: &mut Rng,
) {
    let base = ObjectBuilder::BASE;
    let (w, d, h) = (
        rng.uniform(0.3, 0.45),
        rng.uniform(0.25, 0.35),
        rng.uniform(0.4, 0.7),
    );
    square_body(b, w, d, h, h * 0.45, &m.body, &m.dark);
    for (k, left) in [true, false].into_iter().enumerate() {
        let (x0, x1, hx, axis) = if left {
            (-w / 2.0, -GAP, -w / 2.0, Vec3::NEG_Y)
        } else {
            (GAP, w / 2.0, w / 2.0, Vec3::Y)
        };
        let lid = b.joint(
            &format!("lid{k}"),
            base,
            JointKind::Revolute,
            Vec3::new(hx, 0.0, h + GAP),
            axis,
            0.0,
            lid_upper,
        );
        b.add(
            lid,
            slab(
                Vec3::new(x0, -d / 2.0, h + GAP),
                Vec3::new(x1, d / 2.0, h + GAP + 0.018),
                &m.lid,
            ),
        );
    }
    if parts >= 3 {
        pedal(b, "pedal", 0.0, -d / 2.0, w * 0.45, &m.pedal);
    }
}

/// Swing bin: a hood on a tall body; the flap swings both ways about its middle.
fn swing_bin(b: &mut ObjectBuilder, m: &Materials, rng: &mut Rng) {
    let base = ObjectBuilder::BASE;
    let (w, d, h) = (
        rng.uniform(0.28, 0.38),
        rng.uniform(0.25, 0.32),
        rng.uniform(0.55, 0.8),
    );
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0, -d / 2.0, 0.0),
            Vec3::new(w / 2.0, d / 2.0, h),
            &m.body,
        ),
    );
    let hood = rng.uniform(0.14, 0.2);
    let t = 0.012;
    let (fx, fz0, fz1) = (w * 0.35, h + 0.02, h + hood - 0.03);
    // Hood: top, sides, back, a strip over and under the opening, and a dark inside.
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0, -d / 2.0, h + hood - t),
            Vec3::new(w / 2.0, d / 2.0, h + hood),
            &m.lid,
        ),
    );
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0, -d / 2.0 + t, h),
            Vec3::new(w / 2.0, d / 2.0, h + hood - t),
            &m.dark,
        ),
    );
    for (x0, x1) in [(-w / 2.0, -fx), (fx, w / 2.0)] {
        b.add(
            base,
            slab(
                Vec3::new(x0, -d / 2.0, h),
                Vec3::new(x1, -d / 2.0 + t, h + hood - t),
                &m.lid,
            ),
        );
    }
    b.add(
        base,
        slab(
            Vec3::new(-fx, -d / 2.0, h),
            Vec3::new(fx, -d / 2.0 + t, fz0),
            &m.lid,
        ),
    );
    b.add(
        base,
        slab(
            Vec3::new(-fx, -d / 2.0, fz1),
            Vec3::new(fx, -d / 2.0 + t, h + hood - t),
            &m.lid,
        ),
    );
    let swing = rng.uniform(0.6, 0.9);
    let zc = (fz0 + fz1) * 0.5;
    let flap = b.joint(
        "flap",
        base,
        JointKind::Revolute,
        Vec3::new(0.0, -d / 2.0 + t * 0.5, zc),
        Vec3::X,
        -swing,
        swing,
    );
    b.add(
        flap,
        slab(
            Vec3::new(-fx + GAP, -d / 2.0 + 0.002, fz0 + GAP),
            Vec3::new(fx - GAP, -d / 2.0 + t - 0.002, fz1 - GAP),
            &m.lid,
        ),
    );
}

/// Recycling bin: compartments side by side, each with a lid (+ a pedal when parts allow).
fn recycling_bin(
    b: &mut ObjectBuilder,
    parts: usize,
    lid_upper: f32,
    m: &Materials,
    rng: &mut Rng,
) {
    let base = ObjectBuilder::BASE;
    let with_pedal = parts == 3 && rng.chance(0.5);
    let k = if with_pedal { parts - 1 } else { parts };
    let cw = rng.uniform(0.2, 0.3);
    let (w, d, h) = (cw * k as f32, rng.uniform(0.28, 0.4), rng.uniform(0.5, 0.8));
    let colours = [
        [0.1, 0.3, 0.7],
        [0.75, 0.6, 0.1],
        [0.15, 0.5, 0.2],
        [0.6, 0.1, 0.1],
    ];
    let first = rng.below(4) as usize;
    for i in 0..k {
        let x0 = -w / 2.0 + cw * i as f32;
        open_box(
            b,
            base,
            Vec3::new(x0 + 0.001, -d / 2.0, 0.0),
            Vec3::new(x0 + cw - 0.001, d / 2.0, h),
            0.01,
            Open::Top,
            &m.body,
        );
        b.add(
            base,
            slab(
                Vec3::new(x0 + 0.012, -d / 2.0 + 0.01, h * 0.5),
                Vec3::new(x0 + cw - 0.012, d / 2.0 - 0.01, h * 0.5 + 0.003),
                &m.dark,
            ),
        );
        let colour = plain("lid", colours[(first + i) % colours.len()]);
        let lid = b.joint(
            &format!("lid{i}"),
            base,
            JointKind::Revolute,
            Vec3::new(x0 + cw / 2.0, d / 2.0 + 0.004, h + GAP),
            Vec3::NEG_X,
            0.0,
            lid_upper,
        );
        b.add(
            lid,
            slab(
                Vec3::new(x0 + 0.003, -d / 2.0 - 0.006, h + GAP),
                Vec3::new(x0 + cw - 0.003, d / 2.0 + 0.004, h + GAP + 0.022),
                &colour,
            ),
        );
    }
    if with_pedal {
        pedal(
            b,
            "pedal",
            -w / 2.0 + cw / 2.0,
            -d / 2.0,
            cw * 0.6,
            &m.pedal,
        );
    }
}

/// Builds a trash can with exactly `parts` moving parts.
pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let body = random_material(
        "body",
        *rng.pick(&[Finish::Metal, Finish::Metal, Finish::Plastic, Finish::Paint]),
        rng,
    );
    let lid = if rng.chance(0.6) {
        body.clone()
    } else {
        random_material("lid", Finish::Plastic, rng)
    };
    let dark = plain("inside", [0.05, 0.05, 0.05]);
    let pedal = random_material("pedal", *rng.pick(&[Finish::Metal, Finish::Plastic]), rng);
    let m = Materials {
        body,
        lid,
        dark,
        pedal,
    };
    let mut b = ObjectBuilder::new("trash_can");
    let lid_upper = rng.uniform(1.3, 1.6);

    let style = match parts {
        1 => *rng.pick(&[0, 2]),
        2 => *rng.pick(&[0, 1, 3]),
        _ => *rng.pick(&[1, 3]),
    };
    match style {
        0 => pedal_bin(&mut b, parts, lid_upper, &m, rng),
        1 => butterfly_bin(&mut b, parts, lid_upper, &m, rng),
        2 => swing_bin(&mut b, &m, rng),
        _ => recycling_bin(&mut b, parts, lid_upper, &m, rng),
    }
    b.build()
}
