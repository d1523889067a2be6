//! Folding chair, front towards −y, in the classic scissor layout seen from the side: each main frame member
//! runs from the front foot up to the seat's back corner and on up as a back post (static, with the backrest
//! and a foot rail), and each rear leg runs from the back foot forward to just under the seat front, crossing
//! the main member at a pivot.
//!
//! Movable parts (revolute, both about axes along x): the seat, hinged along its back edge, flips up towards
//! the backrest; and the rear-leg frame (both rear legs and their foot rail, mounted outside the main frame)
//! swings about the crossing pivot towards the front legs, closing the X. With 1 part either moves and the
//! other is static. Variations: metal tubes or square wooden bars, seat/back materials, sizes, rake.

use glam::{Affine3A, Quat, Vec2, Vec3};

use super::shapes_a::tube;
use crate::object::{ArticulatedObject, JointKind, Material};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cuboid, oriented_cuboid};
use crate::synth::texture::{Finish, random_material};

const GAP: f32 = 0.002;

/// A straight frame member: a round tube, or a square wooden bar of the same width.
fn member(a: Vec3, b: Vec3, r: f32, wood: bool, mat: &Material) -> crate::object::RenderMesh {
    if wood {
        let d = b - a;
        let rot = Quat::from_rotation_arc(Vec3::Z, d.normalize_or(Vec3::Z));
        oriented_cuboid(
            Affine3A::from_rotation_translation(rot, (a + b) * 0.5),
            Vec3::new(2.0 * r, 2.0 * r, d.length()),
            mat,
        )
    } else {
        tube(&[a, b], r, r, 12, mat)
    }
}

/// Where the lines `p + s·u` and `q + t·v` (in the y-z plane) cross; the midpoint of p and q if parallel.
fn cross_point(p: Vec2, u: Vec2, q: Vec2, v: Vec2) -> Vec2 {
    let den = u.perp_dot(v);
    if den.abs() < 1e-9 {
        return (p + q) * 0.5;
    }
    p + u * ((q - p).perp_dot(v) / den)
}

pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let wood = rng.chance(0.4);
    let frame = if wood {
        random_material("frame", Finish::Wood, rng)
    } else {
        random_material("frame", Finish::Metal, rng)
    };
    let panel_finish = if wood {
        *rng.pick(&[Finish::Wood, Finish::Paint])
    } else {
        *rng.pick(&[Finish::Wood, Finish::Paint, Finish::Plastic])
    };
    let panel = random_material("seat", panel_finish, rng);
    let r = if wood {
        rng.uniform(0.011, 0.015)
    } else {
        rng.uniform(0.009, 0.012)
    };
    let seat_h = rng.uniform(0.42, 0.47);
    let seat_d = rng.uniform(0.34, 0.42);
    let seat_w = rng.uniform(0.38, 0.46);
    let seat_t = rng.uniform(0.012, 0.022);
    let back_h = rng.uniform(0.34, 0.45);
    let rake = rng.uniform(0.1, 0.2); // backward lean of the back posts (run per rise)
    let (seat_moves, legs_move) = if parts >= 2 {
        (true, true)
    } else {
        let s = rng.chance(0.65);
        (s, !s)
    };

    let mut b = ObjectBuilder::new("folding_chair");
    let base = ObjectBuilder::BASE;
    let xa = seat_w / 2.0 + GAP + r; // main members just outside the seat
    let xb = xa + 2.0 * r + 0.003; // rear legs outside the main members

    // Main member (y, z): front foot → seat back corner → top of the back post.
    let a_foot = Vec2::new(-seat_d / 2.0 - rng.uniform(0.03, 0.07), r);
    let a_seat = Vec2::new(seat_d / 2.0 + r, seat_h - r);
    let a_top = a_seat + Vec2::new(back_h * rake, back_h);
    // Rear leg: back foot → under the seat front.
    let b_foot = Vec2::new(seat_d / 2.0 + rng.uniform(0.06, 0.12), r);
    let b_top = Vec2::new(-seat_d / 2.0 + rng.uniform(0.03, 0.06), seat_h - 0.03);
    let pivot2 = cross_point(a_foot, a_seat - a_foot, b_foot, b_top - b_foot);
    let yz = |x: f32, p: Vec2| Vec3::new(x, p.x, p.y);

    for s in [-1.0f32, 1.0] {
        let x = s * xa;
        b.add(base, member(yz(x, a_foot), yz(x, a_seat), r, wood, &frame));
        b.add(base, member(yz(x, a_seat), yz(x, a_top), r, wood, &frame));
    }
    // Foot rail between the front feet.
    let rail_a = a_foot + (a_seat - a_foot) * 0.15;
    b.add(
        base,
        member(yz(-xa, rail_a), yz(xa, rail_a), r * 0.8, wood, &frame),
    );
    // Backrest: a panel between the posts, leaning with them.
    let lean = (back_h * rake).atan2(back_h);
    let mid = a_seat + (a_top - a_seat) * 0.72;
    let panel_h = back_h * rng.uniform(0.3, 0.45);
    b.add(
        base,
        oriented_cuboid(
            Affine3A::from_rotation_translation(Quat::from_rotation_x(-lean), yz(0.0, mid)),
            Vec3::new(2.0 * xa, rng.uniform(0.012, 0.02), panel_h),
            &panel,
        ),
    );

    // Rear-leg frame: swings about the crossing pivot; positive angles close it onto the main members.
    let ub = (b_foot - pivot2).normalize_or(Vec2::Y);
    let ua = (a_foot - pivot2).normalize_or(Vec2::Y);
    let closing = ub.angle_to(ua); // counter-clockwise in (y, z) is about +x
    let legs = if legs_move {
        b.joint(
            "rear_legs",
            base,
            JointKind::Revolute,
            yz(0.0, pivot2),
            Vec3::X * closing.signum(),
            0.0,
            closing.abs() * rng.uniform(0.75, 0.9),
        )
    } else {
        base
    };
    for s in [-1.0f32, 1.0] {
        let x = s * xb;
        b.add(legs, member(yz(x, b_foot), yz(x, b_top), r, wood, &frame));
    }
    let rail_b = b_foot + (b_top - b_foot) * 0.15;
    b.add(
        legs,
        member(yz(-xb, rail_b), yz(xb, rail_b), r * 0.8, wood, &frame),
    );
    // Pivot bolts through both members (static: they sit on the axis).
    for s in [-1.0f32, 1.0] {
        b.add(
            base,
            member(
                yz(s * (xa - r), pivot2),
                yz(s * (xb + r + 0.004), pivot2),
                r * 0.45,
                false,
                &frame,
            ),
        );
    }

    // Seat: hinged along its back bottom edge, positive angles lift the front (about −x).
    let back_edge = seat_d / 2.0 - 0.005;
    let seat = if seat_moves {
        b.joint(
            "seat",
            base,
            JointKind::Revolute,
            Vec3::new(0.0, back_edge, seat_h + GAP),
            Vec3::NEG_X,
            0.0,
            rng.uniform(0.42, 0.48) * std::f32::consts::PI,
        )
    } else {
        base
    };
    b.add(
        seat,
        cuboid(
            Vec3::new(0.0, back_edge - seat_d / 2.0, seat_h + GAP + seat_t / 2.0),
            Vec3::new(seat_w, seat_d, seat_t),
            &panel,
        ),
    );
    b.build()
}
