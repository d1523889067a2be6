//! The fit's preview: the twin, coloured by part with its joint axes, rendered from a few of the
//! dataset's own cameras beside the photos taken from them (and beside the ground truth drawn the
//! same way, when the dataset has it), for both states. One picture says
//! whether the parts and joints came out right (`artmesh fit` writes it as `preview.png`; the page
//! shows it).

use super::GtRenderer;
use super::viewer::TwinScene;
use crate::data::{Camera, Intrinsics, RgbaImage};
use crate::gpu::{GpuContext, GpuResult};
use crate::object::ArticulatedObject;

/// Background behind photos and renders (light grey, so dark and white objects both show).
const BACKGROUND: [u8; 3] = [235, 235, 235];

/// Tiles are at most this many pixels wide (photos are shrunk by a whole factor to fit).
pub const MAX_TILE: u32 = 256;

/// One camera of a state and the photo taken from it.
pub struct PreviewView<'a> {
    /// The dataset's camera.
    pub camera: Camera,
    /// Its colour image (alpha is the foreground).
    pub photo: &'a RgbaImage,
}

/// A second twin drawn between each photo and the fitted twin: the ground truth, when known.
pub struct PreviewTruth<'a> {
    pub object: &'a ArticulatedObject,
    /// Its end configuration (one value per joint, radians / metres).
    pub end: &'a [f32],
}

/// Renders the preview of `object` (start: every joint at 0; end: `end`): one row per state, each
/// of the state's `views` as a photo tile, then the `truth`'s tile (when given) and the twin's
/// tile from the same camera.
pub async fn preview(
    ctx: &GpuContext,
    object: &ArticulatedObject,
    end: &[f32],
    views: [&[PreviewView<'_>]; 2],
    truth: Option<PreviewTruth<'_>>,
) -> GpuResult<RgbaImage> {
    let scene = |object: &ArticulatedObject, end: &[f32]| {
        let mut scene = TwinScene::new(object.clone(), end.to_vec());
        scene.colour_by_part = true;
        scene.show_axes = true;
        scene
    };
    let mut scenes: Vec<TwinScene> = truth.iter().map(|t| scene(t.object, t.end)).collect();
    scenes.push(scene(object, end));
    let tiles = 1 + scenes.len() as u32;
    let columns = views.iter().map(|v| v.len()).max().unwrap_or(0).max(1);
    let first = views.iter().flat_map(|v| v.iter()).next();
    let shrink = first.map_or(1, |v| v.photo.width.div_ceil(MAX_TILE).max(1));
    let (tw, th) = first.map_or((MAX_TILE, MAX_TILE), |v| {
        (v.photo.width / shrink, v.photo.height / shrink)
    });
    let renderer = GtRenderer::new(ctx, tw.max(1), th.max(1))?;
    let mut sheet = Sheet::new(tiles * columns as u32 * tw, 2 * th);
    for (row, state_views) in views.iter().enumerate() {
        let meshes: Vec<_> = scenes
            .iter_mut()
            .map(|s| {
                s.set_state(row == 1);
                s.meshes()
            })
            .collect();
        for (col, view) in state_views.iter().enumerate() {
            let (x0, y0) = (tiles * col as u32 * tw, row as u32 * th);
            sheet.paste(&shrunk(view.photo, shrink, tw, th), x0, y0);
            let camera = scaled(&view.camera, shrink, tw, th);
            for (k, m) in meshes.iter().enumerate() {
                let render = renderer.render_view(ctx, m, &camera).await?;
                sheet.paste(&render.rgba, x0 + (1 + k as u32) * tw, y0);
            }
        }
    }
    Ok(sheet.image)
}

/// `camera` for an image `shrink` times smaller, `width` × `height`.
fn scaled(camera: &Camera, shrink: u32, width: u32, height: u32) -> Camera {
    let k = camera.intrinsics;
    let s = 1.0 / shrink as f32;
    Camera {
        camera_to_world: camera.camera_to_world,
        intrinsics: Intrinsics {
            width,
            height,
            fx: k.fx * s,
            fy: k.fy * s,
            cx: k.cx * s,
            cy: k.cy * s,
        },
    }
}

/// `image` averaged over `shrink` × `shrink` blocks into `width` × `height` (premultiplied by alpha,
/// so the background does not bleed into the object's rim).
fn shrunk(image: &RgbaImage, shrink: u32, width: u32, height: u32) -> RgbaImage {
    let mut pixels = Vec::with_capacity((width * height * 4) as usize);
    for y in 0..height {
        for x in 0..width {
            let mut sum = [0u32; 4];
            for dy in 0..shrink {
                for dx in 0..shrink {
                    let p = image
                        .pixel(x * shrink + dx, y * shrink + dy)
                        .unwrap_or([0; 4]);
                    let a = u32::from(p[3]);
                    for c in 0..3 {
                        sum[c] += u32::from(p[c]) * a / 255;
                    }
                    sum[3] += a;
                }
            }
            let n = shrink * shrink;
            let alpha = sum[3] / n;
            let colour = |c: usize| (sum[c] * 255 / sum[3].max(1)).min(255) as u8;
            pixels.extend([colour(0), colour(1), colour(2), alpha as u8]);
        }
    }
    RgbaImage {
        width,
        height,
        pixels,
    }
}

/// The picture being assembled.
struct Sheet {
    image: RgbaImage,
}

impl Sheet {
    fn new(width: u32, height: u32) -> Sheet {
        let pixel = [BACKGROUND[0], BACKGROUND[1], BACKGROUND[2], 255];
        Sheet {
            image: RgbaImage {
                width,
                height,
                pixels: pixel.repeat((width * height) as usize),
            },
        }
    }

    /// Composites `tile` (alpha over the background) with its top-left corner at (`x0`, `y0`).
    fn paste(&mut self, tile: &RgbaImage, x0: u32, y0: u32) {
        let width = self.image.width;
        for y in 0..tile.height.min(self.image.height.saturating_sub(y0)) {
            for x in 0..tile.width.min(width.saturating_sub(x0)) {
                let Some(src) = tile.pixel(x, y) else {
                    continue;
                };
                let at = (((y0 + y) * width + x0 + x) * 4) as usize;
                let dst = &mut self.image.pixels[at..at + 4];
                let a = u16::from(src[3]);
                for c in 0..3 {
                    dst[c] = ((u16::from(src[c]) * a + u16::from(dst[c]) * (255 - a)) / 255) as u8;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shrinking_averages_only_the_foreground() {
        // A 2×2 image: one opaque red pixel, three transparent: the colour stays red, alpha ¼.
        let image = RgbaImage {
            width: 2,
            height: 2,
            pixels: vec![255, 0, 0, 255, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
        };
        let small = shrunk(&image, 2, 1, 1);
        assert_eq!(small.pixels, [255, 0, 0, 63]);
    }

    #[test]
    fn pasting_composites_over_the_background() {
        let mut sheet = Sheet::new(2, 1);
        let tile = RgbaImage {
            width: 1,
            height: 1,
            pixels: vec![0, 0, 0, 255],
        };
        sheet.paste(&tile, 1, 0);
        assert_eq!(sheet.image.pixels, [235, 235, 235, 255, 0, 0, 0, 255]);
    }
}
