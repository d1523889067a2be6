//! Box: an open-topped body (a bottom and four walls, so the inside shows when it is opened) closed by
//!
//! - one lid hinged along the back edge (1 movable part): a wooden chest with metal straps and a latch, a
//!   painted or plastic storage box, or a flat cardboard box (pizza/gift box);
//! - two leaves (2 movable parts): either a cardboard carton's flaps hinged on opposite rim edges (left/right
//!   or front/back) and meeting in the middle, sometimes with the other two flaps standing open as part of
//!   the body, or two lids side by side both hinged at the back (toy chest).
//!
//! Every joint is revolute about a rim edge; positive angles swing the leaf up and outward.

use std::f32::consts::PI;

use glam::Vec3;

use super::shapes_a::rotation_about;
use crate::object::{ArticulatedObject, JointKind, Material};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cuboid, cylinder};
use crate::synth::texture::{Finish, material, random_material, random_plain};

/// Gap between the closed leaves and the rim, so the rest pose does not z-fight.
const GAP: f32 = 0.0015;

#[derive(Clone, Copy, PartialEq)]
enum Style {
    Chest,
    Storage,
    Cardboard,
}

pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let style = *rng.pick(&[Style::Chest, Style::Storage, Style::Cardboard]);
    let (w, d, h, wall) = match style {
        Style::Chest => (
            rng.uniform(0.4, 0.75),
            rng.uniform(0.28, 0.42),
            rng.uniform(0.25, 0.42),
            rng.uniform(0.012, 0.022),
        ),
        Style::Storage => (
            rng.uniform(0.25, 0.5),
            rng.uniform(0.2, 0.35),
            rng.uniform(0.15, 0.3),
            rng.uniform(0.006, 0.012),
        ),
        // A flat pizza/gift box when it has one lid, a shipping carton when it has flaps.
        Style::Cardboard if parts == 1 => (
            rng.uniform(0.25, 0.4),
            rng.uniform(0.25, 0.4),
            rng.uniform(0.04, 0.08),
            0.003,
        ),
        Style::Cardboard => (
            rng.uniform(0.25, 0.5),
            rng.uniform(0.2, 0.4),
            rng.uniform(0.18, 0.4),
            0.004,
        ),
    };
    let body_mat = match style {
        Style::Chest => random_material("wood", Finish::Wood, rng),
        Style::Storage => {
            let finish = *rng.pick(&[Finish::Paint, Finish::Plastic]);
            random_material("shell", finish, rng)
        }
        Style::Cardboard => {
            let tone = rng.uniform(0.8, 1.15);
            let seed = rng.next_u64();
            material(
                "cardboard",
                Finish::Paint,
                [0.5 * tone, 0.34 * tone, 0.18 * tone],
                seed,
            )
        }
    };
    let lid_mat = if style == Style::Storage && rng.chance(0.4) {
        random_material("lid", Finish::Plastic, rng)
    } else {
        body_mat.clone()
    };
    let trim = random_plain("trim", Finish::Metal, rng);

    let mut b = ObjectBuilder::new("box");
    add_body(&mut b, w, d, h, wall, &body_mat);
    if style == Style::Chest {
        add_chest_fittings(&mut b, w, d, h, &trim, rng);
    }

    let lid_t = match style {
        Style::Chest => rng.uniform(0.015, 0.03),
        Style::Storage => rng.uniform(0.008, 0.015),
        Style::Cardboard => wall,
    };
    // Wooden and plastic lids overhang the walls a little; cardboard is flush.
    let over = if style == Style::Cardboard {
        0.0
    } else {
        rng.uniform(0.006, 0.015)
    };
    let top = h + GAP;
    if parts == 1 {
        let open = rng.uniform(0.6, 0.85) * PI;
        let xs = (-w / 2.0 - over, w / 2.0 + over);
        let lid = back_lid(&mut b, "lid", xs, d, top, over, open);
        add_lid_slab(&mut b, lid, xs, d, top, over, lid_t, &lid_mat);
        if style != Style::Cardboard {
            add_lid_fittings(&mut b, lid, xs, d, top, over, lid_t, &trim);
        }
    } else if style == Style::Cardboard || rng.chance(0.3) {
        add_flaps(
            &mut b,
            w,
            d,
            top,
            lid_t.min(0.006),
            &lid_mat,
            style == Style::Cardboard,
            rng,
        );
    } else {
        // Two lids side by side, both hinged at the back, split in the middle with a gap.
        let open = rng.uniform(0.6, 0.85) * PI;
        let halves = [(-w / 2.0 - over, -GAP), (GAP, w / 2.0 + over)];
        for (k, xs) in halves.into_iter().enumerate() {
            let name = if k == 0 { "lid_left" } else { "lid_right" };
            let lid = back_lid(&mut b, name, xs, d, top, over, open);
            add_lid_slab(&mut b, lid, xs, d, top, over, lid_t, &lid_mat);
            add_lid_fittings(&mut b, lid, xs, d, top, over, lid_t, &trim);
        }
    }
    b.build()
}

/// Bottom and four walls of an open box `w`×`d`×`h` with walls `t` thick.
fn add_body(b: &mut ObjectBuilder, w: f32, d: f32, h: f32, t: f32, mat: &Material) {
    let base = ObjectBuilder::BASE;
    b.add(
        base,
        cuboid(Vec3::new(0.0, 0.0, t / 2.0), Vec3::new(w, d, t), mat),
    );
    let wall_h = h - t;
    let zc = t + wall_h / 2.0;
    for s in [-1.0, 1.0] {
        b.add(
            base,
            cuboid(
                Vec3::new(0.0, s * (d - t) / 2.0, zc),
                Vec3::new(w, t, wall_h),
                mat,
            ),
        );
        b.add(
            base,
            cuboid(
                Vec3::new(s * (w - t) / 2.0, 0.0, zc),
                Vec3::new(t, d - 2.0 * t, wall_h),
                mat,
            ),
        );
    }
}

/// Metal straps down the front and back, a hasp under the lid latch, and side handles.
fn add_chest_fittings(
    b: &mut ObjectBuilder,
    w: f32,
    d: f32,
    h: f32,
    trim: &Material,
    rng: &mut Rng,
) {
    let base = ObjectBuilder::BASE;
    let strap_w = rng.uniform(0.02, 0.035);
    for x in [-w / 4.0, w / 4.0] {
        for s in [-1.0, 1.0] {
            b.add(
                base,
                cuboid(
                    Vec3::new(x, s * (d / 2.0 + 0.0005), h / 2.0),
                    Vec3::new(strap_w, 0.002, h - 0.004),
                    trim,
                ),
            );
        }
    }
    b.add(
        base,
        cuboid(
            Vec3::new(0.0, -d / 2.0 - 0.001, h - 0.025),
            Vec3::new(0.03, 0.003, 0.03),
            trim,
        ),
    );
    if rng.chance(0.6) {
        // Carrying handles: a bar on two posts on each end wall.
        let z = h * 0.7;
        for s in [-1.0, 1.0] {
            let x = s * (w / 2.0 + 0.02);
            b.add(
                base,
                cylinder(Vec3::new(x, -0.05, z), Vec3::new(x, 0.05, z), 0.006, trim),
            );
            for y in [-0.045, 0.045] {
                b.add(
                    base,
                    cylinder(
                        Vec3::new(s * w / 2.0, y, z),
                        Vec3::new(x, y, z),
                        0.005,
                        trim,
                    ),
                );
            }
        }
    }
}

/// Adds a lid link hinged along the back edge (+y) of the top, spanning `xs`, opening up to `open` radians.
fn back_lid(
    b: &mut ObjectBuilder,
    name: &str,
    xs: (f32, f32),
    d: f32,
    top: f32,
    over: f32,
    open: f32,
) -> usize {
    // Hinge on the lid's bottom back edge: about −x, positive angles lift the front edge.
    b.joint(
        name,
        ObjectBuilder::BASE,
        JointKind::Revolute,
        Vec3::new((xs.0 + xs.1) / 2.0, d / 2.0 + over, top),
        Vec3::NEG_X,
        0.0,
        open,
    )
}

#[allow(clippy::too_many_arguments)]
fn add_lid_slab(
    b: &mut ObjectBuilder,
    lid: usize,
    xs: (f32, f32),
    d: f32,
    top: f32,
    over: f32,
    t: f32,
    mat: &Material,
) {
    b.add(
        lid,
        cuboid(
            Vec3::new((xs.0 + xs.1) / 2.0, 0.0, top + t / 2.0),
            Vec3::new(xs.1 - xs.0, d + 2.0 * over, t),
            mat,
        ),
    );
}

/// A latch plate hanging in front of the body and a strap across the lid.
#[allow(clippy::too_many_arguments)]
fn add_lid_fittings(
    b: &mut ObjectBuilder,
    lid: usize,
    xs: (f32, f32),
    d: f32,
    top: f32,
    over: f32,
    t: f32,
    trim: &Material,
) {
    let x = (xs.0 + xs.1) / 2.0;
    // In front of the lid's front face; the overhang keeps it clear of the body's hasp.
    b.add(
        lid,
        cuboid(
            Vec3::new(x, -d / 2.0 - over - 0.0015, top + t / 2.0 - 0.008),
            Vec3::new(0.025, 0.003, t + 0.016),
            trim,
        ),
    );
    // Straps over the lid in line with the body's straps at x = ±w/4 (one per half-lid).
    let quarter = (xs.1 - xs.0).abs().max(0.0) / 4.0;
    let straps: &[f32] = if xs.0 < 0.0 && xs.1 > 0.0 {
        &[-1.0, 1.0]
    } else {
        &[0.0]
    };
    for &k in straps {
        b.add(
            lid,
            cuboid(
                Vec3::new(x + k * quarter, 0.0, top + t + 0.0005),
                Vec3::new(0.025, d + 2.0 * over, 0.002),
                trim,
            ),
        );
    }
}

/// Two flaps hinged on opposite rim edges that meet in the middle; cartons may also show their other two
/// flaps standing open (static, part of the body).
#[allow(clippy::too_many_arguments)]
fn add_flaps(
    b: &mut ObjectBuilder,
    w: f32,
    d: f32,
    top: f32,
    t: f32,
    mat: &Material,
    carton: bool,
    rng: &mut Rng,
) {
    let along_x = rng.chance(0.5);
    let open = rng.uniform(0.75, 0.95) * PI;
    // `reach`: distance from the centre to the hinged edges; `span`: length along the hinge.
    let (reach, span) = if along_x { (w / 2.0, d) } else { (d / 2.0, w) };
    let flap_len = reach - GAP;
    for (k, s) in [-1.0f32, 1.0].into_iter().enumerate() {
        // The flap on the `s` side is hinged at `s·reach` and reaches inward (−s) to the middle. Its tip must
        // rise: about +y for the −x side (tip at +x), −y for +x; about −x for the +y side, +x for −y.
        let (pivot, axis, centre, size) = if along_x {
            (
                Vec3::new(s * reach, 0.0, top),
                Vec3::Y * s,
                Vec3::new(s * (reach - flap_len / 2.0), 0.0, top + t / 2.0),
                Vec3::new(flap_len, span - 2.0 * GAP, t),
            )
        } else {
            (
                Vec3::new(0.0, s * reach, top),
                Vec3::X * -s,
                Vec3::new(0.0, s * (reach - flap_len / 2.0), top + t / 2.0),
                Vec3::new(span - 2.0 * GAP, flap_len, t),
            )
        };
        let name = ["flap_a", "flap_b"][k];
        let flap = b.joint(
            name,
            ObjectBuilder::BASE,
            JointKind::Revolute,
            pivot,
            axis,
            0.0,
            open,
        );
        b.add(flap, cuboid(centre, size, mat));
    }
    if carton && rng.chance(0.6) {
        // The other pair stands open outward, tilted a little past vertical, clear of the moving flaps' edges.
        let (reach, span) = if along_x { (d / 2.0, w) } else { (w / 2.0, d) };
        let len = rng.uniform(0.6, 1.0) * reach;
        let tilt = rng.uniform(0.55, 0.75) * PI;
        for s in [-1.0f32, 1.0] {
            let (pivot, axis, centre, size) = if along_x {
                (
                    Vec3::new(0.0, s * reach, top),
                    Vec3::X * -s,
                    Vec3::new(0.0, s * (reach - len / 2.0), top + t / 2.0),
                    Vec3::new(span - 2.0 * GAP - 0.004, len, t),
                )
            } else {
                (
                    Vec3::new(s * reach, 0.0, top),
                    Vec3::Y * s,
                    Vec3::new(s * (reach - len / 2.0), 0.0, top + t / 2.0),
                    Vec3::new(len, span - 2.0 * GAP - 0.004, t),
                )
            };
            let flap = cuboid(centre, size, mat).transformed(&rotation_about(pivot, axis, tilt));
            b.add(ObjectBuilder::BASE, flap);
        }
    }
}
