//! The part surfaces the dataset measured: per state and part, points back-projected from every
//! view's full-resolution depth and part map, with normals from the depth map's neighbours, and
//! averaged in voxels so that a hundred overlapping views become one even sample of each part.
//!
//! These are the fit's most direct evidence of where each part went: at 800² a pixel covers about
//! 2 mm of a 1 m object and the depth is quantised to 1 mm, while the photometric stages see the
//! object at 64². Pixels on a part's silhouette or a depth jump mix two surfaces and are skipped.

use std::collections::HashMap;

use glam::{DVec3, Vec2, Vec3};
use serde::Serialize;

use crate::data::Frame;
use crate::data::parallel;

/// How the clouds are sampled.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CloudOptions {
    /// Pixels back-projected per state at most (the pixel stride grows to stay under it).
    pub max_samples: usize,
    /// A part's voxel edge is its extent divided by this (finer parts get finer voxels) …
    pub voxels_across: f32,
    /// … but never below this (m): the depth maps' own resolution.
    pub min_voxel: f32,
    /// Points per part and state at most (the voxels grow to stay under it).
    pub max_points: usize,
}

impl Default for CloudOptions {
    fn default() -> Self {
        Self {
            max_samples: 4_000_000,
            voxels_across: 120.0,
            min_voxel: 0.001,
            max_points: 8000,
        }
    }
}

/// One part's measured surface in one state.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PartCloud {
    /// Voxel-averaged points (m, world frame).
    pub points: Vec<Vec3>,
    /// Unit normals, one per point, facing the cameras that saw it.
    pub normals: Vec<Vec3>,
    /// Mean colour (RGB in 0–1), one per point.
    pub colors: Vec<Vec3>,
    /// Pixels that went into it (after the stride).
    pub pixels: usize,
    /// Pixels labelled with the part in the views with depth, all of them (silhouettes too).
    pub labelled: usize,
    /// RMS standard deviation (m) of the points' positions, from the depth noise of the views
    /// they were averaged from ([`DepthNoise`]); 0 when unknown.
    pub noise: f32,
}

/// Every part's measured surface in one state.
#[derive(Debug, Clone, PartialEq)]
pub struct ObservedState {
    /// Indexed by part id (0 is the static base).
    pub parts: Vec<PartCloud>,
    /// Views that had both a depth and a part map, of `views`.
    pub views_with_depth: usize,
    pub views: usize,
    /// Pixel stride used (1 = every pixel).
    pub stride: usize,
    /// The depth maps' noise, estimated from the maps themselves (`None`: no view with depth).
    pub noise: Option<DepthNoise>,
}

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
struct Sample {
    part: usize,
    point: Vec3,
    normal: Vec3,
    color: Vec3,
    /// Variance (m²) of the point's position along its normal.
    variance: f32,
}

/// What [`samples`] back-projected from one state's frames.
struct Sampled {
    samples: Vec<Sample>,
    /// Pixels labelled with each part in the views with depth.
    labelled: Vec<usize>,
    /// Views with a depth and a part map of the colour image's size.
    views: usize,
    stride: usize,
    noise: Option<DepthNoise>,
}

/// Back-projects the labelled, depth-carrying pixels of `frames` (part ids < `num_parts`).
fn samples(frames: &[Frame], num_parts: usize, max_samples: usize) -> Sampled {
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
fn view_noise(depth: &[u16], ids: &[i16], w: usize, h: usize, parts: usize) -> Option<(f32, f32)> {
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
const MAX_NORMAL_ERROR: f32 = 0.1;

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
fn frame_samples(
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
        let [a, b, c] = solve3(m, v)?;
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

/// Solves a 3 × 3 system by Cramer's rule; `None` when (near) singular.
fn solve3(m: [[f64; 3]; 3], v: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    if d.abs() < 1e-9 {
        return None;
    }
    let mut out = [0.0; 3];
    for (k, o) in out.iter_mut().enumerate() {
        let mut mk = m;
        for row in 0..3 {
            mk[row][k] = v[row];
        }
        *o = det(&mk) / d;
    }
    Some(out)
}

/// A robust size of a point set: twice the RMS distance from its centroid.
fn extent(points: impl Iterator<Item = Vec3> + Clone) -> f32 {
    let n = points.clone().count().max(1) as f64;
    let c = points.clone().map(|p| p.as_dvec3()).sum::<DVec3>() / n;
    let var = points
        .map(|p| (p.as_dvec3() - c).length_squared())
        .sum::<f64>()
        / n;
    2.0 * var.sqrt() as f32
}

/// The voxel edge (m) part `part` is averaged at, the same in both states.
fn voxel_edge(states: [&[Sample]; 2], part: usize, options: &CloudOptions) -> f32 {
    let size = states
        .iter()
        .map(|s| extent(s.iter().filter(|x| x.part == part).map(|x| x.point)))
        .fold(0.0f32, f32::max);
    (size / options.voxels_across.max(1.0)).max(options.min_voxel)
}

/// A voxel and the side of a thin part its samples face.
type VoxelKey = (i32, i32, i32, u8);
/// Sums of positions, normals, colours and variances, and the sample count.
type VoxelSums = (DVec3, DVec3, DVec3, f64, u32);

/// Averages one part's samples in voxels of edge `edge`, keeping opposite-facing sides of a thin
/// part apart (the key includes the normal's dominant axis and sign).
fn voxelise(samples: &[&Sample], edge: f32) -> PartCloud {
    let mut cells: HashMap<VoxelKey, VoxelSums> = HashMap::new();
    for s in samples {
        let v = (s.point / edge).floor();
        let a = s.normal.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let side = u8::from(s.normal[axis] > 0.0);
        let key = (v.x as i32, v.y as i32, v.z as i32, axis as u8 * 2 + side);
        let cell = cells
            .entry(key)
            .or_insert((DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, 0.0, 0));
        cell.0 += s.point.as_dvec3();
        cell.1 += s.normal.as_dvec3();
        cell.2 += s.color.as_dvec3();
        cell.3 += f64::from(s.variance);
        cell.4 += 1;
    }
    let mut cells: Vec<_> = cells.into_iter().collect();
    // HashMap order is random: sort so the cloud (and every fit from it) is reproducible.
    cells.sort_unstable_by_key(|c| c.0);
    let mut cloud = PartCloud {
        pixels: samples.len(),
        ..PartCloud::default()
    };
    // A voxel's mean of n independent samples has variance Σ var / n².
    let mut variance = 0.0;
    for (_, (p, n, c, var, count)) in cells {
        let normal = n.normalize_or_zero();
        if normal != DVec3::ZERO {
            let count = f64::from(count);
            cloud.points.push((p / count).as_vec3());
            cloud.normals.push(normal.as_vec3());
            cloud.colors.push((c / count).as_vec3());
            variance += var / (count * count);
        }
    }
    cloud.noise = (variance / cloud.points.len().max(1) as f64).sqrt() as f32;
    cloud
}

/// Both states' measured part surfaces from their frames (`frames[0]` start, `frames[1]` end).
pub(crate) fn observe_states(
    frames: [&[Frame]; 2],
    num_parts: usize,
    options: &CloudOptions,
) -> [ObservedState; 2] {
    let sampled = frames.map(|f| samples(f, num_parts, options.max_samples));
    let edges: Vec<f32> = (0..num_parts)
        .map(|part| voxel_edge([&sampled[0].samples, &sampled[1].samples], part, options))
        .collect();
    // Each (state, part) cloud is independent: voxelised on every core.
    let jobs: Vec<(usize, usize)> = (0..2)
        .flat_map(|s| (0..num_parts).map(move |part| (s, part)))
        .collect();
    let mut clouds = parallel::map(&jobs, |&(s, part)| {
        let mine: Vec<&Sample> = sampled[s]
            .samples
            .iter()
            .filter(|x| x.part == part)
            .collect();
        let mut edge = edges[part];
        loop {
            let cloud = voxelise(&mine, edge);
            if cloud.points.len() <= options.max_points {
                return PartCloud {
                    labelled: sampled[s].labelled[part],
                    ..cloud
                };
            }
            edge *= 1.25;
        }
    })
    .into_iter();
    std::array::from_fn(|s| ObservedState {
        parts: clouds.by_ref().take(num_parts).collect(),
        views_with_depth: sampled[s].views,
        views: frames[s].len(),
        stride: sampled[s].stride,
        noise: sampled[s].noise,
    })
}

/// Both states' measured part surfaces from `dataset`'s `split` views at full resolution;
/// `None` when a state has no view of that split.
pub fn observe_dataset(
    dataset: &crate::data::Dataset,
    split: crate::data::Split,
    options: &CloudOptions,
) -> Option<[ObservedState; 2]> {
    use crate::data::State;
    let start = dataset.views(State::Start, split)?;
    let end = dataset.views(State::End, split)?;
    Some(observe_states(
        [&start.frames, &end.frames],
        dataset.num_parts,
        options,
    ))
}

impl PartCloud {
    /// This cloud and `other` of the same part in the same frame, averaged together in voxels of
    /// the part's edge (the two sides of a thin part kept apart): where both saw a place it comes
    /// out once.
    pub fn merged(&self, other: &PartCloud) -> PartCloud {
        let joined = PartCloud {
            points: [&self.points[..], &other.points].concat(),
            normals: [&self.normals[..], &other.normals].concat(),
            colors: [&self.colors[..], &other.colors].concat(),
            pixels: self.pixels + other.pixels,
            labelled: self.labelled + other.labelled,
            // Both clouds' points pooled: their RMS noise (voxelised_under averages it on).
            noise: {
                let var = |c: &PartCloud| f64::from(c.noise).powi(2) * c.points.len() as f64;
                let n = (self.points.len() + other.points.len()).max(1) as f64;
                ((var(self) + var(other)) / n).sqrt() as f32
            },
        };
        joined.voxelised_under(joined.points.len(), 1.0)
    }

    /// The cloud averaged again in coarser voxels (the two sides of a thin part kept apart) until
    /// it has at most `max_points` points; itself if it already has.
    pub fn coarsened(&self, max_points: usize) -> PartCloud {
        if self.points.len() <= max_points {
            return self.clone();
        }
        self.voxelised_under(max_points, 1.25)
    }

    /// Averaged in voxels of the part's default edge times `scale`, the edge growing by a quarter
    /// until at most `max_points` points come out.
    fn voxelised_under(&self, max_points: usize, scale: f32) -> PartCloud {
        let samples: Vec<Sample> = (0..self.points.len())
            .map(|i| Sample {
                part: 0,
                point: self.points[i],
                normal: self.normals[i],
                color: self.colors[i],
                variance: self.noise.powi(2),
            })
            .collect();
        let refs: Vec<&Sample> = samples.iter().collect();
        let defaults = CloudOptions::default();
        let mut edge = scale
            * (extent(self.points.iter().copied()) / defaults.voxels_across)
                .max(defaults.min_voxel);
        loop {
            let cloud = voxelise(&refs, edge);
            if cloud.points.len() <= max_points.max(1) {
                return PartCloud {
                    pixels: self.pixels,
                    labelled: self.labelled,
                    ..cloud
                };
            }
            edge *= 1.25;
        }
    }
}

impl ObservedState {
    /// The points of every part but `part`, at most `max` of them (evenly thinned): what a
    /// joint of `part` attaches to.
    pub fn others(&self, part: usize, max: usize) -> Vec<Vec3> {
        let total: usize = self
            .parts
            .iter()
            .enumerate()
            .filter(|(p, _)| *p != part)
            .map(|(_, c)| c.points.len())
            .sum();
        let step = total / max.max(1) + 1;
        self.parts
            .iter()
            .enumerate()
            .filter(|(p, _)| *p != part)
            .flat_map(|(_, c)| c.points.iter().copied())
            .step_by(step)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{Camera, DepthMap, PartMap, RgbaImage};
    use crate::rng::Rng;

    /// A `size`² view of a wall facing the camera at `metres`, every pixel of part 0, its depth
    /// with Gaussian noise of `sigma_mm` and rounded to the millimetre as a depth PNG holds it.
    fn wall(size: u32, metres: f32, sigma_mm: f32, seed: u64) -> Frame {
        let mut rng = Rng::new(seed);
        let n = (size * size) as usize;
        let millimetres = (0..n)
            .map(|_| {
                let (u, v) = (rng.uniform(1e-7, 1.0), rng.uniform(0.0, 1.0));
                let z = (-2.0 * u.ln()).sqrt() * (std::f32::consts::TAU * v).cos();
                (1000.0 * metres + sigma_mm * z).round() as u16
            })
            .collect();
        Frame {
            name: "0000".into(),
            camera: Camera::from_fov(glam::Mat4::IDENTITY, size, size, 0.691, None),
            time: 0.0,
            rgba: RgbaImage {
                width: size,
                height: size,
                pixels: vec![200; 4 * n],
            },
            depth: Some(DepthMap {
                width: size,
                height: size,
                millimetres,
            }),
            parts: Some(PartMap {
                width: size,
                height: size,
                ids: vec![0; n],
            }),
        }
    }

    #[test]
    fn the_depth_noise_is_estimated_from_the_map_alone() {
        for (sigma, metres) in [(2.0, 1.0), (8.0, 2.5)] {
            let frame = wall(200, metres, sigma, 7);
            let d = frame.depth.as_ref().unwrap();
            let ids = &frame.parts.as_ref().unwrap().ids;
            let (est, at) = view_noise(&d.millimetres, ids, 200, 200, 1).unwrap();
            // Rounding adds 1/12 mm² of variance.
            let expected = (sigma * sigma + 1.0 / 12.0).sqrt() / 1000.0;
            assert!((est / expected - 1.0).abs() < 0.1, "{est} vs {expected}");
            assert!((at - metres).abs() < 0.01, "{at}");
        }
        // Noise-free depth: only the rounding, and samples from the nearest neighbours.
        let frame = wall(200, 2.0, 0.0, 7);
        let (_, _, noise) = frame_samples(&frame, 1, 4);
        let noise = noise.unwrap();
        assert!(noise.sigma < 0.000_5, "{noise:?}");
        assert_eq!(noise.reach, 1);
    }

    #[test]
    fn noisy_depth_is_averaged_over_a_plane_fit() {
        // 8 mm of noise at 2.5 m with 800 px across 39.6°: a pixel covers 2.3 mm, so the
        // nearest neighbours' normals would be noise; the plane fits must average it away.
        let frame = wall(800, 2.5, 8.0, 3);
        let (samples, _, noise) = frame_samples(&frame, 1, 8);
        let noise = noise.unwrap();
        assert!(noise.reach > 1, "{noise:?}");
        assert!(!samples.is_empty());
        let n = samples.len() as f32;
        let rms_z = (samples
            .iter()
            .map(|s| (s.point.z + 2.5).powi(2))
            .sum::<f32>()
            / n)
            .sqrt();
        // Each sample averages (2R + 1)² pixels: its depth error is σ / (2R + 1) or so.
        assert!(rms_z < 0.008 / 3.0, "{rms_z}");
        // Each normal's error is at most MAX_NORMAL_ERROR per tangent direction (how the reach
        // is chosen), so the RMS tilt is within √2 of it.
        let tilt = (samples
            .iter()
            .map(|s| s.normal.angle_between(Vec3::Z).powi(2))
            .sum::<f32>()
            / n)
            .sqrt();
        assert!(tilt < std::f32::consts::SQRT_2 * MAX_NORMAL_ERROR, "{tilt}");
        assert!(
            samples
                .iter()
                .all(|s| s.variance < (0.008f32).powi(2) / 9.0),
            "per-sample variance"
        );
    }
}
