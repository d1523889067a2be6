//! Pixel helpers that the sensor model's depth and part-map degradations share: how sizes scale
//! with the image, a random pixel that passes a test, and the pixels of a disc.

use crate::rng::Rng;

/// Image width (pixels) for which the sensor model's hole and blob sizes are given: the
/// benchmark's 800² captures. Sizes scale with `width / REFERENCE_WIDTH`, so a 64² capture loses
/// a few pixels to a hole rather than a whole part.
pub const REFERENCE_WIDTH: f32 = 800.0;

/// Random draws before a pick gives up: a view that shows almost nothing gets no hole or blob.
const PICK_TRIES: usize = 64;

/// How much larger than at [`REFERENCE_WIDTH`] a size in pixels is for an image `width` wide.
pub(super) fn size_scale(width: u32) -> f32 {
    width as f32 / REFERENCE_WIDTH
}

/// A random pixel `(x, y)` of a `width`×`height` image whose row-major index satisfies `wanted`;
/// `None` when [`PICK_TRIES`] draws all miss.
pub(super) fn pick_pixel(
    width: usize,
    height: usize,
    rng: &mut Rng,
    wanted: impl Fn(usize) -> bool,
) -> Option<(usize, usize)> {
    if width == 0 || height == 0 {
        return None;
    }
    (0..PICK_TRIES).find_map(|_| {
        let x = rng.below(width as u32) as usize;
        let y = rng.below(height as u32) as usize;
        wanted(y * width + x).then_some((x, y))
    })
}

/// Calls `visit` with the row-major index of every pixel whose centre lies within `radius` of
/// pixel `(cx, cy)`'s centre, clipped to the `width`×`height` image (always the centre itself).
pub(super) fn for_each_in_disc(
    width: usize,
    height: usize,
    (cx, cy): (usize, usize),
    radius: f32,
    mut visit: impl FnMut(usize),
) {
    let reach = radius.max(0.0).ceil() as usize;
    let r2 = radius * radius;
    for y in cy.saturating_sub(reach)..(cy + reach + 1).min(height) {
        for x in cx.saturating_sub(reach)..(cx + reach + 1).min(width) {
            let (dx, dy) = (x as f32 - cx as f32, y as f32 - cy as f32);
            if dx * dx + dy * dy <= r2 || (x, y) == (cx, cy) {
                visit(y * width + x);
            }
        }
    }
}
