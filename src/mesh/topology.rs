//! Topology edits of the reconstruction phase on the CPU copy of the mesh field: densification
//! (1 → 4 splits at edge midpoints), pruning (dropping faces and the vertices only they used),
//! hardening part labels, and the connectivity facts the quality report counts (edges,
//! components). Every edit returns a `new vertex → old vertex` map so the optimiser can carry its
//! moments across ([`crate::optim::FRESH`] marks vertices that did not exist before).

use std::collections::HashMap;

use glam::Vec3;

use crate::data::TriMesh;
use crate::optim::FRESH;
use crate::raster::{MeshField, SH_FLOATS};

/// The part of each vertex: the argmax of its logits (ties go to the lower part).
pub fn harden_parts(field: &MeshField) -> Vec<u32> {
    let p = field.num_parts.max(1);
    field
        .part_logits
        .chunks_exact(p)
        .map(|l| {
            let mut best = 0;
            for (k, &v) in l.iter().enumerate() {
                if v > l[best] {
                    best = k;
                }
            }
            best as u32
        })
        .collect()
}

/// Faces whose three vertices do not share one hardened part.
pub fn cross_part_faces(faces: &[[u32; 3]], parts: &[u32]) -> usize {
    faces
        .iter()
        .filter(|f| {
            let p = parts[f[0] as usize];
            parts[f[1] as usize] != p || parts[f[2] as usize] != p
        })
        .count()
}

/// The part a face belongs to: the label two or three of its vertices share, else its first
/// vertex's (only cross-part faces of a global remesh need the fallback).
pub(crate) fn face_part(face: &[u32; 3], parts: &[u32]) -> u32 {
    let [a, b, c] = face.map(|v| parts[v as usize]);
    if b == c { b } else { a }
}

/// Area-weighted vertex normals (zero for vertices no face uses).
pub(crate) fn vertex_normals(positions: &[Vec3], faces: &[[u32; 3]]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for f in faces {
        let [a, b, c] = f.map(|v| positions[v as usize]);
        let n = (b - a).cross(c - a);
        for &v in f {
            normals[v as usize] += n;
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

/// Keeps the faces with `keep[f]` and the vertices they use, in order. Returns the new field and
/// the new → old vertex map.
pub(crate) fn retain_faces(field: &MeshField, keep: &[bool]) -> (MeshField, Vec<u32>) {
    let faces: Vec<[u32; 3]> = field
        .faces
        .iter()
        .zip(keep)
        .filter(|(_, k)| **k)
        .map(|(f, _)| *f)
        .collect();
    compact(field, faces)
}

/// `field` with `faces` as its faces and only the vertices they use.
pub(crate) fn compact(field: &MeshField, faces: Vec<[u32; 3]>) -> (MeshField, Vec<u32>) {
    let mut new_of = vec![u32::MAX; field.num_vertices()];
    let mut map = Vec::new();
    for f in &faces {
        for &v in f {
            if new_of[v as usize] == u32::MAX {
                new_of[v as usize] = map.len() as u32;
                map.push(v);
            }
        }
    }
    let faces = faces
        .iter()
        .map(|f| f.map(|v| new_of[v as usize]))
        .collect();
    (gather_vertices(field, &map, faces), map)
}

/// A field whose vertex i is `field`'s vertex `map[i]`, with the given faces.
pub(crate) fn gather_vertices(field: &MeshField, map: &[u32], faces: Vec<[u32; 3]>) -> MeshField {
    let p = field.num_parts;
    let mut out = MeshField::new(Vec::with_capacity(map.len()), faces, p, 0.0);
    for &v in map {
        let v = v as usize;
        out.positions.push(field.positions[v]);
        out.sh
            .extend_from_slice(&field.sh[v * SH_FLOATS..(v + 1) * SH_FLOATS]);
        out.opacity.push(field.opacity[v]);
        out.part_logits
            .extend_from_slice(&field.part_logits[v * p..(v + 1) * p]);
    }
    out
}

/// Splits every selected face 1 → 4 at its edge midpoints. A midpoint is shared by the two faces
/// of a split edge; a neighbour that is not split keeps its edge, so the result may have
/// T-junctions there (the rasterizer does not mind, and the remeshing rebuilds connectivity).
/// Midpoints take the mean of their edge's attributes; in the returned map they are [`FRESH`].
pub(crate) fn split_faces(field: &MeshField, selected: &[bool]) -> (MeshField, Vec<u32>) {
    let mut out = field.clone();
    let mut map: Vec<u32> = (0..field.num_vertices() as u32).collect();
    let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
    let p = field.num_parts;
    let mut faces = Vec::with_capacity(field.faces.len());
    for (f, face) in field.faces.iter().enumerate() {
        if !selected.get(f).copied().unwrap_or(false) {
            faces.push(*face);
            continue;
        }
        let mut m = [0u32; 3];
        for i in 0..3 {
            let (a, b) = (face[i], face[(i + 1) % 3]);
            let key = (a.min(b), a.max(b));
            m[i] = *midpoint.entry(key).or_insert_with(|| {
                let (a, b) = (a as usize, b as usize);
                out.positions
                    .push(0.5 * (field.positions[a] + field.positions[b]));
                for k in 0..SH_FLOATS {
                    let s = 0.5 * (field.sh[a * SH_FLOATS + k] + field.sh[b * SH_FLOATS + k]);
                    out.sh.push(s);
                }
                out.opacity
                    .push(0.5 * (field.opacity[a] + field.opacity[b]));
                for k in 0..p {
                    let l = 0.5 * (field.part_logits[a * p + k] + field.part_logits[b * p + k]);
                    out.part_logits.push(l);
                }
                map.push(FRESH);
                (out.positions.len() - 1) as u32
            });
        }
        let [a, b, c] = *face;
        faces.extend([
            [a, m[0], m[2]],
            [m[0], b, m[1]],
            [m[2], m[1], c],
            [m[0], m[1], m[2]],
        ]);
    }
    out.faces = faces;
    (out, map)
}

/// Edge facts of a triangle set.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct EdgeCounts {
    /// Distinct undirected edges.
    pub edges: usize,
    /// Edges used by exactly one face (holes and open rims).
    pub boundary: usize,
    /// Edges used by three faces or more.
    pub non_manifold: usize,
}

/// The three edges of `face`, each as it runs around the face (a→b).
pub(crate) fn face_edges(face: &[u32; 3]) -> [(u32, u32); 3] {
    [(face[0], face[1]), (face[1], face[2]), (face[2], face[0])]
}

/// The edge between `a` and `b` whichever way it runs: the key of per-edge maps.
pub(crate) fn undirected(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Counts the edges of `faces` by how many faces use them.
pub fn edge_counts(faces: &[[u32; 3]]) -> EdgeCounts {
    let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
    for (a, b) in faces.iter().flat_map(face_edges) {
        *uses.entry(undirected(a, b)).or_default() += 1;
    }
    EdgeCounts {
        edges: uses.len(),
        boundary: uses.values().filter(|&&n| n == 1).count(),
        non_manifold: uses.values().filter(|&&n| n > 2).count(),
    }
}

/// The connected component (through shared vertices) of every face, numbered from 0 in order of
/// first appearance, and the number of components.
pub fn face_components(faces: &[[u32; 3]]) -> (Vec<u32>, usize) {
    let n = faces
        .iter()
        .flatten()
        .map(|&v| v as usize + 1)
        .max()
        .unwrap_or(0);
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for f in faces {
        let r = find(&mut parent, f[0]);
        for &v in &f[1..] {
            let s = find(&mut parent, v);
            parent[s as usize] = r;
        }
    }
    let mut label: HashMap<u32, u32> = HashMap::new();
    let components = faces
        .iter()
        .map(|f| {
            let root = find(&mut parent, f[0]);
            let next = label.len() as u32;
            *label.entry(root).or_insert(next)
        })
        .collect();
    (components, label.len())
}

/// Keeps, per component, the faces of components holding at least `min_fraction` of the
/// largest one's faces: the remeshing's small floaters go, real pieces stay.
pub(crate) fn drop_small_components(faces: &[[u32; 3]], min_fraction: f32) -> Vec<bool> {
    let (component, count) = face_components(faces);
    let mut size = vec![0usize; count];
    for &c in &component {
        size[c as usize] += 1;
    }
    let largest = size.iter().copied().max().unwrap_or(0);
    let threshold = (min_fraction * largest as f32).ceil() as usize;
    component
        .iter()
        .map(|&c| size[c as usize] >= threshold.max(1))
        .collect()
}

/// Indices grouped by equal key, groups in order of their key's first appearance (so results do
/// not depend on hash order). The voxel grids of the seeding and the thinning use it.
pub(crate) fn groups_in_order<K: std::hash::Hash + Eq>(
    keys: impl IntoIterator<Item = K>,
) -> Vec<Vec<u32>> {
    let mut slot: HashMap<K, usize> = HashMap::new();
    let mut groups: Vec<Vec<u32>> = Vec::new();
    for (i, key) in keys.into_iter().enumerate() {
        let g = *slot.entry(key).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(i as u32);
    }
    groups
}

/// Length of a face's longest edge.
pub(crate) fn longest_edge(positions: &[Vec3], face: &[u32; 3]) -> f32 {
    let [a, b, c] = face.map(|v| positions[v as usize]);
    a.distance(b).max(b.distance(c)).max(c.distance(a))
}

/// Median edge length of `faces`.
pub(crate) fn median_edge(positions: &[Vec3], faces: &[[u32; 3]]) -> f32 {
    let mut lengths: Vec<f32> = faces
        .iter()
        .flat_map(face_edges)
        .map(|(a, b)| positions[a as usize].distance(positions[b as usize]))
        .collect();
    if lengths.is_empty() {
        return 0.0;
    }
    let mid = lengths.len() / 2;
    *lengths.select_nth_unstable_by(mid, f32::total_cmp).1
}

/// Thins vertices to an even spacing: one representative per (voxel of side `cell`, part, normal
/// side), the
/// vertex nearest the voxel's mean, which keeps its position. It takes the voxel's mean colour,
/// opacity and part logits (one soup vertex's colour is noisy; their mean is the surface's), and
/// the mean of the voxel's `normals` (a smoothed normal for the tangent planes). Returns the thinned
/// field (no faces) and its normals.
pub(crate) fn thin_vertices(
    field: &MeshField,
    normals: &[Vec3],
    parts: &[u32],
    cell: f32,
) -> (MeshField, Vec<Vec3>) {
    let cell = cell.max(1e-9);
    let positions = &field.positions;
    // Vertices are also binned by their normal's dominant axis and sign, so the two sides of a
    // part thinner than a voxel stay apart (averaging their normals would cancel them).
    let side = |n: Vec3| {
        let a = n.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        2 * axis + u32::from(n[axis as usize] < 0.0)
    };
    let groups = groups_in_order(positions.iter().enumerate().map(|(v, p)| {
        (
            (*p / cell).floor().as_ivec3().to_array(),
            parts[v],
            side(normals[v]),
        )
    }));
    let mut chosen = Vec::with_capacity(groups.len());
    let mut smoothed = Vec::with_capacity(groups.len());
    for members in &groups {
        let mean =
            members.iter().map(|&v| positions[v as usize]).sum::<Vec3>() / members.len() as f32;
        let best = members
            .iter()
            .copied()
            .min_by(|&a, &b| {
                let da = positions[a as usize].distance_squared(mean);
                let db = positions[b as usize].distance_squared(mean);
                da.total_cmp(&db)
            })
            .unwrap_or(members[0]);
        let normal = members.iter().map(|&v| normals[v as usize]).sum::<Vec3>();
        chosen.push(best);
        smoothed.push(normal.normalize_or(normals[best as usize]));
    }
    let mut out = gather_vertices(field, &chosen, Vec::new());
    let p = field.num_parts;
    for (i, members) in groups.iter().enumerate() {
        let n = members.len() as f32;
        let mean = |values: &[f32], stride: usize, k: usize| {
            members
                .iter()
                .map(|&v| values[v as usize * stride + k])
                .sum::<f32>()
                / n
        };
        for k in 0..SH_FLOATS {
            out.sh[i * SH_FLOATS + k] = mean(&field.sh, SH_FLOATS, k);
        }
        out.opacity[i] = mean(&field.opacity, 1, 0);
        for k in 0..p {
            out.part_logits[i * p + k] = mean(&field.part_logits, p, k);
        }
    }
    (out, smoothed)
}

/// One mesh per part: each face goes to [`face_part`]'s part, with only the vertices its faces use.
pub fn part_meshes(
    positions: &[Vec3],
    faces: &[[u32; 3]],
    parts: &[u32],
    num_parts: usize,
) -> Vec<TriMesh> {
    part_submeshes(faces, parts, num_parts)
        .into_iter()
        .map(|sub| TriMesh {
            positions: sub
                .vertices
                .iter()
                .map(|&v| positions[v as usize])
                .collect(),
            triangles: sub.triangles,
        })
        .collect()
}

/// A part's share of a mesh: the source vertices it uses and its triangles over them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PartSubmesh {
    /// Source vertex index of each of the part's vertices.
    pub vertices: Vec<u32>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

/// The split behind [`part_meshes`], keeping the source vertex of each part vertex so per-vertex
/// attributes (colours) can follow.
pub fn part_submeshes(faces: &[[u32; 3]], parts: &[u32], num_parts: usize) -> Vec<PartSubmesh> {
    let mut subs = vec![PartSubmesh::default(); num_parts];
    let mut index: Vec<HashMap<u32, u32>> = vec![HashMap::new(); num_parts];
    for f in faces {
        let k = (face_part(f, parts) as usize).min(num_parts.saturating_sub(1));
        let sub = &mut subs[k];
        let tri = f.map(|v| {
            *index[k].entry(v).or_insert_with(|| {
                sub.vertices.push(v);
                (sub.vertices.len() - 1) as u32
            })
        });
        sub.triangles.push(tri);
    }
    subs
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> MeshField {
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::Y,
            Vec3::new(5.0, 5.0, 5.0),
        ];
        let mut field = MeshField::new(positions, vec![[0, 1, 2], [0, 2, 3]], 2, 0.0);
        for v in 0..5 {
            field.set_color(v, Vec3::splat(v as f32 / 4.0));
            field.part_logits[v * 2 + usize::from(v >= 2)] = 1.0;
        }
        field
    }

    #[test]
    fn splitting_shares_midpoints_and_interpolates() {
        let field = quad();
        let (split, map) = split_faces(&field, &[true, true]);
        // 5 old vertices + 5 distinct edges' midpoints (the diagonal is shared).
        assert_eq!(split.num_vertices(), 10);
        assert_eq!(split.faces.len(), 8);
        assert_eq!(map.iter().filter(|&&m| m == FRESH).count(), 5);
        split.validate().unwrap();
        // Area is preserved.
        let area = |f: &MeshField| -> f32 {
            f.faces
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|v| f.positions[v as usize]);
                    0.5 * (b - a).cross(c - a).length()
                })
                .sum()
        };
        assert!((area(&split) - area(&field)).abs() < 1e-6);
        // The midpoint of 0-1 carries the mean colour.
        let m = split
            .positions
            .iter()
            .position(|p| *p == Vec3::new(0.5, 0.0, 0.0))
            .unwrap();
        let c0 = |f: &MeshField, v: usize| f.sh[v * SH_FLOATS];
        assert!((c0(&split, m) - 0.5 * (c0(&field, 0) + c0(&field, 1))).abs() < 1e-6);
    }

    #[test]
    fn retaining_compacts_vertices_and_maps_them_back() {
        let field = quad();
        let (kept, map) = retain_faces(&field, &[false, true]);
        assert_eq!(kept.faces, vec![[0, 1, 2]]);
        assert_eq!(map, vec![0, 2, 3]);
        assert_eq!(kept.positions[1], field.positions[2]);
        assert_eq!(harden_parts(&kept), vec![0, 1, 1]);
        kept.validate().unwrap();
    }

    #[test]
    fn edges_components_and_cross_part_faces() {
        // Edge 0-1 has three faces; 4-5-6 is a separate piece.
        let faces = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [0, 1, 7], [0, 1, 8]];
        let e = edge_counts(&faces);
        assert_eq!((e.edges, e.boundary, e.non_manifold), (12, 10, 1));
        let (comp, n) = face_components(&faces);
        assert_eq!(n, 2);
        assert_eq!(comp, vec![0, 0, 1, 0, 0]);
        assert_eq!(
            drop_small_components(&faces, 0.5),
            vec![true, true, false, true, true]
        );
        let parts = [0, 0, 0, 1, 1, 1, 1, 0, 0];
        assert_eq!(cross_part_faces(&faces, &parts), 1);
        assert_eq!(face_part(&[0, 3, 4], &parts), 1);
    }
    #[test]
    fn thinning_keeps_sides_and_parts_apart_and_averages_colour() {
        // Four vertices in one voxel: two facing +z (part 0), one facing −z (part 0), one of part 1.
        let positions = vec![
            Vec3::new(0.1, 0.1, 0.1),
            Vec3::new(0.2, 0.2, 0.1),
            Vec3::new(0.15, 0.15, 0.12),
            Vec3::new(0.3, 0.3, 0.3),
        ];
        let mut field = MeshField::new(positions.clone(), Vec::new(), 2, 0.0);
        for (v, grey) in [0.2f32, 0.6, 0.9, 0.5].into_iter().enumerate() {
            field.set_color(v, Vec3::splat(grey));
        }
        let normals = [Vec3::Z, Vec3::Z, -Vec3::Z, Vec3::Z];
        let parts = [0, 0, 0, 1];
        let (thin, smoothed) = thin_vertices(&field, &normals, &parts, 1.0);
        assert_eq!(thin.num_vertices(), 3);
        // The +z pair became one vertex at one of their positions, with their mean colour.
        let pair = thin
            .positions
            .iter()
            .position(|p| *p == positions[0] || *p == positions[1])
            .unwrap();
        assert_eq!(smoothed[pair], Vec3::Z);
        let mean = 0.5 * (field.sh[0] + field.sh[SH_FLOATS]);
        assert!((thin.sh[pair * SH_FLOATS] - mean).abs() < 1e-6);
        assert!(thin.positions.contains(&positions[2]) && thin.positions.contains(&positions[3]));
    }

    #[test]
    fn part_meshes_split_faces_by_label() {
        let field = quad();
        let parts = harden_parts(&field);
        let meshes = part_meshes(&field.positions, &field.faces, &parts, 2);
        // Face 0 = (0, 1, 2): labels 0, 0, 1 → part 0; face 1 = (0, 2, 3): 0, 1, 1 → part 1.
        assert_eq!(meshes[0].triangles.len(), 1);
        assert_eq!(meshes[1].triangles.len(), 1);
        assert_eq!(
            meshes[1].positions,
            vec![field.positions[0], field.positions[2], field.positions[3]]
        );
    }
}
