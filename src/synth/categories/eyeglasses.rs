//! Eyeglasses standing upright on their rims, lenses facing −y: the front (two rims swept as round, oval or
//! squarish superellipse tubes, lenses, bridge and end pieces) is the base, and the temples fold on revolute
//! hinges about vertical axes at the end pieces. At rest (0) a temple is folded inward behind the lenses;
//! positive angles swing it back until it points +y (open).
//!
//! With 2 movable parts both temples move; with 1, one temple moves and the other is part of the base,
//! either open or folded. Folded temples stack like real ones: the one that folds first (inner) sits a few
//! millimetres lower than the other, so the two never cross at the same height. Variations: metal wire or
//! thick plastic/tortoiseshell frames, clear or dark lenses, sizes and rim shapes.

use std::f32::consts::FRAC_PI_2;

use glam::{Affine3A, Vec2, Vec3};

use super::shapes_a::{bezier, prism, rotation_about, superellipse, tube};
use crate::object::{ArticulatedObject, JointKind};
use crate::rng::Rng;
use crate::synth::builder::ObjectBuilder;
use crate::synth::texture::{Finish, material, plain, random_material};

pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let metal = rng.chance(0.4);
    let a = rng.uniform(0.022, 0.029); // lens half-width
    let b_half = a * rng.uniform(0.6, 0.85); // lens half-height
    let power = if rng.chance(0.5) {
        2.0
    } else {
        rng.uniform(2.6, 4.0)
    };
    let (rim_r, temple_r) = if metal {
        (rng.uniform(0.0012, 0.0016), rng.uniform(0.0012, 0.0015))
    } else {
        (rng.uniform(0.0025, 0.0035), rng.uniform(0.0022, 0.003))
    };
    let bridge_gap = rng.uniform(0.014, 0.02);
    let temple_len = rng.uniform(0.125, 0.145);

    let frame = if metal {
        random_material("frame", Finish::Metal, rng)
    } else if rng.chance(0.3) {
        // Tortoiseshell: wood-like streaks in dark brown.
        let seed = rng.next_u64();
        material("tortoiseshell", Finish::Wood, [0.22, 0.1, 0.035], seed)
    } else {
        random_material("frame", Finish::Plastic, rng)
    };
    let sleeve = plain("ear_sleeve", [0.04, 0.04, 0.04]);
    let lens = if rng.chance(0.35) {
        plain("dark_lens", [0.04, 0.05, 0.06])
    } else {
        plain("lens", [0.72, 0.78, 0.82])
    };

    let mut b = ObjectBuilder::new("eyeglasses");
    let base = ObjectBuilder::BASE;
    let zc = b_half + rim_r + 0.0005; // rims touch the table
    for sx in [-1.0f32, 1.0] {
        let centre = Vec3::new(sx * (bridge_gap / 2.0 + a), 0.0, zc);
        let ring = superellipse(centre, Vec3::X, Vec3::Z, a, b_half, power, 48);
        b.add(base, tube(&ring, rim_r, rim_r, 8, &frame));
        // Lens: the same outline, 1.5 mm thick, in the rim's plane (local z → −y).
        let outline: Vec<Vec2> = superellipse(
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            a - rim_r * 0.5,
            b_half - rim_r * 0.5,
            power,
            32,
        )
        .iter()
        .take(32)
        .map(|p| p.truncate())
        .collect();
        let pose = Affine3A::from_translation(centre) * Affine3A::from_rotation_x(FRAC_PI_2);
        b.add(base, prism(&outline, -0.00075, 0.00075, pose, &lens));
    }
    // Bridge: an arch between the inner rim edges, a little above the lens centres.
    let inner = bridge_gap / 2.0 + a * 0.1;
    b.add(
        base,
        tube(
            &bezier(
                Vec3::new(-inner, 0.0, zc + b_half * 0.45),
                Vec3::new(0.0, -0.003, zc + b_half * 1.0),
                Vec3::new(inner, 0.0, zc + b_half * 0.45),
                8,
            ),
            rim_r * 0.9,
            rim_r * 0.9,
            8,
            &frame,
        ),
    );

    // Hinges: the inner (first-folding) temple sits lower than the outer one by a temple's thickness.
    let hinge_x = bridge_gap / 2.0 + 2.0 * a + 0.005;
    let hinge_y = rng.uniform(0.007, 0.011);
    let z_mid = zc + b_half * 0.3;
    let stack = 2.0 * temple_r + 0.0015;
    let inner_side = *rng.pick(&[-1.0f32, 1.0]);
    let back_tilt = rng.uniform(0.1, 0.16); // folded temples point a little backward, clear of the far hinge
    let splay = rng.uniform(0.03, 0.08); // open temples spread a little outward
    let fold = FRAC_PI_2 - back_tilt + splay;
    let fixed_open = parts == 1 && rng.chance(0.5);

    for sx in [-1.0f32, 1.0] {
        let is_inner = sx == inner_side;
        let zh = if is_inner {
            z_mid - stack / 2.0
        } else {
            z_mid + stack / 2.0
        };
        let yh = if is_inner { hinge_y } else { hinge_y + 0.003 };
        let pivot = Vec3::new(sx * hinge_x, yh, zh);
        // End piece: from the rim's outer edge out and back to the hinge.
        let rim_edge = Vec3::new(sx * (bridge_gap / 2.0 + 1.9 * a), 0.0, zh);
        let piece = bezier(rim_edge, Vec3::new(sx * hinge_x, -0.001, zh), pivot, 6);
        b.add(
            base,
            tube(&piece, temple_r * 1.2, temple_r * 1.2, 8, &frame),
        );

        // The temple drawn open (pointing +y, splayed outward), then folded to the rest pose.
        let dir = Vec3::new(sx * splay.sin(), splay.cos(), 0.0);
        let straight = temple_len * 0.72;
        let p1 = pivot + dir * straight + Vec3::new(0.0, 0.0, -0.002);
        let drop = rng.uniform(0.01, 0.018).min(zh - temple_r - 0.003);
        let tip = pivot + dir * temple_len + Vec3::new(0.0, 0.0, -drop);
        let mut path = vec![pivot];
        path.extend(bezier(p1, p1 + dir * (temple_len - straight) * 0.6, tip, 8));
        let (bar, ear): (Vec<Vec3>, Vec<Vec3>) = if metal {
            (path[..2].to_vec(), path[1..].to_vec())
        } else {
            (path.clone(), Vec::new())
        };
        let mut temple_meshes = vec![tube(&bar, temple_r, temple_r, 8, &frame)];
        if !ear.is_empty() {
            temple_meshes.push(tube(&ear, temple_r * 1.6, temple_r * 1.3, 8, &sleeve));
        }
        // Positive angles open the temple: about +z on the −x side, −z on the +x side.
        let axis = Vec3::Z * -sx;
        let folded = rotation_about(pivot, axis, -fold);
        let moving = parts == 2 || !is_inner;
        if moving {
            let name = if sx < 0.0 {
                "temple_left"
            } else {
                "temple_right"
            };
            let link = b.joint(name, base, JointKind::Revolute, pivot, axis, 0.0, fold);
            for m in temple_meshes {
                b.add(link, m.transformed(&folded));
            }
        } else {
            for m in temple_meshes {
                b.add(
                    base,
                    if fixed_open {
                        m
                    } else {
                        m.transformed(&folded)
                    },
                );
            }
        }
    }
    b.build()
}
