//! Storage furniture: a carcass (sides, top, bottom, back, dividers) on a plinth, legs or the floor, with a
//! grid of drawers (prismatic, sliding out along −y), doors (revolute about a vertical hinge at their left or
//! right edge, swinging out towards −y) and open niches. Archetypes: chests of drawers and dressers,
//! cupboards and wardrobes, sideboards of mixed columns, and tall hutches of door, drawer and niche rows.
//! Every drawer and door hangs on the carcass.

use glam::Vec3;

use super::shapes_b::{Cell, Fill, FrontStyle, Pull, cabinet, slab, splits};
use crate::object::ArticulatedObject;
use crate::rng::Rng;
use crate::synth::builder::{ObjectBuilder, cylinder, frustum};
use crate::synth::texture::{Finish, random_material, random_plain};

/// A band of the front: a row (split left to right) or a column (split bottom to top).
#[derive(Debug, Clone)]
struct Band {
    /// Relative size across the bands.
    weight: f32,
    /// Fills along the band, with relative sizes.
    fills: Vec<(f32, Fill)>,
}

/// Lays `bands` over the front `[x0, x1] × [z0, z1]`: rows bottom to top when `by_rows`, else columns left
/// to right.
fn lay_out(bands: &[Band], by_rows: bool, x0: f32, x1: f32, z0: f32, z1: f32) -> Vec<Cell> {
    let weights: Vec<f32> = bands.iter().map(|b| b.weight).collect();
    let outer = if by_rows {
        splits(z0, z1 - z0, &weights)
    } else {
        splits(x0, x1 - x0, &weights)
    };
    let mut cells = Vec::new();
    for (i, band) in bands.iter().enumerate() {
        let w: Vec<f32> = band.fills.iter().map(|f| f.0).collect();
        let inner = if by_rows {
            splits(x0, x1 - x0, &w)
        } else {
            splits(z0, z1 - z0, &w)
        };
        for (j, &(_, fill)) in band.fills.iter().enumerate() {
            let rect = if by_rows {
                [inner[j], inner[j + 1], outer[i], outer[i + 1]]
            } else {
                [outer[i], outer[i + 1], inner[j], inner[j + 1]]
            };
            cells.push(Cell { rect, fill });
        }
    }
    cells
}

/// `k` doors side by side, the outer ones hinged on the outside so neighbours swing apart.
fn door_row(k: usize, rng: &mut Rng) -> Vec<(f32, Fill)> {
    let middle = rng.chance(0.5);
    (0..k)
        .map(|i| {
            let hinge_left = if 2 * i + 1 == k {
                middle
            } else {
                2 * i + 1 < k
            };
            (1.0, Fill::Door { hinge_left })
        })
        .collect()
}

fn drawers(k: usize) -> Vec<(f32, Fill)> {
    vec![(1.0, Fill::Drawer); k]
}

/// Splits `n` drawers into rows of at most `m`, fuller rows on top (small top drawers, deep bottom ones).
fn drawer_rows(n: usize, m: usize, rng: &mut Rng) -> Vec<usize> {
    let mut rows = Vec::new();
    let mut rem = n;
    while rem > 0 {
        let c = if rem <= m {
            rem
        } else if rng.chance(0.7) {
            m
        } else {
            rng.int_in(1, m)
        };
        rows.push(c);
        rem -= c;
    }
    rows.sort_unstable();
    rows
}

/// Front layout, carcass width and height for `n` movable parts: `(bands, by_rows, width, height)`.
type Layout = (Vec<Band>, bool, f32, f32);

/// Picks an archetype and lays out its front for `n` movable parts.
fn layout(n: usize, rng: &mut Rng) -> Layout {
    match rng.below(4) {
        0 => chest_of_drawers(n, rng),
        1 if n <= 8 => cupboard(n, rng),
        2 if n >= 2 => hutch(n, rng),
        _ => sideboard(n, rng),
    }
}

/// Chest of drawers / dresser / nightstand: rows of drawers, maybe an open niche at the bottom.
fn chest_of_drawers(n: usize, rng: &mut Rng) -> Layout {
    let min_m = n.div_ceil(5).max(1);
    let m = rng.int_in(min_m, (min_m + 1).min(3)).min(n);
    let rows = drawer_rows(n, m, rng);
    // `rows` runs bottom to top; bottom rows a little deeper.
    let mut bands: Vec<Band> = rows
        .iter()
        .enumerate()
        .map(|(i, &c)| Band {
            weight: 1.0 + 0.12 * (rows.len() - i) as f32,
            fills: drawers(c),
        })
        .collect();
    // Low chests get an open niche below (a nightstand) so they do not read as a bare box.
    if rows.len() == 1 || (rows.len() == 2 && rng.chance(0.5)) {
        bands.insert(
            0,
            Band {
                weight: 1.6,
                fills: vec![(1.0, Fill::Open)],
            },
        );
    }
    let cell_w = rng.uniform(0.4, 0.6);
    let w = (m as f32 * cell_w).max(0.42);
    let row_h = rng.uniform(0.14, 0.22);
    let h: f32 = bands.iter().map(|b| b.weight).sum::<f32>() * row_h;
    (bands, true, w, h)
}

/// Cupboard / wardrobe: columns of one or two stacked doors (two doors side by side per column pair).
fn cupboard(n: usize, rng: &mut Rng) -> Layout {
    let stacked = n > 4 || (n >= 2 && rng.chance(0.35));
    let cols = if stacked { n.div_ceil(2) } else { n };
    let mut per_col = vec![if stacked { 2 } else { 1 }; cols];
    if stacked && n % 2 == 1 {
        let k = rng.below(cols as u32) as usize;
        per_col[k] = 1;
    }
    let bands: Vec<Band> = per_col
        .iter()
        .enumerate()
        .map(|(i, &k)| {
            let hinge_left = if 2 * i + 1 == cols {
                rng.chance(0.5)
            } else {
                2 * i + 1 < cols
            };
            Band {
                weight: 1.0,
                fills: vec![(1.0, Fill::Door { hinge_left }); k],
            }
        })
        .collect();
    let w = cols as f32 * rng.uniform(0.38, 0.55);
    let h = if stacked || rng.chance(0.5) {
        rng.uniform(1.3, 2.0)
    } else {
        rng.uniform(0.6, 1.0)
    };
    (bands, false, w, h)
}

/// Tall hutch: doors (or an open niche) on top, rows of drawers, doors below.
fn hutch(n: usize, rng: &mut Rng) -> Layout {
    let mut rem = n;
    let top_doors = if rng.chance(0.2) {
        0
    } else {
        rng.int_in(1, 2).min(rem - 1)
    };
    rem -= top_doors;
    let bottom_doors = if rem >= 3 && rng.chance(0.6) {
        rng.int_in(1, 2)
    } else {
        0
    };
    rem -= bottom_doors;
    let m = rem.div_ceil(3).clamp(1, 3);
    let rows = drawer_rows(rem, m, rng);
    let mut bands = Vec::new();
    if bottom_doors > 0 {
        bands.push(Band {
            weight: 3.0,
            fills: door_row(bottom_doors, rng),
        });
    }
    for &c in &rows {
        bands.push(Band {
            weight: 1.0,
            fills: drawers(c),
        });
    }
    let top = if top_doors == 0 {
        vec![(1.0, Fill::Open)]
    } else {
        door_row(top_doors, rng)
    };
    bands.push(Band {
        weight: rng.uniform(3.0, 4.5),
        fills: top,
    });
    let widest = top_doors.max(bottom_doors).max(m);
    let w = (widest as f32 * rng.uniform(0.4, 0.55)).max(0.6);
    let total: f32 = bands.iter().map(|b| b.weight).sum();
    let h = (total * rng.uniform(0.15, 0.2)).clamp(1.1, 2.1);
    (bands, true, w, h)
}

/// Sideboard: columns of drawers, doors, a drawer over a door, or an open niche.
fn sideboard(n: usize, rng: &mut Rng) -> Layout {
    let cols = rng.int_in(1, 4).min(n).max(n.div_ceil(5));
    // Each column starts with its minimum and grows up to its capacity until all parts are placed.
    #[derive(Clone, Copy, PartialEq)]
    enum Col {
        Drawers,
        Doors,
        DrawerOverDoor,
    }
    let mut kinds: Vec<Col> = (0..cols)
        .map(|_| match rng.below(3) {
            0 => Col::Drawers,
            1 => Col::Doors,
            _ => Col::DrawerOverDoor,
        })
        .collect();
    let cap = |k: Col| match k {
        Col::Drawers => 5,
        Col::Doors => 2,
        Col::DrawerOverDoor => 3,
    };
    let min = |k: Col| match k {
        Col::DrawerOverDoor => 2,
        _ => 1,
    };
    // Too few parts for the minimums, or too many for the capacities: fall back to drawer columns.
    // (`cols` ≥ n / 5 and ≤ n, so all-drawer columns always fit.)
    while kinds.iter().map(|&k| min(k)).sum::<usize>() > n
        || kinds.iter().map(|&k| cap(k)).sum::<usize>() < n
    {
        match kinds.iter().position(|&k| k != Col::Drawers) {
            Some(i) => kinds[i] = Col::Drawers,
            None => break,
        }
    }
    let mut counts: Vec<usize> = kinds.iter().map(|&k| min(k)).collect();
    let mut placed: usize = counts.iter().sum();
    while placed < n {
        let open: Vec<usize> = (0..cols).filter(|&i| counts[i] < cap(kinds[i])).collect();
        if open.is_empty() {
            break;
        }
        let i = *rng.pick(&open);
        counts[i] += 1;
        placed += 1;
    }
    let mut bands: Vec<Band> = kinds
        .iter()
        .zip(&counts)
        .enumerate()
        .map(|(i, (&kind, &k))| {
            let hinge_left = if 2 * i + 1 == cols {
                rng.chance(0.5)
            } else {
                2 * i + 1 < cols
            };
            let door = Fill::Door { hinge_left };
            let fills = match kind {
                Col::Drawers => drawers(k),
                Col::Doors => vec![(1.0, door); k],
                // A door below one or two drawers.
                Col::DrawerOverDoor => {
                    let mut f = vec![(2.5, door)];
                    f.extend(vec![(1.0, Fill::Drawer); k - 1]);
                    f
                }
            };
            Band {
                weight: rng.uniform(0.9, 1.2),
                fills,
            }
        })
        .collect();
    // Sometimes an open niche column in the middle of a wide sideboard.
    if cols >= 2 && rng.chance(0.25) {
        bands.insert(
            cols / 2,
            Band {
                weight: 0.8,
                fills: vec![(1.0, Fill::Open), (1.0, Fill::Open)],
            },
        );
    }
    let tallest = counts.iter().copied().max().unwrap_or(1);
    let w = bands.len() as f32 * rng.uniform(0.4, 0.55);
    let h = (tallest as f32 * rng.uniform(0.15, 0.2)).max(rng.uniform(0.6, 0.9));
    (bands, false, w, h)
}

/// Builds a storage unit with exactly `parts` drawers and doors.
pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let (bands, by_rows, w, h) = layout(parts, rng);
    let d = rng.uniform(0.38, 0.6);
    let t = rng.uniform(0.016, 0.022);

    let carcass_finish = *rng.pick(&[Finish::Wood, Finish::Wood, Finish::Paint]);
    let carcass = random_material("carcass", carcass_finish, rng);
    let front = if rng.chance(0.6) {
        carcass.clone()
    } else {
        random_material(
            "front",
            *rng.pick(&[Finish::Paint, Finish::Wood, Finish::Plastic]),
            rng,
        )
    };
    let style = FrontStyle {
        front,
        inner: random_plain("drawer_box", Finish::Wood, rng),
        handle: random_plain(
            "pull",
            *rng.pick(&[Finish::Metal, Finish::Metal, Finish::Wood]),
            rng,
        ),
        drawer_pull: *rng.pick(&[Pull::Bar, Pull::Knob, Pull::Tab]),
        door_pull: *rng.pick(&[Pull::Bar, Pull::Knob]),
        thickness: rng.uniform(0.016, 0.022),
    };

    let mut b = ObjectBuilder::new("storage_furniture");
    let base = ObjectBuilder::BASE;
    // What carries the carcass: a recessed plinth, four legs, or nothing.
    let stand = rng.below(3);
    let lift = match stand {
        0 => rng.uniform(0.05, 0.1),
        1 => rng.uniform(0.1, 0.22),
        _ => 0.0,
    };
    match stand {
        0 => b.add(
            base,
            slab(
                Vec3::new(-w / 2.0 + 0.03, -d / 2.0 + 0.04, 0.0),
                Vec3::new(w / 2.0 - 0.03, d / 2.0 - 0.02, lift),
                &carcass,
            ),
        ),
        1 => {
            let legs = random_plain("legs", *rng.pick(&[Finish::Wood, Finish::Metal]), rng);
            let r = rng.uniform(0.015, 0.025);
            let tapered = rng.chance(0.5);
            for sx in [-1.0, 1.0] {
                for sy in [-1.0, 1.0] {
                    let p = Vec3::new(sx * (w / 2.0 - 0.04), sy * (d / 2.0 - 0.04), 0.0);
                    let top = p + Vec3::Z * lift;
                    b.add(
                        base,
                        if tapered {
                            frustum(p, top, r * 0.6, r, &legs)
                        } else {
                            cylinder(p, top, r, &legs)
                        },
                    );
                }
            }
        }
        _ => {}
    }
    let lo = Vec3::new(-w / 2.0, -d / 2.0, lift);
    let hi = Vec3::new(w / 2.0, d / 2.0, lift + h);
    let cells = lay_out(&bands, by_rows, lo.x, hi.x, lo.z, hi.z);
    let door_upper = rng.uniform(1.5, 1.9);
    cabinet(&mut b, "", lo, hi, t, &cells, &carcass, &style, door_upper);
    // An overhanging top on low units.
    if h < 1.2 && rng.chance(0.6) {
        let o = rng.uniform(0.005, 0.03);
        let top = random_material("top", *rng.pick(&[Finish::Wood, Finish::Paint]), rng);
        b.add(
            base,
            slab(
                Vec3::new(-w / 2.0 - o, -d / 2.0 - o - 0.02, hi.z),
                Vec3::new(w / 2.0 + o, d / 2.0 + o, hi.z + rng.uniform(0.02, 0.035)),
                &top,
            ),
        );
    }
    b.build()
}
