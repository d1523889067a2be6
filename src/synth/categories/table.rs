//! Table / desk: a top on legs or on one or two pedestals, with drawers under the top between them (an
//! apron), pedestals of stacked drawers or a door under a drawer, and legs where no pedestal stands. Drawers
//! are prismatic along −y, pedestal doors revolute about a vertical hinge on the pedestal's outer edge; all
//! hang on the static top-and-legs body.

use glam::Vec3;

use super::shapes_b::{Cell, Fill, FrontStyle, Pull, cabinet, slab, splits};
use crate::object::{ArticulatedObject, Material};
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cylinder};
use crate::synth::texture::{Finish, random_material, random_plain};

/// Most drawers in one pedestal.
const PEDESTAL_MAX: usize = 4;

/// How the drawers are spread: pedestal count, apron drawers and parts per pedestal, for `n` parts.
fn drawer_counts(n: usize, rng: &mut Rng) -> (usize, usize, Vec<usize>) {
    // Pedestal count p: the apron holds up to 3 drawers without pedestals, 2 beside one, 1 between two.
    let apron_cap = |p: usize| 3 - p;
    let feasible: Vec<usize> = (0..=2)
        .filter(|&p| p <= n && p * PEDESTAL_MAX + apron_cap(p) >= n)
        .collect();
    let p = *rng.pick(&feasible);
    let apron_lo = n.saturating_sub(p * PEDESTAL_MAX);
    let apron_hi = apron_cap(p).min(n - p);
    let apron = if p == 0 {
        n
    } else {
        rng.int_in(apron_lo, apron_hi)
    };
    let mut ped = vec![1usize; p];
    for _ in 0..(n - apron - p) {
        let open: Vec<usize> = (0..p).filter(|&i| ped[i] < PEDESTAL_MAX).collect();
        if open.is_empty() {
            break;
        }
        ped[*rng.pick(&open)] += 1;
    }
    (p, apron, ped)
}

/// The table's size and what its fronts share.
struct Desk {
    /// Width, depth and height of the top's underside.
    w: f32,
    d: f32,
    under: f32,
    /// Carcass panel thickness.
    t: f32,
    body: Material,
    style: FrontStyle,
    door_upper: f32,
}

/// A pedestal between `x0` and `x1` on a plinth holding `k` parts: a door under a drawer (one pedestal in
/// three), else a stack of drawers, the top one shallow. Its door hinges on the outer edge (`right`).
fn pedestal(
    b: &mut ObjectBuilder,
    desk: &Desk,
    index: usize,
    [x0, x1]: [f32; 2],
    (right, k): (bool, usize),
    rng: &mut Rng,
) {
    let (d, under, body) = (desk.d, desk.under, &desk.body);
    let plinth = 0.03;
    b.add(
        ObjectBuilder::BASE,
        slab(
            Vec3::new(x0 + 0.02, -d / 2.0 + 0.05, 0.0),
            Vec3::new(x1 - 0.02, d / 2.0 - 0.03, plinth),
            body,
        ),
    );
    let (lo, hi) = (
        Vec3::new(x0, -d / 2.0 + 0.01, plinth),
        Vec3::new(x1, d / 2.0 - 0.01, under),
    );
    let fills: Vec<(f32, Fill)> = if k <= 2 && rng.chance(0.4) {
        let mut f = vec![(3.0, Fill::Door { hinge_left: !right })];
        f.extend(vec![(1.0, Fill::Drawer); k - 1]);
        f
    } else {
        (0..k)
            .map(|i| (if i + 1 == k && k > 2 { 0.7 } else { 1.0 }, Fill::Drawer))
            .collect()
    };
    let weights: Vec<f32> = fills.iter().map(|f| f.0).collect();
    let z = splits(lo.z, hi.z - lo.z, &weights);
    let cells: Vec<Cell> = fills
        .iter()
        .enumerate()
        .map(|(i, &(_, fill))| Cell {
            rect: [x0, x1, z[i], z[i + 1]],
            fill,
        })
        .collect();
    cabinet(
        b,
        &format!("ped{index}_"),
        lo,
        hi,
        desk.t,
        &cells,
        body,
        &desk.style,
        desk.door_upper,
    );
}

/// Legs at the sides without a pedestal (`sides` lists where pedestals stand). Narrows the knee space
/// `[x0, x1]` to the legs.
fn legs(b: &mut ObjectBuilder, desk: &Desk, sides: &[bool], knee: &mut [f32; 2], rng: &mut Rng) {
    let (w, d, under) = (desk.w, desk.d, desk.under);
    let leg_mat = if rng.chance(0.5) {
        desk.body.clone()
    } else {
        random_plain("legs", *rng.pick(&[Finish::Metal, Finish::Wood]), rng)
    };
    let round = rng.chance(0.5);
    let leg = rng.uniform(0.025, 0.045);
    for right in [false, true] {
        if sides.contains(&right) {
            continue;
        }
        let x = if right {
            w / 2.0 - leg - 0.01
        } else {
            -w / 2.0 + leg + 0.01
        };
        for y in [-d / 2.0 + leg + 0.01, d / 2.0 - leg - 0.01] {
            let foot = Vec3::new(x, y, 0.0);
            b.add(
                ObjectBuilder::BASE,
                if round {
                    cylinder(foot, foot + Vec3::Z * under, leg * 0.5, &leg_mat)
                } else {
                    slab(
                        foot - Vec3::new(leg / 2.0, leg / 2.0, 0.0),
                        foot + Vec3::new(leg / 2.0, leg / 2.0, under),
                        &leg_mat,
                    )
                },
            );
        }
        if right {
            knee[1] = x - leg / 2.0 - 0.002;
        } else {
            knee[0] = x + leg / 2.0 + 0.002;
        }
    }
}

/// The apron: a shallow drawer housing with `apron` drawers under the top across the knee space, a plain
/// rail when empty. Returns the apron's bottom (z).
fn apron(b: &mut ObjectBuilder, desk: &Desk, apron: usize, knee: [f32; 2], rng: &mut Rng) -> f32 {
    let (d, under, t) = (desk.d, desk.under, desk.t);
    let apron_h = rng.uniform(0.1, 0.15);
    let (lo, hi) = (
        Vec3::new(knee[0], -d / 2.0 + 0.02, under - apron_h),
        Vec3::new(knee[1], d / 2.0 - 0.02, under),
    );
    if apron > 0 {
        let x = splits(lo.x, hi.x - lo.x, &vec![1.0; apron]);
        let cells: Vec<Cell> = (0..apron)
            .map(|i| Cell {
                rect: [x[i], x[i + 1], lo.z, hi.z],
                fill: Fill::Drawer,
            })
            .collect();
        cabinet(
            b,
            "apron_",
            lo,
            hi,
            t,
            &cells,
            &desk.body,
            &desk.style,
            desk.door_upper,
        );
    } else {
        b.add(
            ObjectBuilder::BASE,
            slab(
                Vec3::new(lo.x, lo.y, under - 0.06),
                Vec3::new(hi.x, lo.y + t, under),
                &desk.body,
            ),
        );
    }
    lo.z
}

/// Builds a table with exactly `parts` drawers and doors.
pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let (p, apron_n, ped) = drawer_counts(parts.max(1), rng);

    let ped_w = rng.uniform(0.36, 0.46);
    let w = match p {
        0 => rng.uniform(0.7, 1.1) + 0.2 * apron_n as f32,
        1 => rng.uniform(1.0, 1.4),
        _ => rng.uniform(1.25, 1.7),
    };
    let d = rng.uniform(0.55, 0.8);
    let height = rng.uniform(0.72, 0.78);
    let top_t = rng.uniform(0.025, 0.045);
    let under = height - top_t;

    let wood = random_material(
        "top",
        *rng.pick(&[Finish::Wood, Finish::Wood, Finish::Paint]),
        rng,
    );
    let body = if rng.chance(0.5) {
        wood.clone()
    } else {
        random_material(
            "body",
            *rng.pick(&[Finish::Paint, Finish::Wood, Finish::Metal]),
            rng,
        )
    };
    let style = FrontStyle {
        front: body.clone(),
        inner: random_plain("drawer_box", Finish::Wood, rng),
        handle: random_plain("pull", Finish::Metal, rng),
        drawer_pull: *rng.pick(&[Pull::Bar, Pull::Knob, Pull::Tab]),
        door_pull: Pull::Bar,
        thickness: rng.uniform(0.016, 0.02),
    };
    let desk = Desk {
        w,
        d,
        under,
        t: 0.018,
        body,
        style,
        door_upper: rng.uniform(1.5, 1.9),
    };

    let mut b = ObjectBuilder::new("table");
    let base = ObjectBuilder::BASE;
    // Top overhangs the frame a little at the front and sides.
    let o = rng.uniform(0.01, 0.04);
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0 - o, -d / 2.0 - o, under),
            Vec3::new(w / 2.0 + o, d / 2.0 + o / 2.0, height),
            &wood,
        ),
    );
    // Pedestals: left is side 0, right side 1 (a single pedestal picks its side at random).
    let sides: Vec<bool> = match p {
        0 => vec![],
        1 => vec![rng.chance(0.5)],
        _ => vec![false, true],
    };
    let mut knee = [-w / 2.0, w / 2.0];
    for (index, (&right, &k)) in sides.iter().zip(&ped).enumerate() {
        let (x0, x1) = if right {
            (w / 2.0 - ped_w, w / 2.0)
        } else {
            (-w / 2.0, -w / 2.0 + ped_w)
        };
        if right {
            knee[1] = x0;
        } else {
            knee[0] = x1;
        }
        pedestal(&mut b, &desk, index, [x0, x1], (right, k), rng);
    }
    legs(&mut b, &desk, &sides, &mut knee, rng);
    let apron_z = apron(&mut b, &desk, apron_n, knee, rng);
    // A modesty panel at the back of the knee space.
    if p > 0 && rng.chance(0.6) {
        b.add(
            base,
            slab(
                Vec3::new(knee[0], d / 2.0 - 0.04, 0.25),
                Vec3::new(knee[1], d / 2.0 - 0.04 + desk.t, apron_z),
                &desk.body,
            ),
        );
    }
    b.build()
}
