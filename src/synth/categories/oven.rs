//! Oven, front towards −y, in two styles:
//!
//! - freestanding range cooker (~0.6 m wide, ~0.9 m tall): hob with burners on top, a control strip with a
//!   row of knobs above the oven door, and sometimes a storage drawer below it;
//! - countertop oven (~0.5 m wide, ~0.3 m tall): door on the left, a control column with stacked knobs on
//!   the right, on small feet.
//!
//! The body is hollow around the cavity (dark enamel liner and a wire rack), so an open door shows inside.
//! Movable parts: the drop-down door, always (revolute about its bottom front edge, along x, opening forward
//! and down by up to ~90°); knobs (revolute about their own axis along −y, up to 3/4 to 1 1/2 turns' worth,
//! each with a fin and a pointer mark so the angle shows); and on cookers possibly the drawer (prismatic
//! along −y). Knobs beyond the movable ones are static parts of the body.

use std::f32::consts::PI;

use glam::Vec3;

use crate::object::{ArticulatedObject, JointKind, Material};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cuboid, cylinder};
use crate::synth::texture::{Finish, plain, random_material, random_plain};

const GAP: f32 = 0.0015;

/// Box between two corners.
fn block(lo: Vec3, hi: Vec3, mat: &Material) -> crate::object::RenderMesh {
    cuboid((lo + hi) * 0.5, hi - lo, mat)
}

struct Mats {
    body: Material,
    enamel: Material,
    glass: Material,
    metal: Material,
    knob: Material,
    mark: Material,
}

pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let body = if rng.chance(0.5) {
        random_material("body", Finish::Paint, rng)
    } else {
        random_material("body", Finish::Metal, rng)
    };
    let mats = Mats {
        body,
        enamel: plain("enamel", [0.04, 0.04, 0.05]),
        glass: plain("glass", [0.02, 0.025, 0.03]),
        metal: random_material("steel", Finish::Metal, rng),
        knob: random_plain("knob", *rng.pick(&[Finish::Plastic, Finish::Metal]), rng),
        mark: plain("mark", [0.8, 0.1, 0.05]),
    };
    let mut b = ObjectBuilder::new("oven");
    // Countertop ovens have room for at most three knobs in their column.
    if parts <= 4 && rng.chance(0.4) {
        countertop(&mut b, parts, &mats, rng);
    } else {
        cooker(&mut b, parts, &mats, rng);
    }
    b.build()
}

/// Which of `total` knobs move: `moving` of them, chosen at random.
fn moving_knobs(total: usize, moving: usize, rng: &mut Rng) -> Vec<bool> {
    let mut flags: Vec<bool> = (0..total).map(|i| i < moving).collect();
    for i in (1..total).rev() {
        let j = rng.below(i as u32 + 1) as usize;
        flags.swap(i, j);
    }
    flags
}

/// A knob on the front face `y_face` at (x, z): skirt, a fin across its face and a red pointer mark.
#[allow(clippy::too_many_arguments)]
fn knob(
    b: &mut ObjectBuilder,
    name: &str,
    moves: bool,
    x: f32,
    z: f32,
    y_face: f32,
    r: f32,
    mats: &Mats,
    rng: &mut Rng,
) {
    let turn = rng.uniform(0.75, 1.5) * PI;
    let link = if moves {
        // About −y (out of the face): positive angles turn it counter-clockwise as seen from the front.
        b.joint(
            name,
            ObjectBuilder::BASE,
            JointKind::Revolute,
            Vec3::new(x, y_face, z),
            Vec3::NEG_Y,
            0.0,
            turn,
        )
    } else {
        ObjectBuilder::BASE
    };
    let depth = r * 0.8;
    let front = y_face - GAP - depth;
    b.add(
        link,
        cylinder(
            Vec3::new(x, y_face - GAP, z),
            Vec3::new(x, front, z),
            r,
            &mats.knob,
        ),
    );
    b.add(
        link,
        cuboid(
            Vec3::new(x, front - 0.006, z),
            Vec3::new(r * 1.7, 0.014, r * 0.4),
            &mats.knob,
        ),
    );
    b.add(
        link,
        cuboid(
            Vec3::new(x + r * 0.6, front - 0.0132, z),
            Vec3::new(r * 0.4, 0.001, r * 0.3),
            &mats.mark,
        ),
    );
}

/// Hollow body `w`×`d` from `z0` to `h` around a cavity open at the front (x in `cx`, z in `cz`, `depth`
/// deep), with a dark liner and a wire rack.
#[allow(clippy::too_many_arguments)]
fn hollow_body(
    b: &mut ObjectBuilder,
    w: f32,
    d: f32,
    z0: f32,
    h: f32,
    cx: (f32, f32),
    cz: (f32, f32),
    depth: f32,
    mats: &Mats,
) {
    let base = ObjectBuilder::BASE;
    let (y0, y1) = (-d / 2.0, d / 2.0);
    let body = &mats.body;
    b.add(
        base,
        block(Vec3::new(-w / 2.0, y0, z0), Vec3::new(cx.0, y1, h), body),
    );
    b.add(
        base,
        block(Vec3::new(cx.1, y0, z0), Vec3::new(w / 2.0, y1, h), body),
    );
    b.add(
        base,
        block(Vec3::new(cx.0, y0, z0), Vec3::new(cx.1, y1, cz.0), body),
    );
    b.add(
        base,
        block(Vec3::new(cx.0, y0, cz.1), Vec3::new(cx.1, y1, h), body),
    );
    let yb = y0 + depth;
    b.add(
        base,
        block(Vec3::new(cx.0, yb, cz.0), Vec3::new(cx.1, y1, cz.1), body),
    );
    // Liner panels 1 mm inside the cavity walls (floor, ceiling, sides, back).
    let e = 0.001;
    let t = 0.001;
    let ya = y0 + 0.004;
    let liner = &mats.enamel;
    b.add(
        base,
        block(
            Vec3::new(cx.0, ya, cz.0 + e),
            Vec3::new(cx.1, yb, cz.0 + e + t),
            liner,
        ),
    );
    b.add(
        base,
        block(
            Vec3::new(cx.0, ya, cz.1 - e - t),
            Vec3::new(cx.1, yb, cz.1 - e),
            liner,
        ),
    );
    b.add(
        base,
        block(
            Vec3::new(cx.0 + e, ya, cz.0),
            Vec3::new(cx.0 + e + t, yb, cz.1),
            liner,
        ),
    );
    b.add(
        base,
        block(
            Vec3::new(cx.1 - e - t, ya, cz.0),
            Vec3::new(cx.1 - e, yb, cz.1),
            liner,
        ),
    );
    b.add(
        base,
        block(
            Vec3::new(cx.0, yb - e - t, cz.0),
            Vec3::new(cx.1, yb - e, cz.1),
            liner,
        ),
    );
    // Wire rack half way up: rods along y on two cross bars.
    let zr = (cz.0 + cz.1) / 2.0;
    let (xa, xb) = (cx.0 + 0.004, cx.1 - 0.004);
    for y in [ya + 0.03, yb - 0.03] {
        b.add(
            base,
            cylinder(
                Vec3::new(xa, y, zr),
                Vec3::new(xb, y, zr),
                0.0025,
                &mats.metal,
            ),
        );
    }
    let rods = 6;
    for k in 0..rods {
        let x = xa + (xb - xa) * (k as f32 + 0.5) / rods as f32;
        b.add(
            base,
            cylinder(
                Vec3::new(x, ya + 0.01, zr + 0.004),
                Vec3::new(x, yb - 0.01, zr + 0.004),
                0.002,
                &mats.metal,
            ),
        );
    }
}

/// The drop-down door over x in `xs`, z in `zs`, on the body front `y_face`.
fn door(
    b: &mut ObjectBuilder,
    xs: (f32, f32),
    zs: (f32, f32),
    y_face: f32,
    mats: &Mats,
    rng: &mut Rng,
) {
    let t = rng.uniform(0.025, 0.04);
    let y_front = y_face - GAP - t;
    // Hinged on its bottom front edge about +x: the top falls forward, and no point goes below the hinge or
    // behind the body's front face.
    let link = b.joint(
        "door",
        ObjectBuilder::BASE,
        JointKind::Revolute,
        Vec3::new(0.0, y_front, zs.0),
        Vec3::X,
        0.0,
        rng.uniform(0.45, 0.5) * PI,
    );
    b.add(
        link,
        block(
            Vec3::new(xs.0, y_front, zs.0),
            Vec3::new(xs.1, y_face - GAP, zs.1),
            &mats.body,
        ),
    );
    let (w, h) = (xs.1 - xs.0, zs.1 - zs.0);
    let mx = w * rng.uniform(0.1, 0.18);
    b.add(
        link,
        block(
            Vec3::new(xs.0 + mx, y_front - 0.001, zs.0 + h * 0.18),
            Vec3::new(xs.1 - mx, y_front + 0.001, zs.1 - h * 0.25),
            &mats.glass,
        ),
    );
    // Handle bar on two stand-offs near the top.
    let zh = zs.1 - h * 0.1;
    let yh = y_front - rng.uniform(0.03, 0.045);
    let (xa, xb) = (xs.0 + w * 0.12, xs.1 - w * 0.12);
    b.add(
        link,
        cylinder(
            Vec3::new(xa, yh, zh),
            Vec3::new(xb, yh, zh),
            0.01,
            &mats.metal,
        ),
    );
    for x in [xa + 0.02, xb - 0.02] {
        b.add(
            link,
            cylinder(
                Vec3::new(x, y_front, zh),
                Vec3::new(x, yh, zh),
                0.006,
                &mats.metal,
            ),
        );
    }
}

fn cooker(b: &mut ObjectBuilder, parts: usize, mats: &Mats, rng: &mut Rng) {
    let base = ObjectBuilder::BASE;
    let w = rng.uniform(0.5, 0.76);
    let d = rng.uniform(0.55, 0.64);
    let h = rng.uniform(0.85, 0.92);
    let plinth = rng.uniform(0.03, 0.06);
    let strip = rng.uniform(0.08, 0.12);
    let drawer = parts >= 2 && rng.chance(0.4);
    let drawer_h = rng.uniform(0.12, 0.16);
    let y_face = -d / 2.0;
    b.add(
        base,
        block(
            Vec3::new(-w / 2.0 + 0.02, y_face + 0.04, 0.0),
            Vec3::new(w / 2.0 - 0.02, d / 2.0 - 0.02, plinth),
            &mats.enamel,
        ),
    );
    let side = rng.uniform(0.04, 0.06);
    let cx = (-w / 2.0 + side, w / 2.0 - side);
    let cz0 = plinth + drawer_h + 0.045;
    let cz1 = h - strip - 0.035;
    hollow_body(b, w, d, plinth, h, cx, (cz0, cz1), d * 0.85, mats);
    door(
        b,
        (-w / 2.0 + 0.01, w / 2.0 - 0.01),
        (cz0 - 0.025, cz1 + 0.025),
        y_face,
        mats,
        rng,
    );

    // Hob: cooktop plate and four burners.
    b.add(
        base,
        block(
            Vec3::new(-w / 2.0, y_face, h),
            Vec3::new(w / 2.0, d / 2.0, h + 0.004),
            &mats.glass,
        ),
    );
    let burner_r = rng.uniform(0.035, 0.05);
    for (i, j) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let c = Vec3::new(i * w / 4.0, j * d / 4.0, h + 0.004);
        let r = burner_r * if (i + j) == 0.0 { 0.8 } else { 1.0 };
        b.add(base, cylinder(c, c + Vec3::Z * 0.012, r, &mats.metal));
        b.add(
            base,
            cylinder(
                c + Vec3::Z * 0.012,
                c + Vec3::Z * 0.016,
                r * 0.6,
                &mats.enamel,
            ),
        );
    }

    if drawer {
        let link = b.joint(
            "drawer",
            base,
            JointKind::Prismatic,
            Vec3::new(0.0, y_face, plinth),
            Vec3::NEG_Y,
            0.0,
            d * rng.uniform(0.45, 0.6),
        );
        let (z0, z1) = (plinth + 0.01, plinth + drawer_h);
        let yf = y_face - GAP;
        b.add(
            link,
            block(
                Vec3::new(-w / 2.0 + 0.01, yf - 0.02, z0),
                Vec3::new(w / 2.0 - 0.01, yf, z1),
                &mats.body,
            ),
        );
        // The box runs back inside the body's solid bottom, hidden until pulled out.
        let (bx0, bx1) = (cx.0 + 0.01, cx.1 - 0.01);
        let depth = d * 0.75;
        b.add(
            link,
            block(
                Vec3::new(bx0, yf, z0 + 0.005),
                Vec3::new(bx1, yf + depth, z0 + 0.015),
                &mats.enamel,
            ),
        );
        for x in [bx0, bx1 - 0.01] {
            b.add(
                link,
                block(
                    Vec3::new(x, yf, z0 + 0.005),
                    Vec3::new(x + 0.01, yf + depth, z1 - 0.03),
                    &mats.enamel,
                ),
            );
        }
        let zh = z1 - 0.03;
        b.add(
            link,
            cylinder(
                Vec3::new(-w * 0.3, yf - 0.045, zh),
                Vec3::new(w * 0.3, yf - 0.045, zh),
                0.009,
                &mats.metal,
            ),
        );
        for x in [-w * 0.28, w * 0.28] {
            b.add(
                link,
                cylinder(
                    Vec3::new(x, yf - 0.02, zh),
                    Vec3::new(x, yf - 0.045, zh),
                    0.006,
                    &mats.metal,
                ),
            );
        }
        // Dark opening behind the drawer front, seen once it slides out.
        b.add(
            base,
            block(
                Vec3::new(bx0, y_face - 0.001, z0 + 0.005),
                Vec3::new(bx1, y_face, z1 - 0.01),
                &mats.enamel,
            ),
        );
    }

    // Knobs in a row across the control strip.
    let moving = parts - 1 - usize::from(drawer);
    let total = moving.max(rng.int_in(3, 6));
    let flags = moving_knobs(total, moving, rng);
    let r = rng
        .uniform(0.018, 0.024)
        .min(w * 0.8 / total as f32 / 2.0 - 0.008);
    let zk = h - strip / 2.0;
    for (k, &moves) in flags.iter().enumerate() {
        let x = -w * 0.4 + w * 0.8 * (k as f32 + 0.5) / total as f32;
        knob(b, &format!("knob_{k}"), moves, x, zk, y_face, r, mats, rng);
    }
}

fn countertop(b: &mut ObjectBuilder, parts: usize, mats: &Mats, rng: &mut Rng) {
    let base = ObjectBuilder::BASE;
    let w = rng.uniform(0.42, 0.56);
    let d = rng.uniform(0.32, 0.42);
    let h = rng.uniform(0.26, 0.34);
    let feet = rng.uniform(0.015, 0.025);
    let panel = rng.uniform(0.1, 0.13);
    let y_face = -d / 2.0;
    for (i, j) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let c = Vec3::new(i * (w / 2.0 - 0.04), j * (d / 2.0 - 0.04), 0.0);
        b.add(base, cylinder(c, c + Vec3::Z * feet, 0.014, &mats.enamel));
    }
    let cx = (-w / 2.0 + 0.03, w / 2.0 - panel - 0.02);
    let cz = (feet + 0.04, h - 0.04);
    hollow_body(b, w, d, feet, h, cx, cz, d * 0.8, mats);
    door(
        b,
        (-w / 2.0 + 0.008, cx.1 + 0.012),
        (cz.0 - 0.025, cz.1 + 0.025),
        y_face,
        mats,
        rng,
    );

    // Knobs stacked in the control column.
    let moving = parts - 1;
    let total = moving.max(rng.int_in(2, 3));
    let flags = moving_knobs(total, moving, rng);
    let pitch = (h - feet - 0.05) / total as f32;
    let r = rng
        .uniform(0.016, 0.022)
        .min(pitch / 2.0 - 0.008)
        .min(panel / 2.0 - 0.012);
    let xk = w / 2.0 - panel / 2.0;
    for (k, &moves) in flags.iter().enumerate() {
        let z = h - 0.025 - pitch * (k as f32 + 0.5);
        knob(b, &format!("knob_{k}"), moves, xk, z, y_face, r, mats, rng);
    }
}
