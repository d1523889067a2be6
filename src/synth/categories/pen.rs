//! Pen lying on the table along x, writing tip towards −x. One movable part (prismatic, along the pen's
//! axis):
//!
//! - capped pen (most): the cap with its clip slides off the tip along −x, uncovering the grip and tip;
//! - click pen: the push button at the back end pops out along +x (the clip is then on the barrel).
//!
//! Variations: length, thickness, grip section, barrel/cap materials (near-textureless plastic, brushed
//! metal, wood), cap colour.

use glam::Vec3;

use crate::object::{ArticulatedObject, JointKind};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cuboid, cylinder, frustum};
use crate::synth::texture::{Finish, plain, random_material, random_plain};

pub(super) fn build(_parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let base = ObjectBuilder::BASE;
    let len = rng.uniform(0.13, 0.15);
    let r = rng.uniform(0.004, 0.0055);
    let capped = rng.chance(0.75);
    let barrel = match rng.below(6) {
        0 => random_material("barrel", Finish::Wood, rng),
        1 | 2 => random_material("barrel", Finish::Metal, rng),
        _ => random_material("barrel", Finish::Plastic, rng),
    };
    let cap_mat = if rng.chance(0.5) {
        barrel.clone()
    } else {
        random_material("cap", Finish::Plastic, rng)
    };
    let grip = if rng.chance(0.5) {
        plain("grip", [0.03, 0.03, 0.035])
    } else {
        barrel.clone()
    };
    let trim = random_plain("trim", Finish::Metal, rng);

    let rc = r + 0.0009; // cap radius: the widest part, resting on the table
    let zc = rc + 0.0003;
    let at = |x: f32| Vec3::new(x, 0.0, zc);
    let x0 = -len / 2.0; // tip end
    let x1 = len / 2.0; // back end
    let mut b = ObjectBuilder::new("pen");
    // Writing point, cone, grip section, barrel, end plug.
    b.add(base, cylinder(at(x0), at(x0 + 0.004), 0.0007, &trim));
    b.add(
        base,
        frustum(at(x0 + 0.003), at(x0 + 0.016), 0.0014, r * 0.85, &grip),
    );
    b.add(
        base,
        cylinder(at(x0 + 0.016), at(x0 + 0.042), r * 0.92, &grip),
    );
    b.add(base, cylinder(at(x0 + 0.042), at(x1 - 0.006), r, &barrel));
    b.add(base, frustum(at(x1 - 0.006), at(x1), r, r * 0.75, &barrel));

    let clip_len = rng.uniform(0.035, 0.045);
    if capped {
        // The cap covers the tip with a 1 mm gap beyond the point; its clip runs back along the top.
        let cap_len = rng.uniform(0.05, 0.062);
        let travel = rng.uniform(0.05, 0.07);
        let cap = b.joint(
            "cap",
            base,
            JointKind::Prismatic,
            at(x0),
            Vec3::NEG_X,
            0.0,
            travel,
        );
        let c0 = x0 - 0.001;
        b.add(
            cap,
            frustum(at(c0 - 0.004), at(c0), rc * 0.75, rc, &cap_mat),
        );
        b.add(cap, cylinder(at(c0), at(c0 + cap_len), rc, &cap_mat));
        let xc = c0 + 0.004 + clip_len / 2.0;
        b.add(
            cap,
            cuboid(
                Vec3::new(xc, 0.0, zc + rc + 0.0011),
                Vec3::new(clip_len, 0.003, 0.0012),
                &trim,
            ),
        );
        b.add(
            cap,
            cuboid(
                Vec3::new(c0 + 0.005, 0.0, zc + rc),
                Vec3::new(0.005, 0.003, 0.003),
                &trim,
            ),
        );
    } else {
        // Clip on the barrel near the back; the button pops out of the end plug.
        let xc = x1 - 0.012 - clip_len / 2.0;
        b.add(
            base,
            cuboid(
                Vec3::new(xc, 0.0, zc + r + 0.0011),
                Vec3::new(clip_len, 0.003, 0.0012),
                &trim,
            ),
        );
        b.add(
            base,
            cuboid(
                Vec3::new(x1 - 0.011, 0.0, zc + r),
                Vec3::new(0.005, 0.003, 0.003),
                &trim,
            ),
        );
        let travel = rng.uniform(0.006, 0.009);
        let button = b.joint(
            "button",
            base,
            JointKind::Prismatic,
            at(x1),
            Vec3::X,
            0.0,
            travel,
        );
        b.add(
            button,
            cylinder(at(x1 - 0.01), at(x1 + 0.004), r * 0.6, &cap_mat),
        );
        b.add(
            button,
            frustum(at(x1 + 0.004), at(x1 + 0.007), r * 0.6, r * 0.45, &cap_mat),
        );
    }
    b.build()
}
