//! A learned segmenter's part map ([`super::SensorModel::Consumer`]): every boundary between
//! labels, part against background included, moved by 1–2 px along a smooth random field with a
//! ragged per-pixel part, and now and then a small blob of another part's label.
//!
//! Labels stay inside the colour image's foreground (alpha > 0, the mask, which stays exact):
//! the segmenter is taken to label the masked photo, so a foreground pixel near the silhouette
//! may lose its label (-1) but no background pixel gains one. Every parameter is a constant below
//! with its source (docs/method.md, "Sensor model").

use super::pixels::{for_each_in_disc, pick_pixel, size_scale};
use crate::data::{PartMap, RgbaImage};
use crate::rng::Rng;

/// How far (pixels) a label boundary moves at the nodes of the smooth shift field (uniform in
/// this range, random direction; between nodes the shift is interpolated, so it varies along
/// the boundary). An engineering choice matching the issue's "part-map boundaries off by
/// 1–2 px": boundary measures for learned segmenters, such as the boundary F-score (Csurka,
/// Larlus & Perronnin 2013, "What is a good evaluation measure for semantic segmentation?",
/// BMVC; Perazzi et al. 2016, the DAVIS benchmark, CVPR), accept a boundary within a tolerance
/// of a few pixels because learned masks are commonly that far off.
pub const BOUNDARY_SHIFT_PX: (f32, f32) = (1.0, 2.0);

/// Spacing (pixels at 800 px wide, scaled with the width, at least 4) of the shift field's
/// nodes: the length over which a boundary's error changes. An engineering choice.
pub const SHIFT_GRID_PX: f32 = 24.0;

/// Per-pixel jitter (± pixels, uniform) added to the smooth shift so boundaries come out ragged;
/// the total shift is held within [`BOUNDARY_SHIFT_PX`]'s maximum on each axis. An engineering
/// choice.
pub const RAGGED_JITTER_PX: f32 = 0.75;

/// Chance per view of one wrong blob: a disc of another visible part's label inside the
/// foreground, as learned segmenters sometimes mislabel a patch. An engineering choice
/// matching the "occasionally a small wrong blob".
pub const WRONG_BLOB_CHANCE: f32 = 0.25;

/// Radius range (pixels at 800 px wide, scaled with the width) of a wrong blob: an engineering
/// choice ("a few pixels").
pub const WRONG_BLOB_RADIUS_PX: (f32, f32) = (3.0, 8.0);

/// Degrades `parts` in place as the segmenter would label the view (see the module docs);
/// `rgba`'s alpha is the foreground (the part map's own labels when the sizes disagree). A map
/// whose size disagrees with its pixel count is left as it is.
pub(super) fn degrade_parts(parts: &mut PartMap, rgba: &RgbaImage, rng: &mut Rng) {
    let (w, h) = (parts.width as usize, parts.height as usize);
    if w == 0 || h == 0 || w.checked_mul(h) != Some(parts.ids.len()) {
        return;
    }
    let foreground = foreground_of(parts, rgba);
    let ideal = parts.ids.clone();
    shift_boundaries(&mut parts.ids, &ideal, &foreground, (w, h), rng);
    if rng.chance(WRONG_BLOB_CHANCE) {
        add_wrong_blob(&mut parts.ids, &ideal, &foreground, (w, h), rng);
    }
}

/// Which pixels are foreground: `rgba`'s alpha when it has the part map's size, otherwise the
/// pixels the part map labels.
pub(super) fn foreground_of(parts: &PartMap, rgba: &RgbaImage) -> Vec<bool> {
    let same_size = rgba.width == parts.width
        && rgba.height == parts.height
        && rgba.pixels.len() == 4 * parts.ids.len();
    if same_size {
        rgba.pixels.chunks_exact(4).map(|p| p[3] > 0).collect()
    } else {
        parts.ids.iter().map(|&id| id >= 0).collect()
    }
}

/// Every foreground pixel takes the `ideal` label of the pixel its shift points at (at most
/// `BOUNDARY_SHIFT_PX.1`, rounded, on each axis, so only pixels within that many pixels of a
/// boundary change); every background pixel is -1.
pub(super) fn shift_boundaries(
    ids: &mut [i16],
    ideal: &[i16],
    foreground: &[bool],
    (w, h): (usize, usize),
    rng: &mut Rng,
) {
    let field = ShiftField::new(w, h, rng);
    let most = BOUNDARY_SHIFT_PX.1;
    let shifted = |at: usize, by: f32, size: usize| {
        (at as i64 + by.clamp(-most, most).round() as i64).clamp(0, size as i64 - 1) as usize
    };
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if !foreground[i] {
                ids[i] = -1;
                continue;
            }
            let (fx, fy) = field.at(x, y);
            let jx = rng.uniform(-RAGGED_JITTER_PX, RAGGED_JITTER_PX);
            let jy = rng.uniform(-RAGGED_JITTER_PX, RAGGED_JITTER_PX);
            ids[i] = ideal[shifted(y, fy + jy, h) * w + shifted(x, fx + jx, w)];
        }
    }
}

/// Paints a disc of another label seen in the view around a random labelled foreground pixel,
/// inside the foreground only (see [`WRONG_BLOB_RADIUS_PX`]). Nothing when the view shows one
/// label only.
pub(super) fn add_wrong_blob(
    ids: &mut [i16],
    ideal: &[i16],
    foreground: &[bool],
    (w, h): (usize, usize),
    rng: &mut Rng,
) {
    let Some(centre) = pick_pixel(w, h, rng, |i| foreground[i] && ideal[i] >= 0) else {
        return;
    };
    let own = ideal[centre.1 * w + centre.0];
    let mut seen = vec![false; i16::MAX as usize + 1];
    for &id in ideal {
        if let Ok(k) = usize::try_from(id) {
            seen[k] = true;
        }
    }
    let others: Vec<i16> = (0..=i16::MAX)
        .filter(|&id| id != own && seen[id as usize])
        .collect();
    if others.is_empty() {
        return;
    }
    let label = *rng.pick(&others);
    let radius = size_scale(w as u32) * rng.uniform(WRONG_BLOB_RADIUS_PX.0, WRONG_BLOB_RADIUS_PX.1);
    for_each_in_disc(w, h, centre, radius, |i| {
        if foreground[i] {
            ids[i] = label;
        }
    });
}

/// A smooth random 2-D shift: a vector per node of a coarse grid, bilinearly interpolated.
struct ShiftField {
    spacing: f32,
    columns: usize,
    nodes: Vec<(f32, f32)>,
}

impl ShiftField {
    fn new(w: usize, h: usize, rng: &mut Rng) -> Self {
        let spacing = (SHIFT_GRID_PX * size_scale(w as u32)).max(4.0);
        let columns = (w as f32 / spacing).ceil() as usize + 2;
        let rows = (h as f32 / spacing).ceil() as usize + 2;
        let nodes = (0..columns * rows)
            .map(|_| {
                let length = rng.uniform(BOUNDARY_SHIFT_PX.0, BOUNDARY_SHIFT_PX.1);
                let (sin, cos) = rng.uniform(0.0, std::f32::consts::TAU).sin_cos();
                (length * cos, length * sin)
            })
            .collect();
        ShiftField {
            spacing,
            columns,
            nodes,
        }
    }

    /// The shift at pixel `(x, y)`: no longer than the longest node's, as an average of them.
    fn at(&self, x: usize, y: usize) -> (f32, f32) {
        let (gx, gy) = (x as f32 / self.spacing, y as f32 / self.spacing);
        let (cx, cy) = (gx.floor() as usize, gy.floor() as usize);
        let (tx, ty) = (gx.fract(), gy.fract());
        let node = |c: usize, r: usize| {
            self.nodes
                .get(r * self.columns + c)
                .copied()
                .unwrap_or((0.0, 0.0))
        };
        let lerp =
            |a: (f32, f32), b: (f32, f32), t: f32| (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        let top = lerp(node(cx, cy), node(cx + 1, cy), tx);
        let bottom = lerp(node(cx, cy + 1), node(cx + 1, cy + 1), tx);
        lerp(top, bottom, ty)
    }
}
