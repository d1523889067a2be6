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
}

/// Pixels between a point and the neighbours its normal is taken from. Two would halve the depth
/// noise in the normals but lose a pixel more along every silhouette: at 200² the laptop's thin
/// lid then fitted flipped (46° off), so one.
const NORMAL_REACH: usize = 1;

/// A back-projected pixel before voxel averaging.
struct Sample {
    part: usize,
    point: Vec3,
    normal: Vec3,
    color: Vec3,
}

/// Back-projects the labelled, depth-carrying pixels of `frames` (part ids < `num_parts`).
fn samples(
    frames: &[Frame],
    num_parts: usize,
    max_samples: usize,
) -> (Vec<Sample>, Vec<usize>, usize, usize) {
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
    for (samples, counts) in per_frame {
        out.extend(samples);
        labelled.iter_mut().zip(counts).for_each(|(n, c)| *n += c);
    }
    (out, labelled, usable.len(), stride)
}

/// One frame's samples at pixel stride `stride`, and its pixel count per part label.
fn frame_samples(frame: &Frame, num_parts: usize, stride: usize) -> (Vec<Sample>, Vec<usize>) {
    let mut out = Vec::new();
    let mut labelled = vec![0; num_parts];
    let (Some(depth), Some(parts)) = (&frame.depth, &frame.parts) else {
        return (out, labelled);
    };
    for &id in &parts.ids {
        if let Some(n) = usize::try_from(id).ok().and_then(|i| labelled.get_mut(i)) {
            *n += 1;
        }
    }
    let (w, h) = (frame.rgba.width as usize, frame.rgba.height as usize);
    let eye = frame.camera.position();
    let point = |x: usize, y: usize| -> Option<Vec3> {
        let d = depth.millimetres[y * w + x];
        (d > 0).then(|| {
            frame.camera.unproject(
                Vec2::new(x as f32 + 0.5, y as f32 + 0.5),
                f32::from(d) / 1000.0,
            )
        })
    };
    const R: usize = NORMAL_REACH;
    for y in (R..h.saturating_sub(R)).step_by(stride) {
        for x in (R..w.saturating_sub(R)).step_by(stride) {
            let i = y * w + x;
            let id = parts.ids[i];
            if id < 0 || id as usize >= num_parts {
                continue;
            }
            // The neighbours out to the normal's reach on the same part and surface: no
            // silhouette, no jump.
            let same = (1..=R)
                .flat_map(|k| [i - k, i + k, i - k * w, i + k * w])
                .all(|j| parts.ids[j] == id);
            let (Some(c), Some(l), Some(r), Some(u), Some(d)) = (
                point(x, y),
                point(x - R, y),
                point(x + R, y),
                point(x, y - R),
                point(x, y + R),
            ) else {
                continue;
            };
            let reach = (c - eye).length();
            let smooth = [l, r, u, d]
                .iter()
                .all(|q| (*q - c).length() < 0.02 * R as f32 * reach);
            if !same || !smooth {
                continue;
            }
            let mut normal = (r - l).cross(u - d).normalize_or_zero();
            if normal.dot(eye - c) < 0.0 {
                normal = -normal;
            }
            if normal != Vec3::ZERO {
                let rgb = &frame.rgba.pixels[4 * i..4 * i + 3];
                out.push(Sample {
                    part: id as usize,
                    point: c,
                    normal,
                    color: Vec3::new(rgb[0].into(), rgb[1].into(), rgb[2].into()) / 255.0,
                });
            }
        }
    }
    (out, labelled)
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
/// Sums of positions, normals and colours, and the sample count.
type VoxelSums = (DVec3, DVec3, DVec3, u32);

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
            .or_insert((DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, 0));
        cell.0 += s.point.as_dvec3();
        cell.1 += s.normal.as_dvec3();
        cell.2 += s.color.as_dvec3();
        cell.3 += 1;
    }
    let mut cells: Vec<_> = cells.into_iter().collect();
    // HashMap order is random: sort so the cloud (and every fit from it) is reproducible.
    cells.sort_unstable_by_key(|c| c.0);
    let mut cloud = PartCloud {
        pixels: samples.len(),
        ..PartCloud::default()
    };
    for (_, (p, n, c, count)) in cells {
        let normal = n.normalize_or_zero();
        if normal != DVec3::ZERO {
            cloud.points.push((p / f64::from(count)).as_vec3());
            cloud.normals.push(normal.as_vec3());
            cloud.colors.push((c / f64::from(count)).as_vec3());
        }
    }
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
        .map(|part| voxel_edge([&sampled[0].0, &sampled[1].0], part, options))
        .collect();
    // Each (state, part) cloud is independent: voxelised on every core.
    let jobs: Vec<(usize, usize)> = (0..2)
        .flat_map(|s| (0..num_parts).map(move |part| (s, part)))
        .collect();
    let mut clouds = parallel::map(&jobs, |&(s, part)| {
        let mine: Vec<&Sample> = sampled[s].0.iter().filter(|x| x.part == part).collect();
        let mut edge = edges[part];
        loop {
            let cloud = voxelise(&mine, edge);
            if cloud.points.len() <= options.max_points {
                return PartCloud {
                    labelled: sampled[s].1[part],
                    ..cloud
                };
            }
            edge *= 1.25;
        }
    })
    .into_iter();
    std::array::from_fn(|s| {
        let (_, _, views_with_depth, stride) = &sampled[s];
        ObservedState {
            parts: clouds.by_ref().take(num_parts).collect(),
            views_with_depth: *views_with_depth,
            views: frames[s].len(),
            stride: *stride,
        }
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
