//! Closing short holes after remeshing (issue 27): a restricted Delaunay mesh of a closed part
//! keeps small holes where the points were sparse or an umbrella disagreed with its neighbours.
//! Each boundary loop of at most a few dozen edges gets the least-area triangulation of its own
//! vertices (no new vertices, so the field's attributes stay as they are), oriented like the faces
//! around it, and never adding an edge the mesh already has, so a manifold mesh stays manifold.
//! Long loops are left open: they are open rims or regions nobody measured.

use std::collections::{HashMap, HashSet};

use glam::Vec3;

use super::topology::{face_edges, undirected};

/// The longest loop [`close_short_holes`] fills: its triangulation takes O(n²) memory and O(n³)
/// time in the loop's length.
pub const MAX_HOLE_EDGES: usize = 256;

/// What [`close_short_holes`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct HoleStats {
    /// Simple boundary loops found.
    pub loops: usize,
    /// Loops closed.
    pub closed: usize,
    /// Faces added.
    pub faces: usize,
    /// Fill faces left out because `keep` refused them (they span an opening the views saw
    /// through); a loop all of whose fill is refused is not counted closed.
    pub refused_faces: usize,
}

/// Faces that close every hole of `faces` (one part's) bounded by a simple loop of at most
/// `max_edges` edges (3 or more; at most [`MAX_HOLE_EDGES`]), less the fill faces `keep` refuses,
/// and what was done.
///
/// The boundary edges are split into simple loops: closed walks along unused boundary edges, cut
/// where a walk comes back to a vertex it passed (a vertex where two holes touch, or a hole and a
/// rim). Each loop is walked against the faces along most of its edges, so the new faces face as
/// their neighbours do (where the remeshed faces around a hole disagree, the majority wins).
pub fn close_short_holes(
    positions: &[Vec3],
    faces: &[[u32; 3]],
    max_edges: usize,
    keep: &dyn Fn(&[u32; 3]) -> bool,
) -> (Vec<[u32; 3]>, HoleStats) {
    let mut stats = HoleStats::default();
    let max_edges = max_edges.min(MAX_HOLE_EDGES);
    if max_edges < 3 {
        return (Vec::new(), stats);
    }
    let (loops, mut edges) = boundary_loops(faces);
    let mut added = Vec::new();
    for BoundaryLoop {
        mut vertices,
        along,
    } in loops
    {
        stats.loops += 1;
        if vertices.len() > max_edges {
            continue;
        }
        // Faces run a→b along a boundary edge; the hole's own faces must run b→a.
        if 2 * along > vertices.len() {
            vertices.reverse();
        }
        if let Some(fill) = least_area_fill(positions, &vertices, &mut edges) {
            let (fill, left): (Vec<[u32; 3]>, Vec<[u32; 3]>) = fill.iter().partition(|f| keep(f));
            if !left.is_empty() {
                stats.refused_faces += left.len();
                forget_diagonals(&left, &fill, &vertices, &mut edges);
            }
            if fill.is_empty() {
                continue;
            }
            stats.closed += 1;
            stats.faces += fill.len();
            added.extend(fill);
        }
    }
    (added, stats)
}

/// Takes the diagonals of the `left` faces of a fill of `hole` back out of `edges`, but for those
/// the `kept` faces still use (the hole's own edges stay).
fn forget_diagonals(
    left: &[[u32; 3]],
    kept: &[[u32; 3]],
    hole: &[u32],
    edges: &mut HashSet<(u32, u32)>,
) {
    let n = hole.len();
    let own: HashSet<(u32, u32)> = (0..n)
        .map(|i| (hole[i], hole[(i + 1) % n]))
        .chain(kept.iter().flat_map(face_edges))
        .map(|(a, b)| undirected(a, b))
        .collect();
    for (a, b) in left.iter().flat_map(face_edges) {
        if !own.contains(&undirected(a, b)) {
            edges.remove(&undirected(a, b));
        }
    }
}

/// A simple boundary loop of a mesh, in its walking order.
pub(super) struct BoundaryLoop {
    /// The loop's vertices (no vertex twice); edge `i` runs from `vertices[i]` to the next.
    pub vertices: Vec<u32>,
    /// How many of its edges the adjacent face runs in the walking direction.
    pub along: usize,
}

/// The boundary of `faces` as simple loops (see [`simple_loops`]), and every edge of the mesh.
pub(super) fn boundary_loops(faces: &[[u32; 3]]) -> (Vec<BoundaryLoop>, HashSet<(u32, u32)>) {
    // Per undirected edge: uses, and the direction of its first face.
    let mut uses: HashMap<(u32, u32), (u32, (u32, u32))> = HashMap::new();
    let mut order = Vec::new(); // edges in order of first use, so the output is deterministic
    for (a, b) in faces.iter().flat_map(face_edges) {
        let e = uses.entry(undirected(a, b)).or_insert_with(|| {
            order.push(undirected(a, b));
            (0, (a, b))
        });
        e.0 += 1;
    }
    let boundary: Vec<(u32, u32)> = order.iter().copied().filter(|e| uses[e].0 == 1).collect();
    let loops = simple_loops(&boundary)
        .into_iter()
        .map(|vertices| {
            let n = vertices.len();
            let along = (0..n)
                .filter(|&i| {
                    let (a, b) = (vertices[i], vertices[(i + 1) % n]);
                    uses[&undirected(a, b)].1 == (a, b)
                })
                .count();
            BoundaryLoop { vertices, along }
        })
        .collect();
    (loops, order.into_iter().collect())
}

/// The `boundary` edges as simple loops (no vertex twice). Every vertex of a mesh's boundary has
/// an even number of boundary edges, so walks along unused edges close; a walk that passes a
/// vertex twice is cut there into two loops.
fn simple_loops(boundary: &[(u32, u32)]) -> Vec<Vec<u32>> {
    let mut adjacent: HashMap<u32, Vec<u32>> = HashMap::new();
    for &(a, b) in boundary {
        adjacent.entry(a).or_default().push(b);
        adjacent.entry(b).or_default().push(a);
    }
    let mut used: HashSet<(u32, u32)> = HashSet::new();
    let unused_from = |v: u32, used: &HashSet<(u32, u32)>| {
        adjacent[&v]
            .iter()
            .copied()
            .find(|&w| !used.contains(&undirected(v, w)))
    };
    let mut loops = Vec::new();
    for &(start, _) in boundary {
        while unused_from(start, &used).is_some() {
            let mut walk = vec![start];
            let mut v = start;
            while let Some(w) = unused_from(v, &used) {
                used.insert(undirected(v, w));
                v = w;
                if v == start {
                    break;
                }
                walk.push(v);
            }
            // A walk that does not close (an odd boundary vertex) is left open.
            if v == start {
                cut_at_repeats(&walk, &mut loops);
            }
        }
    }
    loops
}

/// Cuts the closed `walk` into simple loops where it passes a vertex again.
fn cut_at_repeats(walk: &[u32], loops: &mut Vec<Vec<u32>>) {
    let mut stack: Vec<u32> = Vec::with_capacity(walk.len());
    let mut at: HashMap<u32, usize> = HashMap::new();
    for &v in walk.iter().chain(&walk[..1]) {
        match at.get(&v) {
            Some(&i) => {
                let rest = stack.split_off(i + 1);
                for u in &rest {
                    at.remove(u);
                }
                if rest.len() >= 2 {
                    loops.push([&[v], &rest[..]].concat());
                }
            }
            None => {
                at.insert(v, stack.len());
                stack.push(v);
            }
        }
    }
}

/// The triangulation of `hole` (its own vertices, in its order) of least total area, by dynamic
/// programming over its sub-chains (O(n³)): it needs no plane, so it also spans a hole that wraps
/// around a curved part, and on a flat one it never folds over (a folded triangulation covers
/// more area). A diagonal the mesh already has is not used (it would make an edge of three
/// faces); `None` when no triangulation avoids them. The new diagonals are added to `edges`.
fn least_area_fill(
    positions: &[Vec3],
    hole: &[u32],
    edges: &mut HashSet<(u32, u32)>,
) -> Option<Vec<[u32; 3]>> {
    let n = hole.len();
    let p = |i: usize| positions[hole[i] as usize];
    let area = |i: usize, m: usize, j: usize| 0.5 * (p(m) - p(i)).cross(p(j) - p(i)).length();
    // cost[i][j]: least area of the polygon hole[i..=j] closed by the chord (i, j); best[i][j]
    // its apex.
    let mut cost = vec![vec![0.0f32; n]; n];
    let mut best = vec![vec![usize::MAX; n]; n];
    for span in 2..n {
        for i in 0..n - span {
            let j = i + span;
            cost[i][j] = f32::INFINITY;
            // The chord (0, n-1) is the hole's own edge; every other one must be new.
            if span < n - 1 && edges.contains(&undirected(hole[i], hole[j])) {
                continue;
            }
            for m in i + 1..j {
                let c = cost[i][m] + cost[m][j] + area(i, m, j);
                if c < cost[i][j] {
                    (cost[i][j], best[i][j]) = (c, m);
                }
            }
        }
    }
    if !cost[0][n - 1].is_finite() {
        return None;
    }
    let mut fill = Vec::with_capacity(n - 2);
    let mut stack = vec![(0, n - 1)];
    while let Some((i, j)) = stack.pop() {
        if j - i < 2 {
            continue;
        }
        let m = best[i][j];
        fill.push([hole[i], hole[m], hole[j]]);
        stack.extend([(i, m), (m, j)]);
        for (a, b) in [(i, m), (m, j)] {
            if b - a >= 2 {
                edges.insert(undirected(hole[a], hole[b]));
            }
        }
    }
    Some(fill)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::edge_counts;

    /// A unit cube's 8 corners and 12 outward faces (its top, z = 1, is faces 2 and 3).
    fn cube() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mesh = crate::data::fixture::box_mesh(Vec3::ZERO, Vec3::ONE);
        (mesh.positions, mesh.triangles)
    }

    #[test]
    fn a_missing_quad_is_closed_outward_and_manifold() {
        let (p, mut faces) = cube();
        let original = faces.clone();
        faces.drain(2..4); // the top (z = 1) quad
        assert_eq!(edge_counts(&faces).boundary, 4);
        let (fill, stats) = close_short_holes(&p, &faces, 8, &|_| true);
        assert_eq!((stats.loops, stats.closed, stats.faces), (1, 1, 2));
        faces.extend(&fill);
        let e = edge_counts(&faces);
        assert_eq!((e.boundary, e.non_manifold), (0, 0));
        // Outward like the faces that were removed.
        let n = |f: &[u32; 3]| {
            (p[f[1] as usize] - p[f[0] as usize]).cross(p[f[2] as usize] - p[f[0] as usize])
        };
        for f in &fill {
            assert!(n(f).dot(n(&original[2])) > 0.0, "{f:?}");
        }
    }

    #[test]
    fn refused_fill_faces_stay_open_and_leave_their_diagonals_free() {
        let (p, mut faces) = cube();
        faces.drain(2..4);
        let (fill, stats) = close_short_holes(&p, &faces, 8, &|_| false);
        assert!(fill.is_empty());
        assert_eq!((stats.loops, stats.closed, stats.refused_faces), (1, 0, 2));
        // Two holes, the first face of the first fill refused: the rest is still closed, and
        // stays manifold.
        faces.drain(0..2);
        let first = std::cell::Cell::new(true);
        let (fill, stats) = close_short_holes(&p, &faces, 8, &|_| !first.replace(false));
        assert_eq!((stats.loops, stats.closed, stats.refused_faces), (2, 2, 1));
        assert_eq!(fill.len(), 3);
        faces.extend(&fill);
        let e = edge_counts(&faces);
        assert_eq!((e.boundary, e.non_manifold), (3, 0));
    }

    #[test]
    fn long_loops_and_open_sheets_stay_open() {
        let (p, mut faces) = cube();
        faces.drain(2..4);
        let (fill, stats) = close_short_holes(&p, &faces, 3, &|_| true);
        assert!(fill.is_empty());
        assert_eq!((stats.loops, stats.closed), (1, 0));
        let (fill, _) = close_short_holes(&p, &faces, 2, &|_| true);
        assert!(fill.is_empty());
    }

    /// A flat sheet of 5x4 unit squares (two faces each, facing +z) without the squares `holes`.
    fn sheet_without(holes: &[(u32, u32)]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let at = |x: u32, y: u32| y * 6 + x;
        let p = (0..30)
            .map(|i| Vec3::new((i % 6) as f32, (i / 6) as f32, 0.0))
            .collect();
        let mut faces = Vec::new();
        for y in 0..4 {
            for x in 0..5 {
                if !holes.contains(&(x, y)) {
                    faces.push([at(x, y), at(x + 1, y), at(x + 1, y + 1)]);
                    faces.push([at(x, y), at(x + 1, y + 1), at(x, y + 1)]);
                }
            }
        }
        (p, faces)
    }

    #[test]
    fn holes_touching_at_a_vertex_are_closed_apart() {
        let (p, mut faces) = sheet_without(&[(1, 1), (2, 2)]);
        let (fill, stats) = close_short_holes(&p, &faces, 12, &|_| true);
        assert_eq!((stats.loops, stats.closed, stats.faces), (3, 2, 4));
        faces.extend(&fill);
        let e = edge_counts(&faces);
        assert_eq!((e.boundary, e.non_manifold), (18, 0));
        for f in &fill {
            let (a, b, c) = (p[f[0] as usize], p[f[1] as usize], p[f[2] as usize]);
            assert!(
                (b - a).cross(c - a).z > 0.0,
                "{f:?} faces +z as the sheet does"
            );
        }
    }

    #[test]
    fn a_non_convex_hole_gets_no_face_outside_it() {
        // An L-shaped hole of three squares.
        let (p, mut faces) = sheet_without(&[(1, 1), (2, 1), (1, 2)]);
        let (fill, stats) = close_short_holes(&p, &faces, 12, &|_| true);
        // The outer rim (18 edges) stays open; the L (8 edges) closes with 6 faces of area 3.
        assert_eq!((stats.loops, stats.closed, stats.faces), (2, 1, 6));
        let area: f32 = fill
            .iter()
            .map(|f| {
                let (a, b, c) = (p[f[0] as usize], p[f[1] as usize], p[f[2] as usize]);
                (b - a).cross(c - a).z * 0.5
            })
            .sum();
        assert!((area - 3.0).abs() < 1e-5, "{area}");
        faces.extend(&fill);
        let e = edge_counts(&faces);
        assert_eq!((e.boundary, e.non_manifold), (18, 0));
    }
}
