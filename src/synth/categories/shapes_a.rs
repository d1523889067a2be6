//! Shapes the builder lacks, for the box/eyeglasses/faucet/chair/knife/oven/pen/pliers generators: flat
//! extruded outlines (knife blades, plier jaws, lenses) and circular tubes swept along a polyline (spouts,
//! chair frames, temples, rims, plier handles). Same conventions as `builder`: outward counter-clockwise
//! winding, unit normals, UVs in metres over [`TILE_METRES`].

use std::f32::consts::TAU;

use glam::{Affine3A, Quat, Vec2, Vec3};

use crate::object::{Material, RenderMesh};
use crate::synth::builder::empty;
use crate::synth::texture::TILE_METRES;

/// Pushes one vertex with its normal and UV (in metres, scaled to texture tiles).
fn vertex(m: &mut RenderMesh, p: Vec3, n: Vec3, uv_metres: Vec2) {
    m.positions.push(p);
    m.normals.push(n);
    m.uvs
        .get_or_insert_with(Vec::new)
        .push(uv_metres / TILE_METRES);
}

/// A flat slab: the polygon `outline` (local x, y in metres, either winding) extruded from local z = `z0` to
/// `z1`, then moved by `pose`. The caps are fans from the mean of the outline's points, so the outline must be
/// star-shaped about that point (every convex outline is; blades and jaws are drawn that way). Fewer than three
/// points or a zero-area outline give an empty mesh.
pub(crate) fn prism(
    outline: &[Vec2],
    z0: f32,
    z1: f32,
    pose: Affine3A,
    material: &Material,
) -> RenderMesh {
    let mut m = empty(material);
    let area: f32 = (0..outline.len())
        .map(|i| outline[i].perp_dot(outline[(i + 1) % outline.len()]))
        .sum();
    if outline.len() < 3 || area.abs() < 1e-12 {
        return m;
    }
    // Counter-clockwise seen from +z, so the fan and side winding below face outward.
    let pts: Vec<Vec2> = if area > 0.0 {
        outline.to_vec()
    } else {
        outline.iter().rev().copied().collect()
    };
    let (lo, hi) = (z0.min(z1), z0.max(z1));
    let centre = pts.iter().copied().sum::<Vec2>() / pts.len() as f32;
    let n = pts.len() as u32;
    for (z, normal) in [(hi, Vec3::Z), (lo, Vec3::NEG_Z)] {
        let c = m.positions.len() as u32;
        vertex(&mut m, centre.extend(z), normal, centre);
        for p in &pts {
            vertex(&mut m, p.extend(z), normal, *p);
        }
        for i in 0..n {
            let (a, b) = (c + 1 + i, c + 1 + (i + 1) % n);
            m.indices
                .push(if normal.z > 0.0 { [c, a, b] } else { [c, b, a] });
        }
    }
    let mut run = 0.0;
    for i in 0..pts.len() {
        let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
        let edge = b - a;
        let len = edge.length();
        if len < 1e-9 {
            continue;
        }
        let normal = Vec3::new(edge.y, -edge.x, 0.0) / len;
        let base = m.positions.len() as u32;
        for (p, s, z) in [
            (a, run, lo),
            (b, run + len, lo),
            (b, run + len, hi),
            (a, run, hi),
        ] {
            vertex(&mut m, p.extend(z), normal, Vec2::new(s, z));
        }
        m.indices.push([base, base + 1, base + 2]);
        m.indices.push([base, base + 2, base + 3]);
        run += len;
    }
    m.transformed(&pose)
}

/// A capped circular tube swept along the polyline `path`, its radius going linearly (by arc length) from
/// `r0` at the first point to `r1` at the last, with `segments` sides. The cross-section is perpendicular to
/// the mean direction at each joint and carried along without twist, so smooth paths (many short segments
/// at bends) give clean tubes. Repeated points are skipped; a path shorter than two distinct points gives an
/// empty mesh.
pub(crate) fn tube(
    path: &[Vec3],
    r0: f32,
    r1: f32,
    segments: u32,
    material: &Material,
) -> RenderMesh {
    let mut m = empty(material);
    let mut pts: Vec<Vec3> = Vec::with_capacity(path.len());
    for &p in path {
        if pts.last().is_none_or(|q: &Vec3| q.distance(p) > 1e-6) {
            pts.push(p);
        }
    }
    if pts.len() < 2 {
        return m;
    }
    let segments = segments.max(3);
    let dirs: Vec<Vec3> = pts.windows(2).map(|w| (w[1] - w[0]).normalize()).collect();
    let tangents: Vec<Vec3> = (0..pts.len())
        .map(|i| {
            let before = dirs[i.saturating_sub(1)];
            let after = dirs[i.min(dirs.len() - 1)];
            (before + after).normalize_or(after)
        })
        .collect();
    let mut lengths = vec![0.0f32];
    for w in pts.windows(2) {
        lengths.push(lengths.last().copied().unwrap_or(0.0) + w[0].distance(w[1]));
    }
    let total = lengths.last().copied().unwrap_or(0.0).max(1e-9);
    // First normal: any direction perpendicular to the first tangent; later ones follow by parallel transport.
    let t0 = tangents[0];
    let helper = if t0.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    let mut normal = t0.cross(helper).normalize();
    let row = segments + 1;
    for (i, (&p, &t)) in pts.iter().zip(&tangents).enumerate() {
        if i > 0 {
            normal = (Quat::from_rotation_arc(tangents[i - 1], t) * normal)
                .reject_from(t)
                .normalize_or(normal);
        }
        let binormal = t.cross(normal);
        let r = r0 + (r1 - r0) * lengths[i] / total;
        for j in 0..=segments {
            let a = j as f32 / segments as f32 * TAU;
            let radial = normal * a.cos() + binormal * a.sin();
            vertex(
                &mut m,
                p + radial * r,
                radial,
                Vec2::new(a * r0.max(r1), lengths[i]),
            );
        }
    }
    for i in 0..pts.len() as u32 - 1 {
        for j in 0..segments {
            let (a, b) = (i * row + j, (i + 1) * row + j);
            m.indices.push([a, a + 1, b + 1]);
            m.indices.push([a, b + 1, b]);
        }
    }
    let last = pts.len() - 1;
    for (k, sign, r) in [(0, -1.0f32, r0), (last, 1.0, r1)] {
        if r <= 0.0 {
            continue;
        }
        let cap_normal = tangents[k] * sign;
        let c = m.positions.len() as u32;
        vertex(&mut m, pts[k], cap_normal, Vec2::ZERO);
        for j in 0..segments {
            // Reuse the ring's positions, with the cap's own normal.
            let p = m.positions[k * row as usize + j as usize];
            vertex(&mut m, p, cap_normal, Vec2::new(p.x + p.y, p.z));
        }
        for j in 0..segments {
            let (a, b) = (c + 1 + j, c + 1 + (j + 1) % segments);
            m.indices
                .push(if sign > 0.0 { [c, a, b] } else { [c, b, a] });
        }
    }
    m
}

/// Points of a superellipse in the plane spanned by `u` and `v` around `centre`: semi-axes `a` (along u) and
/// `b` (along v), exponent `power` (2 = ellipse, larger = squarer), `n` points, closed (the first point is
/// repeated at the end) for [`tube`].
pub(crate) fn superellipse(
    centre: Vec3,
    u: Vec3,
    v: Vec3,
    a: f32,
    b: f32,
    power: f32,
    n: usize,
) -> Vec<Vec3> {
    let e = 2.0 / power.max(0.5);
    (0..=n)
        .map(|i| {
            let t = i as f32 / n.max(1) as f32 * TAU;
            let (s, c) = t.sin_cos();
            centre + u * (a * c.signum() * c.abs().powf(e)) + v * (b * s.signum() * s.abs().powf(e))
        })
        .collect()
}

/// Quadratic Bézier from `a` to `c` pulled towards `b`, as `n + 1` points (for bent tubes).
pub(crate) fn bezier(a: Vec3, b: Vec3, c: Vec3, n: usize) -> Vec<Vec3> {
    (0..=n)
        .map(|i| {
            let t = i as f32 / n.max(1) as f32;
            a * (1.0 - t) * (1.0 - t) + b * 2.0 * t * (1.0 - t) + c * t * t
        })
        .collect()
}

/// The rigid motion rotating by `angle` about the line through `pivot` along `axis` (to place parts at a
/// pose other than the one they are drawn in).
pub(crate) fn rotation_about(pivot: Vec3, axis: Vec3, angle: f32) -> Affine3A {
    Affine3A::from_translation(pivot)
        * Affine3A::from_axis_angle(axis.normalize_or(Vec3::Z), angle)
        * Affine3A::from_translation(-pivot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::builder::test_support;

    /// The shared winding checks, plus: every face of these convex test shapes looks away from the centre.
    fn assert_outward(m: &RenderMesh) {
        test_support::assert_outward(m);
        let centre = m.positions.iter().copied().sum::<Vec3>() / m.positions.len() as f32;
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            assert!((b - a).cross(c - a).dot((a + b + c) / 3.0 - centre) > -1e-9);
        }
    }

    #[test]
    fn shapes_wind_outward() {
        let mat = Material::default();
        let square = [
            Vec2::new(0.0, 0.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
        ];
        assert_outward(&prism(&square, 0.0, 0.2, Affine3A::IDENTITY, &mat));
        let pose = Affine3A::from_rotation_x(1.0);
        assert_outward(&prism(&square, 0.3, -0.1, pose, &mat));
        assert_outward(&tube(
            &[Vec3::ZERO, Vec3::new(0.1, 0.2, 0.3)],
            0.05,
            0.03,
            12,
            &mat,
        ));
        assert!(
            tube(&[Vec3::ONE, Vec3::ONE], 0.1, 0.1, 8, &mat)
                .indices
                .is_empty()
        );
        assert!(prism(&square[..2], 0.0, 1.0, pose, &mat).indices.is_empty());
    }

    #[test]
    fn bent_tube_keeps_its_radius() {
        let path = bezier(
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, 0.2),
            Vec3::new(0.0, -0.2, 0.2),
            12,
        );
        let m = tube(&path, 0.01, 0.01, 10, &Material::default());
        let ring = 11usize;
        for (i, p) in path.iter().enumerate() {
            for j in 0..ring {
                let d = m.positions[i * ring + j].distance(*p);
                assert!((d - 0.01).abs() < 1e-5, "ring {i}: {d}");
            }
        }
    }
}
