//! Refrigerator: a tall enamel or steel cabinet with a light liner and glass shelves, split into stacked
//! compartments: fridge and freezer doors (revolute about a vertical hinge at the outer front edge, French
//! pairs swinging apart) with bins on their inside, and pull-out freezer drawers (prismatic along −y) with a
//! basket. Layouts: single door, top or bottom freezer, side by side, French door with drawers, four doors.

use glam::Vec3;

use super::shapes_b::{GAP, Open, door_leaf, drawer_front, open_box, slab, splits};
use crate::object::{ArticulatedObject, Material};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cylinder};
use crate::synth::texture::{Finish, material, random_material};

/// One horizontal compartment, bottom to top.
#[derive(Debug, Clone, Copy)]
enum Row {
    /// One door (hinge side shared by the whole fridge).
    Door,
    /// Two doors side by side swinging apart.
    Pair,
    /// A pull-out drawer.
    Drawer,
}

impl Row {
    fn parts(self) -> usize {
        match self {
            Row::Pair => 2,
            _ => 1,
        }
    }
}

/// Compartments (bottom to top) with relative heights, for `n` movable parts.
fn layout(n: usize, rng: &mut Rng) -> Vec<(f32, Row)> {
    use Row::*;
    let options: &[&[(f32, Row)]] = match n {
        1 => &[&[(1.0, Door)]],
        2 => &[
            &[(2.4, Door), (1.0, Door)],
            &[(1.0, Drawer), (2.2, Door)],
            &[(1.0, Pair)],
        ],
        3 => &[
            &[(1.0, Drawer), (2.0, Pair)],
            &[(0.8, Drawer), (0.8, Drawer), (2.2, Door)],
            &[(1.0, Drawer), (2.4, Door), (0.9, Door)],
        ],
        _ => &[
            &[(0.8, Drawer), (0.8, Drawer), (2.4, Pair)],
            &[(1.0, Pair), (1.6, Pair)],
            &[(1.0, Drawer), (0.7, Door), (2.0, Pair)],
        ],
    };
    let rows = rng.pick(options).to_vec();
    debug_assert_eq!(rows.iter().map(|r| r.1.parts()).sum::<usize>(), n);
    rows
}

struct Style {
    shell: Material,
    liner: Material,
    glass: Material,
    handle: Material,
    door_t: f32,
}

/// A fridge door covering `rect` in front of `y_face`, hinged on the left or right outer edge, with a
/// bar handle near its free edge and bins on its inner side (inside `opening` when closed).
#[allow(clippy::too_many_arguments)]
fn fridge_door(
    b: &mut ObjectBuilder,
    name: &str,
    rect: [f32; 4],
    opening: [f32; 4],
    y_face: f32,
    hinge_left: bool,
    upper: f32,
    s: &Style,
) {
    let [x0, x1, z0, z1] = rect;
    let t = s.door_t;
    let yf = y_face - GAP;
    let link = door_leaf(b, name, rect, y_face, hinge_left, upper, t, &s.shell);
    // Inner panel and bins reach into the opening, clear of its walls.
    let [ox0, ox1, oz0, oz1] = opening;
    let (ix0, ix1) = (ox0 + 0.012, ox1 - 0.012);
    b.add(
        link,
        slab(
            Vec3::new(ix0, yf, oz0 + 0.012),
            Vec3::new(ix1, yf + 0.015, oz1 - 0.012),
            &s.liner,
        ),
    );
    let bins = ((oz1 - oz0) / 0.35).floor().clamp(1.0, 4.0) as usize;
    let z = splits(oz0, oz1 - oz0, &vec![1.0; bins]);
    for &zk in &z[..bins] {
        let zb = zk + 0.03;
        open_box(
            b,
            link,
            Vec3::new(ix0 + 0.005, yf + 0.015, zb),
            Vec3::new(ix1 - 0.005, yf + 0.015 + 0.08, zb + 0.08),
            0.006,
            Open::Top,
            &s.liner,
        );
    }
    // Long vertical bar on standoffs near the free edge.
    let hx = if hinge_left { x1 - 0.05 } else { x0 + 0.05 };
    let len = ((z1 - z0) * 0.6).clamp(0.15, 0.7);
    let zc = if z1 - z0 > 0.9 {
        z0 + (z1 - z0) * 0.55
    } else {
        z0 + (z1 - z0) * 0.5
    };
    let yb = yf - t - 0.035;
    bar_handle(
        b,
        link,
        [
            Vec3::new(hx, yb, zc - len / 2.0),
            Vec3::new(hx, yb, zc + len / 2.0),
        ],
        [-0.45f32, 0.45].map(|e| Vec3::new(hx, yb, zc + len * e)),
        yf - t,
        &s.handle,
    );
}

/// A freezer drawer: front covering `rect`, wire-like basket inside `opening`, horizontal bar on top.
#[allow(clippy::too_many_arguments)]
fn freezer_drawer(
    b: &mut ObjectBuilder,
    name: &str,
    rect: [f32; 4],
    opening: [f32; 4],
    y_face: f32,
    depth: f32,
    s: &Style,
) {
    let [x0, x1, z0, z1] = rect;
    let t = s.door_t;
    let yf = y_face - GAP;
    let link = drawer_front(b, name, rect, y_face, depth * 0.75, t, &s.shell);
    let [ox0, ox1, oz0, oz1] = opening;
    open_box(
        b,
        link,
        Vec3::new(ox0 + 0.01, yf, oz0 + 0.01),
        Vec3::new(ox1 - 0.01, y_face + depth, oz0 + (oz1 - oz0) * 0.75),
        0.008,
        Open::Top,
        &s.liner,
    );
    let zb = z1 - (z1 - z0) * 0.15;
    let yb = yf - t - 0.035;
    let half = (x1 - x0) * 0.3;
    let xc = (x0 + x1) * 0.5;
    bar_handle(
        b,
        link,
        [Vec3::new(xc - half, yb, zb), Vec3::new(xc + half, yb, zb)],
        [-0.9f32, 0.9].map(|e| Vec3::new(xc + half * e, yb, zb)),
        yf - t,
        &s.handle,
    );
}

/// A round bar from `ends[0]` to `ends[1]` held by two square standoffs, centred on `feet` (on the bar's
/// axis), that reach back to the door face at `y = y_back`.
fn bar_handle(
    b: &mut ObjectBuilder,
    link: usize,
    ends: [Vec3; 2],
    feet: [Vec3; 2],
    y_back: f32,
    material: &Material,
) {
    b.add(link, cylinder(ends[0], ends[1], 0.011, material));
    for p in feet {
        b.add(
            link,
            slab(
                Vec3::new(p.x - 0.008, p.y, p.z - 0.008),
                Vec3::new(p.x + 0.008, y_back, p.z + 0.008),
                material,
            ),
        );
    }
}

/// Shell, liner, glass and handle materials and the door thickness.
fn random_style(rng: &mut Rng) -> Style {
    let shell = match rng.below(3) {
        0 => random_material("shell", Finish::Metal, rng),
        1 => random_material("shell", Finish::Paint, rng),
        // White or cream enamel: nearly textureless.
        _ => {
            let tone = rng.uniform(0.8, 0.92);
            let seed = rng.next_u64();
            material(
                "shell",
                Finish::Plastic,
                [tone, tone, tone * rng.uniform(0.9, 1.0)],
                seed,
            )
        }
    };
    Style {
        shell,
        liner: material("liner", Finish::Plastic, [0.9, 0.92, 0.93], rng.next_u64()),
        glass: material("shelf", Finish::Plastic, [0.6, 0.7, 0.72], rng.next_u64()),
        handle: random_material("handle", *rng.pick(&[Finish::Metal, Finish::Plastic]), rng),
        door_t: rng.uniform(0.045, 0.07),
    }
}

/// The static cabinet: its outer corners and wall thickness.
struct Cabinet {
    lo: Vec3,
    hi: Vec3,
    wall: f32,
}

/// Toe kick under the cabinet, then the shell with its liner, `w` × `d` up to height `h`.
fn cabinet(b: &mut ObjectBuilder, w: f32, d: f32, h: f32, s: &Style, rng: &mut Rng) -> Cabinet {
    let wall = 0.035;
    let base = ObjectBuilder::BASE;
    let foot = rng.uniform(0.02, 0.05);
    let dark = crate::synth::texture::plain("kick", [0.08, 0.08, 0.08]);
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0 + 0.02, -d / 2.0 + 0.04, 0.0),
            Vec3::new(w / 2.0 - 0.02, d / 2.0 - 0.02, foot),
            &dark,
        ),
    );
    let lo = Vec3::new(-w / 2.0, -d / 2.0, foot);
    let hi = Vec3::new(w / 2.0, d / 2.0, h);
    open_box(b, base, lo, hi, wall, Open::Front, &s.shell);
    // Liner: a thin white box just inside the walls.
    open_box(
        b,
        base,
        lo + Vec3::new(wall, 0.0, wall),
        hi - Vec3::new(wall, wall, wall),
        0.004,
        Open::Front,
        &s.liner,
    );
    Cabinet { lo, hi, wall }
}

/// The inside of compartment `i` of `count` spanning `[z0, z1]`: the divider below it and, behind doors,
/// glass shelves. Returns its opening `[x0, x1, z0, z1]` inside the walls.
fn compartment_inside(
    b: &mut ObjectBuilder,
    c: &Cabinet,
    (i, count): (usize, usize),
    [z0, z1]: [f32; 2],
    row: Row,
    s: &Style,
) -> [f32; 4] {
    let base = ObjectBuilder::BASE;
    let (lo, hi, wall) = (c.lo, c.hi, c.wall);
    let oz0 = if i == 0 { z0 + wall } else { z0 + wall * 0.5 };
    let oz1 = if i + 1 == count {
        z1 - wall
    } else {
        z1 - wall * 0.5
    };
    if i > 0 {
        // Insulated divider between compartments.
        b.add(
            base,
            slab(
                Vec3::new(lo.x + wall, lo.y, z0 - wall * 0.5),
                Vec3::new(hi.x - wall, hi.y - wall, z0 + wall * 0.5),
                &s.liner,
            ),
        );
    }
    let (ox0, ox1) = (lo.x + wall, hi.x - wall);
    // Glass shelves, set back behind the door bins.
    if !matches!(row, Row::Drawer) {
        let shelves = ((oz1 - oz0) / 0.3).floor() as usize;
        for k in 1..shelves {
            let zs = oz0 + (oz1 - oz0) * k as f32 / shelves as f32;
            b.add(
                base,
                slab(
                    Vec3::new(ox0, lo.y + 0.14, zs - 0.004),
                    Vec3::new(ox1, hi.y - wall, zs + 0.004),
                    &s.glass,
                ),
            );
        }
    }
    [ox0, ox1, oz0, oz1]
}

/// How the fronts hang and how many of each are already named.
struct Fronts {
    hinge_left: bool,
    upper: f32,
    /// Depth of a freezer drawer's basket.
    depth: f32,
    doors: usize,
    drawers: usize,
}

/// The door, door pair or drawer closing a compartment spanning `[z0, z1]` with inside `opening`.
fn compartment_front(
    b: &mut ObjectBuilder,
    c: &Cabinet,
    [z0, z1]: [f32; 2],
    opening: [f32; 4],
    row: Row,
    f: &mut Fronts,
    s: &Style,
) {
    let (lo, hi) = (c.lo, c.hi);
    let [ox0, ox1, oz0, oz1] = opening;
    match row {
        Row::Door => {
            fridge_door(
                b,
                &format!("door{}", f.doors),
                [lo.x, hi.x, z0, z1],
                opening,
                lo.y,
                f.hinge_left,
                f.upper,
                s,
            );
            f.doors += 1;
        }
        Row::Pair => {
            // A thin mullion behind the meeting edges.
            b.add(
                ObjectBuilder::BASE,
                slab(
                    Vec3::new(-0.01, lo.y, oz0),
                    Vec3::new(0.01, lo.y + 0.03, oz1),
                    &s.liner,
                ),
            );
            for left in [true, false] {
                let (rx0, rx1, px0, px1) = if left {
                    (lo.x, 0.0, ox0, -0.01)
                } else {
                    (0.0, hi.x, 0.01, ox1)
                };
                fridge_door(
                    b,
                    &format!("door{}", f.doors),
                    [rx0, rx1, z0, z1],
                    [px0, px1, oz0, oz1],
                    lo.y,
                    left,
                    f.upper,
                    s,
                );
                f.doors += 1;
            }
        }
        Row::Drawer => {
            freezer_drawer(
                b,
                &format!("drawer{}", f.drawers),
                [lo.x, hi.x, z0, z1],
                opening,
                lo.y,
                f.depth,
                s,
            );
            f.drawers += 1;
        }
    }
}

/// Builds a refrigerator with exactly `parts` doors and drawers.
pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let rows = layout(parts, rng);
    let has_pair = rows.iter().any(|r| matches!(r.1, Row::Pair));
    let w = if has_pair {
        rng.uniform(0.75, 0.92)
    } else {
        rng.uniform(0.55, 0.72)
    };
    let d = rng.uniform(0.6, 0.72);
    // A one-door fridge is sometimes an under-counter one.
    let h = if parts == 1 && rng.chance(0.4) {
        rng.uniform(0.8, 0.9)
    } else {
        rng.uniform(1.55, 1.95)
    };
    let s = random_style(rng);
    let hinge_left = rng.chance(0.5);
    let upper = rng.uniform(1.55, 1.9);

    let mut b = ObjectBuilder::new("refrigerator");
    let c = cabinet(&mut b, w, d, h, &s, rng);
    let mut fronts = Fronts {
        hinge_left,
        upper,
        depth: d - c.wall - 0.03,
        doors: 0,
        drawers: 0,
    };
    let weights: Vec<f32> = rows.iter().map(|r| r.0).collect();
    let z = splits(c.lo.z, c.hi.z - c.lo.z, &weights);
    for (i, &(_, row)) in rows.iter().enumerate() {
        let span = [z[i], z[i + 1]];
        let opening = compartment_inside(&mut b, &c, (i, rows.len()), span, row, &s);
        compartment_front(&mut b, &c, span, opening, row, &mut fronts, &s);
    }
    b.build()
}
