//! Exact nearest-neighbour search over point sets: a k-d tree. The articulation phase registers and matches
//! part point clouds with it, and the evaluation's Chamfer distance finds nearest surface samples with it.

use glam::Vec3;

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
    pub(crate) fn nearest_index(&self, q: Vec3) -> Option<(usize, f64)> {
        self.nearest_slot(q)
            .map(|(i, d2)| (self.input[i] as usize, d2))
    }

    /// The input index of the point nearest to `q` among those whose input index passes `keep`,
    /// and its squared distance; `None` when no point passes.
    pub(crate) fn nearest_index_where(
        &self,
        q: Vec3,
        keep: impl Fn(usize) -> bool,
    ) -> Option<(usize, f64)> {
        let mut best = (f64::INFINITY, usize::MAX);
        self.search(q.as_dvec3(), 0, self.points.len(), &mut best, &keep);
        (best.1 < self.points.len()).then(|| (self.input[best.1] as usize, best.0))
    }

    /// Where in the tree's order the point nearest to `q` is stored, and its squared distance.
    fn nearest_slot(&self, q: Vec3) -> Option<(usize, f64)> {
        let mut best = (f64::INFINITY, usize::MAX);
        self.search(q.as_dvec3(), 0, self.points.len(), &mut best, &|_| true);
        (best.1 < self.points.len()).then_some((best.1, best.0))
    }

    fn search<F: Fn(usize) -> bool>(
        &self,
        q: glam::DVec3,
        lo: usize,
        hi: usize,
        best: &mut (f64, usize),
        keep: &F,
    ) {
        let consider = |i: usize, best: &mut (f64, usize)| {
            let d2 = q.distance_squared(self.points[i].as_dvec3());
            if d2 < best.0 && keep(self.input[i] as usize) {
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
        self.search(q, near.0, near.1, best, keep);
        // The far side can only hold a closer point if the splitting plane is closer than the best so far.
        if diff * diff < best.0 {
            self.search(q, far.0, far.1, best, keep);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn filtered_queries_near_a_surface_match_brute_force() {
        // Points on a wavy sheet (as the registration's clouds are), queried just off it.
        let mut rng = Rng::new(3);
        let sheet = |u: f32, v: f32| Vec3::new(u, v, 0.05 * (6.0 * u).sin());
        let pts: Vec<Vec3> = (0..3000)
            .map(|_| sheet(rng.next_f32(), rng.next_f32()))
            .collect();
        let tree = KdTree::new(&pts);
        for _ in 0..300 {
            let q = sheet(rng.next_f32(), rng.next_f32()) + Vec3::Z * (rng.next_f32() - 0.5) * 0.1;
            let odd = |i: usize| i % 2 == 1;
            let brute = |keep: &dyn Fn(usize) -> bool| {
                (0..pts.len())
                    .filter(|&i| keep(i))
                    .map(|i| q.as_dvec3().distance_squared(pts[i].as_dvec3()))
                    .fold(f64::INFINITY, f64::min)
            };
            assert_eq!(
                tree.nearest_index(q).map(|(_, d2)| d2),
                Some(brute(&|_| true))
            );
            let (i, d2) = tree.nearest_index_where(q, odd).unwrap();
            assert!(odd(i));
            assert_eq!(d2, brute(&odd));
        }
    }
}
