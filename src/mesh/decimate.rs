//! Decimation to a face budget by quadric edge collapse (Garland and Heckbert, "Surface
//! Simplification Using Quadric Error Metrics", 1997): each vertex carries the sum of the squared
//! distances to its faces' planes, and the edge whose collapse adds the least of it goes first.
//!
//! - The collapsed pair moves to whichever of its two ends or their midpoint the summed quadric
//!   likes best (no 3 × 3 solve: a near-flat patch makes it ill-conditioned, and the ends keep
//!   the vertex colours meaningful).
//! - Open rims keep their shape: each boundary edge adds a heavily weighted plane through it,
//!   perpendicular to its face.
//! - A collapse is refused when it would break the surface: when the two ends share a neighbour
//!   that is not opposite their edge (the link condition, which keeps every edge on at most two
//!   faces), when it joins two rim vertices across the inside, or when a face around it would
//!   flip or fold to nothing.

use std::cmp::Ordering;
use std::collections::{BTreeSet, BinaryHeap};

use glam::{DMat4, DVec3, DVec4, Vec3};

use super::topology::{face_edges, undirected};

/// Weight of a rim's constraint planes against the faces' own.
const RIM_WEIGHT: f64 = 100.0;
/// A face whose normal turns further than this (cosine) in a collapse blocks it.
const MIN_NORMAL_COSINE: f64 = 0.2;

/// A decimated mesh and, for each of its vertices, the input vertex it stands for.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Decimated {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    /// Input vertex index of each output vertex (to carry colours and the like over).
    pub source: Vec<u32>,
}

/// An edge collapse waiting in the queue: cheapest first; stale when either end changed since.
struct Candidate {
    cost: f64,
    a: u32,
    b: u32,
    stamps: (u32, u32),
}

impl PartialEq for Candidate {
    fn eq(&self, other: &Self) -> bool {
        self.cost.total_cmp(&other.cost) == Ordering::Equal
    }
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        // BinaryHeap is a max-heap: the lowest cost must compare greatest.
        other.cost.total_cmp(&self.cost)
    }
}

/// The mesh being decimated: positions, quadrics, faces and each vertex's faces.
struct Work {
    positions: Vec<DVec3>,
    quadrics: Vec<DMat4>,
    faces: Vec<[u32; 3]>,
    alive: Vec<bool>,
    vertex_faces: Vec<Vec<u32>>,
    stamps: Vec<u32>,
    rim: Vec<bool>,
    /// The input vertex each vertex stands for: of those collapsed into it, the one nearest.
    representative: Vec<u32>,
    original: Vec<DVec3>,
}

/// `triangles` over `positions` with at most `max_faces` faces (fewer collapses when the surface
/// allows no more). Faces indexing past `positions` are dropped first.
pub fn decimate(positions: &[Vec3], triangles: &[[u32; 3]], max_faces: usize) -> Decimated {
    let n = positions.len();
    let faces: Vec<[u32; 3]> = triangles
        .iter()
        .copied()
        .filter(|t| {
            t.iter().all(|&i| (i as usize) < n) && t[0] != t[1] && t[1] != t[2] && t[0] != t[2]
        })
        .collect();
    let mut w = Work::new(positions, faces);
    let mut live = w.faces.len();
    let mut heap = BinaryHeap::new();
    for (a, b) in w.edges() {
        w.push(&mut heap, a, b);
    }
    while live > max_faces {
        let Some(c) = heap.pop() else { break };
        if !c.cost.is_finite() || (w.stamps[c.a as usize], w.stamps[c.b as usize]) != c.stamps {
            continue;
        }
        if let Some(removed) = w.collapse(c.a, c.b) {
            live -= removed;
            for m in w.neighbours(c.b) {
                w.push(&mut heap, c.b, m);
            }
        }
    }
    w.finish()
}

impl Work {
    fn new(positions: &[Vec3], faces: Vec<[u32; 3]>) -> Work {
        let n = positions.len();
        let positions: Vec<DVec3> = positions.iter().map(|p| p.as_dvec3()).collect();
        let mut quadrics = vec![DMat4::ZERO; n];
        let mut vertex_faces = vec![Vec::new(); n];
        let mut uses: std::collections::HashMap<(u32, u32), (u32, u32)> = Default::default();
        for (f, t) in faces.iter().enumerate() {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let normal = (b - a).cross(c - a);
            let area = 0.5 * normal.length();
            if area > 0.0 {
                let q = plane_quadric(normal.normalize(), a) * area;
                for &i in t {
                    quadrics[i as usize] += q;
                }
            }
            for (k, &i) in t.iter().enumerate() {
                vertex_faces[i as usize].push(f as u32);
                let j = t[(k + 1) % 3];
                uses.entry((i.min(j), i.max(j))).or_insert((0, f as u32)).0 += 1;
            }
        }
        let mut rim = vec![false; n];
        for (&(i, j), &(count, f)) in &uses {
            if count != 1 {
                continue;
            }
            rim[i as usize] = true;
            rim[j as usize] = true;
            let t = faces[f as usize].map(|k| positions[k as usize]);
            let (p, q) = (positions[i as usize], positions[j as usize]);
            let face_normal = (t[1] - t[0]).cross(t[2] - t[0]);
            let side = (q - p).cross(face_normal);
            if side.length_squared() > 0.0 {
                let weight = RIM_WEIGHT * (q - p).length_squared();
                let quadric = plane_quadric(side.normalize(), p) * weight;
                quadrics[i as usize] += quadric;
                quadrics[j as usize] += quadric;
            }
        }
        Work {
            representative: (0..n as u32).collect(),
            original: positions.clone(),
            positions,
            quadrics,
            alive: vec![true; faces.len()],
            faces,
            vertex_faces,
            stamps: vec![0; n],
            rim,
        }
    }

    /// Every edge once.
    fn edges(&self) -> BTreeSet<(u32, u32)> {
        self.faces
            .iter()
            .flat_map(face_edges)
            .map(|(a, b)| undirected(a, b))
            .collect()
    }

    /// Live neighbours of `v`.
    fn neighbours(&self, v: u32) -> BTreeSet<u32> {
        self.vertex_faces[v as usize]
            .iter()
            .filter(|&&f| self.alive[f as usize])
            .flat_map(|&f| self.faces[f as usize])
            .filter(|&u| u != v)
            .collect()
    }

    /// Where collapsing `a` and `b` puts the survivor, and the quadric error there.
    fn placement(&self, a: u32, b: u32) -> (DVec3, f64) {
        let q = self.quadrics[a as usize] + self.quadrics[b as usize];
        let (pa, pb) = (self.positions[a as usize], self.positions[b as usize]);
        [pa, pb, 0.5 * (pa + pb)]
            .into_iter()
            .map(|p| (p, error(&q, p)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap_or((pa, f64::INFINITY))
    }

    fn push(&self, heap: &mut BinaryHeap<Candidate>, a: u32, b: u32) {
        let (_, cost) = self.placement(a, b);
        heap.push(Candidate {
            cost,
            a,
            b,
            stamps: (self.stamps[a as usize], self.stamps[b as usize]),
        });
    }

    /// Collapses `a` into `b` when the surface allows it; the number of faces removed.
    fn collapse(&mut self, a: u32, b: u32) -> Option<usize> {
        let live = |w: &Work, v: u32| -> Vec<u32> {
            w.vertex_faces[v as usize]
                .iter()
                .copied()
                .filter(|&f| w.alive[f as usize])
                .collect()
        };
        let (fa, fb) = (live(self, a), live(self, b));
        let shared: Vec<u32> = fa.iter().copied().filter(|f| fb.contains(f)).collect();
        if shared.is_empty() {
            return None;
        }
        // The link condition: the ends' common neighbours are exactly those opposite the edge.
        let opposite: BTreeSet<u32> = shared
            .iter()
            .flat_map(|&f| self.faces[f as usize])
            .filter(|&v| v != a && v != b)
            .collect();
        let common: BTreeSet<u32> = self
            .neighbours(a)
            .intersection(&self.neighbours(b))
            .copied()
            .collect();
        if common != opposite {
            return None;
        }
        // A triangle or tetrahedron on its own would fold to nothing.
        let around: BTreeSet<u32> = self
            .neighbours(a)
            .union(&self.neighbours(b))
            .copied()
            .collect();
        if around
            .iter()
            .all(|v| *v == a || *v == b || opposite.contains(v))
        {
            return None;
        }
        let edge_on_rim = shared.len() == 1;
        if self.rim[a as usize] && self.rim[b as usize] && !edge_on_rim {
            return None;
        }
        let (target, _) = self.placement(a, b);
        // No face around the pair may flip or fold.
        for &f in fa.iter().chain(&fb).filter(|f| !shared.contains(f)) {
            let t = self.faces[f as usize];
            let before = t.map(|v| self.positions[v as usize]);
            let after = t.map(|v| {
                if v == a || v == b {
                    target
                } else {
                    self.positions[v as usize]
                }
            });
            let n0 = (before[1] - before[0]).cross(before[2] - before[0]);
            let n1 = (after[1] - after[0]).cross(after[2] - after[0]);
            if n1.length_squared() <= 1e-12 * n0.length_squared()
                || n0.dot(n1) < MIN_NORMAL_COSINE * n0.length() * n1.length()
            {
                return None;
            }
        }
        for &f in &shared {
            self.alive[f as usize] = false;
        }
        for &f in &fa {
            if self.alive[f as usize] {
                for v in &mut self.faces[f as usize] {
                    if *v == a {
                        *v = b;
                    }
                }
                self.vertex_faces[b as usize].push(f);
            }
        }
        self.vertex_faces[a as usize].clear();
        self.positions[b as usize] = target;
        let (ra, rb) = (
            self.representative[a as usize],
            self.representative[b as usize],
        );
        let nearer_a = self.original[ra as usize].distance(target)
            < self.original[rb as usize].distance(target);
        self.representative[b as usize] = if nearer_a { ra } else { rb };
        let qa = self.quadrics[a as usize];
        self.quadrics[b as usize] += qa;
        self.rim[b as usize] |= self.rim[a as usize];
        self.stamps[a as usize] += 1;
        self.stamps[b as usize] += 1;
        Some(shared.len())
    }

    /// The live faces over the vertices they use, renumbered in order of first use.
    fn finish(self) -> Decimated {
        let mut map = vec![u32::MAX; self.positions.len()];
        let mut out = Decimated::default();
        for (t, _) in self.faces.iter().zip(&self.alive).filter(|(_, a)| **a) {
            out.triangles.push(t.map(|v| {
                if map[v as usize] == u32::MAX {
                    map[v as usize] = out.positions.len() as u32;
                    out.positions.push(self.positions[v as usize].as_vec3());
                    out.source.push(self.representative[v as usize]);
                }
                map[v as usize]
            }));
        }
        out
    }
}

/// The quadric of squared distance to the plane through `p` with unit normal `n`.
fn plane_quadric(n: DVec3, p: DVec3) -> DMat4 {
    let plane = DVec4::new(n.x, n.y, n.z, -n.dot(p));
    DMat4::from_cols(
        plane * plane.x,
        plane * plane.y,
        plane * plane.z,
        plane * plane.w,
    )
}

/// `q` evaluated at `p` (homogeneous `pᵀ Q p`).
fn error(q: &DMat4, p: DVec3) -> f64 {
    let h = p.extend(1.0);
    h.dot(*q * h).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::edge_counts;

    /// A UV sphere of radius 1 with `rings` × `2 rings` quads (poles fanned).
    fn sphere(rings: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let segments = 2 * rings;
        let mut p = vec![Vec3::Z, -Vec3::Z];
        for r in 1..rings {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            for s in 0..segments {
                let phi = std::f32::consts::TAU * s as f32 / segments as f32;
                p.push(Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                ));
            }
        }
        let at = |r: u32, s: u32| 2 + (r - 1) * segments + s % segments;
        let mut t = Vec::new();
        for s in 0..segments {
            t.push([0, at(1, s), at(1, s + 1)]);
            t.push([1, at(rings - 1, s + 1), at(rings - 1, s)]);
            for r in 1..rings - 1 {
                t.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
                t.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
            }
        }
        (p, t)
    }

    #[test]
    fn a_sphere_keeps_its_shape_and_stays_closed() {
        let (p, t) = sphere(60);
        assert!(t.len() > 14_000);
        let d = decimate(&p, &t, 1000);
        assert!(
            d.triangles.len() <= 1000 && d.triangles.len() > 900,
            "{}",
            d.triangles.len()
        );
        let counts = edge_counts(&d.triangles);
        assert_eq!((counts.boundary, counts.non_manifold), (0, 0));
        for q in &d.positions {
            assert!((q.length() - 1.0).abs() < 0.01, "{q}");
        }
        for (v, &s) in d.positions.iter().zip(&d.source) {
            assert!(v.distance(p[s as usize]) < 0.1);
        }
    }

    #[test]
    fn an_open_sheet_keeps_its_rim() {
        // A 40 × 40 grid on the unit square, gently curved.
        let n = 40u32;
        let p: Vec<Vec3> = (0..=n)
            .flat_map(|y| (0..=n).map(move |x| (x, y)))
            .map(|(x, y)| {
                let (u, v) = (x as f32 / n as f32, y as f32 / n as f32);
                Vec3::new(u, v, 0.05 * (u * 3.0).sin())
            })
            .collect();
        let id = |x: u32, y: u32| y * (n + 1) + x;
        let t: Vec<[u32; 3]> = (0..n)
            .flat_map(|y| (0..n).map(move |x| (x, y)))
            .flat_map(|(x, y)| {
                [
                    [id(x, y), id(x + 1, y), id(x + 1, y + 1)],
                    [id(x, y), id(x + 1, y + 1), id(x, y + 1)],
                ]
            })
            .collect();
        let d = decimate(&p, &t, 200);
        assert!(d.triangles.len() <= 200, "{}", d.triangles.len());
        let counts = edge_counts(&d.triangles);
        assert_eq!(counts.non_manifold, 0);
        // The corners survive, and the rim still bounds the unit square.
        for corner in [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)] {
            let nearest = d
                .positions
                .iter()
                .map(|q| (q.truncate() - corner.truncate()).length())
                .fold(f32::INFINITY, f32::min);
            assert!(nearest < 1e-6, "corner {corner} lost ({nearest})");
        }
        let area: f32 = d
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| d.positions[i as usize].truncate());
                0.5 * ((b - a).perp_dot(c - a)).abs()
            })
            .sum();
        assert!((area - 1.0).abs() < 0.01, "{area}");
    }

    #[test]
    fn bad_indices_and_tiny_budgets_are_safe() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let d = decimate(&p, &[[0, 1, 2], [0, 1, 9], [1, 1, 2]], 0);
        assert_eq!(d.triangles.len(), 1);
        assert!(decimate(&[], &[], 10).triangles.is_empty());
    }
}
