//! The bake-off's per-pixel image loss on the CPU: the render against the target on one
//! part's pixels, with a per-pixel SSIM map (the GPU loss only reduces SSIM over the image).

use glam::Vec3;

use crate::data::Frame;
use crate::fit::photometric::target_rgb;
use crate::loss::{LossWeights, SSIM_C1, SSIM_C2, ssim_taps};

/// Σ over pixels labelled `label` (part id; −1 is background) of the per-pixel image loss (the bake-off's masked loss).
pub(super) fn masked_image_loss(
    planes: &[f32],
    frame: &Frame,
    label: i16,
    background: Vec3,
    weights: &LossWeights,
) -> (f64, usize) {
    let (w, h) = (frame.rgba.width as usize, frame.rgba.height as usize);
    let n = w * h;
    // The target composited over the background exactly as the GPU loss sees it.
    let planar = target_rgb(frame, background);
    let target: Vec<[f64; 3]> = (0..n)
        .map(|i| [0, 1, 2].map(|c| f64::from(planar[c * n + i])))
        .collect();
    let ssim = ssim_map(planes, &target, w, h);
    let ids = frame.parts.as_ref().map(|p| &p.ids);
    let (mut sum, mut count) = (0.0, 0);
    for i in 0..n {
        if ids.is_none_or(|ids| ids[i] != label) {
            continue;
        }
        let l1 = (0..3)
            .map(|c| (f64::from(planes[c * n + i]) - target[i][c]).abs())
            .sum::<f64>()
            / 3.0;
        let mut loss = f64::from(weights.l1) * l1 + f64::from(weights.ssim) * (1.0 - ssim[i]);
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
