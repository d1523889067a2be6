//! Closest-point queries on a triangle set: the search behind the vertex-wise motion consistency
//! (paper §3.2), which matches every transported vertex to the nearest surface point of the same
//! part in the other articulation state.
//!
//! [`closest_point_on_triangle`] answers one triangle exactly; [`TriangleBvh`] answers a whole
//! set with a bounding-volume hierarchy (median split over triangle centroids, axis-aligned boxes,
//! nearest-child-first traversal that skips every box farther away than the best hit so far).

use glam::Vec3;

/// Triangles thinner than this (twice the area over the squared longest edge, squared) are
/// treated as segments: their plane is numerically meaningless in f32.
const DEGENERATE: f32 = 1e-12;

/// Triangles per BVH leaf: small enough to prune well, large enough to keep the tree shallow.
const LEAF_SIZE: usize = 4;

/// Deepest traversal stack: median splits halve the set, so 2³² triangles need 31 levels.
const MAX_DEPTH: usize = 64;

/// The point of triangle `abc` closest to `p`, with its barycentric weights `(wa, wb, wc)`
/// (summing to 1, all ≥ 0 up to rounding).
///
/// The weights say which Voronoi region `p` lies in: all three positive in the face region, the
/// weight of the vertex opposite an edge exactly `0.0` in that edge's region, and exactly one
/// weight `1.0` (the others `0.0`) in a vertex region. Degenerate triangles (collinear or
/// coincident corners) are handled as their three edges, so the result is never NaN for finite
/// input.
pub(crate) fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, Vec3) {
    let ab = b - a;
    let ac = c - a;
    let n = ab.cross(ac);
    let nn = n.length_squared();
    let longest = ab
        .length_squared()
        .max(ac.length_squared())
        .max((c - b).length_squared());
    if nn <= DEGENERATE * longest * longest || nn.is_nan() {
        return closest_on_edges(p, [a, b, c], [true; 3]);
    }

    // Unnormalised barycentrics of p's projection onto the plane: signed areas of the
    // sub-triangles opposite each corner, measured along n. Written with edge vectors rather
    // than p-relative dot products so a far-away p does not cancel catastrophically in f32.
    let ap = p - a;
    let wb = n.dot(ap.cross(ac));
    let wc = n.dot(ab.cross(ap));
    let wa = n.dot((c - b).cross(p - b));
    if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
        // Face region: the projection lies inside.
        let v = wb / nn;
        let w = wc / nn;
        let u = 1.0 - v - w;
        return (a * u + b * v + c * w, Vec3::new(u, v, w));
    }
    // Outside the prism: the closest point is on an edge that faces p, i.e. one whose opposite
    // corner has a negative weight (at most two such edges).
    closest_on_edges(p, [a, b, c], [wa, wb, wc].map(|w| w < 0.0 || w.is_nan()))
}

/// The closest point on the edges opposite the corners flagged in `opposite`.
fn closest_on_edges(p: Vec3, corners: [Vec3; 3], opposite: [bool; 3]) -> (Vec3, Vec3) {
    let mut best = (corners[0], Vec3::X);
    let mut best_d2 = f32::INFINITY;
    for k in (0..3).filter(|&k| opposite[k]) {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let (point, t) = closest_on_segment(p, corners[i], corners[j]);
        let d2 = (p - point).length_squared();
        if d2 < best_d2 {
            best_d2 = d2;
            let mut weights = [0.0; 3];
            weights[i] = 1.0 - t;
            weights[j] = t;
            best = (point, Vec3::from_array(weights));
        }
    }
    best
}

/// The point of segment `uv` closest to `p` and its parameter t ∈ [0, 1] (u + t (v − u)); t is
/// exactly 0 or 1 at the end points and 0 for a zero-length segment.
fn closest_on_segment(p: Vec3, u: Vec3, v: Vec3) -> (Vec3, f32) {
    let e = v - u;
    let len2 = e.length_squared();
    let t = if len2 > 0.0 {
        ((p - u).dot(e) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    // The end points themselves, not u + e·t, so vertex regions return a corner exactly.
    let point = if t == 0.0 {
        u
    } else if t == 1.0 {
        v
    } else {
        u + e * t
    };
    (point, t)
}

/// The answer of [`TriangleBvh::closest`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ClosestPoint {
    /// Index into the `faces` slice the tree was built from.
    pub face: u32,
    /// The closest surface point.
    pub point: Vec3,
    /// Its barycentric weights on that face, as [`closest_point_on_triangle`] returns them.
    pub barycentric: Vec3,
    /// Squared distance from the query to `point`.
    pub distance_squared: f32,
}

/// A bounding-volume hierarchy over a triangle set for nearest-surface-point queries.
#[derive(Debug, Clone, Default)]
pub(crate) struct TriangleBvh {
    /// Depth-first order: an inner node's left child follows it directly.
    nodes: Vec<Node>,
    /// Triangle corners in leaf order, so a leaf reads one contiguous run.
    triangles: Vec<[Vec3; 3]>,
    /// The face index of each entry of `triangles`.
    face_ids: Vec<u32>,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    min: Vec3,
    max: Vec3,
    /// Leaf: first triangle. Inner node: index of the right child.
    first: u32,
    /// Leaf: number of triangles (≥ 1). Inner node: 0.
    count: u32,
}

impl Node {
    /// Squared distance from `q` to the box (0 inside).
    fn distance_squared(&self, q: Vec3) -> f32 {
        let d = (self.min - q).max(q - self.max).max(Vec3::ZERO);
        d.length_squared()
    }
}

impl TriangleBvh {
    /// A tree over `faces` (vertex indices into `positions`). Only these faces are searched;
    /// answers name them by their index in `faces`.
    ///
    /// # Panics
    /// If a face refers to a vertex outside `positions` (callers validate their meshes first).
    pub fn new(positions: &[Vec3], faces: &[[u32; 3]]) -> Self {
        let triangles: Vec<[Vec3; 3]> = faces
            .iter()
            .map(|f| f.map(|v| positions[v as usize]))
            .collect();
        let mut order: Vec<(u32, Vec3)> = triangles
            .iter()
            .enumerate()
            .map(|(i, t)| (i as u32, (t[0] + t[1] + t[2]) / 3.0))
            .collect();
        let mut nodes = Vec::with_capacity(2 * faces.len().div_ceil(LEAF_SIZE));
        if !order.is_empty() {
            build(&mut nodes, &triangles, &mut order, 0);
        }
        Self {
            nodes,
            triangles: order.iter().map(|&(i, _)| triangles[i as usize]).collect(),
            face_ids: order.iter().map(|&(i, _)| i).collect(),
        }
    }

    /// Number of triangles in the tree (the tests check it).
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether the tree holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The surface point closest to `q`; `None` for an empty tree or a non-finite query. Of
    /// equally close faces, the first one met wins.
    pub fn closest(&self, q: Vec3) -> Option<ClosestPoint> {
        if !q.is_finite() {
            return None;
        }
        let root = self.nodes.first()?;
        let mut best: Option<ClosestPoint> = None;
        let mut best_d2 = f32::INFINITY;
        // Pending far children with the box distance they had when pushed.
        let mut stack = [(0u32, 0.0f32); MAX_DEPTH];
        let mut depth = 0;
        let mut current = Some((0u32, root.distance_squared(q)));
        while let Some((index, box_d2)) = current.take().or_else(|| {
            (depth > 0).then(|| {
                depth -= 1;
                stack[depth]
            })
        }) {
            // The best hit may have improved since this node was pushed.
            if box_d2 >= best_d2 {
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                for (k, [a, b, c]) in self.triangles[range.clone()].iter().enumerate() {
                    let (point, barycentric) = closest_point_on_triangle(q, *a, *b, *c);
                    let d2 = (q - point).length_squared();
                    if d2 < best_d2 {
                        best_d2 = d2;
                        best = Some(ClosestPoint {
                            face: self.face_ids[range.start + k],
                            point,
                            barycentric,
                            distance_squared: d2,
                        });
                    }
                }
                continue;
            }
            // Visit the nearer child now, keep the farther one for later.
            let left = index + 1;
            let right = node.first;
            let dl = self.nodes[left as usize].distance_squared(q);
            let dr = self.nodes[right as usize].distance_squared(q);
            let (near, far) = if dl <= dr {
                ((left, dl), (right, dr))
            } else {
                ((right, dr), (left, dl))
            };
            if far.1 < best_d2 {
                stack[depth] = far;
                depth += 1;
            }
            current = Some(near);
        }
        best
    }
}

/// Appends the subtree over `order` (face index, centroid) to `nodes`, depth first; `first` is
/// the position of `order[0]` in the final leaf order.
fn build(nodes: &mut Vec<Node>, triangles: &[[Vec3; 3]], order: &mut [(u32, Vec3)], first: usize) {
    let (mut min, mut max) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let (mut cmin, mut cmax) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for &(i, centroid) in order.iter() {
        for &v in &triangles[i as usize] {
            min = min.min(v);
            max = max.max(v);
        }
        cmin = cmin.min(centroid);
        cmax = cmax.max(centroid);
    }
    let index = nodes.len();
    nodes.push(Node {
        min,
        max,
        first: first as u32,
        count: order.len() as u32,
    });
    if order.len() <= LEAF_SIZE {
        return;
    }
    // Median split along the centroids' longest extent: a balanced tree whatever the layout.
    let extent = cmax - cmin;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |p, q| p.1[axis].total_cmp(&q.1[axis]));
    let (left, right) = order.split_at_mut(mid);
    build(nodes, triangles, left, first);
    let right_index = nodes.len() as u32;
    build(nodes, triangles, right, first + mid);
    nodes[index].first = right_index;
    nodes[index].count = 0;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-5
    }

    #[test]
    fn each_voronoi_region_of_a_triangle() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let cases = [
            // Face region, above and below the plane.
            (
                Vec3::new(0.25, 0.25, 1.0),
                Vec3::new(0.25, 0.25, 0.0),
                Vec3::new(0.5, 0.25, 0.25),
            ),
            (
                Vec3::new(0.2, 0.1, -2.0),
                Vec3::new(0.2, 0.1, 0.0),
                Vec3::new(0.7, 0.2, 0.1),
            ),
            // Vertex regions.
            (Vec3::new(-1.0, -1.0, 0.5), a, Vec3::X),
            (Vec3::new(2.0, -0.5, 0.0), b, Vec3::Y),
            (Vec3::new(-0.5, 3.0, -1.0), c, Vec3::Z),
            // Edge regions: ab (y < 0), ac (x < 0), bc (x + y > 1).
            (
                Vec3::new(0.3, -1.0, 0.2),
                Vec3::new(0.3, 0.0, 0.0),
                Vec3::new(0.7, 0.3, 0.0),
            ),
            (
                Vec3::new(-0.5, 0.6, 0.0),
                Vec3::new(0.0, 0.6, 0.0),
                Vec3::new(0.4, 0.0, 0.6),
            ),
            (
                Vec3::new(1.0, 1.0, 0.3),
                Vec3::new(0.5, 0.5, 0.0),
                Vec3::new(0.0, 0.5, 0.5),
            ),
        ];
        for (p, want_point, want_weights) in cases {
            let (point, weights) = closest_point_on_triangle(p, a, b, c);
            assert!(close(point, want_point), "{p}: {point} vs {want_point}");
            assert!(
                close(weights, want_weights),
                "{p}: {weights} vs {want_weights}"
            );
            assert!(close(a * weights.x + b * weights.y + c * weights.z, point));
        }
        // Off-face regions report exact zeros (and exact ones at vertices).
        let (_, w) = closest_point_on_triangle(Vec3::new(0.3, -1.0, 0.0), a, b, c);
        assert_eq!(w.z, 0.0);
        let (_, w) = closest_point_on_triangle(Vec3::new(2.0, -0.5, 0.0), a, b, c);
        assert_eq!(w, Vec3::Y);
    }

    #[test]
    fn degenerate_triangles_give_no_nan() {
        let p = Vec3::new(0.3, 0.7, -0.2);
        let segment = [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
        ];
        let (point, w) = closest_point_on_triangle(p, segment[0], segment[1], segment[2]);
        assert!(close(point, Vec3::new(0.3, 0.0, 0.0)), "{point}");
        assert!((w.element_sum() - 1.0).abs() < 1e-6 && w.is_finite());
        let dot = Vec3::splat(0.5);
        let (point, w) = closest_point_on_triangle(p, dot, dot, dot);
        assert_eq!(point, dot);
        assert_eq!(w.element_sum(), 1.0);
    }

    #[test]
    fn triangle_answer_beats_random_surface_points() {
        let mut rng = Rng::new(7);
        let v = |rng: &mut Rng| {
            Vec3::new(
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            )
        };
        for _ in 0..500 {
            let (a, b, c, p) = (v(&mut rng), v(&mut rng), v(&mut rng), v(&mut rng) * 2.0);
            let (point, w) = closest_point_on_triangle(p, a, b, c);
            assert!(w.min_element() >= -1e-6 && (w.element_sum() - 1.0).abs() < 1e-5);
            let d = (p - point).length();
            for _ in 0..50 {
                let (s, t) = (rng.next_f32(), rng.next_f32());
                let (s, t) = if s + t > 1.0 {
                    (1.0 - s, 1.0 - t)
                } else {
                    (s, t)
                };
                let other = a + (b - a) * s + (c - a) * t;
                assert!(d <= (p - other).length() + 1e-5);
            }
        }
    }

    #[test]
    fn bvh_matches_brute_force_on_random_soups() {
        let mut rng = Rng::new(42);
        for (soup, &count) in [0usize, 1, 3, 5, 17, 200, 1500].iter().enumerate() {
            let mut positions = Vec::new();
            let mut faces = Vec::new();
            for _ in 0..count {
                let centre = Vec3::new(
                    rng.uniform(-1.0, 1.0),
                    rng.uniform(-1.0, 1.0),
                    rng.uniform(-1.0, 1.0),
                );
                let base = positions.len() as u32;
                for _ in 0..3 {
                    let offset = Vec3::new(
                        rng.uniform(-0.1, 0.1),
                        rng.uniform(-0.1, 0.1),
                        rng.uniform(-0.1, 0.1),
                    );
                    positions.push(centre + offset);
                }
                faces.push([base, base + 1, base + 2]);
            }
            // Unused vertices must not matter.
            positions.push(Vec3::splat(-10.0));
            let bvh = TriangleBvh::new(&positions, &faces);
            assert_eq!(bvh.len(), count);
            for _ in 0..300 {
                let q = Vec3::new(
                    rng.uniform(-1.5, 1.5),
                    rng.uniform(-1.5, 1.5),
                    rng.uniform(-1.5, 1.5),
                );
                let brute = faces
                    .iter()
                    .enumerate()
                    .map(|(f, &[a, b, c])| {
                        let [a, b, c] = [a, b, c].map(|v| positions[v as usize]);
                        (
                            f,
                            (q - closest_point_on_triangle(q, a, b, c).0).length_squared(),
                        )
                    })
                    .min_by(|x, y| x.1.total_cmp(&y.1));
                let found = bvh.closest(q);
                match (brute, found) {
                    (None, None) => {}
                    (Some((f, d2)), Some(hit)) => {
                        assert!(
                            (hit.distance_squared - d2).abs() <= 1e-6 * d2.max(1e-6),
                            "soup {soup}: {hit:?} vs face {f} at {d2}"
                        );
                        let [a, b, c] = faces[hit.face as usize].map(|v| positions[v as usize]);
                        let (point, weights) = closest_point_on_triangle(q, a, b, c);
                        assert_eq!((point, weights), (hit.point, hit.barycentric));
                    }
                    other => panic!("soup {soup}: {other:?}"),
                }
            }
        }
    }

    #[test]
    fn bvh_uses_only_the_given_faces_and_rejects_nan() {
        let positions = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::new(1.0, 0.0, 5.0),
            Vec3::new(0.0, 1.0, 5.0),
        ];
        let bvh = TriangleBvh::new(&positions, &[[3, 4, 5]]);
        let hit = bvh.closest(Vec3::new(0.2, 0.2, 0.1)).unwrap();
        assert_eq!(hit.face, 0);
        assert!(close(hit.point, Vec3::new(0.2, 0.2, 5.0)));
        assert!(bvh.closest(Vec3::NAN).is_none());
        assert!(
            TriangleBvh::new(&positions, &[])
                .closest(Vec3::ZERO)
                .is_none()
        );
    }
}
