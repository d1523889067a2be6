//! Rigid-body mass properties of triangle meshes for URDF `<inertial>` elements: a uniform solid
//! for closed meshes, a thin shell for open ones, always a tensor that physics engines accept.

use std::collections::HashMap;

use glam::{DMat3, DVec3, Vec3};

use crate::articulation::sums::outer;

/// Density (kg/m³) the exports assume: light wood.
pub(crate) const DENSITY: f64 = 500.0;
/// Wall thickness (m) of the thin-shell model used for open meshes.
pub(crate) const SHELL_THICKNESS: f64 = 0.005;

/// Smallest |volume| / area^(3/2) for which a closed mesh counts as a solid. A sphere has ≈0.094,
/// a 1 m × 1 m × 1 mm slab ≈3.5e-4, so this only rejects flat or numerically empty closed
/// surfaces (a double-sided quad), which fall back to the shell model.
const MIN_VOLUME_RATIO: f64 = 1e-6;

/// How [`MassProperties`] distributes the mass.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum InertiaModel {
    /// Uniform solid filling the closed surface.
    Solid,
    /// Uniform wall of [`SHELL_THICKNESS`] over the surface (open or volume-less meshes).
    Shell,
}

/// Mass, centre of mass and inertia tensor of a mesh, in the mesh frame and SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MassProperties {
    /// Mass (kg), always positive.
    pub mass: f64,
    /// Centre of mass (m), mesh frame.
    pub center: DVec3,
    /// Inertia tensor (kg·m²) about `center`, axes of the mesh frame: symmetric, positive
    /// definite and satisfying the triangle inequality of its principal moments.
    pub inertia: DMat3,
    /// Which mass model produced the numbers.
    pub model: InertiaModel,
}

/// Mass properties of the mesh at `density`: a uniform solid when the mesh is closed
/// (every edge shared by exactly two triangles with opposite orientation) and encloses a clearly
/// positive volume (inward-facing closed meshes count: use |V| and flip), else a thin shell of
/// SHELL_THICKNESS over its surface area. None when the mesh has no finite, non-degenerate triangle
/// (or `density` is not positive and finite, or so extreme that the result overflows).
///
/// Triangles with out-of-range indices or non-finite vertices are skipped; vertices at
/// bit-identical positions are treated as one, so unindexed (STL-style) meshes can be closed. The
/// tensor gets a small isotropic floor when needed to be physically valid (see `floor_inertia`).
pub(crate) fn mass_properties(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    density: f64,
) -> Option<MassProperties> {
    if !(density.is_finite() && density > 0.0) {
        return None;
    }
    // Weld by exact position: STL and unindexed glTF duplicate every corner, and closedness is a
    // property of the surface, not of its indexing. `+ 0.0` turns -0.0 into 0.0 so bits agree.
    let mut weld: HashMap<[u32; 3], usize> = HashMap::new();
    let mut canonical = |i: usize, p: &Vec3| {
        let key = (*p + Vec3::ZERO).to_array().map(f32::to_bits);
        p.is_finite().then(|| *weld.entry(key).or_insert(i))
    };
    let canonical: Vec<Option<usize>> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| canonical(i, p))
        .collect();
    let tris: Vec<[usize; 3]> = (triangles.iter())
        .filter_map(
            |t| match t.map(|i| canonical.get(i as usize).copied().flatten()) {
                [Some(a), Some(b), Some(c)] if a != b && b != c && c != a => Some([a, b, c]),
                _ => None,
            },
        )
        .collect();
    if tris.is_empty() {
        return None;
    }

    // Closed and consistently oriented: each directed edge once, its reverse once.
    let mut edges: HashMap<(usize, usize), u32> = HashMap::with_capacity(3 * tris.len());
    for &[a, b, c] in &tris {
        for e in [(a, b), (b, c), (c, a)] {
            *edges.entry(e).or_insert(0) += 1;
        }
    }
    let closed = edges
        .iter()
        .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1));

    // Moments relative to the corner centroid: keeps the cancelling tetrahedron terms small for
    // meshes far from the origin.
    let corner = |i: usize| positions[i].as_dvec3();
    let reference =
        tris.iter().flatten().map(|&i| corner(i)).sum::<DVec3>() / (3 * tris.len()) as f64;
    let (mut volume, mut vol_first, mut vol_second) = (0.0, DVec3::ZERO, DMat3::ZERO);
    let (mut area, mut area_first, mut area_second) = (0.0, DVec3::ZERO, DMat3::ZERO);
    for &[a, b, c] in &tris {
        let v = [a, b, c].map(|i| corner(i) - reference);
        let s = v[0] + v[1] + v[2];
        let sum_outer = outer(v[0], v[0]) + outer(v[1], v[1]) + outer(v[2], v[2]) + outer(s, s);
        // Signed tetrahedron (reference, a, b, c), det = 6·volume: its canonical covariance
        // [[2,1,1],[1,2,1],[1,1,2]]/120 = (1 + 11ᵀ)/120 gives ∫x dV = det·s/24 and
        // ∫xxᵀ dV = det/120·(Σvvᵀ + ssᵀ).
        let det = v[0].dot(v[1].cross(v[2]));
        volume += det / 6.0;
        vol_first += s * (det / 24.0);
        vol_second += sum_outer * (det / 120.0);
        // Uniform triangle: ∫λᵢλⱼ dA = A(1 + δᵢⱼ)/12 over barycentrics gives ∫x dA = A·s/3 and
        // ∫xxᵀ dA = A/12·(Σvvᵀ + ssᵀ).
        let tri_area = 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
        area += tri_area;
        area_first += s * (tri_area / 3.0);
        area_second += sum_outer * (tri_area / 12.0);
    }
    if area <= 0.0 {
        return None;
    }

    let solid = closed && volume.abs() > MIN_VOLUME_RATIO * area.powf(1.5);
    let (k, (size, first, second), model) = if solid {
        // Inward-facing: every tetrahedron changes sign, so flipping all three sums is exact.
        let sums = (volume, vol_first, vol_second);
        (density * volume.signum(), sums, InertiaModel::Solid)
    } else {
        let sums = (area, area_first, area_second);
        (density * SHELL_THICKNESS, sums, InertiaModel::Shell)
    };
    let (mass, first, second) = (k * size, first * k, second * k);
    let offset = first / mass;
    // Parallel-axis shift of the second moment to the centre of mass, then I = tr(C)·1 − C.
    let cov = second - outer(offset, offset) * mass;
    let inertia = DMat3::from_diagonal(DVec3::splat(trace(cov))) - cov;
    let inertia = floor_inertia((inertia + inertia.transpose()) * 0.5);
    // Only extreme densities or coordinates over- or underflow; refuse rather than export inf/NaN.
    let center = reference + offset;
    if !(mass.is_normal() && center.is_finite() && inertia.is_finite()) {
        return None;
    }
    Some(MassProperties {
        mass,
        center,
        inertia,
        model,
    })
}

/// Adds `floor · identity` when the principal moments I1 ≤ I2 ≤ I3 are not positive or break
/// I1 + I2 ≥ I3 (each with a 1e-12·trace margin for roundoff), with
/// floor = max(1e-9, 1e-6·trace/3) + deficit. A flat plate sits exactly on I1 + I2 = I3 and a
/// line-like sliver has I1 ≈ 0, both rejected by physics engines; the floor gives them a margin
/// while moving the tensor by about 1e-6 relative. The deficit (how far I1 or I1 + I2 - I3 is below
/// zero) is roundoff-sized except for non-physical tensors of self-intersecting closed meshes.
fn floor_inertia(inertia: DMat3) -> DMat3 {
    let [i1, i2, i3] = principal_moments(inertia);
    let tr = i1 + i2 + i3;
    let margin = 1e-12 * tr.abs();
    if i1 > margin && i1 + i2 - i3 >= margin {
        return inertia;
    }
    let deficit = (-i1).max(i3 - i1 - i2).max(0.0);
    let floor = 1e-9_f64.max(1e-6 * tr / 3.0) + deficit;
    inertia + DMat3::from_diagonal(DVec3::splat(floor))
}

/// Eigenvalues of a symmetric matrix, ascending (the Jacobi solver of the articulation seeds:
/// accurate for the near-repeated moments of symmetric bodies, where the closed-form cubic loses digits).
fn principal_moments(m: DMat3) -> [f64; 3] {
    let (mut d, _) = crate::articulation::init::symmetric_eigen(m.transpose().to_cols_array_2d());
    d.sort_by(f64::total_cmp);
    d
}

fn trace(m: DMat3) -> f64 {
    m.x_axis.x + m.y_axis.y + m.z_axis.z
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    /// Axis-aligned box, 8 shared vertices, 12 outward triangles.
    fn box_mesh(center: Vec3, half: Vec3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let sign = |bit: u32| if bit == 0 { -1.0 } else { 1.0 };
        let positions: Vec<Vec3> = (0..8u32)
            .map(|i| center + half * Vec3::new(sign(i & 1), sign(i & 2), sign(i & 4)))
            .collect();
        let quads = [
            [0, 2, 6, 4],
            [1, 3, 7, 5],
            [0, 1, 5, 4],
            [2, 3, 7, 6],
            [0, 1, 3, 2],
            [4, 5, 7, 6],
        ];
        let mut tris = Vec::new();
        for q in quads {
            for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                let [a, b, c] = t.map(|i: u32| positions[i as usize] - center);
                tris.push(if (b - a).cross(c - a).dot(a + b + c) > 0.0 {
                    t
                } else {
                    [t[0], t[2], t[1]]
                });
            }
        }
        (positions, tris)
    }

    fn box_inertia(mass: f64, dims: DVec3) -> DMat3 {
        let d2 = dims * dims;
        DMat3::from_diagonal(DVec3::new(d2.y + d2.z, d2.x + d2.z, d2.x + d2.y) * (mass / 12.0))
    }

    fn max_abs(m: DMat3) -> f64 {
        m.to_cols_array()
            .iter()
            .fold(0.0, |acc, x| acc.max(x.abs()))
    }

    fn assert_close(actual: DMat3, expected: DMat3, rel: f64) {
        assert!(
            actual.abs_diff_eq(expected, rel * max_abs(expected)),
            "{actual:?} vs {expected:?}"
        );
    }

    /// Mass > 0, symmetric, positive definite (Sylvester) and I1 + I2 ≥ I3.
    fn assert_valid(p: &MassProperties) {
        let m = p.inertia;
        assert!(
            p.mass.is_finite() && p.mass > 0.0 && p.center.is_finite(),
            "{p:?}"
        );
        assert!(
            m.abs_diff_eq(m.transpose(), 1e-12 * trace(m)),
            "not symmetric: {m:?}"
        );
        let minor2 = m.x_axis.x * m.y_axis.y - m.y_axis.x * m.x_axis.y;
        assert!(
            m.x_axis.x > 0.0 && minor2 > 0.0 && m.determinant() > 0.0,
            "not positive definite: {m:?}"
        );
        let [i1, i2, i3] = principal_moments(m);
        assert!(
            i1 > 0.0 && i1 + i2 >= i3,
            "triangle inequality: {i1} {i2} {i3}"
        );
    }

    #[test]
    fn closed_box_matches_analytic_solid() {
        let (center, half) = (Vec3::new(0.1, -0.2, 0.3), Vec3::new(0.2, 0.3, 0.45));
        let (pos, tris) = box_mesh(center, half);
        let p = mass_properties(&pos, &tris, DENSITY).unwrap();
        // Analytic values from the f32 corners actually stored (centre ± half rounds).
        let (lo, hi) = (pos[0].as_dvec3(), pos[7].as_dvec3());
        let dims = hi - lo;
        let mass = DENSITY * dims.x * dims.y * dims.z;
        assert_eq!(p.model, InertiaModel::Solid);
        assert!((p.mass - mass).abs() <= 1e-9 * mass);
        assert!(p.center.abs_diff_eq((lo + hi) * 0.5, 1e-12));
        assert_close(p.inertia, box_inertia(mass, dims), 1e-9);
        assert_valid(&p);
    }

    #[test]
    fn flipped_box_gives_same_result() {
        let (pos, tris) = box_mesh(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, 0.25, 0.125));
        let flipped: Vec<[u32; 3]> = tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
        let (a, b) = (
            mass_properties(&pos, &tris, DENSITY).unwrap(),
            mass_properties(&pos, &flipped, DENSITY).unwrap(),
        );
        assert_eq!(b.model, InertiaModel::Solid);
        assert!((a.mass - b.mass).abs() <= 1e-12 * a.mass && a.center.abs_diff_eq(b.center, 1e-12));
        assert_close(b.inertia, a.inertia, 1e-12);
    }

    #[test]
    fn rigid_motion_rotates_tensor_and_moves_centre() {
        let (pos, tris) = box_mesh(Vec3::ZERO, Vec3::new(0.2, 0.35, 0.1));
        let base = mass_properties(&pos, &tris, DENSITY).unwrap();
        let rot = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        let shift = DVec3::new(1.5, -2.0, 0.3);
        let moved: Vec<Vec3> = pos
            .iter()
            .map(|p| (rot * p.as_dvec3() + shift).as_vec3())
            .collect();
        let p = mass_properties(&moved, &tris, DENSITY).unwrap();
        let r = DMat3::from_quat(rot);
        assert!((p.mass - base.mass).abs() <= 1e-5 * base.mass);
        assert!(p.center.abs_diff_eq(shift + rot * base.center, 1e-6));
        assert_close(p.inertia, r * base.inertia * r.transpose(), 1e-5);
        assert_valid(&p);
    }

    #[test]
    fn uv_sphere_close_to_two_fifths_m_r2() {
        let (r, seg, rings) = (0.5_f32, 64u32, 32u32);
        let mut pos = vec![Vec3::Z * r];
        for k in 1..rings {
            let theta = k as f32 * std::f32::consts::PI / rings as f32;
            for j in 0..seg {
                let phi = j as f32 * std::f32::consts::TAU / seg as f32;
                let (s, c) = theta.sin_cos();
                pos.push(r * Vec3::new(s * phi.cos(), s * phi.sin(), c));
            }
        }
        pos.push(-Vec3::Z * r);
        let south = pos.len() as u32 - 1;
        let ring = |k: u32, j: u32| 1 + (k - 1) * seg + j % seg;
        let mut tris = Vec::new();
        for j in 0..seg {
            tris.push([0, ring(1, j), ring(1, j + 1)]);
            for k in 1..rings - 1 {
                tris.push([ring(k, j), ring(k + 1, j), ring(k + 1, j + 1)]);
                tris.push([ring(k, j), ring(k + 1, j + 1), ring(k, j + 1)]);
            }
            tris.push([south, ring(rings - 1, j + 1), ring(rings - 1, j)]);
        }
        let p = mass_properties(&pos, &tris, DENSITY).unwrap();
        assert_eq!(p.model, InertiaModel::Solid);
        let r = r as f64;
        assert!(
            (p.mass / (DENSITY * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3)) - 1.0).abs() < 0.01
        );
        assert!(p.center.length() < 1e-6);
        assert_close(p.inertia, DMat3::IDENTITY * (0.4 * p.mass * r * r), 0.01);
        assert_valid(&p);
    }

    #[test]
    fn open_box_is_shell_matching_dense_subdivision() {
        let half = Vec3::new(0.2, 0.3, 0.45);
        let (pos, mut tris) = box_mesh(Vec3::ZERO, half);
        tris.retain(|t| !t.iter().all(|&i| pos[i as usize].z > 0.0)); // drop the two +z triangles
        assert_eq!(tris.len(), 10);
        let p = mass_properties(&pos, &tris, DENSITY).unwrap();
        let d = 2.0 * half.as_dvec3();
        let area = 2.0 * (d.x * d.y + d.x * d.z + d.y * d.z) - d.x * d.y;
        assert_eq!(p.model, InertiaModel::Shell);
        assert!((p.mass - DENSITY * area * SHELL_THICKNESS).abs() <= 1e-9 * p.mass);
        // Independent estimate: each triangle cut into n² equal sub-triangles, each a point mass
        // at its centroid.
        let n = 16;
        let (mut mass, mut first, mut second) = (0.0, DVec3::ZERO, DMat3::ZERO);
        for t in &tris {
            let [a, b, c] = t.map(|i| pos[i as usize].as_dvec3());
            let m =
                DENSITY * SHELL_THICKNESS * 0.5 * (b - a).cross(c - a).length() / (n * n) as f64;
            for i in 0..n {
                for j in 0..n - i {
                    let mut uvs = vec![(3 * i + 1, 3 * j + 1)];
                    if i + j + 1 < n {
                        uvs.push((3 * i + 2, 3 * j + 2));
                    }
                    for (u, v) in uvs {
                        let x = a
                            + (b - a) * (u as f64 / (3 * n) as f64)
                            + (c - a) * (v as f64 / (3 * n) as f64);
                        mass += m;
                        first += x * m;
                        second += outer(x, x) * m;
                    }
                }
            }
        }
        let com = first / mass;
        let cov = second - outer(com, com) * mass;
        assert!((mass / p.mass - 1.0).abs() < 1e-9 && p.center.abs_diff_eq(com, 1e-3));
        assert_close(
            p.inertia,
            DMat3::from_diagonal(DVec3::splat(trace(cov))) - cov,
            0.01,
        );
        assert_valid(&p);
    }

    #[test]
    fn single_triangle_is_valid_shell() {
        let pos = [
            Vec3::ZERO,
            Vec3::new(0.3, 0.0, 0.1),
            Vec3::new(0.0, 0.2, 0.0),
        ];
        let p = mass_properties(&pos, &[[0, 1, 2]], DENSITY).unwrap();
        assert_eq!(p.model, InertiaModel::Shell);
        assert!(
            p.center
                .abs_diff_eq((pos[0] + pos[1] + pos[2]).as_dvec3() / 3.0, 1e-9)
        );
        assert_valid(&p);
    }

    #[test]
    fn sliver_gets_floor() {
        // Line-like: one principal moment ≈ 0, which engines reject.
        let pos = [Vec3::ZERO, Vec3::X, Vec3::new(0.5, 1e-6, 0.0)];
        let p = mass_properties(&pos, &[[0, 1, 2]], DENSITY).unwrap();
        assert_valid(&p);
        let [i1, _, _] = principal_moments(p.inertia);
        assert!(
            i1 >= 0.99e-6 * trace(p.inertia) / 3.0,
            "floor not applied: {i1}"
        );
    }

    #[test]
    fn unindexed_box_is_welded_into_a_solid() {
        let (pos, tris) = box_mesh(Vec3::new(-0.5, 0.0, 2.0), Vec3::new(0.1, 0.2, 0.3));
        let soup: Vec<Vec3> = tris.iter().flatten().map(|&i| pos[i as usize]).collect();
        let soup_tris: Vec<[u32; 3]> = (0..tris.len() as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        let (a, b) = (
            mass_properties(&pos, &tris, DENSITY).unwrap(),
            mass_properties(&soup, &soup_tris, DENSITY).unwrap(),
        );
        assert_eq!(b.model, InertiaModel::Solid);
        assert!((a.mass - b.mass).abs() <= 1e-12 * a.mass);
        assert_close(b.inertia, a.inertia, 1e-12);
    }

    #[test]
    fn garbage_triangles_are_skipped() {
        let (mut pos, mut tris) = box_mesh(Vec3::ZERO, Vec3::new(0.1, 0.2, 0.3));
        let clean = mass_properties(&pos, &tris, DENSITY).unwrap();
        pos.push(Vec3::NAN);
        pos.push(Vec3::new(f32::INFINITY, 0.0, 0.0));
        tris.extend([[0, 1, 8], [9, 2, 3], [0, 1, u32::MAX], [4, 4, 5]]);
        let p = mass_properties(&pos, &tris, DENSITY).unwrap();
        assert_eq!(p.model, InertiaModel::Solid);
        assert_close(p.inertia, clean.inertia, 1e-12);
    }

    #[test]
    fn degenerate_and_extreme_inputs_never_panic() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let none = |pos: &[Vec3], tris: &[[u32; 3]], density: f64| {
            assert_eq!(
                mass_properties(pos, tris, density),
                None,
                "{pos:?} {tris:?}"
            );
        };
        none(&[], &[], DENSITY);
        none(&tri, &[], DENSITY);
        none(&[Vec3::NAN; 3], &[[0, 1, 2]], DENSITY);
        none(&tri, &[[0, 1, 3], [u32::MAX, 0, 1]], DENSITY);
        none(&[Vec3::ZERO, Vec3::X, Vec3::X * 2.0], &[[0, 1, 2]], DENSITY); // collinear
        none(&[Vec3::ONE; 3], &[[0, 1, 2]], DENSITY); // welds to one point
        none(&tri, &[[0, 1, 2]], f64::NAN);
        none(&tri, &[[0, 1, 2]], 0.0);
        none(&tri, &[[0, 1, 2]], f64::MIN_POSITIVE); // mass underflows
        none(&tri.map(|p| p * 1e38), &[[0, 1, 2]], 1e200); // second moment overflows
        let far = tri.map(|p| p * 1e20 + Vec3::splat(1e21));
        assert_valid(&mass_properties(&far, &[[0, 1, 2]], DENSITY).unwrap());
    }

    #[test]
    fn jacobi_recovers_known_spectrum() {
        let r = DMat3::from_quat(DQuat::from_axis_angle(
            DVec3::new(-1.0, 0.5, 2.0).normalize(),
            1.1,
        ));
        let m = r * DMat3::from_diagonal(DVec3::new(3.0, 1.0, 2.0)) * r.transpose();
        let [a, b, c] = principal_moments(m);
        assert!((a - 1.0).abs() < 1e-12 && (b - 2.0).abs() < 1e-12 && (c - 3.0).abs() < 1e-12);
    }
}
