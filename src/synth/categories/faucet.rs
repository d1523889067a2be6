//! Faucet (tap) on a basin deck, spout towards −y. Two layouts:
//!
//! - single-lever mixer (1–2 movable parts): a column on a round base; the spout leaves a swivel collar half
//!   way up and turns about the column's vertical axis (revolute, symmetric range); the lever on top lifts
//!   about a horizontal axis at the hub's back (or front) edge. With 1 part only one of them moves.
//! - two-handle tap (2–3 movable parts): a central column with a gooseneck or a low spout, and hot/cold lever
//!   handles on risers at ±x that turn outward about their vertical axes (quarter to third of a turn). With 3
//!   parts the spout also swivels.
//!
//! Variations: sizes, spout shape, lever direction, deck plate or separate escutcheons, chrome/brushed/brass
//! metal, white ceramic handles.

use glam::Vec3;

use super::shapes_a::{bezier, tube};
use crate::object::{ArticulatedObject, JointKind, Material};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cuboid, cylinder, frustum, sphere};
use crate::synth::texture::{Finish, plain, random_material};

const GAP: f32 = 0.0015;

pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let chrome = random_material("metal", Finish::Metal, rng);
    let handle_mat = if rng.chance(0.3) {
        plain("ceramic", [0.85, 0.85, 0.83])
    } else {
        chrome.clone()
    };
    let two_handle = match parts {
        1 => false,
        3 => true,
        _ => rng.chance(0.5),
    };
    let mut b = ObjectBuilder::new("faucet");
    if two_handle {
        two_handles(&mut b, parts, &chrome, &handle_mat, rng);
    } else {
        mixer(&mut b, parts, &chrome, &handle_mat, rng);
    }
    b.build()
}

/// The link the spout hangs on: when it `moves`, a swivel about the column axis at height `z` turning both
/// ways by a swing drawn from `swing` (only then is the generator advanced); otherwise the base.
fn spout_link(
    b: &mut ObjectBuilder,
    moves: bool,
    z: f32,
    swing: (f32, f32),
    rng: &mut Rng,
) -> usize {
    if !moves {
        return ObjectBuilder::BASE;
    }
    let swing = rng.uniform(swing.0, swing.1);
    b.joint(
        "spout",
        ObjectBuilder::BASE,
        JointKind::Revolute,
        Vec3::new(0.0, 0.0, z),
        Vec3::Z,
        -swing,
        swing,
    )
}

/// Single-lever mixer: column, swivel spout, lifting lever on top.
fn mixer(
    b: &mut ObjectBuilder,
    parts: usize,
    chrome: &Material,
    lever_mat: &Material,
    rng: &mut Rng,
) {
    let base = ObjectBuilder::BASE;
    let r = rng.uniform(0.018, 0.026);
    let h = rng.uniform(0.13, 0.24);
    let plate_t = rng.uniform(0.008, 0.014);
    b.add(
        base,
        frustum(
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, plate_t),
            r * 2.0,
            r * 1.7,
            chrome,
        ),
    );
    b.add(
        base,
        cylinder(
            Vec3::new(0.0, 0.0, plate_t),
            Vec3::new(0.0, 0.0, h),
            r,
            chrome,
        ),
    );
    let (spout_moves, lever_moves) = if parts >= 2 {
        (true, true)
    } else {
        let s = rng.chance(0.5);
        (s, !s)
    };

    // Spout: a tube from inside the collar forward, rising a little, its tip bent down to an aerator.
    let rs = rng.uniform(0.008, 0.012);
    let zs = h * rng.uniform(0.45, 0.6);
    let len = rng.uniform(0.12, 0.2);
    let rise = rng.uniform(0.0, 0.02).min(h - zs - rs - 0.02);
    let spout = spout_link(b, spout_moves, zs, (0.6, 1.1), rng);
    let collar = rs + 0.006;
    b.add(
        spout,
        cylinder(
            Vec3::new(0.0, 0.0, zs - collar),
            Vec3::new(0.0, 0.0, zs + collar),
            r + GAP,
            chrome,
        ),
    );
    let p1 = Vec3::new(0.0, -len * 0.8, zs + rise);
    let tip = Vec3::new(0.0, -len, zs + rise - 0.03);
    let mut path = vec![Vec3::new(0.0, -r * 0.5, zs)];
    path.extend(bezier(p1, Vec3::new(0.0, -len, zs + rise), tip, 6));
    b.add(spout, tube(&path, rs, rs * 0.9, 16, chrome));
    b.add(
        spout,
        cylinder(
            tip + Vec3::Z * 0.004,
            tip - Vec3::Z * 0.006,
            rs * 0.95,
            chrome,
        ),
    );

    // Lever: hub on the column top plus an arm; it pivots on the hub's bottom edge opposite the arm, so
    // lifting never digs into the column.
    let side = *rng.pick(&[-1.0f32, 1.0]); // arm towards −y (front) or +y (back)
    let hub_h = rng.uniform(0.02, 0.035);
    let lever = if lever_moves {
        let lift = rng.uniform(0.4, 0.7);
        b.joint(
            "lever",
            base,
            JointKind::Revolute,
            Vec3::new(0.0, -side * r, h + GAP),
            Vec3::X * side,
            0.0,
            lift,
        )
    } else {
        base
    };
    b.add(
        lever,
        cylinder(
            Vec3::new(0.0, 0.0, h + GAP),
            Vec3::new(0.0, 0.0, h + GAP + hub_h),
            r * 0.95,
            lever_mat,
        ),
    );
    b.add(
        lever,
        sphere(Vec3::new(0.0, 0.0, h + GAP + hub_h), r * 0.5, lever_mat),
    );
    let arm_len = rng.uniform(0.06, 0.1);
    let z_arm = h + GAP + hub_h * 0.7;
    b.add(
        lever,
        tube(
            &[
                Vec3::new(0.0, 0.0, z_arm),
                Vec3::new(0.0, side * arm_len, z_arm + arm_len * rng.uniform(0.1, 0.3)),
            ],
            0.009,
            0.006,
            12,
            lever_mat,
        ),
    );
}

/// Two-handle tap: centre spout column, hot/cold levers on risers at ±x.
fn two_handles(
    b: &mut ObjectBuilder,
    parts: usize,
    chrome: &Material,
    handle_mat: &Material,
    rng: &mut Rng,
) {
    let base = ObjectBuilder::BASE;
    let hx = rng.uniform(0.07, 0.1);
    let plate_t = rng.uniform(0.008, 0.014);
    let riser_r = rng.uniform(0.014, 0.019);
    let r = rng.uniform(0.016, 0.022);
    if rng.chance(0.5) {
        b.add(
            base,
            cuboid(
                Vec3::new(0.0, 0.0, plate_t / 2.0),
                Vec3::new(2.0 * hx + 0.05, rng.uniform(0.05, 0.07), plate_t),
                chrome,
            ),
        );
    } else {
        for x in [-hx, 0.0, hx] {
            b.add(
                base,
                frustum(
                    Vec3::new(x, 0.0, 0.0),
                    Vec3::new(x, 0.0, plate_t),
                    riser_r * 1.8,
                    riser_r * 1.5,
                    chrome,
                ),
            );
        }
    }

    // Handles: a riser (static) and a hub with a lever arm pointing forward at rest, turning outward.
    let riser_top = plate_t + rng.uniform(0.025, 0.045);
    let hub_h = rng.uniform(0.015, 0.025);
    let arm_len = rng.uniform(0.06, 0.08);
    let turn = rng.uniform(0.5, 0.65) * std::f32::consts::PI;
    let ball = rng.chance(0.5);
    for (k, sx) in [-1.0f32, 1.0].into_iter().enumerate() {
        let x = sx * hx;
        b.add(
            base,
            cylinder(
                Vec3::new(x, 0.0, plate_t),
                Vec3::new(x, 0.0, riser_top),
                riser_r,
                chrome,
            ),
        );
        // Positive angles swing the arm from −y towards the outside: about −z on the left, +z on the right.
        let name = ["handle_left", "handle_right"][k];
        let link = b.joint(
            name,
            base,
            JointKind::Revolute,
            Vec3::new(x, 0.0, riser_top),
            Vec3::Z * sx,
            0.0,
            turn,
        );
        let z0 = riser_top + GAP;
        b.add(
            link,
            cylinder(
                Vec3::new(x, 0.0, z0),
                Vec3::new(x, 0.0, z0 + hub_h),
                riser_r * 0.95,
                handle_mat,
            ),
        );
        let za = z0 + hub_h * 0.6;
        let end = Vec3::new(x, -arm_len, za + arm_len * 0.15);
        b.add(
            link,
            tube(&[Vec3::new(x, 0.0, za), end], 0.009, 0.006, 12, handle_mat),
        );
        if ball {
            b.add(link, sphere(end, 0.01, handle_mat));
        }
    }
    let handle_top = riser_top + GAP + hub_h + 0.02;

    // Spout column and spout, well above the handles so a swivel clears them.
    let rs = rng.uniform(0.008, 0.011);
    let gooseneck = rng.chance(0.5);
    let h = if gooseneck {
        rng.uniform(0.1, 0.16)
    } else {
        handle_top + rng.uniform(0.03, 0.06)
    };
    b.add(
        base,
        cylinder(
            Vec3::new(0.0, 0.0, plate_t),
            Vec3::new(0.0, 0.0, h),
            r,
            chrome,
        ),
    );
    let spout = spout_link(b, parts == 3, h, (0.5, 1.0), rng);
    b.add(
        spout,
        cylinder(
            Vec3::new(0.0, 0.0, h + GAP),
            Vec3::new(0.0, 0.0, h + GAP + 0.015),
            r * 1.05,
            chrome,
        ),
    );
    let z0 = h + GAP + 0.012;
    let (path, tip_dir) = if gooseneck {
        let reach = rng.uniform(0.12, 0.18);
        let height = rng.uniform(0.1, 0.16);
        let end = Vec3::new(0.0, -reach, z0 + height * 0.55);
        let path = bezier(
            Vec3::new(0.0, 0.0, z0),
            Vec3::new(0.0, reach * 0.05, z0 + height * 1.5),
            end,
            16,
        );
        (path, Vec3::new(0.0, -0.25, -1.0).normalize())
    } else {
        let reach = rng.uniform(0.1, 0.16);
        let path = bezier(
            Vec3::new(0.0, 0.0, z0),
            Vec3::new(0.0, -reach * 0.3, z0 + 0.02),
            Vec3::new(0.0, -reach, z0 + 0.005),
            10,
        );
        (path, Vec3::new(0.0, -0.4, -1.0).normalize())
    };
    b.add(spout, tube(&path, rs, rs * 0.9, 16, chrome));
    let tip = *path.last().unwrap_or(&Vec3::ZERO);
    b.add(
        spout,
        cylinder(
            tip - tip_dir * 0.004,
            tip + tip_dir * 0.012,
            rs * 1.05,
            chrome,
        ),
    );
}
