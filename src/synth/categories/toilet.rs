//! Toilet: an enamel pedestal and oval bowl with a cistern behind, a seat ring and a lid on the same
//! horizontal hinge at the back of the bowl (revolute, lifting the front), and a flush lever on the cistern
//! (revolute about an axis into the cistern). One part: the lid (the seat is fixed); two: seat and lid, or
//! lid and lever; three: all of them. The lid's range is at least twice the seat's, so at every sampled
//! state it stays above the seat.

use glam::{Affine3A, Vec3};

use super::shapes_b::{GAP, slab};
use crate::object::{ArticulatedObject, JointKind, Material, RenderMesh};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cylinder, frustum, torus};
use crate::synth::texture::{Finish, material, plain, random_material};

/// `mesh` stretched by `scale` about the vertical line through `centre` (oval shapes from round ones).
fn stretched(mesh: RenderMesh, centre: Vec3, scale: Vec3) -> RenderMesh {
    let to = Affine3A::from_translation(centre)
        * Affine3A::from_scale(scale)
        * Affine3A::from_translation(-centre);
    mesh.transformed(&to)
}

/// The toilet's materials.
struct Materials {
    enamel: Material,
    seat: Material,
    water: Material,
    chrome: Material,
}

fn random_materials(rng: &mut Rng) -> Materials {
    let tone = rng.uniform(0.85, 0.95);
    let enamel = material(
        "enamel",
        Finish::Plastic,
        [tone, tone, tone * rng.uniform(0.95, 1.0)],
        rng.next_u64(),
    );
    let seat = match rng.below(3) {
        0 => random_material("seat", Finish::Wood, rng),
        1 => random_material("seat", Finish::Plastic, rng),
        _ => enamel.clone(),
    };
    let water = plain("water", [0.35, 0.45, 0.5]);
    let chrome = random_material("chrome", Finish::Metal, rng);
    Materials {
        enamel,
        seat,
        water,
        chrome,
    }
}

/// The oval bowl: centre `c` on the floor, radius `r` across, stretched by `oval` front to back, rim at
/// `top`.
struct Bowl {
    c: Vec3,
    r: f32,
    oval: f32,
    top: f32,
}

impl Bowl {
    /// Round shapes made oval about the bowl's axis.
    fn oval(&self, mesh: RenderMesh) -> RenderMesh {
        stretched(mesh, self.c, Vec3::new(1.0, self.oval, 1.0))
    }

    /// Back edge of the bowl (y).
    fn rear(&self) -> f32 {
        self.c.y + self.r * self.oval
    }
}

/// Pedestal narrowing upwards from a wider foot, then the bowl flaring to the rim, and the water.
fn pedestal_and_bowl(b: &mut ObjectBuilder, bowl: &Bowl, m: &Materials) {
    let base = ObjectBuilder::BASE;
    let (c, r, top) = (bowl.c, bowl.r, bowl.top);
    b.add(
        base,
        bowl.oval(frustum(
            c,
            c + Vec3::Z * (top * 0.5),
            r * 0.75,
            r * 0.55,
            &m.enamel,
        )),
    );
    b.add(
        base,
        bowl.oval(frustum(
            c + Vec3::Z * (top * 0.45),
            c + Vec3::Z * top,
            r * 0.6,
            r,
            &m.enamel,
        )),
    );
    // Water and the inside of the bowl, just above the rim surface.
    b.add(
        base,
        bowl.oval(cylinder(
            c + Vec3::Z * top,
            c + Vec3::Z * (top + 0.001),
            r * 0.72,
            &m.water,
        )),
    );
}

/// The cistern's width, front face (y) and bottom and height (z).
struct Cistern {
    tw: f32,
    ty0: f32,
    tz0: f32,
    th: f32,
}

/// Cistern behind the bowl, on a block joining it to the pedestal, with an overhanging lid.
fn cistern(b: &mut ObjectBuilder, bowl: &Bowl, m: &Materials, rng: &mut Rng) -> Cistern {
    let base = ObjectBuilder::BASE;
    let (r, yb, bowl_top) = (bowl.r, bowl.c.y, bowl.top);
    let (tw, td) = (rng.uniform(0.36, 0.48), rng.uniform(0.15, 0.2));
    let th = rng.uniform(0.3, 0.42);
    // Far enough behind the hinge that the raised lid's thickness clears the cistern.
    let ty0 = bowl.rear() + 0.08;
    let tz0 = bowl_top + 0.02;
    b.add(
        base,
        slab(
            Vec3::new(-r * 0.55, yb, 0.0),
            Vec3::new(r * 0.55, ty0 + td * 0.8, bowl_top),
            &m.enamel,
        ),
    );
    b.add(
        base,
        slab(
            Vec3::new(-tw / 2.0, ty0, tz0),
            Vec3::new(tw / 2.0, ty0 + td, tz0 + th),
            &m.enamel,
        ),
    );
    b.add(
        base,
        slab(
            Vec3::new(-tw / 2.0 - 0.01, ty0 - 0.01, tz0 + th),
            Vec3::new(tw / 2.0 + 0.01, ty0 + td + 0.01, tz0 + th + 0.025),
            &m.enamel,
        ),
    );
    Cistern { tw, ty0, tz0, th }
}

/// Seat ring and lid: ovals over the bowl, hinged at the back; the seat moves only when `moving_seat`.
fn seat_and_lid(
    b: &mut ObjectBuilder,
    bowl: &Bowl,
    moving_seat: bool,
    m: &Materials,
    rng: &mut Rng,
) {
    let base = ObjectBuilder::BASE;
    let (c, r, oval, bowl_top, rear) = (bowl.c, bowl.r, bowl.oval, bowl.top, bowl.rear());
    let seat_t = rng.uniform(0.018, 0.025);
    let major = r * 0.78;
    let minor = r * 0.2;
    let sc = c + Vec3::Z * (bowl_top + GAP + seat_t / 2.0);
    let seat_mesh = stretched(
        torus(sc, Vec3::Z, major, minor, &m.seat),
        sc,
        Vec3::new(1.0, oval, seat_t / (2.0 * minor)),
    );
    let hinge = Vec3::new(0.0, rear + 0.02, bowl_top + GAP);
    let lid_upper = rng.uniform(1.7, 1.9);
    if moving_seat {
        let seat = b.joint(
            "seat",
            base,
            JointKind::Revolute,
            hinge,
            Vec3::NEG_X,
            0.0,
            lid_upper * 0.5 - 0.03,
        );
        b.add(seat, seat_mesh);
    } else {
        b.add(base, seat_mesh);
    }
    // Hinge posts at the back of the bowl.
    for s in [-1.0f32, 1.0] {
        b.add(
            base,
            cylinder(
                Vec3::new(s * r * 0.45, rear + 0.02, bowl_top),
                Vec3::new(s * r * 0.45, rear + 0.02, bowl_top + 0.02),
                0.012,
                &m.chrome,
            ),
        );
    }
    let lid_t = rng.uniform(0.015, 0.022);
    let lid = b.joint(
        "lid",
        base,
        JointKind::Revolute,
        hinge,
        Vec3::NEG_X,
        0.0,
        lid_upper,
    );
    let lz = bowl_top + GAP + seat_t + GAP;
    b.add(
        lid,
        bowl.oval(cylinder(
            c + Vec3::Z * lz,
            c + Vec3::Z * (lz + lid_t),
            major + minor,
            &m.seat,
        )),
    );
}

/// A chrome lever on the cistern front near its left end; positive angles push its tip down.
fn flush_lever(b: &mut ObjectBuilder, t: &Cistern, chrome: &Material, rng: &mut Rng) {
    let side = if rng.chance(0.7) { -1.0 } else { 1.0 };
    let pivot = Vec3::new(
        side * (t.tw / 2.0 - 0.05),
        t.ty0 - GAP,
        t.tz0 + t.th - rng.uniform(0.05, 0.08),
    );
    let link = b.joint(
        "flush_lever",
        ObjectBuilder::BASE,
        JointKind::Revolute,
        pivot,
        Vec3::NEG_Y * side,
        0.0,
        rng.uniform(0.5, 0.7),
    );
    b.add(link, cylinder(pivot, pivot - Vec3::Y * 0.012, 0.02, chrome));
    let arm = pivot - Vec3::Y * 0.018;
    b.add(
        link,
        cylinder(
            arm,
            arm - Vec3::X * (side * rng.uniform(0.08, 0.11)),
            0.008,
            chrome,
        ),
    );
}

/// Builds a toilet with exactly `parts` moving parts.
pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let (moving_seat, lever) = match parts {
        1 => (false, false),
        2 => {
            let seat = rng.chance(0.6);
            (seat, !seat)
        }
        _ => (true, true),
    };
    let m = random_materials(rng);
    let r = rng.uniform(0.16, 0.19); // bowl radius across (x)
    let oval = rng.uniform(1.2, 1.4); // front-back stretch
    let top = rng.uniform(0.38, 0.42);
    let yb = -rng.uniform(0.02, 0.06); // bowl centre
    let bowl = Bowl {
        c: Vec3::new(0.0, yb, 0.0),
        r,
        oval,
        top,
    };
    let mut b = ObjectBuilder::new("toilet");
    pedestal_and_bowl(&mut b, &bowl, &m);
    let tank = cistern(&mut b, &bowl, &m, rng);
    seat_and_lid(&mut b, &bowl, moving_seat, &m, rng);
    if lever {
        flush_lever(&mut b, &tank, &m.chrome, rng);
    }
    b.build()
}
