//! Knife lying flat on the table along x. One movable part, the blade, in one of two kinds:
//!
//! - folding pocket knife (revolute): a handle of two scales (wood, metal or plastic) with a slot between
//!   them; the steel blade turns about a vertical pivot pin at the handle's +x end, from folded into the slot
//!   (rest, 0) through a half turn to open. Which way it swings out (±y) is random.
//! - utility knife (prismatic): a plastic or metal body with a rubber grip; the trapezoid blade and its slider
//!   button slide out of the nose along +x.
//!
//! Variations: lengths, widths, blade outline (drop point, clip point, straight), materials.

use std::f32::consts::PI;

use glam::{Affine3A, Vec2, Vec3};

use super::shapes_a::{prism, rotation_about};
use crate::object::{ArticulatedObject, JointKind};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cuboid, cylinder};
use crate::synth::texture::{Finish, material, plain, random_material, random_plain};

const GAP: f32 = 0.0008;

pub(super) fn build(_parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let mut b = ObjectBuilder::new("knife");
    if rng.chance(0.65) {
        folding(&mut b, rng);
    } else {
        utility(&mut b, rng);
    }
    b.build()
}

/// Brushed steel for blades (the metal palette also has brass, wrong for a blade).
fn blade_steel(rng: &mut Rng) -> crate::object::Material {
    let tone = rng.uniform(0.5, 0.7);
    let seed = rng.next_u64();
    material(
        "blade",
        Finish::Metal,
        [tone, tone * 1.01, tone * 1.04],
        seed,
    )
}

/// Handle outline from the butt (x = −len) to a round end around the pivot (origin), slightly bellied.
fn handle_outline(len: f32, w: f32) -> Vec<Vec2> {
    let mut pts = Vec::new();
    let n = 10;
    // Bottom edge, butt → pivot.
    for i in 0..=n {
        let t = i as f32 / n as f32;
        let belly = 0.88 + 0.12 * (PI * t).sin();
        pts.push(Vec2::new(-len + t * len, -w / 2.0 * belly));
    }
    // Round end around the pivot.
    for i in 1..8 {
        let a = -PI / 2.0 + PI * i as f32 / 8.0;
        pts.push(Vec2::new(a.cos(), a.sin()) * (w / 2.0 * 0.88));
    }
    // Top edge, pivot → butt.
    for i in 0..=n {
        let t = 1.0 - i as f32 / n as f32;
        let belly = 0.88 + 0.12 * (PI * t).sin();
        pts.push(Vec2::new(-len + t * len, w / 2.0 * belly));
    }
    pts
}

fn folding(b: &mut ObjectBuilder, rng: &mut Rng) {
    let base = ObjectBuilder::BASE;
    let len = rng.uniform(0.085, 0.12);
    let w = rng.uniform(0.019, 0.026);
    let blade_t = rng.uniform(0.002, 0.003);
    let scale_t = rng.uniform(0.003, 0.005);
    let scales = match rng.below(3) {
        0 => random_material("scales", Finish::Wood, rng),
        1 => random_material("scales", Finish::Metal, rng),
        _ => random_material("scales", Finish::Plastic, rng),
    };
    let steel = blade_steel(rng);
    let pin = random_plain("pin", Finish::Metal, rng);

    let outline = handle_outline(len, w);
    let z_blade = scale_t + GAP;
    let z_top = z_blade + blade_t + GAP;
    b.add(
        base,
        prism(&outline, 0.0, scale_t, Affine3A::IDENTITY, &scales),
    );
    b.add(
        base,
        prism(
            &outline,
            z_top,
            z_top + scale_t,
            Affine3A::IDENTITY,
            &scales,
        ),
    );
    // Back spring closing the slot along the butt, short so the folded blade clears it.
    b.add(
        base,
        cuboid(
            Vec3::new(-len * 0.93, 0.0, z_blade + blade_t / 2.0),
            Vec3::new(len * 0.1, w * 0.7, blade_t + 2.0 * GAP),
            &scales,
        ),
    );
    // Pivot pin head, proud of the top scale.
    let z_pin = z_top + scale_t;
    b.add(
        base,
        cylinder(
            Vec3::new(0.0, 0.0, z_pin - 0.001),
            Vec3::new(0.0, 0.0, z_pin + 0.0008),
            0.0032,
            &pin,
        ),
    );

    // Blade drawn open (along +x, spine +y, edge −y), then folded by half a turn into the slot.
    let blade_len = len * rng.uniform(0.72, 0.85);
    let bw = w * rng.uniform(0.68, 0.8);
    let (spine, edge) = (bw * 0.42, bw * 0.58);
    let tip_y = match rng.below(3) {
        0 => -edge * 0.1, // drop point
        1 => spine * 0.1, // clip point
        _ => spine * 0.8, // straight back (sheepsfoot-ish)
    };
    let r_tang = w * 0.38;
    let blade_outline = vec![
        Vec2::new(-r_tang, 0.0),
        Vec2::new(-r_tang * 0.7, -r_tang * 0.7),
        Vec2::new(blade_len * 0.2, -edge),
        Vec2::new(blade_len * 0.6, -edge * 0.95),
        Vec2::new(blade_len * 0.85, -edge * 0.55),
        Vec2::new(blade_len, tip_y),
        Vec2::new(blade_len * 0.72, spine * 0.9),
        Vec2::new(blade_len * 0.4, spine),
        Vec2::new(0.0, spine),
        Vec2::new(-r_tang * 0.7, r_tang * 0.7),
    ];
    let open = prism(
        &blade_outline,
        z_blade,
        z_blade + blade_t,
        Affine3A::IDENTITY,
        &steel,
    );
    let axis = if rng.chance(0.5) {
        Vec3::Z
    } else {
        Vec3::NEG_Z
    };
    let upper = rng.uniform(0.95, 1.0) * PI;
    let blade = b.joint(
        "blade",
        base,
        JointKind::Revolute,
        Vec3::ZERO,
        axis,
        0.0,
        upper,
    );
    b.add(
        blade,
        open.transformed(&rotation_about(Vec3::ZERO, axis, -upper)),
    );
}

fn utility(b: &mut ObjectBuilder, rng: &mut Rng) {
    let base = ObjectBuilder::BASE;
    let len = rng.uniform(0.13, 0.17);
    let w = rng.uniform(0.022, 0.03);
    let h = rng.uniform(0.014, 0.02);
    let body = if rng.chance(0.7) {
        random_material("body", Finish::Plastic, rng)
    } else {
        random_material("body", Finish::Metal, rng)
    };
    let rubber = plain("grip", [0.03, 0.03, 0.03]);
    let steel = blade_steel(rng);
    let bw = rng.uniform(0.012, 0.016);
    let nose_w = (w * 0.6).max(bw + 0.004);
    let x_front = len / 2.0;
    let outline = vec![
        Vec2::new(-len / 2.0, -w * 0.4),
        Vec2::new(-len / 2.0 + 0.01, -w / 2.0),
        Vec2::new(x_front - 0.035, -w / 2.0),
        Vec2::new(x_front, -nose_w / 2.0),
        Vec2::new(x_front, nose_w / 2.0),
        Vec2::new(x_front - 0.035, w / 2.0),
        Vec2::new(-len / 2.0 + 0.01, w / 2.0),
        Vec2::new(-len / 2.0, w * 0.4),
    ];
    b.add(base, prism(&outline, 0.0, h, Affine3A::IDENTITY, &body));
    // The dark slot the slider runs in, and a rubber grip behind it.
    let travel = rng.uniform(0.03, 0.045);
    let slider_len = 0.016;
    let slot_x0 = x_front - 0.045 - travel - slider_len;
    b.add(
        base,
        cuboid(
            Vec3::new(slot_x0 + (travel + slider_len) / 2.0, 0.0, h),
            Vec3::new(travel + slider_len, 0.005, 0.0016),
            &rubber,
        ),
    );
    let (grip_x0, grip_x1) = (-len / 2.0 + 0.012, slot_x0 - 0.004);
    if grip_x1 - grip_x0 > 0.02 {
        b.add(
            base,
            cuboid(
                Vec3::new((grip_x0 + grip_x1) / 2.0, 0.0, h),
                Vec3::new(grip_x1 - grip_x0, w * 0.8, 0.002),
                &rubber,
            ),
        );
    }

    // Blade retracted with its tip just inside the nose; slides +x.
    let blade_len = rng.uniform(0.055, 0.065);
    let tip = x_front - 0.002;
    let back = tip - blade_len;
    let blade_outline = vec![
        Vec2::new(back, -bw / 2.0),
        Vec2::new(tip, -bw / 2.0),
        Vec2::new(tip - bw * 0.9, bw / 2.0),
        Vec2::new(back + 0.004, bw / 2.0),
    ];
    let blade = b.joint(
        "blade",
        base,
        JointKind::Prismatic,
        Vec3::new(tip, 0.0, h / 2.0),
        Vec3::X,
        0.0,
        travel,
    );
    b.add(
        blade,
        prism(
            &blade_outline,
            h / 2.0 - 0.0003,
            h / 2.0 + 0.0003,
            Affine3A::IDENTITY,
            &steel,
        ),
    );
    // Slider button with grip ridges, riding above the slot.
    let sx = slot_x0 + slider_len / 2.0;
    let top = h + 0.0012;
    b.add(
        blade,
        cuboid(
            Vec3::new(sx, 0.0, top + 0.002),
            Vec3::new(slider_len, 0.011, 0.004),
            &body,
        ),
    );
    for k in 0..3 {
        let x = sx - slider_len * 0.3 + k as f32 * slider_len * 0.3;
        b.add(
            blade,
            cuboid(
                Vec3::new(x, 0.0, top + 0.0045),
                Vec3::new(0.0025, 0.011, 0.002),
                &rubber,
            ),
        );
    }
}
