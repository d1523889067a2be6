//! Contact sheets: each object rendered at two joint configurations side by side, tiles in a grid, so a
//! person can see at a glance that generated or imported objects look right and move as they should.

use glam::Vec3;

use super::{GtRenderer, posed_part_meshes};
use crate::data::{Camera, RgbaImage, look_at};
use crate::gpu::{GpuContext, GpuResult};
use crate::object::ArticulatedObject;
use crate::object::mesh_bounds;

/// Background of the sheet (light grey, so black and white objects both show).
const BACKGROUND: [u8; 4] = [230, 230, 230, 255];

/// Horizontal field of view of the sheet's camera.
const FOV_X: f32 = 0.7;

/// One entry of a sheet: an object and the two configurations to show (one joint value per joint).
pub struct SheetEntry<'a> {
    /// The object.
    pub object: &'a ArticulatedObject,
    /// Joint values of the left and right tile.
    pub states: [Vec<f32>; 2],
}

/// A camera looking at `centre` from the front-right and above (the front of synthetic objects faces −y),
/// far enough that a sphere of `radius` fits the view.
pub fn overview_camera(centre: Vec3, radius: f32, tile: u32) -> Camera {
    let direction = Vec3::new(0.55, -1.0, 0.65).normalize();
    let distance = radius.max(1e-3) / (FOV_X * 0.5).sin() * 1.05;
    let pose = look_at(centre + direction * distance, centre, Vec3::Z);
    Camera::from_fov(pose, tile, tile, FOV_X, None)
}

/// Renders every entry as a pair of `tile`² views (same camera for both states, framed on the union of
/// both), `pairs_per_row` pairs per row, composited over a light grey background.
pub async fn contact_sheet(
    ctx: &GpuContext,
    entries: &[SheetEntry<'_>],
    tile: u32,
    pairs_per_row: usize,
) -> GpuResult<RgbaImage> {
    let renderer = GtRenderer::new(ctx, tile, tile)?;
    let per_row = pairs_per_row.max(1);
    let rows = entries.len().div_ceil(per_row).max(1);
    let (width, height) = (tile as usize * 2 * per_row, tile as usize * rows);
    let mut pixels: Vec<u8> = BACKGROUND.repeat(width * height);
    for (i, entry) in entries.iter().enumerate() {
        let posed = entry
            .states
            .each_ref()
            .map(|q| posed_part_meshes(entry.object, q));
        let Some((lo, hi)) = mesh_bounds(posed.iter().flatten().map(|m| &m.mesh)) else {
            continue; // nothing to show
        };
        let camera = overview_camera((lo + hi) * 0.5, (hi - lo).length() * 0.5, tile);
        for (side, meshes) in posed.iter().enumerate() {
            let view = renderer.render_view(ctx, meshes, &camera).await?;
            let x0 = ((i % per_row) * 2 + side) * tile as usize;
            let y0 = (i / per_row) * tile as usize;
            for y in 0..tile as usize {
                for x in 0..tile as usize {
                    let src = &view.rgba.pixels[(y * tile as usize + x) * 4..][..4];
                    let dst = &mut pixels[((y0 + y) * width + x0 + x) * 4..][..4];
                    let a = u16::from(src[3]);
                    for c in 0..3 {
                        dst[c] =
                            ((u16::from(src[c]) * a + u16::from(dst[c]) * (255 - a)) / 255) as u8;
                    }
                }
            }
        }
    }
    Ok(RgbaImage {
        width: width as u32,
        height: height as u32,
        pixels,
    })
}
