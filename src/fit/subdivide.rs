//! Mesh preparation for fitting: welding coincident vertices and conforming edge bisection until
//! every edge is short enough for per-vertex colours to carry the image detail.

use std::collections::HashMap;

use glam::Vec3;

/// Merges vertices closer than `tolerance` (grid-snapped), dropping faces that collapse.
/// Returns the new positions, faces and, per new vertex, one old vertex it came from.
pub fn weld(
    positions: &[Vec3],
    faces: &[[u32; 3]],
    tolerance: f32,
) -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<u32>) {
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut remap = Vec::with_capacity(positions.len());
    let mut out = Vec::new();
    let mut origin = Vec::new();
    for (i, p) in positions.iter().enumerate() {
        let key = (*p / tolerance.max(1e-12)).round().as_i64vec3().to_array();
        let id = *index.entry(key).or_insert_with(|| {
            out.push(*p);
            origin.push(i as u32);
            (out.len() - 1) as u32
        });
        remap.push(id);
    }
    let faces = faces
        .iter()
        .map(|f| f.map(|v| remap[v as usize]))
        .filter(|f| f[0] != f[1] && f[1] != f[2] && f[0] != f[2])
        .collect();
    (out, faces, origin)
}

/// Splits every edge longer than `max_edge` at its midpoint, repeatedly, splitting the faces
/// around it so the mesh stays conforming (no T-junctions). `attach` is called for every new
/// vertex with the two vertices of the edge it splits, so callers can carry attributes along.
pub fn subdivide_to_edge(
    positions: &mut Vec<Vec3>,
    faces: &mut Vec<[u32; 3]>,
    max_edge: f32,
    max_faces: usize,
    attach: &mut dyn FnMut(u32, u32),
) {
    loop {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
        let key = |a: u32, b: u32| if a < b { (a, b) } else { (b, a) };
        for f in faces.iter() {
            for i in 0..3 {
                let (a, b) = (f[i], f[(i + 1) % 3]);
                if positions[a as usize].distance(positions[b as usize]) > max_edge {
                    midpoint.entry(key(a, b)).or_insert(u32::MAX);
                }
            }
        }
        // Each split edge adds at most two faces.
        if midpoint.is_empty() || faces.len() + 2 * midpoint.len() > max_faces {
            return;
        }
        let mut edges: Vec<_> = midpoint.keys().copied().collect();
        edges.sort_unstable();
        for (a, b) in edges {
            let m = positions.len() as u32;
            positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
            attach(a, b);
            midpoint.insert((a, b), m);
        }
        let mut next = Vec::with_capacity(faces.len() * 2);
        for f in faces.iter() {
            let mids: [Option<u32>; 3] =
                std::array::from_fn(|i| midpoint.get(&key(f[i], f[(i + 1) % 3])).copied());
            split_face(*f, mids, &mut next);
        }
        *faces = next;
    }
}

/// Splits face (v0, v1, v2) whose edges (v0v1, v1v2, v2v0) have the given midpoints, keeping
/// its orientation.
fn split_face(f: [u32; 3], mids: [Option<u32>; 3], out: &mut Vec<[u32; 3]>) {
    let split = mids.iter().filter(|m| m.is_some()).count();
    // Rotate so the split edges come first: edge 0 always split when any is.
    let rot = (0..3)
        .find(|&r| match split {
            1 => mids[r].is_some(),
            2 => mids[r].is_some() && mids[(r + 1) % 3].is_some(),
            _ => true,
        })
        .unwrap_or(0);
    let v = |i: usize| f[(i + rot) % 3];
    let m = |i: usize| mids[(i + rot) % 3].unwrap_or(u32::MAX);
    match split {
        0 => out.push(f),
        1 => {
            out.push([v(0), m(0), v(2)]);
            out.push([m(0), v(1), v(2)]);
        }
        2 => {
            out.push([v(0), m(0), v(2)]);
            out.push([m(0), v(1), m(1)]);
            out.push([m(0), m(1), v(2)]);
        }
        _ => {
            out.push([v(0), m(0), m(2)]);
            out.push([m(0), v(1), m(1)]);
            out.push([m(2), m(1), v(2)]);
            out.push([m(0), m(1), m(2)]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_normal(p: &[Vec3], f: &[u32; 3]) -> Vec3 {
        (p[f[1] as usize] - p[f[0] as usize]).cross(p[f[2] as usize] - p[f[0] as usize])
    }

    #[test]
    fn bisection_is_conforming_and_keeps_orientation_and_area() {
        let mut p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let mut f = vec![[0, 1, 2], [1, 3, 2]];
        let mut new = 0;
        subdivide_to_edge(&mut p, &mut f, 0.3, 10_000, &mut |_, _| new += 1);
        assert_eq!(new, p.len() - 4);
        let area: f32 = f.iter().map(|t| area_normal(&p, t).z).sum();
        assert!((area - 2.0).abs() < 1e-4, "area {area}");
        assert!(
            f.iter().all(|t| area_normal(&p, t).z > 0.0),
            "a face flipped"
        );
        // Conforming: every interior edge is shared by exactly two faces.
        let mut count: HashMap<(u32, u32), usize> = HashMap::new();
        for t in &f {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        assert!(count.values().all(|&c| c <= 2));
        for t in &f {
            for i in 0..3 {
                assert!(p[t[i] as usize].distance(p[t[(i + 1) % 3] as usize]) <= 0.3 + 1e-6);
            }
        }
    }

    #[test]
    fn weld_merges_duplicates() {
        let p = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::X + Vec3::splat(1e-7),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let (q, f, _) = weld(&p, &[[0, 1, 2], [3, 4, 2]], 1e-5);
        assert_eq!(q.len(), 4);
        assert_eq!(f, vec![[0, 1, 2], [1, 3, 2]]);
    }
}
