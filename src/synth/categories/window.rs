//! Window: a frame standing on z = 0 (jambs, head, sill, mullions) holding glazed sashes. Styles:
//! double-hung (lower sash slides up in the front track, upper sash down in the back track, prismatic along
//! z; one or two such windows side by side), horizontal sliders (sashes in alternating front and back tracks
//! sliding past each other along x), and casements (sashes hinged on a vertical edge swinging out towards −y,
//! neighbours apart; in two-row frames the upper ones are awnings hinged at the top). Every sash hangs on
//! the frame; panes that do not move belong to the frame.

use glam::Vec3;

use super::shapes_b::{GAP, slab, splits};
use crate::object::{ArticulatedObject, JointKind, Material};
use crate::rng::Rng;
use crate::synth::builder::ObjectBuilder;
use crate::synth::texture::{Finish, material, random_material};

struct Look {
    frame: Material,
    glass: Material,
    /// Sash rail width and thickness.
    rail: f32,
    thick: f32,
    /// Muntin bars across each pane (0 = plain glass).
    muntins: usize,
}

/// A glazed sash filling `[x0, x1] × [z0, z1]` between `y0` and `y0 + look.thick`, on `link`.
fn sash(b: &mut ObjectBuilder, link: usize, rect: [f32; 4], y0: f32, look: &Look) {
    let [x0, x1, z0, z1] = rect;
    let (r, y1) = (look.rail.min((x1 - x0) * 0.3), y0 + look.thick);
    let m = &look.frame;
    b.add(
        link,
        slab(Vec3::new(x0, y0, z0), Vec3::new(x0 + r, y1, z1), m),
    );
    b.add(
        link,
        slab(Vec3::new(x1 - r, y0, z0), Vec3::new(x1, y1, z1), m),
    );
    b.add(
        link,
        slab(Vec3::new(x0 + r, y0, z0), Vec3::new(x1 - r, y1, z0 + r), m),
    );
    b.add(
        link,
        slab(Vec3::new(x0 + r, y0, z1 - r), Vec3::new(x1 - r, y1, z1), m),
    );
    let ym = y0 + look.thick * 0.5;
    b.add(
        link,
        slab(
            Vec3::new(x0 + r, ym - 0.003, z0 + r),
            Vec3::new(x1 - r, ym + 0.003, z1 - r),
            &look.glass,
        ),
    );
    // Muntins: thin bars on both faces of the glass.
    let n = look.muntins;
    if n > 0 {
        for k in 1..=n {
            let f = k as f32 / (n + 1) as f32;
            let x = x0 + r + (x1 - x0 - 2.0 * r) * f;
            let z = z0 + r + (z1 - z0 - 2.0 * r) * f;
            b.add(
                link,
                slab(
                    Vec3::new(x - 0.008, ym - 0.009, z0 + r),
                    Vec3::new(x + 0.008, ym + 0.009, z1 - r),
                    m,
                ),
            );
            b.add(
                link,
                slab(
                    Vec3::new(x0 + r, ym - 0.009, z - 0.008),
                    Vec3::new(x1 - r, ym + 0.009, z + 0.008),
                    m,
                ),
            );
        }
    }
}

/// The frame's opening columns and what the sashes in them share.
struct Frame<'a> {
    look: &'a Look,
    /// Front and back faces of the frame (y).
    y0: f32,
    y1: f32,
    /// Frame bar width.
    fb: f32,
    /// Opening columns.
    cols: usize,
    /// Casement columns may carry an awning above.
    two_rows: bool,
    /// Moving sashes in all.
    parts: usize,
}

/// Sashes still to place, and a running number for their names.
struct Sashes {
    left: usize,
    count: usize,
}

impl Sashes {
    /// The next sash's name, e.g. `casement3`.
    fn name(&mut self, what: &str) -> String {
        self.count += 1;
        format!("{what}{}", self.count)
    }
}

/// Jambs, head, sill (protruding to the front) and mullions of a `w` × `h` frame with `cols` openings of
/// width `col_w`. Returns the openings' edges along x (left and right edge of each column in turn).
fn frame(b: &mut ObjectBuilder, f: &Frame, w: f32, h: f32, col_w: f32, rng: &mut Rng) -> Vec<f32> {
    let base = ObjectBuilder::BASE;
    let (y0, y1, fb, cols) = (f.y0, f.y1, f.fb, f.cols);
    let m = &f.look.frame;
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0, y0, 0.0),
            Vec3::new(-w / 2.0 + fb, y1, h),
            m,
        ),
    );
    b.add(
        base,
        slab(
            Vec3::new(w / 2.0 - fb, y0, 0.0),
            Vec3::new(w / 2.0, y1, h),
            m,
        ),
    );
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0 + fb, y0, h - fb),
            Vec3::new(w / 2.0 - fb, y1, h),
            m,
        ),
    );
    b.add(
        base,
        slab(
            Vec3::new(-w / 2.0 - 0.02, y0 - rng.uniform(0.02, 0.05), 0.0),
            Vec3::new(w / 2.0 + 0.02, y1, fb),
            m,
        ),
    );
    let mut xs = vec![-w / 2.0 + fb];
    for c in 0..cols {
        let x1 = xs[2 * c] + col_w;
        xs.push(x1);
        if c + 1 < cols {
            b.add(
                base,
                slab(Vec3::new(x1, y0, fb), Vec3::new(x1 + fb, y1, h - fb), m),
            );
            xs.push(x1 + fb);
        }
    }
    xs
}

/// Double-hung column `c` over `opening`: lower sash in front rising, upper sash behind falling (fixed when
/// no parts are left for it).
fn double_hung(
    b: &mut ObjectBuilder,
    f: &Frame,
    c: usize,
    opening: [f32; 4],
    sashes: &mut Sashes,
    rng: &mut Rng,
) {
    let base = ObjectBuilder::BASE;
    let (look, cols) = (f.look, f.cols);
    let [ox0, ox1, oz0, oz1] = opening;
    let zm = (oz0 + oz1) * 0.5;
    let travel = (zm - oz0) * rng.uniform(0.7, 0.9);
    let front_y = -look.thick - 0.003;
    let lower = b.joint(
        &sashes.name("lower_sash"),
        base,
        JointKind::Prismatic,
        Vec3::new((ox0 + ox1) * 0.5, 0.0, oz0),
        Vec3::Z,
        0.0,
        travel,
    );
    sash(
        b,
        lower,
        [ox0 + GAP, ox1 - GAP, oz0 + GAP, zm + 0.01],
        front_y,
        look,
    );
    sashes.left -= 1;
    let upper = if sashes.left > 0 && (cols - c) <= sashes.left {
        sashes.left -= 1;
        b.joint(
            &sashes.name("upper_sash"),
            base,
            JointKind::Prismatic,
            Vec3::new((ox0 + ox1) * 0.5, 0.0, oz1),
            Vec3::NEG_Z,
            0.0,
            travel,
        )
    } else {
        base
    };
    sash(
        b,
        upper,
        [ox0 + GAP, ox1 - GAP, zm - 0.01, oz1 - GAP],
        0.003,
        look,
    );
}

/// Slider over `opening`: k sashes in alternating tracks; front ones slide right, back ones left.
fn slider(b: &mut ObjectBuilder, f: &Frame, opening: [f32; 4], sashes: &mut Sashes, rng: &mut Rng) {
    let base = ObjectBuilder::BASE;
    let (look, parts) = (f.look, f.parts);
    let [ox0, ox1, oz0, oz1] = opening;
    let k = parts.max(2);
    let x = splits(ox0, ox1 - ox0, &vec![1.0; k]);
    let pane = (ox1 - ox0) / k as f32;
    // With three panes the outer front ones share the middle of the front track: half each.
    let reach = if k == 3 { 0.45 } else { 0.9 };
    for i in 0..k {
        let front = i % 2 == 0;
        let moving = i < parts;
        let dir = if front && !(k == 3 && i == 2) {
            Vec3::X
        } else {
            Vec3::NEG_X
        };
        let link = if moving {
            b.joint(
                &sashes.name("sash"),
                base,
                JointKind::Prismatic,
                Vec3::new((x[i] + x[i + 1]) * 0.5, 0.0, oz0),
                dir,
                0.0,
                pane * reach * rng.uniform(0.85, 1.0),
            )
        } else {
            base
        };
        let y = if front { -look.thick - 0.003 } else { 0.003 };
        // Neighbouring sashes overlap a little behind each other, as real sliders do.
        let lap = if k == 3 && i == 1 { 0.0 } else { 0.01 };
        sash(
            b,
            link,
            [
                (x[i] - lap).max(ox0 + GAP),
                (x[i + 1] + lap).min(ox1 - GAP),
                oz0 + GAP,
                oz1 - GAP,
            ],
            y,
            look,
        );
    }
}

/// Casement column `c` over `opening` (outer-hinged so neighbours swing apart), maybe an awning above.
fn casement(
    b: &mut ObjectBuilder,
    f: &Frame,
    c: usize,
    opening: [f32; 4],
    sashes: &mut Sashes,
    rng: &mut Rng,
) {
    let base = ObjectBuilder::BASE;
    let (look, y0, y1, fb, cols) = (f.look, f.y0, f.y1, f.fb, f.cols);
    let m = &look.frame;
    let [ox0, ox1, oz0, oz1] = opening;
    let zt = if f.two_rows && sashes.left >= 2 && (cols - c) < sashes.left {
        let zt = oz0 + (oz1 - oz0) * rng.uniform(0.6, 0.7);
        b.add(
            base,
            slab(Vec3::new(ox0, y0, zt), Vec3::new(ox1, y1, zt + fb * 0.7), m),
        );
        // Awning: hinged at the top, bottom swinging out.
        let top = zt + fb * 0.7;
        let awning = b.joint(
            &sashes.name("awning"),
            base,
            JointKind::Revolute,
            Vec3::new((ox0 + ox1) * 0.5, y0 - GAP, oz1 - GAP),
            Vec3::NEG_X,
            0.0,
            rng.uniform(0.5, 0.8),
        );
        sash(
            b,
            awning,
            [ox0 + GAP, ox1 - GAP, top + GAP, oz1 - GAP],
            y0 - GAP,
            look,
        );
        sashes.left -= 1;
        zt
    } else {
        oz1
    };
    let hinge_left = if 2 * c + 1 == cols {
        rng.chance(0.5)
    } else {
        2 * c + 1 < cols
    };
    let (hx, axis) = if hinge_left {
        (ox0 + GAP, Vec3::NEG_Z)
    } else {
        (ox1 - GAP, Vec3::Z)
    };
    let link = b.joint(
        &sashes.name("casement"),
        base,
        JointKind::Revolute,
        Vec3::new(hx, y0 - GAP, oz0),
        axis,
        0.0,
        rng.uniform(1.2, 1.7),
    );
    sash(
        b,
        link,
        [ox0 + GAP, ox1 - GAP, oz0 + GAP, zt - GAP],
        y0 - GAP,
        look,
    );
    sashes.left -= 1;
}

/// Builds a window with exactly `parts` moving sashes.
pub(super) fn build(parts: usize, rng: &mut Rng) -> ArticulatedObject {
    let finish = *rng.pick(&[Finish::Wood, Finish::Paint, Finish::Paint, Finish::Metal]);
    let look = Look {
        frame: random_material("frame", finish, rng),
        glass: material("glass", Finish::Plastic, [0.45, 0.6, 0.68], rng.next_u64()),
        rail: rng.uniform(0.035, 0.055),
        thick: rng.uniform(0.03, 0.04),
        muntins: if rng.chance(0.3) { 1 } else { 0 },
    };
    let depth = 2.0 * look.thick + rng.uniform(0.02, 0.04);
    let fb = rng.uniform(0.045, 0.075); // frame bar width
    let style = rng.below(3);
    let mut b = ObjectBuilder::new("window");
    // Columns of the frame: double-hung windows come one or two wide, sliders span one opening.
    let cols = match style {
        0 => parts.div_ceil(2),
        1 => 1,
        _ => {
            if parts >= 2 && rng.chance(0.3) {
                parts.div_ceil(2)
            } else {
                parts
            }
        }
    };
    let two_rows = style == 2 && cols < parts;
    // Wide frames get narrower columns so the window stays under about 2.3 m.
    let col_w = match style {
        1 => rng.uniform(0.35, 0.55) * parts.max(2) as f32,
        _ => rng.uniform(0.45, 0.75).min(2.0 / cols as f32),
    };
    let w = col_w * cols as f32 + fb * (cols as f32 + 1.0);
    let h = match style {
        0 => rng.uniform(1.1, 1.6),
        1 => rng.uniform(0.8, 1.3),
        _ => rng.uniform(0.8, 1.5),
    }
    .min(2.5);
    let f = Frame {
        look: &look,
        y0: -depth / 2.0,
        y1: depth / 2.0,
        fb,
        cols,
        two_rows,
        parts,
    };
    let xs = frame(&mut b, &f, w, h, col_w, rng);
    let (oz0, oz1) = (fb, h - fb);
    let mut sashes = Sashes {
        left: parts,
        count: 0,
    };
    for c in 0..cols {
        let opening = [xs[2 * c], xs[2 * c + 1], oz0, oz1];
        match style {
            0 => double_hung(&mut b, &f, c, opening, &mut sashes, rng),
            1 => slider(&mut b, &f, opening, &mut sashes, rng),
            _ => casement(&mut b, &f, c, opening, &mut sashes, rng),
        }
    }
    b.build()
}
