//! Depth pixels to surface samples: each view's depth noise estimated from its own map, and per
//! pixel a point and normal from a plane fitted over a window of its part wide enough that the
//! noise leaves the normal within [`MAX_NORMAL_ERROR`]; the samples of every view of a state.

use glam::{DMat3, DVec3, Vec2, Vec3};
use serde::Serialize;

use crate::data::Frame;
use crate::data::parallel;

/// How noisy a capture's depth maps are, estimated from the maps alone (never from how they
/// were made): per view, the median RMS residual of 3 × 3 pixel plane fits over one part.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DepthNoise {
    /// Median over the views of a depth pixel's standard deviation about its local plane (m).
    pub sigma: f32,
    /// Median over the views of the depth (m) that standard deviation was measured at.
    pub depth: f32,
    /// Median over the views of the half-width (px) of the windows the samples' planes were
    /// fitted over ([`reach`]; 1: the nearest neighbours, as for noise-free depth).
    pub reach: usize,
}

/// A back-projected pixel before voxel averaging.
pub(super) struct Sample {
    pub(super) part: usize,
    pub(super) point: Vec3,
    pub(super) normal: Vec3,
    pub(super) color: Vec3,
    /// Variance (m²) of the point's position along its normal.
    pub(super) variance: f32,
}

/// What [`samples`] back-projected from one state's frames.
pub(super) struct Sampled {
    pub(super) samples: Vec<Sample>,
    /// Pixels labelled with each part in the views with depth.
    pub(super) labelled: Vec<usize>,
    /// Views with a depth and a part map of the colour image's size.
    pub(super) views: usize,
    pub(super) stride: usize,
    pub(super) noise: Option<DepthNoise>,
}

/// Back-projects the labelled, depth-carrying pixels of `frames` (part ids < `num_parts`).
pub(super) fn samples(frames: &[Frame], num_parts: usize, max_samples: usize) -> Sampled {
    let usable: Vec<&Frame> = frames
        .iter()
        .filter(|f| {
            let (w, h) = (f.rgba.width, f.rgba.height);
            f.depth
                .as_ref()
                .zip(f.parts.as_ref())
                .is_some_and(|(d, p)| {
                    d.width == w && d.height == h && p.width == w && p.height == h
                })
        })
        .collect();
    let pixels: usize = usable
        .iter()
        .map(|f| f.rgba.width as usize * f.rgba.height as usize)
        .sum();
    let stride = ((pixels as f64 / max_samples.max(1) as f64).sqrt().ceil() as usize).max(1);
    // Frames are independent: sampled on every core, concatenated in frame order.
    let per_frame = parallel::map(&usable, |frame| frame_samples(frame, num_parts, stride));
    let mut out = Vec::with_capacity(per_frame.iter().map(|f| f.0.len()).sum());
    let mut labelled = vec![0; num_parts];
    let mut noises = Vec::new();
    for (samples, counts, noise) in per_frame {
        out.extend(samples);
        labelled.iter_mut().zip(counts).for_each(|(n, c)| *n += c);
        noises.extend(noise);
    }
    Sampled {
        samples: out,
        labelled,
        views: usable.len(),
        stride,
        noise: median_noise(&noises),
    }
}

/// The median of each field over the views' noise estimates.
fn median_noise(views: &[DepthNoise]) -> Option<DepthNoise> {
    fn median<T: Copy + PartialOrd>(mut v: Vec<T>) -> T {
        v.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
        v[v.len() / 2]
    }
    (!views.is_empty()).then(|| DepthNoise {
        sigma: median(views.iter().map(|n| n.sigma).collect()),
        depth: median(views.iter().map(|n| n.depth).collect()),
        reach: median(views.iter().map(|n| n.reach).collect()),
    })
}

/// Windows a view's noise is estimated from, at most (evenly spread): plenty for a median.
const NOISE_WINDOWS: usize = 20_000;

/// Median of s / σ for s the RMS residual of a 3 × 3 plane fit (6 degrees of freedom) to
/// Gaussian noise of deviation σ: √(median χ²₆ / 6) = √(5.348 / 6).
const PLANE_FIT_MEDIAN: f32 = 0.944;

/// A view's depth noise: the median RMS residual of plane fits to 3 × 3 windows of depth that
/// lie on one part, over [`PLANE_FIT_MEDIAN`]. Windows across a crease or a depth jump fit
/// badly, but they are a minority at any resolution where depth can measure a joint, and the
/// median ignores them. Returns (σ, the windows' median depth), both in metres.
pub(super) fn view_noise(
    depth: &[u16],
    ids: &[i16],
    w: usize,
    h: usize,
    parts: usize,
) -> Option<(f32, f32)> {
    let step = ((w * h / NOISE_WINDOWS) as f64).sqrt().ceil().max(1.0) as usize;
    let mut residuals = Vec::new();
    let mut depths = Vec::new();
    for y in (1..h.saturating_sub(1)).step_by(step) {
        for x in (1..w.saturating_sub(1)).step_by(step) {
            let id = ids[y * w + x];
            if id < 0 || id as usize >= parts {
                continue;
            }
            let mut d = [0f32; 9];
            let mut ok = true;
            for (k, v) in d.iter_mut().enumerate() {
                let j = (y + k / 3 - 1) * w + x + k % 3 - 1;
                ok &= ids[j] == id && depth[j] > 0;
                *v = f32::from(depth[j]);
            }
            if !ok {
                continue;
            }
            // Least squares over the symmetric window: the slopes decouple.
            let mean = d.iter().sum::<f32>() / 9.0;
            let (mut bx, mut by) = (0.0, 0.0);
            for (k, v) in d.iter().enumerate() {
                bx += (k % 3) as f32 * v - v;
                by += (k / 3) as f32 * v - v;
            }
            let (bx, by) = (bx / 6.0, by / 6.0);
            let rss: f32 = d
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    let (dx, dy) = ((k % 3) as f32 - 1.0, (k / 3) as f32 - 1.0);
                    (v - mean - bx * dx - by * dy).powi(2)
                })
                .sum();
            residuals.push((rss / 6.0).sqrt());
            depths.push(mean);
        }
    }
    if residuals.is_empty() {
        return None;
    }
    let mid = residuals.len() / 2;
    let sigma = *residuals.select_nth_unstable_by(mid, f32::total_cmp).1 / PLANE_FIT_MEDIAN;
    let depth = *depths.select_nth_unstable_by(mid, f32::total_cmp).1;
    Some((sigma / 1000.0, depth / 1000.0))
}

/// Largest error (rad) of a sample's fitted normal: the voxels keep a thin part's two sides
/// apart by the normal's dominant axis, which needs well under 45°, and a match one point
/// spacing ℓ away is then off by about ℓ/10 in its point-to-plane distance, under the spread of
/// the voxel averaging itself (ℓ/√12).
pub(crate) const MAX_NORMAL_ERROR: f32 = 0.1;

/// The half-width (px) of the window a view's samples are fitted over: the smallest whose
/// least-squares plane has a normal error σ / (f √S) under [`MAX_NORMAL_ERROR`], with f the
/// pixel's footprint (m) and S = Σ dx² over the (2R + 1)² window; at most a 128th of the image's
/// shorter side (a window must stay small against a part's image: a handle spans about that at
/// the suites' framing), and 1 for noise-free depth. (A reach of 2 on noise-free depth loses a
/// pixel more along every silhouette: at 200² the laptop's thin lid then fitted flipped, 46° off.)
fn reach(sigma: f32, depth: f32, focal_px: f32, w: usize, h: usize) -> usize {
    let footprint = depth / focal_px.max(1e-6);
    let most = (w.min(h) / 128).max(1);
    (1..=most)
        .find(|&r| {
            let r = r as f32;
            let s = (2.0 * r + 1.0).powi(2) * r * (r + 1.0) / 3.0;
            sigma / (footprint * s.sqrt()) <= MAX_NORMAL_ERROR
        })
        .unwrap_or(most)
}

/// One frame's samples at pixel stride `stride`, its pixel count per part label, and its depth
/// noise.
pub(super) fn frame_samples(
    frame: &Frame,
    num_parts: usize,
    stride: usize,
) -> (Vec<Sample>, Vec<usize>, Option<DepthNoise>) {
    let mut labelled = vec![0; num_parts];
    let (Some(depth), Some(parts)) = (&frame.depth, &frame.parts) else {
        return (Vec::new(), labelled, None);
    };
    for &id in &parts.ids {
        if let Some(n) = usize::try_from(id).ok().and_then(|i| labelled.get_mut(i)) {
            *n += 1;
        }
    }
    let (w, h) = (frame.rgba.width as usize, frame.rgba.height as usize);
    let ids = &parts.ids;
    let Some((sigma, at)) = view_noise(&depth.millimetres, ids, w, h, num_parts) else {
        return (Vec::new(), labelled, None);
    };
    let r = reach(sigma, at, frame.camera.intrinsics.fx, w, h);
    let noise = DepthNoise {
        sigma,
        depth: at,
        reach: r,
    };
    let view = View {
        frame,
        depth: &depth.millimetres,
        ids,
        w,
        num_parts,
        sigma_mm: 1000.0 * sigma,
    };
    let mut out = Vec::new();
    for y in (r..h.saturating_sub(r)).step_by(stride) {
        for x in (r..w.saturating_sub(r)).step_by(stride) {
            let sample = if r == 1 {
                view.neighbour_sample(x, y)
            } else {
                view.plane_sample(x, y, r)
            };
            out.extend(sample);
        }
    }
    (out, labelled, Some(noise))
}

/// One view's maps, as the samplers read them.
struct View<'a> {
    frame: &'a Frame,
    depth: &'a [u16],
    ids: &'a [i16],
    w: usize,
    num_parts: usize,
    /// The view's depth noise (mm).
    sigma_mm: f32,
}

impl View<'_> {
    /// The part at pixel `i`, if it is one of the object's.
    fn part(&self, i: usize) -> Option<usize> {
        let id = self.ids[i];
        (id >= 0 && (id as usize) < self.num_parts).then_some(id as usize)
    }

    /// Pixel (x, y) back-projected at depth `mm`.
    fn point(&self, x: f32, y: f32, mm: f32) -> Vec3 {
        self.frame
            .camera
            .unproject(Vec2::new(x + 0.5, y + 0.5), mm / 1000.0)
    }

    /// A sample with `normal` at `point` of pixel `i`, turned to face the camera.
    fn sample(
        &self,
        i: usize,
        part: usize,
        point: Vec3,
        normal: Vec3,
        variance: f32,
    ) -> Option<Sample> {
        let eye = self.frame.camera.position();
        let mut normal = normal.normalize_or_zero();
        if normal.dot(eye - point) < 0.0 {
            normal = -normal;
        }
        let rgb = &self.frame.rgba.pixels[4 * i..4 * i + 3];
        (normal != Vec3::ZERO).then(|| Sample {
            part,
            point,
            normal,
            color: Vec3::new(rgb[0].into(), rgb[1].into(), rgb[2].into()) / 255.0,
            variance,
        })
    }

    /// Noise-free depth: the pixel's own depth, the normal from its four nearest neighbours
    /// on the same part and surface (no silhouette, no jump).
    fn neighbour_sample(&self, x: usize, y: usize) -> Option<Sample> {
        let (w, i) = (self.w, y * self.w + x);
        let part = self.part(i)?;
        if [i - 1, i + 1, i - w, i + w]
            .iter()
            .any(|&j| self.ids[j] != self.ids[i])
        {
            return None;
        }
        let at = |j: usize| {
            let d = self.depth[j];
            (d > 0).then(|| self.point((j % w) as f32, (j / w) as f32, f32::from(d)))
        };
        let (c, l, r, u, d) = (at(i)?, at(i - 1)?, at(i + 1)?, at(i - w)?, at(i + w)?);
        let reach = (c - self.frame.camera.position()).length();
        if [l, r, u, d]
            .iter()
            .any(|q| (*q - c).length() >= 0.02 * reach)
        {
            return None;
        }
        let variance = (self.sigma_mm / 1000.0).powi(2);
        self.sample(i, part, c, (r - l).cross(u - d), variance)
    }

    /// Noisy depth: a least-squares plane over the (2r + 1)² window's pixels on the same part;
    /// the point is the plane's depth at the pixel and the normal the plane's, so both average
    /// the window's noise. Windows mostly off the part, or that a plane does not fit (a
    /// crease, a depth jump, a flying pixel at the centre), give no sample.
    fn plane_sample(&self, x: usize, y: usize, r: usize) -> Option<Sample> {
        let (w, i) = (self.w, y * self.w + x);
        let part = self.part(i)?;
        if self.depth[i] == 0 {
            return None;
        }
        let ri = r as i64;
        let window = || {
            (-ri..=ri)
                .flat_map(move |dy| (-ri..=ri).map(move |dx| (dx, dy)))
                .filter_map(move |(dx, dy)| {
                    let j = (y as i64 + dy) as usize * w + (x as i64 + dx) as usize;
                    let d = self.depth[j];
                    (self.ids[j] == self.ids[i] && d > 0).then_some((
                        dx as f64,
                        dy as f64,
                        f64::from(d),
                    ))
                })
        };
        // Normal equations of d = a + b dx + c dy.
        let (mut m, mut v) = ([[0f64; 3]; 3], [0f64; 3]);
        let mut n = 0usize;
        for (dx, dy, d) in window() {
            let row = [1.0, dx, dy];
            for a in 0..3 {
                v[a] += row[a] * d;
                for b in 0..3 {
                    m[a][b] += row[a] * row[b];
                }
            }
            n += 1;
        }
        // Three quarters of the window: enough spread for both slopes.
        if 4 * n < 3 * (2 * r + 1).pow(2) {
            return None;
        }
        // The normal matrix is symmetric, so rows read as columns; (near) singular: the window's
        // pixels do not spread in both directions.
        let normal_matrix = DMat3::from_cols_array_2d(&m);
        if normal_matrix.determinant().abs() < 1e-9 {
            return None;
        }
        let [a, b, c] = (normal_matrix.inverse() * DVec3::from_array(v)).to_array();
        let rss: f64 = window()
            .map(|(dx, dy, d)| (d - a - b * dx - c * dy).powi(2))
            .sum();
        let s = (rss / (n - 3) as f64).sqrt() as f32;
        let centre = f64::from(self.depth[i]) - a;
        // Over twice the view's noise is no plane; a centre 3σ off it is an outlier.
        if s > 2.0 * self.sigma_mm || centre.abs() as f32 > 3.0 * self.sigma_mm {
            return None;
        }
        let (xf, yf, rf) = (x as f32, y as f32, r as f64);
        let at = |dx: f64, dy: f64| {
            self.point(xf + dx as f32, yf + dy as f32, (a + b * dx + c * dy) as f32)
        };
        let normal = (at(rf, 0.0) - at(-rf, 0.0)).cross(at(0.0, -rf) - at(0.0, rf));
        let variance = (self.sigma_mm / 1000.0).powi(2) / n as f32;
        self.sample(i, part, at(0.0, 0.0), normal, variance)
    }
}
