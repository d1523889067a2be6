//! The bake-off's per-pixel image loss on the CPU: the render against the target on one
//! part's pixels, with a per-pixel SSIM map (the GPU loss only reduces SSIM over the image).

use glam::Vec3;

use crate::data::Frame;
use crate::fit::photometric::target_rgb;
use crate::loss::{LossWeights, SSIM_C1, SSIM_C2, ssim_taps};

/// Σ over pixels labelled `label` (part id; −1 is background) of the per-pixel image loss (the
/// bake-off's masked loss) and their count.
///
/// Only the label's bounding box grown by the SSIM window's radius is evaluated: every window
/// centred in the box lies inside that crop (or beyond the image, zero-padded in both), so the
/// result is the whole image's, at the part's share of the cost (a part is a few percent of an
/// 800² view, and the paper preset's bake-off renders ~100 of them per candidate).
pub(super) fn masked_image_loss(
    planes: &[f32],
    frame: &Frame,
    label: i16,
    background: Vec3,
    weights: &LossWeights,
) -> (f64, usize) {
    let (w, h) = (frame.rgba.width as usize, frame.rgba.height as usize);
    let n = w * h;
    let ids = frame.parts.as_ref().map(|p| &p.ids);
    let selected = |i: usize| ids.is_none_or(|ids| ids[i] == label);
    let Some((x0, y0, x1, y1)) = bounding_box(w, h, selected) else {
        return (0.0, 0);
    };
    let r = ssim_taps().len() / 2;
    let (cx0, cy0) = (x0.saturating_sub(r), y0.saturating_sub(r));
    let (cx1, cy1) = ((x1 + r).min(w - 1), (y1 + r).min(h - 1));
    let (cw, ch) = (cx1 - cx0 + 1, cy1 - cy0 + 1);
    let image_index = |j: usize| (cy0 + j / cw) * w + cx0 + j % cw;
    // The render's colour and the target composited over the background exactly as the GPU loss
    // sees it, both cropped.
    let planar = target_rgb(frame, background);
    let mut render = vec![0.0f32; 3 * cw * ch];
    let mut target = vec![[0.0f64; 3]; cw * ch];
    for (j, t) in target.iter_mut().enumerate() {
        let i = image_index(j);
        for c in 0..3 {
            render[c * cw * ch + j] = planes[c * n + i];
            t[c] = f64::from(planar[c * n + i]);
        }
    }
    let ssim = ssim_map(&render, &target, cw, ch);
    let (mut sum, mut count) = (0.0, 0);
    for (j, (t, s)) in target.iter().zip(&ssim).enumerate() {
        let i = image_index(j);
        if !selected(i) {
            continue;
        }
        let l1 = (0..3)
            .map(|c| (f64::from(planes[c * n + i]) - t[c]).abs())
            .sum::<f64>()
            / 3.0;
        let mut loss = f64::from(weights.l1) * l1 + f64::from(weights.ssim) * (1.0 - s);
        if let Some(d) = frame
            .depth
            .as_ref()
            .map(|d| d.millimetres[i])
            .filter(|&d| d > 0)
        {
            loss += f64::from(weights.depth)
                * (f64::from(planes[3 * n + i]) - f64::from(d) / 1000.0).abs();
        }
        sum += loss;
        count += 1;
    }
    (sum, count)
}

/// The inclusive pixel box `(x0, y0, x1, y1)` of the pixels `selected` keeps; none when it keeps none.
fn bounding_box(
    w: usize,
    h: usize,
    selected: impl Fn(usize) -> bool,
) -> Option<(usize, usize, usize, usize)> {
    let mut b: Option<(usize, usize, usize, usize)> = None;
    for y in 0..h {
        for x in 0..w {
            if selected(y * w + x) {
                b = Some(b.map_or((x, y, x, y), |(x0, y0, x1, y1)| {
                    (x0.min(x), y0.min(y), x1.max(x), y1.max(y))
                }));
            }
        }
    }
    b
}

/// Per-pixel SSIM (mean over RGB) of the render's first three planes against `target`, with
/// the image loss's 11-tap Gaussian window and zero padding.
fn ssim_map(planes: &[f32], target: &[[f64; 3]], w: usize, h: usize) -> Vec<f64> {
    let taps = ssim_taps();
    let r = taps.len() / 2;
    // One separable pass along x (step 1) or y (step w), zero padding.
    let pass = |img: &[f64], along_x: bool| -> Vec<f64> {
        let mut out = vec![0.0; w * h];
        for y in 0..h {
            for x in 0..w {
                let (pos, len) = if along_x { (x, w) } else { (y, h) };
                out[y * w + x] = (0..taps.len())
                    .filter_map(|t| {
                        let q = (pos + t).checked_sub(r).filter(|&q| q < len)?;
                        Some(
                            taps[t]
                                * if along_x {
                                    img[y * w + q]
                                } else {
                                    img[q * w + x]
                                },
                        )
                    })
                    .sum();
            }
        }
        out
    };
    let blur = |img: &[f64]| pass(&pass(img, true), false);
    let n = w * h;
    let mut total = vec![0.0; n];
    for c in 0..3 {
        let a: Vec<f64> = planes[c * n..(c + 1) * n]
            .iter()
            .map(|&v| f64::from(v))
            .collect();
        let b: Vec<f64> = target.iter().map(|t| t[c]).collect();
        let prod =
            |p: &[f64], q: &[f64]| -> Vec<f64> { p.iter().zip(q).map(|(x, y)| x * y).collect() };
        let (ma, mb) = (blur(&a), blur(&b));
        let (saa, sbb, sab) = (
            blur(&prod(&a, &a)),
            blur(&prod(&b, &b)),
            blur(&prod(&a, &b)),
        );
        for i in 0..n {
            let (va, vb, cov) = (
                saa[i] - ma[i] * ma[i],
                sbb[i] - mb[i] * mb[i],
                sab[i] - ma[i] * mb[i],
            );
            total[i] += (2.0 * ma[i] * mb[i] + SSIM_C1) * (2.0 * cov + SSIM_C2)
                / ((ma[i] * ma[i] + mb[i] * mb[i] + SSIM_C1) * (va + vb + SSIM_C2))
                / 3.0;
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{Camera, DepthMap, PartMap, RgbaImage};
    use crate::rng::Rng;

    /// The whole image's masked loss, as the bake-off computed it before it cropped.
    fn whole_image(planes: &[f32], frame: &Frame, label: i16, bg: Vec3, w: &LossWeights) -> f64 {
        let n = planes.len() / 5;
        let planar = target_rgb(frame, bg);
        let target: Vec<[f64; 3]> = (0..n)
            .map(|i| [0, 1, 2].map(|c| f64::from(planar[c * n + i])))
            .collect();
        let (iw, ih) = (frame.rgba.width as usize, frame.rgba.height as usize);
        let ssim = ssim_map(planes, &target, iw, ih);
        let ids = &frame.parts.as_ref().unwrap().ids;
        let depth = &frame.depth.as_ref().unwrap().millimetres;
        (0..n)
            .filter(|&i| ids[i] == label)
            .map(|i| {
                let l1 = (0..3)
                    .map(|c| (f64::from(planes[c * n + i]) - target[i][c]).abs())
                    .sum::<f64>()
                    / 3.0;
                let d = (depth[i] > 0).then(|| {
                    f64::from(w.depth)
                        * (f64::from(planes[3 * n + i]) - f64::from(depth[i]) / 1000.0).abs()
                });
                f64::from(w.l1) * l1 + f64::from(w.ssim) * (1.0 - ssim[i]) + d.unwrap_or(0.0)
            })
            .sum()
    }

    #[test]
    fn the_crop_gives_the_whole_images_loss() {
        let (w, h) = (40u32, 30u32);
        let n = (w * h) as usize;
        let mut rng = Rng::new(7);
        let pixels = (0..4 * n).map(|_| rng.below(256) as u8).collect();
        // Part 1 is a blob touching the left border; part 2 a blob in the middle; 3 is absent.
        let ids = (0..n)
            .map(|i| match (i % w as usize, i / w as usize) {
                (x, y) if x < 6 && (8..14).contains(&y) => 1,
                (x, y) if (15..22).contains(&x) && (10..17).contains(&y) => 2,
                _ => -1,
            })
            .collect();
        let millimetres = (0..n).map(|_| rng.below(3000) as u16).collect();
        let frame = Frame {
            name: "0000".into(),
            camera: Camera::from_fov(glam::Mat4::IDENTITY, w, h, 0.7, None),
            time: 1.0,
            rgba: RgbaImage {
                width: w,
                height: h,
                pixels,
            },
            depth: Some(DepthMap {
                width: w,
                height: h,
                millimetres,
            }),
            parts: Some(PartMap {
                width: w,
                height: h,
                ids,
            }),
        };
        let planes: Vec<f32> = (0..5 * n).map(|_| rng.next_f32()).collect();
        let (bg, weights) = (Vec3::new(0.2, 0.3, 0.4), LossWeights::default());
        for (label, pixels) in [(1, 36), (2, 49), (3, 0)] {
            let (sum, count) = masked_image_loss(&planes, &frame, label, bg, &weights);
            assert_eq!(count, pixels, "part {label}");
            let want = whole_image(&planes, &frame, label, bg, &weights);
            assert!(
                (sum - want).abs() <= 1e-9 * want.max(1.0),
                "part {label}: {sum} vs {want}"
            );
        }
    }
}
