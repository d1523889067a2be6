//! Stitching a thin part's rims (issue 27). The restricted Delaunay step keeps the two sides of a
//! thin part apart (their normals are 180° apart), so a knife blade or a spectacle frame comes out
//! as two sheets whose boundary loops run side by side along the rim, a gap of about the part's
//! thickness between them. Where two boundary runs stay that close, they are zipped together with
//! a strip of triangles over their own vertices, oriented like the faces on either side; a loop
//! with nothing near it (a real opening, or a region nobody measured) is left as it is.

use std::collections::{HashMap, HashSet};

use glam::Vec3;

use super::holes::{BoundaryLoop, boundary_loops};
use super::spatial::KdTree;
use super::topology::undirected;

/// Runs shorter than this many vertices are not zipped: a few boundary vertices that happen to be
/// near another loop are not a rim.
const MIN_RUN: usize = 4;

/// Consecutive vertices of a run match vertices at most this many steps back on the other side,
/// or this many forward (nearest neighbours jitter where the spacing is uneven).
const MAX_STEP: usize = 6;
const MAX_JITTER: i64 = 2;

/// A loop's own vertices this close along it are its neighbours on the same side, never its
/// other side.
const SAME_LOOP_SKIP: usize = 16;

/// What [`stitch_rims`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct RimStats {
    /// Runs of boundary zipped to another run.
    pub zipped: usize,
    /// Faces added.
    pub faces: usize,
}

/// Faces that zip together the boundary runs of `faces` (one part's) that stay within `max_gap`
/// of another stretch of boundary, and what was done.
///
/// Each loop is walked along its faces (a face runs aᵢ → aᵢ₊₁ on the loop). A vertex is matched to
/// the nearest boundary vertex within `max_gap` of another loop, or of its own loop more than
/// [`SAME_LOOP_SKIP`] steps away (a thin part whose sides join somewhere has one loop down one
/// side of the rim and back up the other). A run of consecutive vertices whose matches walk one
/// loop backwards (the two sides of a rim run opposite ways) is zipped to that stretch (or fanned
/// to one vertex where the matches stay on it), the whole loop when every vertex matched. A strip
/// face that would give an edge a third face is left out, so a manifold mesh stays manifold.
///
/// The two edges of a narrow band seen from one side also run side by side opposite ways; their
/// strip folds back under the band and gives it a back face, as a thin plate has. Refusing such
/// folds was measured: the quick suite's CD-s rose 9.89 -> 10.14 mm (storage furniture
/// 25.94 -> 29.86) and no figure improved.
pub fn stitch_rims(
    positions: &[Vec3],
    faces: &[[u32; 3]],
    max_gap: f32,
) -> (Vec<[u32; 3]>, RimStats) {
    let mut stats = RimStats::default();
    let (loops, mut edges) = boundary_loops(faces);
    let loops: Vec<Vec<u32>> = loops
        .into_iter()
        .map(
            |BoundaryLoop {
                 mut vertices,
                 along,
             }| {
                if 2 * along < vertices.len() {
                    vertices.reverse();
                }
                vertices
            },
        )
        .collect();
    let all: Vec<(usize, usize)> = loops
        .iter()
        .enumerate()
        .flat_map(|(l, vs)| (0..vs.len()).map(move |i| (l, i)))
        .collect();
    let tree = KdTree::new(
        &all.iter()
            .map(|&(l, i)| positions[loops[l][i] as usize])
            .collect::<Vec<_>>(),
    );
    // The boundary edges zips have consumed: each can take one more face only once.
    let mut consumed: HashSet<(u32, u32)> = HashSet::new();
    let mut added = Vec::new();
    for (a, a_loop) in loops.iter().enumerate() {
        if a_loop.len() < MIN_RUN {
            continue;
        }
        // The nearest boundary vertex of another loop, or of this loop's far side (a thin part
        // whose sides join somewhere has one loop running down one side of the rim and back up
        // the other).
        let n = a_loop.len();
        let matches: Vec<Option<(usize, usize)>> = (0..n)
            .map(|i| {
                let far = |k: usize| {
                    let (l, j) = all[k];
                    l != a || (i + n - j) % n > SAME_LOOP_SKIP && (j + n - i) % n > SAME_LOOP_SKIP
                };
                let (k, d2) = tree.nearest_index_where(positions[a_loop[i] as usize], far)?;
                (d2.sqrt() <= max_gap as f64).then_some(all[k])
            })
            .collect();
        for run in runs(&matches, &loops) {
            let b_loop = &loops[run.partner];
            let Some((chain_a, chain_b)) = run.chains(a_loop, b_loop) else {
                continue;
            };
            let strip = zip(positions, &chain_a, &chain_b, &mut edges, &mut consumed);
            if strip.is_empty() {
                continue;
            }
            stats.zipped += 1;
            stats.faces += strip.len();
            added.extend(strip);
        }
    }
    (added, stats)
}

/// A run of consecutive loop vertices matched into one loop (another, or its own far side).
struct Run {
    /// The loop matched into.
    partner: usize,
    /// First index of the run in its own loop, and its vertex count (the whole loop when closed).
    start: usize,
    len: usize,
    /// The partner loop's vertex each run vertex matched, in run order.
    matched: Vec<usize>,
    /// Whether the run is its whole loop.
    closed: bool,
}

impl Run {
    /// The run's own vertices and the partner's stretch (one vertex or more), both in the
    /// direction the strip walks, when the matches walk the partner backwards and the two share
    /// no vertex; `None` otherwise.
    fn chains(&self, own: &[u32], partner: &[u32]) -> Option<(Vec<u32>, Vec<u32>)> {
        let n = partner.len();
        // Backward steps between consecutive matches (small, some maybe forward: see [`runs`]).
        let steps: i64 = self
            .matched
            .windows(2)
            .map(|w| back_step(w[0], w[1], n))
            .sum();
        let own_chain: Vec<u32> = (0..self.len + usize::from(self.closed))
            .map(|k| own[(self.start + k) % own.len()])
            .collect();
        let partner_chain: Vec<u32> = if self.closed {
            let last = self.matched[self.matched.len() - 1];
            // Closed on both sides: the matches must go once around the partner.
            if steps + back_step(last, self.matched[0], n) != n as i64 {
                return None;
            }
            (0..=n)
                .map(|k| partner[(self.matched[0] + n - k % n) % n])
                .collect()
        } else {
            if !(0..n as i64).contains(&steps) {
                return None;
            }
            (0..=steps as usize)
                .map(|k| partner[(self.matched[0] + n - k) % n])
                .collect()
        };
        let shared = own_chain.iter().any(|v| partner_chain.contains(v));
        (!shared).then_some((own_chain, partner_chain))
    }
}

/// How many steps back along a loop of `n` vertices `to` is from `from` (negative: forward),
/// the shorter way round.
fn back_step(from: usize, to: usize, n: usize) -> i64 {
    let back = ((from + n - to) % n) as i64;
    if back > n as i64 / 2 {
        back - n as i64
    } else {
        back
    }
}

/// The maximal runs of at least [`MIN_RUN`] consecutive vertices whose matches walk one of
/// `loops` backwards in steps of at most [`MAX_STEP`] (or [`MAX_JITTER`] forward), cyclic over the
/// loop (a run may wrap past its end).
fn runs(matches: &[Option<(usize, usize)>], loops: &[Vec<u32>]) -> Vec<Run> {
    let n = matches.len();
    // Whether vertex i + 1 continues vertex i's run.
    let continues = |i: usize| match (matches[i % n], matches[(i + 1) % n]) {
        (Some((l, j)), Some((next, k))) => {
            l == next && (-MAX_JITTER..=MAX_STEP as i64).contains(&back_step(j, k, loops[l].len()))
        }
        _ => false,
    };
    let matched = |s: usize, len: usize| -> Vec<usize> {
        (0..len)
            .map(|k| matches[(s + k) % n].map_or(0, |(_, j)| j))
            .collect()
    };
    if (0..n).all(continues) {
        let Some((partner, _)) = matches[0] else {
            return Vec::new();
        };
        return vec![Run {
            partner,
            start: 0,
            len: n,
            matched: matched(0, n),
            closed: true,
        }];
    }
    // Start just after a break, so no run is cut by the loop's end.
    let Some(first) = (0..n).find(|&i| !continues(i + n - 1)) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut i = 0;
    while i < n {
        let s = first + i;
        let mut len = 1;
        while i + len < n && continues(s + len - 1) {
            len += 1;
        }
        if let Some((partner, _)) = matches[s % n]
            && len >= MIN_RUN
        {
            out.push(Run {
                partner,
                start: s % n,
                len,
                matched: matched(s, len),
                closed: false,
            });
        }
        i += len;
    }
    out
}

/// The strip between `a` (its faces run aᵢ → aᵢ₊₁) and `b` (walking the same way, its faces run
/// bⱼ₊₁ → bⱼ), advancing on whichever side gives the shorter new edge. A face is left out where
/// it would take a boundary edge another zip `consumed`, cross on an edge already in `edges` or
/// give one of its new edges a third face (a closed strip that set out along its partner and came
/// back the same way); the short holes that leaves are closed afterwards. The boundary edges it
/// takes go into `consumed`, its new edges into `edges`.
fn zip(
    positions: &[Vec3],
    a: &[u32],
    b: &[u32],
    edges: &mut HashSet<(u32, u32)>,
    consumed: &mut HashSet<(u32, u32)>,
) -> Vec<[u32; 3]> {
    let p = |v: u32| positions[v as usize];
    let (m, n) = (a.len() - 1, b.len() - 1);
    let (mut i, mut j) = (0, 0);
    let mut strip = Vec::with_capacity(m + n);
    // Faces on each new edge so far.
    let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
    while i < m || j < n {
        let advance_a =
            j == n || (i < m && p(a[i + 1]).distance(p(b[j])) <= p(a[i]).distance(p(b[j + 1])));
        // Both kinds of face have their boundary edge first.
        let face = if advance_a {
            i += 1;
            [a[i], a[i - 1], b[j]]
        } else {
            j += 1;
            [b[j - 1], b[j], a[i]]
        };
        let own = undirected(face[0], face[1]);
        let new = [undirected(face[1], face[2]), undirected(face[2], face[0])];
        let fits = face[2] != face[0]
            && face[2] != face[1]
            && edges.contains(&own)
            && !consumed.contains(&own)
            && new
                .iter()
                .all(|e| !edges.contains(e) && uses.get(e).is_none_or(|&u| u < 2));
        if fits {
            consumed.insert(own);
            for e in new {
                *uses.entry(e).or_insert(0) += 1;
            }
            strip.push(face);
        }
    }
    edges.extend(uses.into_keys());
    strip
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::edge_counts;

    /// A thin slab's two faces (top facing +z, bottom facing −z) over an n×n grid of unit squares,
    /// `gap` apart, without the rim between them.
    fn slab(n: u32, gap: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let side = n + 1;
        let at = |x: u32, y: u32, s: u32| s * side * side + y * side + x;
        let mut p = Vec::new();
        for s in 0..2 {
            for y in 0..side {
                for x in 0..side {
                    p.push(Vec3::new(
                        x as f32,
                        y as f32,
                        if s == 0 { gap } else { 0.0 },
                    ));
                }
            }
        }
        let mut faces = Vec::new();
        for y in 0..n {
            for x in 0..n {
                for s in 0..2 {
                    let [a, b, c, d] =
                        [(x, y), (x + 1, y), (x + 1, y + 1), (x, y + 1)].map(|(x, y)| at(x, y, s));
                    // The top faces +z, the bottom −z.
                    if s == 0 {
                        faces.extend([[a, b, c], [a, c, d]]);
                    } else {
                        faces.extend([[a, c, b], [a, d, c]]);
                    }
                }
            }
        }
        (p, faces)
    }

    /// Two faces joining the [`slab`]'s sides over the rim square at `x` along y = 0, oriented
    /// like the slab's faces.
    fn joined_at(n: u32, x: u32) -> [[u32; 3]; 2] {
        let side = n + 1;
        let (t, b) = (|x: u32| x, |x: u32| side * side + x);
        [[t(x + 1), t(x), b(x)], [b(x), b(x + 1), t(x + 1)]]
    }

    #[test]
    fn a_thin_slab_is_closed_at_its_rim_and_stays_oriented() {
        let (p, mut faces) = slab(4, 0.3);
        assert_eq!(edge_counts(&faces).boundary, 32);
        let (strip, stats) = stitch_rims(&p, &faces, 0.5);
        assert_eq!((stats.zipped, stats.faces), (1, 32));
        faces.extend(&strip);
        let e = edge_counts(&faces);
        assert_eq!((e.boundary, e.non_manifold), (0, 0));
        // Every edge is used once in each direction: one consistent orientation.
        let mut directed: HashSet<(u32, u32)> = HashSet::new();
        for f in &faces {
            for i in 0..3 {
                assert!(directed.insert((f[i], f[(i + 1) % 3])), "{f:?}");
            }
        }
        // The strip faces outward: the face at x = 0 points −x.
        for f in &strip {
            let [a, b, c] = f.map(|v| p[v as usize]);
            let n = (b - a).cross(c - a);
            let centre = (a + b + c) / 3.0 - Vec3::new(2.0, 2.0, 0.15);
            assert!(n.dot(centre) > 0.0, "{f:?} faces inward");
        }
    }

    #[test]
    fn sheets_farther_apart_than_the_gap_stay_open() {
        let (p, faces) = slab(4, 2.0);
        let (strip, stats) = stitch_rims(&p, &faces, 0.5);
        assert!(strip.is_empty());
        assert_eq!(stats, RimStats::default());
    }

    #[test]
    fn a_rim_partly_near_its_other_side_is_zipped_only_there() {
        // The bottom sheet's outer row at y = 4 bent down by 2: the rim stays near its other
        // side along three of the four edges.
        let (mut p, mut faces) = slab(4, 0.3);
        for v in &mut p[25..] {
            if v.y == 4.0 {
                v.z -= 2.0;
            }
        }
        let (strip, stats) = stitch_rims(&p, &faces, 0.5);
        assert_eq!(stats.zipped, 1);
        faces.extend(&strip);
        let e = edge_counts(&faces);
        assert_eq!(e.non_manifold, 0);
        // The run stops a row short of the bent edge (10 of 16 edges per side); the rest stays
        // open on both sides (6 + 6), with the two bridges that end the strip.
        assert_eq!(e.boundary, 6 + 6 + 2, "{e:?}");
    }

    #[test]
    fn sides_joined_along_one_edge_are_zipped_along_the_others() {
        // The slab's sides joined by hand along y = 0: one boundary loop runs up one side's rim
        // and back down the other's.
        let n = 16;
        let (p, mut faces) = slab(n, 0.3);
        for x in 0..n {
            faces.extend(joined_at(n, x));
        }
        assert_eq!(edge_counts(&faces).boundary, 2 * 3 * n as usize + 2);
        let (strip, stats) = stitch_rims(&p, &faces, 0.5);
        assert_eq!(stats.zipped, 1);
        faces.extend(&strip);
        let e = edge_counts(&faces);
        assert_eq!(e.non_manifold, 0);
        // Near the joined edge the other side is too few steps along the loop to be matched:
        // two short holes are left, and closing short holes closes them.
        assert!(e.boundary <= 40, "{e:?}");
        let (fill, _) = crate::mesh::close_short_holes(&p, &faces, 48, &|_| true);
        faces.extend(fill);
        let e = edge_counts(&faces);
        assert_eq!((e.boundary, e.non_manifold), (0, 0));
    }

    #[test]
    fn a_rim_already_joined_in_one_place_is_zipped_around_it() {
        // The slab's sides joined by hand over one square of the rim: the strip leaves out the
        // faces that would meet that join, and closing short holes closes what that leaves.
        let n = 12;
        let (p, mut faces) = slab(n, 0.3);
        faces.extend(joined_at(n, 5));
        let (strip, stats) = stitch_rims(&p, &faces, 0.5);
        assert!(stats.zipped >= 1, "{stats:?}");
        faces.extend(&strip);
        assert_eq!(edge_counts(&faces).non_manifold, 0);
        let (fill, _) = crate::mesh::close_short_holes(&p, &faces, 48, &|_| true);
        faces.extend(fill);
        let e = edge_counts(&faces);
        assert_eq!((e.boundary, e.non_manifold), (0, 0));
    }
}
