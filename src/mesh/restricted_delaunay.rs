//! Part-aware restricted Delaunay remeshing (paper §3.1, "Part-aware restricted Delaunay
//! remeshing"; docs/design.md §5). `spade` triangulates in 2-D only, so the restricted Delaunay
//! triangulation of a part's surface is approximated the localised way (Gopi et al. 2000): each
//! vertex takes its k nearest same-part neighbours whose normals agree with its own, projects them
//! on its tangent plane, triangulates them there and proposes the triangles of its own umbrella;
//! a triangle is kept when all three of its vertices propose it, then triangles proposed by two are
//! added where they keep every edge manifold. Only connectivity changes: vertices and their
//! attributes stay as they are.

use std::collections::HashMap;

use glam::{DVec2, Vec3};
use spade::{DelaunayTriangulation, Point2, Triangulation};

use super::topology::{longest_edge, median_edge};

/// Knobs of [`restricted_delaunay`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RemeshOptions {
    /// Neighbours per vertex (the umbrella is built from these).
    pub neighbours: usize,
    /// Edges longer than this multiple of the local spacing (the distance to the 4th nearest
    /// neighbour) are not proposed: no slivers across gaps, concave corners or boundaries.
    pub max_edge_factor: f32,
    /// Neighbours whose normal makes a larger angle with the vertex's (cosine below this) are
    /// ignored, so the two sides of a thin part stay apart.
    pub min_normal_cosine: f32,
}

impl Default for RemeshOptions {
    fn default() -> Self {
        Self {
            neighbours: 12,
            max_edge_factor: 2.0,
            min_normal_cosine: 0.5,
        }
    }
}

/// A uniform grid over points for k-nearest-neighbour queries.
struct Grid {
    cell: f32,
    origin: Vec3,
    cells: HashMap<[i32; 3], Vec<u32>>,
}

impl Grid {
    fn new(points: &[Vec3]) -> Self {
        let lo = points
            .iter()
            .copied()
            .fold(Vec3::splat(f32::MAX), Vec3::min);
        let hi = points
            .iter()
            .copied()
            .fold(Vec3::splat(f32::MIN), Vec3::max);
        let extent = (hi - lo).max(Vec3::splat(1e-6));
        // About two points per occupied cell for a surface sample.
        let area = 2.0 * (extent.x * extent.y + extent.y * extent.z + extent.z * extent.x);
        let cell = (2.0 * area / points.len().max(1) as f32).sqrt().max(1e-6);
        let mut cells: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
        for (i, p) in points.iter().enumerate() {
            cells
                .entry(Self::key(*p, lo, cell))
                .or_default()
                .push(i as u32);
        }
        Self {
            cell,
            origin: lo,
            cells,
        }
    }

    fn key(p: Vec3, origin: Vec3, cell: f32) -> [i32; 3] {
        ((p - origin) / cell).floor().as_ivec3().to_array()
    }

    /// Indices of the `k` points nearest to `points[i]` passing `keep`, nearest first.
    fn nearest(
        &self,
        points: &[Vec3],
        i: usize,
        k: usize,
        keep: &dyn Fn(usize) -> bool,
    ) -> Vec<u32> {
        let p = points[i];
        let c = Self::key(p, self.origin, self.cell);
        let mut found: Vec<(f32, u32)> = Vec::new();
        let max_ring: i32 = 64;
        for ring in 0..=max_ring {
            for dz in -ring..=ring {
                for dy in -ring..=ring {
                    for dx in -ring..=ring {
                        if dx.abs().max(dy.abs()).max(dz.abs()) != ring {
                            continue;
                        }
                        if let Some(list) = self.cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                            for &j in list {
                                if j as usize != i && keep(j as usize) {
                                    found.push((points[j as usize].distance_squared(p), j));
                                }
                            }
                        }
                    }
                }
            }
            found.sort_by(|a, b| a.0.total_cmp(&b.0));
            // Every point within `ring` cells is found; beyond that, distances exceed ring · cell.
            let reach = ring as f32 * self.cell;
            if found.len() >= k && found[k - 1].0 <= reach * reach {
                break;
            }
        }
        found.truncate(k);
        found.into_iter().map(|(_, j)| j).collect()
    }
}

/// Unit normal of the least-squares plane through `points` (smallest principal axis), or `None`
/// when they do not span a plane.
fn plane_normal(points: &[Vec3]) -> Option<Vec3> {
    let mean = points.iter().copied().sum::<Vec3>() / points.len().max(1) as f32;
    let mut c = [[0.0f64; 3]; 3];
    for p in points {
        let d = (*p - mean).as_dvec3().to_array();
        for (r, row) in c.iter_mut().enumerate() {
            for (s, value) in row.iter_mut().enumerate() {
                *value += d[r] * d[s];
            }
        }
    }
    // Inverse iteration on the covariance gives its smallest eigenvector.
    let m = glam::DMat3::from_cols_array_2d(&c);
    let shifted = m + glam::DMat3::IDENTITY * (1e-12 * (c[0][0] + c[1][1] + c[2][2]).max(1e-30));
    if shifted.determinant().abs() < 1e-300 {
        return None;
    }
    let inv = shifted.inverse();
    let mut v = glam::DVec3::new(0.577, 0.577, 0.577);
    for _ in 0..32 {
        v = (inv * v).normalize_or_zero();
        if v == glam::DVec3::ZERO {
            return None;
        }
    }
    Some(v.as_vec3())
}

/// Connectivity for one part's vertices (`normals`, when given, are the current mesh's vertex
/// normals: they pick the tangent plane's side and keep thin parts' sides apart).
pub fn restricted_delaunay(
    points: &[Vec3],
    normals: Option<&[Vec3]>,
    options: &RemeshOptions,
) -> Vec<[u32; 3]> {
    if points.len() < 3 {
        return Vec::new();
    }
    let grid = Grid::new(points);
    let k = options.neighbours.max(3).min(points.len() - 1);
    let mut votes: HashMap<[u32; 3], (u32, [u32; 3])> = HashMap::new();
    for i in 0..points.len() {
        let own = normals.map(|n| n[i]);
        let keep = |j: usize| match (own, normals) {
            (Some(a), Some(n)) => a.dot(n[j]) >= options.min_normal_cosine,
            _ => true,
        };
        let near = grid.nearest(points, i, k, &keep);
        if near.len() < 2 {
            continue;
        }
        let mut patch: Vec<Vec3> = near.iter().map(|&j| points[j as usize]).collect();
        patch.push(points[i]);
        // The tangent plane is fitted to the patch (optimised vertices' own normals are noisy);
        // the vertex normal only picks its side.
        let own = own.filter(|n| n.length_squared() > 0.0);
        let Some(mut n) = (match (plane_normal(&patch), own) {
            (Some(p), Some(o)) if p.dot(o) < 0.0 => Some(-p),
            (Some(p), _) => Some(p),
            (None, o) => o,
        }) else {
            continue;
        };
        n = n.normalize();
        let t1 = n.any_orthonormal_vector();
        let t2 = n.cross(t1);
        let mut dists: Vec<f32> = near
            .iter()
            .map(|&j| points[j as usize].distance(points[i]))
            .collect();
        dists.sort_by(f32::total_cmp);
        // The local spacing: the 4th neighbour's distance (one grid step inside a surface, still
        // under 1.5 steps on its boundary, where more distant neighbours are one-sided).
        let max_edge = options.max_edge_factor * dists[3.min(dists.len() - 1)];

        let mut tri: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::new();
        // Local index of each inserted point (duplicates in the plane merge into one handle).
        let mut local: HashMap<usize, u32> = HashMap::new();
        let mut centre = None;
        for (slot, &j) in near.iter().chain(std::iter::once(&(i as u32))).enumerate() {
            let d = points[j as usize] - points[i];
            let q = DVec2::new(f64::from(d.dot(t1)), f64::from(d.dot(t2)));
            if let Ok(handle) = tri.insert(Point2::new(q.x, q.y)) {
                local.entry(handle.index()).or_insert(j);
                if slot == near.len() {
                    centre = Some(handle.index());
                }
            }
        }
        let Some(centre) = centre else { continue };
        if local.get(&centre) != Some(&(i as u32)) {
            continue;
        }
        for face in tri.inner_faces() {
            let h = face.vertices().map(|v| v.fix().index());
            if !h.contains(&centre) {
                continue;
            }
            let Some(ids) = h
                .iter()
                .map(|x| local.get(x).copied())
                .collect::<Option<Vec<u32>>>()
            else {
                continue;
            };
            let [a, b, c] = [ids[0], ids[1], ids[2]];
            let (pa, pb, pc) = (points[a as usize], points[b as usize], points[c as usize]);
            if longest_edge(points, &[a, b, c]) > max_edge {
                continue;
            }
            // Orient by the vertex's normal.
            let oriented = if (pb - pa).cross(pc - pa).dot(n) >= 0.0 {
                [a, b, c]
            } else {
                [a, c, b]
            };
            let mut key = [a, b, c];
            key.sort_unstable();
            votes.entry(key).or_insert((0, oriented)).0 += 1;
        }
    }
    accept_votes(votes, points)
}

/// Keeps triangles proposed by all three vertices, then two-vote triangles that leave every
/// edge with at most two faces, then one-vote triangles that close holes.
fn accept_votes(votes: HashMap<[u32; 3], (u32, [u32; 3])>, points: &[Vec3]) -> Vec<[u32; 3]> {
    let mut ranked: Vec<([u32; 3], u32, [u32; 3])> =
        votes.into_iter().map(|(k, (n, f))| (k, n, f)).collect();
    ranked.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut edge_use: HashMap<(u32, u32), u32> = HashMap::new();
    let edge = |a: u32, b: u32| if a < b { (a, b) } else { (b, a) };
    let mut faces = Vec::new();
    let mut single = Vec::new();
    for (_, count, f) in ranked {
        if count < 2 {
            single.push(f);
            continue;
        }
        let edges = [edge(f[0], f[1]), edge(f[1], f[2]), edge(f[2], f[0])];
        if edges
            .iter()
            .any(|e| edge_use.get(e).copied().unwrap_or(0) >= 2)
        {
            continue;
        }
        for e in edges {
            *edge_use.entry(e).or_default() += 1;
        }
        faces.push(f);
    }
    // Where neighbouring umbrellas disagreed a hole is left; a one-vote triangle that closes it
    // (two or three of its edges already on the hole's rim, none overused, no edge longer than
    // twice the accepted faces' median) fills it. Two rounds: a filled notch can expose the next.
    let limit = 2.0 * median_edge(points, &faces);
    for _ in 0..2 {
        single.retain(|f| {
            let edges = [edge(f[0], f[1]), edge(f[1], f[2]), edge(f[2], f[0])];
            let uses = edges.map(|e| edge_use.get(&e).copied().unwrap_or(0));
            let fills = uses.iter().all(|&u| u < 2)
                && uses.iter().filter(|&&u| u == 1).count() >= 2
                && longest_edge(points, f) <= limit;
            if fills {
                for e in edges {
                    *edge_use.entry(e).or_default() += 1;
                }
                faces.push(*f);
            }
            !fills
        });
    }
    faces
}

/// The paper's part-aware remeshing: faces are rebuilt per hardened part with
/// [`restricted_delaunay`] over that part's vertices only, so no face spans two parts.
pub fn part_aware_remesh(
    positions: &[Vec3],
    normals: Option<&[Vec3]>,
    parts: &[u32],
    options: &RemeshOptions,
) -> Vec<[u32; 3]> {
    let num_parts = parts.iter().copied().max().map_or(0, |m| m + 1);
    let mut faces = Vec::new();
    for part in 0..num_parts {
        let ids: Vec<u32> = (0..positions.len() as u32)
            .filter(|&v| parts[v as usize] == part)
            .collect();
        let pts: Vec<Vec3> = ids.iter().map(|&v| positions[v as usize]).collect();
        let nrm: Option<Vec<Vec3>> = normals.map(|n| ids.iter().map(|&v| n[v as usize]).collect());
        for f in restricted_delaunay(&pts, nrm.as_deref(), options) {
            faces.push(f.map(|v| ids[v as usize]));
        }
    }
    faces
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    use crate::mesh::topology::{edge_counts, face_components};

    fn components(_n: usize, faces: &[[u32; 3]]) -> usize {
        face_components(faces).1
    }

    fn longest(p: &[Vec3], faces: &[[u32; 3]]) -> f32 {
        faces.iter().map(|f| longest_edge(p, f)).fold(0.0, f32::max)
    }

    fn grid(
        nx: usize,
        ny: usize,
        h: f32,
        rng: &mut Rng,
        keep: impl Fn(f32, f32) -> bool,
    ) -> Vec<Vec3> {
        let mut p = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = (
                    i as f32 * h + rng.uniform(-0.2, 0.2) * h,
                    j as f32 * h + rng.uniform(-0.2, 0.2) * h,
                );
                if keep(x, y) {
                    p.push(Vec3::new(x, y, 0.0));
                }
            }
        }
        p
    }

    fn assert_manifold(faces: &[[u32; 3]]) {
        let bad = edge_counts(faces).non_manifold;
        assert_eq!(bad, 0, "{bad} edges with more than two faces");
    }

    #[test]
    fn plane_gives_one_manifold_sheet() {
        let mut rng = Rng::new(1);
        let p = grid(20, 20, 0.05, &mut rng, |_, _| true);
        let faces = restricted_delaunay(&p, None, &RemeshOptions::default());
        assert_manifold(&faces);
        assert_eq!(components(p.len(), &faces), 1);
        assert!(
            faces.len() as f32 >= 0.9 * 2.0 * 19.0 * 19.0,
            "{} faces",
            faces.len()
        );
        assert!(longest(&p, &faces) < 3.0 * 0.05);
    }

    #[test]
    fn sphere_gives_a_closed_manifold() {
        let n = 600;
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        let p: Vec<Vec3> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - z * z).sqrt();
                let a = golden * i as f32;
                Vec3::new(r * a.cos(), r * a.sin(), z)
            })
            .collect();
        let faces = restricted_delaunay(&p, Some(&p), &RemeshOptions::default());
        assert_manifold(&faces);
        assert_eq!(components(n, &faces), 1);
        let counts = edge_counts(&faces);
        let closed =
            (counts.edges - counts.boundary - counts.non_manifold) as f32 / counts.edges as f32;
        assert!(
            closed > 0.97,
            "{:.1} % of edges have two faces",
            100.0 * closed
        );
        // Euler characteristic of a sphere, up to a few small holes.
        let euler = n as i64 - counts.edges as i64 + faces.len() as i64;
        assert!((euler - 2).abs() <= 6, "V − E + F = {euler}");
    }

    #[test]
    fn thin_box_keeps_its_two_sides_apart() {
        // Two sheets 2 mm apart sampled every 5 cm: nearest neighbours cross the gap, normals do not.
        let mut rng = Rng::new(2);
        let top = grid(12, 12, 0.05, &mut rng, |_, _| true);
        let mut p: Vec<Vec3> = top.iter().map(|q| *q + Vec3::Z * 0.001).collect();
        let mut normals = vec![Vec3::Z; p.len()];
        let half = p.len() as u32;
        p.extend(top.iter().map(|q| *q - Vec3::Z * 0.001));
        normals.extend(std::iter::repeat_n(-Vec3::Z, top.len()));
        let faces = restricted_delaunay(&p, Some(&normals), &RemeshOptions::default());
        assert_manifold(&faces);
        let mixed = faces
            .iter()
            .filter(|f| f.iter().any(|&v| v < half) && f.iter().any(|&v| v >= half))
            .count();
        assert_eq!(mixed, 0, "{mixed} faces join the two sides");
        assert_eq!(components(p.len(), &faces), 2);
        // Each side faces outwards.
        for f in &faces {
            let n =
                (p[f[1] as usize] - p[f[0] as usize]).cross(p[f[2] as usize] - p[f[0] as usize]);
            assert!(n.dot(normals[f[0] as usize]) > 0.0);
        }
    }

    #[test]
    fn l_shape_has_no_sliver_across_the_notch() {
        let h = 0.05;
        let mut rng = Rng::new(3);
        let inside = |x: f32, y: f32| !(x > 0.5 + 0.5 * h && y > 0.5 + 0.5 * h);
        let p = grid(21, 21, h, &mut rng, inside);
        let faces = restricted_delaunay(&p, None, &RemeshOptions::default());
        assert_manifold(&faces);
        assert_eq!(components(p.len(), &faces), 1);
        assert!(longest(&p, &faces) < 3.0 * h);
        for f in &faces {
            let c = (p[f[0] as usize] + p[f[1] as usize] + p[f[2] as usize]) / 3.0;
            assert!(
                !(c.x > 0.5 + 1.5 * h && c.y > 0.5 + 1.5 * h),
                "a face in the notch at {c}"
            );
        }
    }

    #[test]
    fn part_aware_faces_never_cross_parts() {
        let mut rng = Rng::new(4);
        let p = grid(20, 10, 0.05, &mut rng, |_, _| true);
        let parts: Vec<u32> = p.iter().map(|q| u32::from(q.x > 0.5)).collect();
        let before = p.clone();
        let faces = part_aware_remesh(&p, None, &parts, &RemeshOptions::default());
        assert_eq!(p, before);
        assert!(
            faces
                .iter()
                .all(|f| parts[f[0] as usize] == parts[f[1] as usize]
                    && parts[f[1] as usize] == parts[f[2] as usize])
        );
        assert_eq!(components(p.len(), &faces), 2);
        assert_manifold(&faces);
    }
}
