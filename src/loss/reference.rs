//! Plain CPU reference of [`super::ImageLoss`]: every term and the full gradient in f64, with
//! straightforward loops (direct 2-D window sums for SSIM, no separable tricks), for tests.

use super::{LossWeights, SSIM_C1, SSIM_C2, SSIM_WINDOW, TargetView, render_channels, ssim_taps};
use crate::gpu::{GpuError, GpuResult};

/// Terms and gradient of one evaluation.
#[derive(Debug, Clone)]
pub struct ReferenceLoss {
    pub total: f64,
    pub l1: f64,
    pub one_minus_ssim: f64,
    pub depth: f64,
    pub part: f64,
    pub mask: f64,
    pub depth_pixels: usize,
    pub label_pixels: usize,
    /// dL/drender, same planar layout as the render.
    pub grad: Vec<f64>,
}

/// The decoded target of one pixel, exactly as the GPU sees it.
struct Pixel {
    rgb: [f64; 3],
    mask: f64,
    depth: f64,
    label: usize,
}

fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Evaluates the loss of `render` (planar, `(5 + num_parts) · W · H` floats) against `target`.
pub fn image_loss(
    width: u32,
    height: u32,
    num_parts: u32,
    render: &[f32],
    target: &TargetView<'_>,
    weights: &LossWeights,
    background: [f32; 3],
) -> GpuResult<ReferenceLoss> {
    let (w, h) = (width as usize, height as usize);
    let n = w * h;
    let channels = render_channels(num_parts) as usize;
    if render.len() != channels * n {
        return Err(GpuError::InvalidInput(format!(
            "reference loss: render has {} floats, expected {}",
            render.len(),
            channels * n
        )));
    }
    if target.rgba.pixels.len() != 4 * n
        || target.depth.is_some_and(|d| d.millimetres.len() != n)
        || target.parts.is_some_and(|p| p.ids.len() != n)
    {
        return Err(GpuError::InvalidInput(
            "reference loss: target images do not match the render size".into(),
        ));
    }
    let bg = background.map(f64::from);
    let pixels: Vec<Pixel> = (0..n)
        .map(|i| {
            let c = &target.rgba.pixels[4 * i..4 * i + 4];
            let m = f64::from(c[3]) / 255.0;
            Pixel {
                rgb: [0, 1, 2].map(|k| f64::from(c[k]) / 255.0 * m + bg[k] * (1.0 - m)),
                mask: m,
                depth: target
                    .depth
                    .map_or(0.0, |d| f64::from(d.millimetres[i]) / 1000.0),
                label: target
                    .parts
                    .map_or(0, |p| (i32::from(p.ids[i]) + 1).max(0) as usize),
            }
        })
        .collect();
    if let Some(bad) = pixels.iter().find(|p| p.label > num_parts as usize) {
        return Err(GpuError::InvalidInput(format!(
            "reference loss: label {} exceeds {num_parts} parts",
            bad.label
        )));
    }
    let r = |c: usize, i: usize| f64::from(render[c * n + i]);
    let mut grad = vec![0.0; channels * n];
    let colour_n = (3 * n) as f64;

    // L1 on colour.
    let mut l1 = 0.0;
    for i in 0..n {
        for c in 0..3 {
            let d = r(c, i) - pixels[i].rgb[c];
            l1 += d.abs();
            grad[c * n + i] += f64::from(weights.l1) * sign(d) / colour_n;
        }
    }
    l1 /= colour_n;

    // SSIM with the full 2-D window, zero padding: S_p and its partials per channel.
    let taps = ssim_taps();
    let radius = (SSIM_WINDOW / 2) as isize;
    let window = |x: usize, y: usize, f: &mut dyn FnMut(usize, f64)| {
        for dy in -radius..=radius {
            for dx in -radius..=radius {
                let (qx, qy) = (x as isize + dx, y as isize + dy);
                if qx < 0 || qy < 0 || qx >= w as isize || qy >= h as isize {
                    continue;
                }
                let g = taps[(dx + radius) as usize] * taps[(dy + radius) as usize];
                f(qy as usize * w + qx as usize, g);
            }
        }
    };
    let mut ssim_sum = 0.0;
    for c in 0..3 {
        // Per pixel p: (∂S/∂μx, ∂S/∂E[x²], ∂S/∂E[xy]).
        let mut partials = vec![[0.0f64; 3]; n];
        for y in 0..h {
            for x in 0..w {
                let mut m = [0.0f64; 5]; // μx, μy, E[x²], E[y²], E[xy]
                window(x, y, &mut |q, g| {
                    let (a, b) = (r(c, q), pixels[q].rgb[c]);
                    m[0] += g * a;
                    m[1] += g * b;
                    m[2] += g * a * a;
                    m[3] += g * b * b;
                    m[4] += g * a * b;
                });
                let (mx, my) = (m[0], m[1]);
                let a1 = 2.0 * mx * my + SSIM_C1;
                let a2 = 2.0 * (m[4] - mx * my) + SSIM_C2;
                let b1 = mx * mx + my * my + SSIM_C1;
                let b2 = (m[2] - mx * mx) + (m[3] - my * my) + SSIM_C2;
                let s = a1 * a2 / (b1 * b2);
                ssim_sum += s;
                partials[y * w + x] = [
                    (2.0 * my * (a2 - a1) - 2.0 * mx * s * (b2 - b1)) / (b1 * b2),
                    -s / b2,
                    2.0 * a1 / (b1 * b2),
                ];
            }
        }
        // dS_total/dx_q = Σ_p g(p − q) [∂μ + 2 x_q ∂xx + y_q ∂xy]; g is symmetric.
        for y in 0..h {
            for x in 0..w {
                let q = y * w + x;
                let (xq, yq) = (r(c, q), pixels[q].rgb[c]);
                let mut d = 0.0;
                window(x, y, &mut |p, g| {
                    let s = partials[p];
                    d += g * (s[0] + 2.0 * xq * s[1] + yq * s[2]);
                });
                grad[c * n + q] -= f64::from(weights.ssim) * d / colour_n;
            }
        }
    }
    let one_minus_ssim = 1.0 - ssim_sum / colour_n;

    // Depth, mask, part cross-entropy.
    let depth_pixels = pixels.iter().filter(|p| p.depth > 0.0).count();
    let label_pixels = pixels.iter().filter(|p| p.label > 0).count();
    let (depth_n, label_n) = (depth_pixels.max(1) as f64, label_pixels.max(1) as f64);
    let (mut depth, mut mask, mut part) = (0.0, 0.0, 0.0);
    for (i, p) in pixels.iter().enumerate() {
        if p.depth > 0.0 {
            let d = r(3, i) - p.depth;
            depth += d.abs();
            grad[3 * n + i] = f64::from(weights.depth) * sign(d) / depth_n;
        }
        let d = r(4, i) - p.mask;
        mask += d.abs();
        grad[4 * n + i] = f64::from(weights.mask) * sign(d) / n as f64;
        if p.label > 0 {
            let logits: Vec<f64> = (0..num_parts as usize).map(|j| r(5 + j, i)).collect();
            let top = logits.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let lse = top + logits.iter().map(|l| (l - top).exp()).sum::<f64>().ln();
            part += lse - logits[p.label - 1];
            for (j, l) in logits.iter().enumerate() {
                let onehot = if j + 1 == p.label { 1.0 } else { 0.0 };
                grad[(5 + j) * n + i] =
                    f64::from(weights.part) * ((l - lse).exp() - onehot) / label_n;
            }
        }
    }
    depth /= depth_n;
    mask /= n as f64;
    part /= label_n;
    let total = f64::from(weights.l1) * l1
        + f64::from(weights.ssim) * one_minus_ssim
        + f64::from(weights.depth) * depth
        + f64::from(weights.part) * part
        + f64::from(weights.mask) * mask;
    Ok(ReferenceLoss {
        total,
        l1,
        one_minus_ssim,
        depth,
        part,
        mask,
        depth_pixels,
        label_pixels,
        grad,
    })
}
