//! Shared pieces of the furniture-like categories (storage furniture, table, refrigerator, trash can,
//! suitcase, window): slabs given by their corners, open boxes, handles, drawers that slide out along −y,
//! doors hinged on a vertical edge, and a cabinet whose front is a grid of drawers, doors and open niches.
//!
//! Conventions: the front of a carcass is the plane `y = lo.y` (fronts sit in front of it, at smaller y);
//! rectangles on the front are `[x0, x1] × [z0, z1]`.

use glam::Vec3;

use crate::object::{JointKind, Material};
use crate::synth::builder::{ObjectBuilder, cuboid, cylinder, frustum};

/// Gap between a moving front and its neighbours or the carcass (so closed parts never z-fight).
pub(super) const GAP: f32 = 0.0015;

/// Axis-aligned box between two opposite corners (any order).
pub(super) fn slab(a: Vec3, b: Vec3, material: &Material) -> crate::object::RenderMesh {
    let (lo, hi) = (a.min(b), a.max(b));
    cuboid((lo + hi) * 0.5, hi - lo, material)
}

/// Which face of an [`open_box`] is left open.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Open {
    /// The −y face (a carcass or drawer seen from the front).
    Front,
    /// The +z face (a bin, a drawer box, a suitcase shell).
    Top,
    /// The −z face (a lid).
    Bottom,
}

/// Five panels of thickness `t` around the box `lo..hi`, leaving the `open` face out.
pub(super) fn open_box(
    b: &mut ObjectBuilder,
    link: usize,
    lo: Vec3,
    hi: Vec3,
    t: f32,
    open: Open,
    material: &Material,
) {
    let t = t.min((hi - lo).min_element() * 0.45);
    // Sides span the full depth and height; front and back fit between them; bottom and top between those.
    b.add(link, slab(lo, Vec3::new(lo.x + t, hi.y, hi.z), material));
    b.add(link, slab(Vec3::new(hi.x - t, lo.y, lo.z), hi, material));
    let (x0, x1) = (lo.x + t, hi.x - t);
    b.add(
        link,
        slab(
            Vec3::new(x0, hi.y - t, lo.z),
            Vec3::new(x1, hi.y, hi.z),
            material,
        ),
    );
    let y0 = if open == Open::Front {
        lo.y
    } else {
        b.add(
            link,
            slab(
                Vec3::new(x0, lo.y, lo.z),
                Vec3::new(x1, lo.y + t, hi.z),
                material,
            ),
        );
        lo.y + t
    };
    let y1 = hi.y - t;
    if open != Open::Bottom {
        b.add(
            link,
            slab(
                Vec3::new(x0, y0, lo.z),
                Vec3::new(x1, y1, lo.z + t),
                material,
            ),
        );
    }
    if open != Open::Top {
        b.add(
            link,
            slab(
                Vec3::new(x0, y0, hi.z - t),
                Vec3::new(x1, y1, hi.z),
                material,
            ),
        );
    }
}

/// Shape of a pull on a drawer or door.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Pull {
    /// A round bar on two square posts.
    Bar,
    /// A round knob (a stem and a wider head).
    Knob,
    /// A flat tab sticking out of the front.
    Tab,
}

/// A pull centred on `centre` (a point of a front face that faces −y), running along `along` (unit x or
/// z) for `length`, sticking out towards −y.
pub(super) fn pull(
    b: &mut ObjectBuilder,
    link: usize,
    centre: Vec3,
    along: Vec3,
    length: f32,
    kind: Pull,
    material: &Material,
) {
    let out = 0.028;
    match kind {
        Pull::Bar => {
            let half = along * (length * 0.5);
            let bar = centre - Vec3::Y * out;
            b.add(link, cylinder(bar - half, bar + half, 0.006, material));
            for end in [-0.4f32, 0.4] {
                let p = centre + along * (length * end);
                b.add(
                    link,
                    cuboid(
                        p - Vec3::Y * (out * 0.5),
                        Vec3::new(0.009, out, 0.009),
                        material,
                    ),
                );
            }
        }
        Pull::Knob => {
            let head = centre - Vec3::Y * out;
            b.add(link, cylinder(centre, head, 0.006, material));
            b.add(
                link,
                frustum(head, head - Vec3::Y * 0.012, 0.014, 0.016, material),
            );
        }
        Pull::Tab => {
            let size = along * length + Vec3::Y * 0.022 + along.cross(Vec3::Y).abs() * 0.01;
            b.add(link, cuboid(centre - Vec3::Y * 0.011, size, material));
        }
    }
}

/// Materials and sizes of the fronts of a cabinet.
#[derive(Debug, Clone)]
pub(super) struct FrontStyle {
    /// Drawer fronts and doors.
    pub front: Material,
    /// Drawer boxes (sides, back, bottom).
    pub inner: Material,
    /// Pulls.
    pub handle: Material,
    /// Pull shape of drawers.
    pub drawer_pull: Pull,
    /// Pull shape of doors.
    pub door_pull: Pull,
    /// Thickness of fronts.
    pub thickness: f32,
}

/// The front panel of thickness `thickness` covering `front` (`[x0, x1, z0, z1]`) just in front of the plane
/// `y = y_face`, inset by [`GAP`] on every side.
fn front_panel(
    front: [f32; 4],
    y_face: f32,
    thickness: f32,
    material: &Material,
) -> crate::object::RenderMesh {
    let [x0, x1, z0, z1] = front;
    let yf = y_face - GAP;
    slab(
        Vec3::new(x0 + GAP, yf - thickness, z0 + GAP),
        Vec3::new(x1 - GAP, yf, z1 - GAP),
        material,
    )
}

/// The moving front of a drawer: a prismatic joint at the centre of `front` (`[x0, x1, z0, z1]`, in front of
/// the plane `y = y_face`) sliding out along −y by up to `travel`, and its front panel. Returns its link.
pub(super) fn drawer_front(
    b: &mut ObjectBuilder,
    name: &str,
    front: [f32; 4],
    y_face: f32,
    travel: f32,
    thickness: f32,
    material: &Material,
) -> usize {
    let [x0, x1, z0, z1] = front;
    let link = b.joint(
        name,
        ObjectBuilder::BASE,
        JointKind::Prismatic,
        Vec3::new((x0 + x1) * 0.5, y_face, (z0 + z1) * 0.5),
        Vec3::NEG_Y,
        0.0,
        travel,
    );
    b.add(link, front_panel(front, y_face, thickness, material));
    link
}

/// The leaf of a door covering `front` (`[x0, x1, z0, z1]`, in front of the plane `y = y_face`): a revolute
/// joint on its left or right front outer edge, so that positive angles (up to `upper`) swing its free edge
/// out towards −y and it never swings into the carcass, and its front panel. Returns its link.
#[allow(clippy::too_many_arguments)]
pub(super) fn door_leaf(
    b: &mut ObjectBuilder,
    name: &str,
    front: [f32; 4],
    y_face: f32,
    hinge_left: bool,
    upper: f32,
    thickness: f32,
    material: &Material,
) -> usize {
    let [x0, x1, z0, z1] = front;
    let yf = y_face - GAP;
    let (hinge_x, axis) = if hinge_left {
        (x0 + GAP, Vec3::NEG_Z)
    } else {
        (x1 - GAP, Vec3::Z)
    };
    let link = b.joint(
        name,
        ObjectBuilder::BASE,
        JointKind::Revolute,
        Vec3::new(hinge_x, yf - thickness, (z0 + z1) * 0.5),
        axis,
        0.0,
        upper,
    );
    b.add(link, front_panel(front, y_face, thickness, material));
    link
}

/// A drawer whose front covers `front` (`[x0, x1, z0, z1]`, in front of the plane `y = y_face`), with a box
/// (sides, back, bottom) inside `opening` reaching `depth` behind the face. It slides out along −y by up to
/// `travel`. Returns its link.
#[allow(clippy::too_many_arguments)]
pub(super) fn drawer(
    b: &mut ObjectBuilder,
    name: &str,
    front: [f32; 4],
    opening: [f32; 4],
    y_face: f32,
    depth: f32,
    travel: f32,
    style: &FrontStyle,
) -> usize {
    let [x0, x1, z0, z1] = front;
    let link = drawer_front(
        b,
        name,
        front,
        y_face,
        travel,
        style.thickness,
        &style.front,
    );
    let ft = style.thickness;
    let yf = y_face - GAP;
    // The box clears the opening by a few millimetres so it never touches the carcass.
    let [ox0, ox1, oz0, oz1] = opening;
    let c = 0.004;
    let box_h = ((oz1 - oz0) * 0.8).max(0.02);
    open_box(
        b,
        link,
        Vec3::new(ox0 + c, yf, oz0 + c),
        Vec3::new(ox1 - c, y_face + depth, (oz0 + c + box_h).min(oz1 - c)),
        0.012,
        Open::Top,
        &style.inner,
    );
    let (w, h) = (x1 - x0, z1 - z0);
    let centre = Vec3::new((x0 + x1) * 0.5, yf - ft, z0 + h * 0.6);
    match style.drawer_pull {
        Pull::Knob if w > 0.7 => {
            for s in [-0.25f32, 0.25] {
                pull(
                    b,
                    link,
                    centre + Vec3::X * (w * s),
                    Vec3::X,
                    0.0,
                    Pull::Knob,
                    &style.handle,
                );
            }
        }
        kind => pull(
            b,
            link,
            centre,
            Vec3::X,
            (w * 0.35).clamp(0.06, 0.3),
            kind,
            &style.handle,
        ),
    }
    link
}

/// A door covering `front` (`[x0, x1, z0, z1]`, in front of the plane `y = y_face`), hinged on its left or
/// right edge so that positive angles (up to `upper`) swing its free edge out towards −y. Returns its link.
pub(super) fn door(
    b: &mut ObjectBuilder,
    name: &str,
    front: [f32; 4],
    y_face: f32,
    hinge_left: bool,
    upper: f32,
    style: &FrontStyle,
) -> usize {
    let [x0, x1, z0, z1] = front;
    let ft = style.thickness;
    let yf = y_face - GAP;
    let link = door_leaf(b, name, front, y_face, hinge_left, upper, ft, &style.front);
    let (w, h) = (x1 - x0, z1 - z0);
    let inset = (w * 0.12).min(0.05);
    let free_x = if hinge_left { x1 - inset } else { x0 + inset };
    let (along, length) = match style.door_pull {
        Pull::Knob => (Vec3::Z, 0.0),
        _ => (Vec3::Z, (h * 0.3).clamp(0.08, 0.35)),
    };
    // Pulls sit at a comfortable height: upper part of low doors, middle of tall ones.
    let z = if h > 0.9 { z0 + h * 0.5 } else { z0 + h * 0.7 };
    pull(
        b,
        link,
        Vec3::new(free_x, yf - ft, z),
        along,
        length,
        style.door_pull,
        &style.handle,
    );
    link
}

/// What fills a cell of a cabinet front.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Fill {
    /// A drawer (one movable part).
    Drawer,
    /// A door hinged on the left or right edge (one movable part).
    Door { hinge_left: bool },
    /// An open niche with nothing in front (static).
    Open,
}

/// One cell of a cabinet front: `[x0, x1, z0, z1]` of the carcass's outer front and what fills it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Cell {
    pub rect: [f32; 4],
    pub fill: Fill,
}

/// Splits `total` into pieces proportional to `weights`, returning the cumulative boundaries from `start`.
pub(super) fn splits(start: f32, total: f32, weights: &[f32]) -> Vec<f32> {
    let sum: f32 = weights.iter().sum::<f32>().max(1e-6);
    let mut out = vec![start];
    let mut acc = start;
    for w in weights {
        acc += total * w / sum;
        out.push(acc);
    }
    out
}

/// A carcass `lo..hi` of panel thickness `t` (open front) with dividers between `cells`, which partition
/// its front `[lo.x, hi.x] × [lo.z, hi.z]`, and their drawers and doors. `door_upper` is the opening angle
/// of every door. Moving links are named `<prefix>drawer<k>` / `<prefix>door<k>`. Returns the number of
/// movable parts added.
#[allow(clippy::too_many_arguments)]
pub(super) fn cabinet(
    b: &mut ObjectBuilder,
    prefix: &str,
    lo: Vec3,
    hi: Vec3,
    t: f32,
    cells: &[Cell],
    carcass: &Material,
    style: &FrontStyle,
    door_upper: f32,
) -> usize {
    let base = ObjectBuilder::BASE;
    open_box(b, base, lo, hi, t, Open::Front, carcass);
    let eps = 1e-4;
    let back = hi.y - t;
    let (mut drawers, mut doors) = (0, 0);
    for cell in cells {
        let [x0, x1, z0, z1] = cell.rect;
        // Dividers: one along the bottom edge and one along the right edge of each inner cell, so every
        // inner boundary gets exactly one panel.
        if z0 > lo.z + eps {
            b.add(
                base,
                slab(
                    Vec3::new(x0.max(lo.x + t), lo.y, z0 - t * 0.5),
                    Vec3::new(x1.min(hi.x - t), back, z0 + t * 0.5),
                    carcass,
                ),
            );
        }
        if x1 < hi.x - eps {
            b.add(
                base,
                slab(
                    Vec3::new(x1 - t * 0.5, lo.y, z0.max(lo.z + t)),
                    Vec3::new(x1 + t * 0.5, back, z1.min(hi.z - t)),
                    carcass,
                ),
            );
        }
        let inner = |v: f32, edge: f32| if (v - edge).abs() < eps { t } else { t * 0.5 };
        let opening = [
            x0 + inner(x0, lo.x),
            x1 - inner(x1, hi.x),
            z0 + inner(z0, lo.z),
            z1 - inner(z1, hi.z),
        ];
        match cell.fill {
            Fill::Drawer => {
                let depth = (hi.y - lo.y - t - 0.015).max(0.05);
                drawer(
                    b,
                    &format!("{prefix}drawer{drawers}"),
                    cell.rect,
                    opening,
                    lo.y,
                    depth,
                    depth * 0.75,
                    style,
                );
                drawers += 1;
            }
            Fill::Door { hinge_left } => {
                door(
                    b,
                    &format!("{prefix}door{doors}"),
                    cell.rect,
                    lo.y,
                    hinge_left,
                    door_upper,
                    style,
                );
                doors += 1;
                // A shelf behind tall doors, set back so it shows when the door is open.
                if opening[3] - opening[2] > 0.45 {
                    let z = (opening[2] + opening[3]) * 0.5;
                    b.add(
                        base,
                        slab(
                            Vec3::new(opening[0], lo.y + 0.03, z - t * 0.4),
                            Vec3::new(opening[1], back, z + t * 0.4),
                            carcass,
                        ),
                    );
                }
            }
            Fill::Open => {}
        }
    }
    drawers + doors
}
