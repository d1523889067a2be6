//! A straightforward CPU renderer of the same model as the GPU rasterizer, in `f64`: every
//! pixel loops over every face in depth order. It exists to check the GPU forward pass; it
//! shares no code with the kernels except the depth-key quantisation that fixes the order.

use glam::{DVec2, DVec3};

use super::field::{MeshField, SH_FLOATS};
use super::kernels::LOG_DEPTH_RANGE;
use super::settings::{BASE_CHANNELS, RasterSettings, sort_key_bits};
use super::state::RenderImages;
use crate::data::Camera;

const C0: f64 = 0.282_094_791_773_878_14;
const C1: f64 = 0.488_602_511_902_919_9;
const C2: [f64; 5] = [
    1.092_548_430_592_079_2,
    -1.092_548_430_592_079_2,
    0.315_391_565_252_520_05,
    -1.092_548_430_592_079_2,
    0.546_274_215_296_039_6,
];
const C3: [f64; 7] = [
    -0.590_043_589_926_643_5,
    2.890_611_442_640_554,
    -0.457_045_799_464_465_8,
    0.373_176_332_590_115_4,
    -0.457_045_799_464_465_8,
    1.445_305_721_320_277,
    -0.590_043_589_926_643_5,
];

/// Real SH basis Y_0..Y_15 at unit direction `d`, zero beyond `degree`.
pub(crate) fn sh_basis(d: DVec3, degree: u32) -> [f64; 16] {
    let (x, y, z) = (d.x, d.y, d.z);
    let mut b = [0.0; 16];
    b[0] = C0;
    if degree >= 1 {
        b[1] = -C1 * y;
        b[2] = C1 * z;
        b[3] = -C1 * x;
    }
    if degree >= 2 {
        b[4] = C2[0] * x * y;
        b[5] = C2[1] * y * z;
        b[6] = C2[2] * (2.0 * z * z - x * x - y * y);
        b[7] = C2[3] * x * z;
        b[8] = C2[4] * (x * x - y * y);
    }
    if degree >= 3 {
        b[9] = C3[0] * y * (3.0 * x * x - y * y);
        b[10] = C3[1] * x * y * z;
        b[11] = C3[2] * y * (4.0 * z * z - x * x - y * y);
        b[12] = C3[3] * z * (2.0 * z * z - 3.0 * x * x - 3.0 * y * y);
        b[13] = C3[4] * x * (4.0 * z * z - x * x - y * y);
        b[14] = C3[5] * z * (x * x - y * y);
        b[15] = C3[6] * x * (x * x - 3.0 * y * y);
    }
    b
}

/// Vertex colour seen from `eye`: max(Σ Y_l c_l + 0.5, 0).
pub(crate) fn vertex_color(field: &MeshField, v: usize, eye: DVec3, degree: u32) -> DVec3 {
    let d = (field.positions[v].as_dvec3() - eye).normalize_or_zero();
    let basis = sh_basis(d, degree.min(3));
    let c = &field.sh[v * SH_FLOATS..(v + 1) * SH_FLOATS];
    let mut rgb = DVec3::splat(0.5);
    for (l, y) in basis.iter().enumerate() {
        rgb += *y * DVec3::new(c[3 * l].into(), c[3 * l + 1].into(), c[3 * l + 2].into());
    }
    rgb.max(DVec3::ZERO)
}

struct Projected {
    face: usize,
    key: u32,
    s: [DVec2; 3],
    inv_w: [f64; 3],
    sigma: f64,
    colors: [DVec3; 3],
}

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

/// The sort key's depth part, as `raster_bin.wgsl` computes it (in `f32`, so the order matches).
fn depth_key(depth: f32, depth_bits: u32) -> u32 {
    let mask = (1u32 << depth_bits) - 1;
    let (lo, hi) = LOG_DEPTH_RANGE;
    let t = ((depth.max(1e-30).ln() - lo) / (hi - lo)).clamp(0.0, 1.0);
    ((t * mask as f32) as u32).min(mask)
}

/// Renders `field` from `camera`: the same planes as [`super::RasterState::read_render`].
pub fn render(field: &MeshField, camera: &Camera, settings: &RasterSettings) -> RenderImages {
    render_with_stats(field, camera, settings).0
}

/// [`render`], plus per face its largest blending weight α·T and the number of pixels it
/// contributed to (what [`super::RasterState::read_face_stats`] returns for one render).
pub(crate) fn render_with_stats(
    field: &MeshField,
    camera: &Camera,
    settings: &RasterSettings,
) -> (RenderImages, Vec<(f32, u32)>) {
    let k = camera.intrinsics;
    let (w, h) = (k.width, k.height);
    let parts = field.num_parts;
    let view = camera.world_to_camera().as_dmat4();
    let eye = camera.position().as_dvec3();
    let degree = settings.sh_degree.min(3);
    let depth_bits = sort_key_bits(w, h).map(|b| b.1).unwrap_or(16);
    let floor = f64::from(settings.opacity_floor.clamp(0.0, 1.0));

    let mut faces = Vec::new();
    for (f, idx) in field.faces.iter().enumerate() {
        let mut s = [DVec2::ZERO; 3];
        let mut wv = [0.0; 3];
        let mut o = 0.0;
        for i in 0..3 {
            let c = view.transform_point3(field.positions[idx[i] as usize].as_dvec3());
            wv[i] = -c.z;
            s[i] = DVec2::new(
                f64::from(k.cx) + f64::from(k.fx) * c.x / wv[i],
                f64::from(k.cy) - f64::from(k.fy) * c.y / wv[i],
            );
            o += sigmoid(field.opacity[idx[i] as usize].into());
        }
        let sigma = floor + (1.0 - floor) * o / 3.0;
        let area2 = (s[1] - s[0]).perp_dot(s[2] - s[0]);
        let min_edge = (s[1] - s[2])
            .length()
            .min((s[2] - s[0]).length())
            .min((s[0] - s[1]).length());
        if wv.iter().any(|&d| d < f64::from(settings.near))
            || sigma < 0.01
            || area2.abs() < 1e-6
            || min_edge < 1e-6
        {
            continue;
        }
        let mean_depth = ((wv[0] + wv[1] + wv[2]) / 3.0) as f32;
        faces.push(Projected {
            face: f,
            key: depth_key(mean_depth, depth_bits),
            s,
            inv_w: wv.map(|d| 1.0 / d),
            sigma,
            colors: idx.map(|v| vertex_color(field, v as usize, eye, degree)),
        });
    }
    faces.sort_by_key(|p| (p.key, p.face));

    let npix = (w * h) as usize;
    let mut stats = vec![(0.0f32, 0u32); field.faces.len()];
    let mut planes = vec![0.0f32; (BASE_CHANNELS + parts) * npix];
    let gamma = f64::from(settings.gamma);
    for py in 0..h {
        for px in 0..w {
            let p = DVec2::new(f64::from(px) + 0.5, f64::from(py) + 0.5);
            let mut t = 1.0f64;
            let mut acc = vec![0.0f64; BASE_CHANNELS + parts];
            for face in &faces {
                let [a, b, c] = face.s;
                let area2 = (b - a).perp_dot(c - a);
                let lambda = [
                    (b - p).perp_dot(c - p) / area2,
                    (c - p).perp_dot(a - p) / area2,
                    (a - p).perp_dot(b - p) / area2,
                ];
                let l = [(b - c).length(), (c - a).length(), (a - b).length()];
                let perimeter = l[0] + l[1] + l[2];
                let u = (0..3)
                    .map(|i| lambda[i] * perimeter / l[i])
                    .fold(f64::INFINITY, f64::min);
                if u <= 0.0 {
                    continue;
                }
                let alpha = (face.sigma * u.powf(gamma)).min(0.99);
                if alpha < f64::from(settings.alpha_min) || alpha <= 0.0 {
                    continue;
                }
                let rho: Vec<f64> = (0..3).map(|i| lambda[i] * face.inv_w[i]).collect();
                let zsum: f64 = rho.iter().sum();
                let mu: Vec<f64> = rho.iter().map(|r| r / zsum).collect();
                let weight = alpha * t;
                let stat = &mut stats[face.face];
                *stat = (stat.0.max(weight as f32), stat.1 + 1);
                let color =
                    face.colors[0] * mu[0] + face.colors[1] * mu[1] + face.colors[2] * mu[2];
                acc[0] += weight * color.x;
                acc[1] += weight * color.y;
                acc[2] += weight * color.z;
                acc[3] += weight / zsum;
                acc[4] += weight;
                let verts = field.faces[face.face];
                for part in 0..parts {
                    let s: f64 = (0..3)
                        .map(|i| {
                            mu[i] * f64::from(field.part_logits[verts[i] as usize * parts + part])
                        })
                        .sum();
                    acc[BASE_CHANNELS + part] += weight * s;
                }
                t *= 1.0 - alpha;
                if t < f64::from(settings.transmittance_min) {
                    break;
                }
            }
            let bg = settings.background.as_dvec3();
            acc[0] += t * bg.x;
            acc[1] += t * bg.y;
            acc[2] += t * bg.z;
            let i = (py * w + px) as usize;
            for (c, value) in acc.iter().enumerate() {
                planes[c * npix + i] = *value as f32;
            }
        }
    }
    let images = RenderImages {
        width: w,
        height: h,
        num_parts: parts,
        planes,
    };
    (images, stats)
}

/// Peak signal-to-noise ratio (dB) between two RGB images in [0, 1], planar as rendered.
pub fn psnr(a: &[f32], b: &[f32]) -> f64 {
    let mse = a
        .iter()
        .zip(b)
        .map(|(x, y)| (f64::from(*x) - f64::from(*y)).powi(2))
        .sum::<f64>()
        / a.len().max(1) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        -10.0 * mse.log10()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn dc_colour_round_trips_through_the_basis() {
        let mut field = MeshField::new(vec![Vec3::ZERO], vec![], 1, 0.0);
        field.set_color(0, Vec3::new(0.2, 0.5, 0.9));
        let c = vertex_color(&field, 0, DVec3::new(0.0, -2.0, 0.0), 3);
        assert!(
            (c - DVec3::new(0.2, 0.5, 0.9)).abs().max_element() < 1e-6,
            "{c}"
        );
    }

    #[test]
    fn depth_keys_are_monotonic() {
        let keys: Vec<u32> = [0.01f32, 0.5, 1.0, 1.001, 3.0, 100.0]
            .iter()
            .map(|&d| depth_key(d, 18))
            .collect();
        assert!(keys.windows(2).all(|k| k[0] < k[1]), "{keys:?}");
    }
}
