//! Chamfer distance between part meshes, in the two conventions of DESIGN.md §7.
//!
//! Each mesh is sampled with `samples` area-weighted surface points (seeded, deterministic on every target);
//! nearest neighbours are found among the other mesh's samples with a k-d tree, as the peers do with their
//! point clouds.
//! - `cd_peer` = (mean squared NN distance a→b + mean squared NN distance b→a) × 1000 — what PARIS, ArtGS and
//!   the ArtMesh paper report as "CD".
//! - `cd_mm` = the mean of the two directions' mean Euclidean NN distance, in millimetres — a true length.
//!
//! Both meshes are sampled with the same seed, so identical meshes give identical samples and exactly 0.

use glam::Vec3;

use crate::data::TriMesh;
use crate::rng::Rng;

/// Surface samples per mesh in the paper's protocol.
pub const DEFAULT_SAMPLES: usize = 10_000;

/// Default sampling seed (any fixed value; fixed so that reruns give the same numbers).
pub const DEFAULT_SEED: u64 = 0x00a7_3e54_c4a3_f3d1;

/// Sampling settings of the Chamfer distance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ChamferOptions {
    /// Surface samples per mesh (must be positive).
    pub samples: usize,
    /// Seed of the sampler (both meshes use it).
    pub seed: u64,
}

impl Default for ChamferOptions {
    fn default() -> Self {
        ChamferOptions {
            samples: DEFAULT_SAMPLES,
            seed: DEFAULT_SEED,
        }
    }
}

/// The Chamfer distance between two meshes in both conventions.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ChamferDistance {
    /// Peer convention: mean squared NN distance a→b + b→a (m²), × 1000.
    pub cd_peer: f64,
    /// Mean of the two directions' mean Euclidean NN distance, millimetres.
    pub cd_mm: f64,
}

/// Checks a mesh for sampling; returns the cumulative triangle areas (the sampling CDF) and the total area.
pub(crate) fn area_cdf(mesh: &TriMesh) -> Result<(Vec<f64>, f64), String> {
    if mesh.triangles.is_empty() {
        return Err("mesh has no triangles".into());
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(format!(
            "vertex {i} has a non-finite position {}",
            mesh.positions[i]
        ));
    }
    let n = mesh.positions.len();
    let mut cdf = Vec::with_capacity(mesh.triangles.len());
    let mut total = 0.0_f64;
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(format!(
                "triangle {t} refers to vertex {bad}, but the mesh has {n} vertices"
            ));
        }
        let [a, b, c] = tri.map(|i| mesh.positions[i as usize].as_dvec3());
        total += 0.5 * (b - a).cross(c - a).length();
        cdf.push(total);
    }
    if !(total.is_finite() && total > 0.0) {
        return Err(format!(
            "mesh has no surface to sample (total area {total})"
        ));
    }
    Ok((cdf, total))
}

/// Uniform in [0, 1) with 53 random bits (triangle choice on meshes with millions of faces stays unbiased).
fn unit_f64(rng: &mut Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// `count` points uniformly distributed over the surface of `mesh` (triangle chosen by area, then a uniform
/// point in it), reproducible from `seed`. Errors for meshes without a samplable surface (no triangles, zero
/// area, bad indices, non-finite vertices) or `count == 0`.
pub fn sample_surface(mesh: &TriMesh, count: usize, seed: u64) -> Result<Vec<Vec3>, String> {
    if count == 0 {
        return Err("the number of surface samples must be positive".into());
    }
    let (cdf, total) = area_cdf(mesh)?;
    let mut rng = Rng::new(seed);
    let mut points = Vec::with_capacity(count);
    for _ in 0..count {
        let target = unit_f64(&mut rng) * total;
        // First triangle whose cumulative area exceeds the target; zero-area triangles are never chosen.
        let t = cdf.partition_point(|&c| c <= target).min(cdf.len() - 1);
        let [a, b, c] = mesh.triangles[t].map(|i| mesh.positions[i as usize].as_dvec3());
        // sqrt makes the barycentric point uniform over the triangle's area.
        let r1 = unit_f64(&mut rng).sqrt();
        let r2 = unit_f64(&mut rng);
        let p = a * (1.0 - r1) + b * (r1 * (1.0 - r2)) + c * (r1 * r2);
        points.push(p.as_vec3());
    }
    Ok(points)
}

/// Ranges at most this long are scanned linearly instead of split further.
const LEAF_SIZE: usize = 8;

/// A k-d tree over a point set for exact nearest-neighbour queries.
///
/// Stored implicitly: the points are reordered so that every range `[lo, hi)` longer than a leaf has its
/// splitting point at the middle index `m`, smaller coordinates (along `axis[m]`) before it and larger after.
#[derive(Debug, Clone)]
pub struct KdTree {
    points: Vec<Vec3>,
    axis: Vec<u8>,
    /// Each stored point's index in the input (the build reorders them).
    input: Vec<u32>,
}

impl KdTree {
    /// Builds the tree (O(n log² n)); non-finite points are the caller's concern (they never match closer).
    pub fn new(points: &[Vec3]) -> Self {
        // Each point travels with its input index through the build.
        let mut entries: Vec<(Vec3, u32)> = points.iter().copied().zip(0..).collect();
        let mut axis = vec![0; points.len()];
        build(&mut entries, &mut axis, 0, points.len());
        let (points, input) = entries.into_iter().unzip();
        KdTree {
            points,
            axis,
            input,
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the tree holds no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Squared distance from `q` to its nearest point (infinite for an empty tree).
    pub fn nearest_distance_squared(&self, q: Vec3) -> f64 {
        self.nearest(q).map_or(f64::INFINITY, |(_, d2)| d2)
    }

    /// The point nearest to `q` and its squared distance; `None` for an empty tree.
    pub fn nearest(&self, q: Vec3) -> Option<(Vec3, f64)> {
        self.nearest_slot(q).map(|(i, d2)| (self.points[i], d2))
    }

    /// The input index of the point nearest to `q` and its squared distance; `None` for an
    /// empty tree.
    pub fn nearest_index(&self, q: Vec3) -> Option<(usize, f64)> {
        self.nearest_slot(q)
            .map(|(i, d2)| (self.input[i] as usize, d2))
    }

    /// Where in the tree's order the point nearest to `q` is stored, and its squared distance.
    fn nearest_slot(&self, q: Vec3) -> Option<(usize, f64)> {
        let mut best = (f64::INFINITY, usize::MAX);
        self.search(q.as_dvec3(), 0, self.points.len(), &mut best);
        (best.1 < self.points.len()).then_some((best.1, best.0))
    }

    fn search(&self, q: glam::DVec3, lo: usize, hi: usize, best: &mut (f64, usize)) {
        let consider = |i: usize, best: &mut (f64, usize)| {
            let d2 = q.distance_squared(self.points[i].as_dvec3());
            if d2 < best.0 {
                *best = (d2, i);
            }
        };
        if hi - lo <= LEAF_SIZE {
            for i in lo..hi {
                consider(i, best);
            }
            return;
        }
        let m = lo + (hi - lo) / 2;
        consider(m, best);
        let p = self.points[m].as_dvec3();
        let axis = usize::from(self.axis[m]);
        let diff = q[axis] - p[axis];
        let (near, far) = if diff < 0.0 {
            ((lo, m), (m + 1, hi))
        } else {
            ((m + 1, hi), (lo, m))
        };
        self.search(q, near.0, near.1, best);
        // The far side can only hold a closer point if the splitting plane is closer than the best so far.
        if diff * diff < best.0 {
            self.search(q, far.0, far.1, best);
        }
    }
}

/// Orders `entries[lo..hi]` as the implicit tree (see [`KdTree`]), recording each splitting
/// point's axis in `axis`.
fn build(entries: &mut [(Vec3, u32)], axis: &mut [u8], lo: usize, hi: usize) {
    if hi - lo <= LEAF_SIZE {
        return;
    }
    let (min, max) = entries[lo..hi]
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(mn, mx), &(p, _)| {
            (mn.min(p), mx.max(p))
        });
    // Split the widest extent: keeps cells compact, so queries prune well.
    let extent = max - min;
    let split = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let m = lo + (hi - lo) / 2;
    entries[lo..hi].select_nth_unstable_by(m - lo, |a, b| a.0[split].total_cmp(&b.0[split]));
    axis[m] = split as u8;
    build(entries, axis, lo, m);
    build(entries, axis, m + 1, hi);
}

/// Mean NN distance and mean squared NN distance from every point of `from` to the points in `to`.
fn directed(from: &[Vec3], to: &KdTree) -> (f64, f64) {
    let (mut sum, mut sum_sq) = (0.0_f64, 0.0_f64);
    for &p in from {
        let d2 = to.nearest_distance_squared(p);
        sum += d2.sqrt();
        sum_sq += d2;
    }
    let n = from.len() as f64;
    (sum / n, sum_sq / n)
}

/// Chamfer distance between two point sets (both conventions). Errors for an empty or non-finite set.
pub fn chamfer_points(a: &[Vec3], b: &[Vec3]) -> Result<ChamferDistance, String> {
    for (name, set) in [("first", a), ("second", b)] {
        if set.is_empty() {
            return Err(format!("the {name} point set is empty"));
        }
        if set.iter().any(|p| !p.is_finite()) {
            return Err(format!("the {name} point set has a non-finite point"));
        }
    }
    let (mean_ab, mean_sq_ab) = directed(a, &KdTree::new(b));
    let (mean_ba, mean_sq_ba) = directed(b, &KdTree::new(a));
    let cd = ChamferDistance {
        cd_peer: (mean_sq_ab + mean_sq_ba) * 1000.0,
        cd_mm: 0.5 * (mean_ab + mean_ba) * 1000.0,
    };
    if cd.cd_peer.is_finite() && cd.cd_mm.is_finite() {
        Ok(cd)
    } else {
        Err("the points are too far apart for a finite distance".into())
    }
}

/// Which of two meshes failed, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MeshFault {
    /// The first (predicted) mesh cannot be sampled.
    First(String),
    /// The second (ground-truth) mesh cannot be sampled.
    Second(String),
    /// Both sample, but the distance is not finite.
    Distance(String),
}

/// Chamfer distance between two meshes: `options.samples` area-weighted samples on each (same seed), then
/// [`chamfer_points`].
pub fn chamfer_meshes(
    a: &TriMesh,
    b: &TriMesh,
    options: &ChamferOptions,
) -> Result<ChamferDistance, MeshFault> {
    let pa = sample_surface(a, options.samples, options.seed).map_err(MeshFault::First)?;
    let pb = sample_surface(b, options.samples, options.seed).map_err(MeshFault::Second)?;
    chamfer_points(&pa, &pb).map_err(MeshFault::Distance)
}
