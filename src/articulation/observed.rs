//! The part surfaces the dataset measured: per state and part, points back-projected from every
//! view's full-resolution depth and part map, with normals from planes fitted over each pixel's
//! part (`sampling`, which also estimates the depth's noise), and averaged in voxels so that a
//! hundred overlapping views become one even sample of each part, each knowing its noise.
//!
//! These are the fit's most direct evidence of where each part went: at 800² a pixel covers about
//! 2 mm of a 1 m object and the depth is quantised to 1 mm, while the photometric stages see the
//! object at 64². Pixels on a part's silhouette or a depth jump mix two surfaces and are skipped.

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use serde::Serialize;

use crate::data::Frame;
use crate::data::parallel;
pub use sampling::DepthNoise;
pub(crate) use sampling::MAX_NORMAL_ERROR;
use sampling::{Sample, samples};

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

mod sampling;
#[cfg(test)]
mod tests;
