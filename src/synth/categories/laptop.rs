//! Laptop: a base slab with keyboard and touchpad, and a screen lid on a revolute hinge along its back edge.

use std::f32::consts::PI;

use glam::Vec3;

use crate::object::{ArticulatedObject, JointKind};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cuboid};
use crate::synth::texture::{Finish, random_material, random_plain};

/// `parts` is always 1 (the lid).
pub(super) fn build(_parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let (w, d) = (rng.uniform(0.28, 0.38), rng.uniform(0.19, 0.26));
    let (base_h, lid_h) = (rng.uniform(0.012, 0.02), rng.uniform(0.006, 0.01));
    let shell = random_material("shell", *rng.pick(&[Finish::Metal, Finish::Plastic]), rng);
    let keys = random_plain("keys", Finish::Plastic, rng);
    let screen = random_material("screen", Finish::Plastic, rng);

    let mut b = ObjectBuilder::new("laptop");
    let base = ObjectBuilder::BASE;
    b.add(
        base,
        cuboid(
            Vec3::new(0.0, 0.0, base_h / 2.0),
            Vec3::new(w, d, base_h),
            &shell,
        ),
    );
    b.add(
        base,
        cuboid(
            Vec3::new(0.0, 0.02, base_h + 0.0005),
            Vec3::new(w * 0.85, d * 0.4, 0.001),
            &keys,
        ),
    );
    b.add(
        base,
        cuboid(
            Vec3::new(0.0, -d * 0.3, base_h + 0.0005),
            Vec3::new(w * 0.3, d * 0.2, 0.001),
            &keys,
        ),
    );
    // The lid rests closed on the base; the hinge runs along the back edge (+y), opening up to ~135°.
    // Gaps of 1 mm keep the closed lid, screen and keys from overlapping.
    let hinge = Vec3::new(0.0, d / 2.0, base_h + 0.001);
    let lid = b.joint(
        "lid",
        base,
        JointKind::Revolute,
        hinge,
        Vec3::NEG_X,
        0.0,
        rng.uniform(0.7, 0.8) * PI,
    );
    b.add(
        lid,
        cuboid(
            Vec3::new(0.0, 0.0, base_h + 0.002 + lid_h / 2.0),
            Vec3::new(w, d, lid_h),
            &shell,
        ),
    );
    b.add(
        lid,
        cuboid(
            Vec3::new(0.0, 0.0, base_h + 0.0015),
            Vec3::new(w * 0.9, d * 0.85, 0.001),
            &screen,
        ),
    );
    b.build()
}
