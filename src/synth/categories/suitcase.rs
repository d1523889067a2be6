//! Suitcase, in one of two poses. Lying on its back: a hard-shell base and a clamshell lid on a revolute
//! hinge along the back edge, a telescopic handle sliding out of the top end (prismatic along −x) and a side
//! carry handle that flips out (revolute). Standing on four spinner wheels: a telescopic handle sliding up
//! (prismatic along +z), a top carry handle flipping up and a side carry handle flipping out (revolute).
//! Every moving part hangs on the static shell.

use glam::Vec3;

use super::shapes_b::{GAP, Open, open_box, slab};
use crate::object::{ArticulatedObject, JointKind, Material};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cylinder};
use crate::synth::texture::{Finish, plain, random_material};

/// A carry handle lying flat against a face, hinged along `pivot` + `axis`: two end blocks and a grip,
/// offset from the pivot by `reach` (the direction the grip lies in at rest) and `out` (off the face).
#[allow(clippy::too_many_arguments)]
fn carry_handle(
    b: &mut ObjectBuilder,
    name: &str,
    pivot: Vec3,
    axis: Vec3,
    along: Vec3,
    reach: Vec3,
    out: Vec3,
    length: f32,
    upper: f32,
    material: &Material,
) {
    let link = b.joint(
        name,
        ObjectBuilder::BASE,
        JointKind::Revolute,
        pivot,
        axis,
        0.0,
        upper,
    );
    let half = along * (length * 0.5);
    let grip = pivot + reach + out * 0.012;
    b.add(link, cylinder(grip - half, grip + half, 0.011, material));
    for s in [-1.0f32, 1.0] {
        // Blocks from the pivot to the grip ends, kept 1 mm off the face.
        let a = pivot + half * s + out * 0.009;
        let c = grip + half * s;
        let lo = a.min(c) - Vec3::splat(0.008);
        let hi = a.max(c) + Vec3::splat(0.008);
        b.add(link, slab(lo, hi, material));
    }
}

/// A telescopic handle: a grip on two tubes that slide along `dir` by up to `travel`. `grip` is the grip
/// centre at rest, the tubes run back from it by `tube` along −`dir`, `spread` apart along `across`.
#[allow(clippy::too_many_arguments)]
fn telescopic(
    b: &mut ObjectBuilder,
    grip: Vec3,
    dir: Vec3,
    across: Vec3,
    spread: f32,
    tube: f32,
    travel: f32,
    material: &Material,
    metal: &Material,
) {
    let link = b.joint(
        "telescopic_handle",
        ObjectBuilder::BASE,
        JointKind::Prismatic,
        grip,
        dir,
        0.0,
        travel,
    );
    let half = across * (spread * 0.5 + 0.015);
    b.add(link, cylinder(grip - half, grip + half, 0.014, material));
    for s in [-0.5f32, 0.5] {
        let p = grip + across * (spread * s);
        b.add(link, cylinder(p, p - dir * tube, 0.008, metal));
    }
}

/// The suitcase's materials.
struct Materials {
    shell: Material,
    trim: Material,
    metal: Material,
    lining: Material,
}

/// Shell length, width and thickness.
#[derive(Clone, Copy)]
struct Size {
    len: f32,
    wid: f32,
    thick: f32,
}

/// Shell wall thickness.
const WALL: f32 = 0.008;

/// Lying on its back: base and clamshell lid, then the telescopic and side handles as parts allow.
fn lying(b: &mut ObjectBuilder, parts: usize, size: Size, m: &Materials, rng: &mut Rng) {
    let Size { len, wid, thick } = size;
    let t = WALL;
    let base = ObjectBuilder::BASE;
    // Lying on its back: length along x, width along y, thickness along z.
    let foot = 0.012;
    for sx in [-1.0f32, 1.0] {
        for sy in [-1.0f32, 1.0] {
            let p = Vec3::new(sx * (len / 2.0 - 0.05), sy * (wid / 2.0 - 0.05), 0.0);
            b.add(base, cylinder(p, p + Vec3::Z * foot, 0.015, &m.trim));
        }
    }
    let split = foot + thick * rng.uniform(0.5, 0.6);
    let lo = Vec3::new(-len / 2.0, -wid / 2.0, foot);
    open_box(
        b,
        base,
        lo,
        Vec3::new(len / 2.0, wid / 2.0, split),
        t,
        Open::Top,
        &m.shell,
    );
    b.add(
        base,
        slab(
            Vec3::new(-len / 2.0 + t, -wid / 2.0 + t, foot + t),
            Vec3::new(len / 2.0 - t, wid / 2.0 - t, foot + t + 0.003),
            &m.lining,
        ),
    );
    // Clamshell lid hinged along the back top edge; positive angles lift its front.
    let lid = b.joint(
        "lid",
        base,
        JointKind::Revolute,
        Vec3::new(0.0, wid / 2.0, split),
        Vec3::NEG_X,
        0.0,
        rng.uniform(1.7, 2.0),
    );
    let top = foot + thick;
    open_box(
        b,
        lid,
        Vec3::new(-len / 2.0, -wid / 2.0, split + GAP),
        Vec3::new(len / 2.0, wid / 2.0, top),
        t,
        Open::Bottom,
        &m.shell,
    );
    b.add(
        lid,
        slab(
            Vec3::new(-len / 2.0 + t, -wid / 2.0 + t, top - t - 0.003),
            Vec3::new(len / 2.0 - t, wid / 2.0 - t, top - t),
            &m.lining,
        ),
    );
    // Ribs across the lid give the shell its moulded look.
    let ribs = rng.int_in(2, 5);
    for k in 0..ribs {
        let x = -len / 2.0 + len * (k as f32 + 1.0) / (ribs as f32 + 1.0);
        b.add(
            lid,
            slab(
                Vec3::new(x - 0.012, -wid / 2.0 + 0.04, top),
                Vec3::new(x + 0.012, wid / 2.0 - 0.04, top + 0.006),
                &m.shell,
            ),
        );
    }
    if parts >= 2 {
        // Out of the −x end, low in the base, sliding out along −x.
        let travel = rng.uniform(0.3, 0.45);
        telescopic(
            b,
            Vec3::new(-len / 2.0 - 0.018, 0.0, foot + 0.035),
            Vec3::NEG_X,
            Vec3::Y,
            wid * 0.5,
            travel + 0.05,
            travel,
            &m.trim,
            &m.metal,
        );
    }
    if parts >= 3 {
        // On the front side of the base, flipping out about its lower edge.
        let z = foot + (split - foot) * 0.3;
        carry_handle(
            b,
            "side_handle",
            Vec3::new(0.0, -wid / 2.0 - GAP, z),
            Vec3::X,
            Vec3::X,
            Vec3::Z * ((split - z) * 0.75),
            Vec3::NEG_Y,
            len * 0.25,
            rng.uniform(1.3, 1.6),
            &m.trim,
        );
    }
}

/// Standing on spinner wheels: the telescopic handle, then the top and side carry handles as parts allow.
fn standing(b: &mut ObjectBuilder, parts: usize, size: Size, m: &Materials, rng: &mut Rng) {
    let Size { len, wid, thick } = size;
    let base = ObjectBuilder::BASE;
    // Standing on spinner wheels: width along x, depth along y, height along z.
    let (w, d, h) = (wid, thick, len);
    let wheel = rng.uniform(0.035, 0.05);
    for sx in [-1.0f32, 1.0] {
        for sy in [-1.0f32, 1.0] {
            let p = Vec3::new(sx * (w / 2.0 - 0.04), sy * (d / 2.0 - 0.04), 0.0);
            b.add(
                base,
                cylinder(
                    p + Vec3::new(-0.012, 0.0, wheel / 2.0),
                    p + Vec3::new(0.012, 0.0, wheel / 2.0),
                    wheel / 2.0,
                    &m.trim,
                ),
            );
            b.add(
                base,
                slab(
                    p + Vec3::new(-0.015, -0.015, wheel * 0.6),
                    p + Vec3::new(0.015, 0.015, wheel + 0.012),
                    &m.trim,
                ),
            );
        }
    }
    let z0 = wheel + 0.012;
    let seam = -d / 2.0 + d * rng.uniform(0.4, 0.5);
    // Front and back halves of the shell with a dark zip band between them.
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0, -d / 2.0, z0),
            Vec3::new(w / 2.0, seam - 0.006, z0 + h),
            &m.shell,
        ),
    );
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0 + 0.004, seam - 0.006, z0 + 0.004),
            Vec3::new(w / 2.0 - 0.004, seam + 0.006, z0 + h - 0.004),
            &m.trim,
        ),
    );
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0, seam + 0.006, z0),
            Vec3::new(w / 2.0, d / 2.0, z0 + h),
            &m.shell,
        ),
    );
    let ribs = rng.int_in(2, 4);
    for k in 0..ribs {
        let x = -w / 2.0 + w * (k as f32 + 1.0) / (ribs as f32 + 1.0);
        b.add(
            base,
            slab(
                Vec3::new(x - 0.01, -d / 2.0 - 0.005, z0 + 0.05),
                Vec3::new(x + 0.01, -d / 2.0, z0 + h - 0.05),
                &m.shell,
            ),
        );
    }
    let top = z0 + h;
    // Telescopic handle at the back of the top, its tubes hidden in the shell.
    let travel = rng.uniform(0.3, 0.5);
    telescopic(
        b,
        Vec3::new(0.0, d / 2.0 - 0.03, top + 0.016),
        Vec3::Z,
        Vec3::X,
        w * 0.55,
        travel + 0.05,
        travel,
        &m.trim,
        &m.metal,
    );
    if parts >= 2 {
        // Top carry handle lying flat towards the front; it flips up about an axis along x.
        carry_handle(
            b,
            "top_handle",
            Vec3::new(0.0, -0.005, top + GAP),
            Vec3::NEG_X,
            Vec3::X,
            Vec3::NEG_Y * (d * 0.3),
            Vec3::Z,
            w * 0.3,
            rng.uniform(1.3, 1.6),
            &m.trim,
        );
    }
    if parts >= 3 {
        // Side carry handle on the +x face, flipping out about its lower edge.
        let z = z0 + h * 0.45;
        carry_handle(
            b,
            "side_handle",
            Vec3::new(w / 2.0 + GAP, 0.0, z),
            Vec3::Y,
            Vec3::Y,
            Vec3::Z * 0.06,
            Vec3::X,
            d * 0.45,
            rng.uniform(1.3, 1.6),
            &m.trim,
        );
    }
}

/// Builds a suitcase with exactly `parts` moving parts.
pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let shell = random_material(
        "shell",
        *rng.pick(&[
            Finish::Plastic,
            Finish::Plastic,
            Finish::Metal,
            Finish::Paint,
        ]),
        rng,
    );
    let trim = plain("trim", [0.04, 0.04, 0.045]);
    let metal = random_material("tubes", Finish::Metal, rng);
    let lining = random_material("lining", Finish::Paint, rng);
    let m = Materials {
        shell,
        trim,
        metal,
        lining,
    };
    let len = rng.uniform(0.5, 0.75);
    let wid = len * rng.uniform(0.6, 0.72);
    let thick = rng.uniform(0.2, 0.3);
    let size = Size { len, wid, thick };
    let mut b = ObjectBuilder::new("suitcase");
    if rng.chance(0.5) {
        lying(&mut b, parts, size, &m, rng);
    } else {
        standing(&mut b, parts, size, &m, rng);
    }
    b.build()
}
