//! Preparing the training views of a preset: integer downsampling of a frame (colour box-filtered
//! with premultiplied alpha; depth and part ids by the nearest valid sample, never mixed across
//! an edge) with its intrinsics scaled to match.

use crate::data::{DepthMap, Frame, PartMap, RgbaImage};
use crate::rng::Rng;

/// A shuffled cycle through `0..count` views: each view once per cycle, a fresh Fisher–Yates
/// order (from the caller's generator) when a cycle ends. Both phases' trainers draw from it.
#[derive(Debug, Clone, Default)]
pub struct ViewCycle {
    order: Vec<usize>,
}

impl ViewCycle {
    /// The next view of the cycle through `count` views (0 when there are none).
    pub fn next(&mut self, count: usize, rng: &mut Rng) -> usize {
        if self.order.is_empty() {
            self.order = (0..count).collect();
            for k in (1..self.order.len()).rev() {
                self.order.swap(k, rng.below(k as u32 + 1) as usize);
            }
        }
        self.order.pop().unwrap_or(0)
    }

    /// Starts a new cycle at the next call.
    pub(crate) fn restart(&mut self) {
        self.order.clear();
    }
}

/// `frame` reduced by `factor` in each direction (the last partial block is cropped).
pub fn downsample_frame(frame: &Frame, factor: u32) -> Frame {
    if factor <= 1 {
        return frame.clone();
    }
    let (w, h) = (frame.rgba.width / factor, frame.rgba.height / factor);
    let (w, h) = (w.max(1), h.max(1));
    let src_w = frame.rgba.width;
    let block = |x: u32, y: u32| {
        (0..factor)
            .flat_map(move |dy| (0..factor).map(move |dx| (x * factor + dx, y * factor + dy)))
    };
    let mut rgba = vec![0u8; (4 * w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0f32; 4];
            let mut n = 0f32;
            for (sx, sy) in block(x, y) {
                if let Some(p) = frame.rgba.pixel(sx, sy) {
                    let a = f32::from(p[3]) / 255.0;
                    for c in 0..3 {
                        sum[c] += f32::from(p[c]) * a;
                    }
                    sum[3] += f32::from(p[3]);
                    n += 1.0;
                }
            }
            let alpha = sum[3] / n.max(1.0);
            let o = (4 * (y * w + x)) as usize;
            for c in 0..3 {
                let a = sum[3] / 255.0;
                rgba[o + c] = if a > 0.0 {
                    (sum[c] / a).round().clamp(0.0, 255.0) as u8
                } else {
                    0
                };
            }
            rgba[o + 3] = alpha.round().clamp(0.0, 255.0) as u8;
        }
    }
    // The block's centre sample (or the first valid one) keeps depth and part ids unmixed.
    let centre = factor / 2;
    let pick = |x: u32, y: u32, valid: &dyn Fn(usize) -> bool| -> Option<usize> {
        let c = ((y * factor + centre) * src_w + x * factor + centre) as usize;
        if valid(c) {
            return Some(c);
        }
        block(x, y)
            .map(|(sx, sy)| (sy * src_w + sx) as usize)
            .find(|&i| valid(i))
    };
    let depth = frame.depth.as_ref().map(|d| {
        let mut mm = vec![0u16; (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                if let Some(i) = pick(x, y, &|i| d.millimetres.get(i).is_some_and(|&v| v > 0)) {
                    mm[(y * w + x) as usize] = d.millimetres[i];
                }
            }
        }
        DepthMap {
            width: w,
            height: h,
            millimetres: mm,
        }
    });
    let parts = frame.parts.as_ref().map(|p| {
        let mut ids = vec![-1i16; (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                if let Some(i) = pick(x, y, &|i| p.ids.get(i).is_some_and(|&v| v >= 0)) {
                    ids[(y * w + x) as usize] = p.ids[i];
                }
            }
        }
        PartMap {
            width: w,
            height: h,
            ids,
        }
    });
    let mut camera = frame.camera;
    let k = &mut camera.intrinsics;
    let f = factor as f32;
    (k.width, k.height, k.fx, k.fy, k.cx, k.cy) = (w, h, k.fx / f, k.fy / f, k.cx / f, k.cy / f);
    Frame {
        name: frame.name.clone(),
        camera,
        time: frame.time,
        rgba: RgbaImage {
            width: w,
            height: h,
            pixels: rgba,
        },
        depth,
        parts,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::fixture;

    #[test]
    fn halving_keeps_geometry_consistent() {
        let dataset = fixture::small_dataset(fixture::FixtureParams::default());
        let frame = &dataset.views[0].frames[0];
        let half = downsample_frame(frame, 2);
        assert_eq!(half.rgba.width, frame.rgba.width / 2);
        // A low-resolution pixel centre is the centre of its 2×2 block: both cameras put the same
        // ray through it.
        let d = half.depth.as_ref().unwrap();
        let (x, y) = (0..d.width * d.height)
            .map(|i| (i % d.width, i / d.width))
            .find(|&(x, y)| d.millimetres[(y * d.width + x) as usize] > 0)
            .unwrap();
        let z = f32::from(d.millimetres[(y * d.width + x) as usize]) / 1000.0;
        let p = half
            .camera
            .unproject(glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5), z);
        let q = frame.camera.unproject(
            glam::Vec2::new(2.0 * x as f32 + 1.0, 2.0 * y as f32 + 1.0),
            z,
        );
        assert!(p.distance(q) < 1e-4, "{p} vs {q}");
    }
}
