//! Tessellation of URDF primitives (box, cylinder along z, sphere), centred on the origin like URDF's.
//!
//! Flat faces get their own vertices so normals stay sharp; UVs are per face (box), wrapped around (cylinder
//! side, sphere) or planar (cylinder caps), glTF convention (`v = 0` at the top).

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3};

use super::{Material, RenderMesh};

/// Segments around the cylinder and sphere: smooth enough at image resolutions, cheap to rasterise.
const SEGMENTS: u32 = 32;
/// Latitude bands of the sphere.
const STACKS: u32 = 16;

/// The six faces of a box: outward normal and two in-face axes u, v with u × v = normal (counter-clockwise).
pub(crate) const BOX_FACES: [(Vec3, Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::Y, Vec3::Z),
    (Vec3::NEG_X, Vec3::Z, Vec3::Y),
    (Vec3::Y, Vec3::Z, Vec3::X),
    (Vec3::NEG_Y, Vec3::X, Vec3::Z),
    (Vec3::Z, Vec3::X, Vec3::Y),
    (Vec3::NEG_Z, Vec3::Y, Vec3::X),
];

/// Box with full side lengths `size`, 24 vertices and 12 triangles.
pub fn box_mesh(size: Vec3, material: Material) -> RenderMesh {
    let h = size * 0.5;
    let mut m = empty(material);
    let uvs = m.uvs.get_or_insert_with(Vec::new);
    for (n, u, v) in BOX_FACES {
        let base = m.positions.len() as u32;
        for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            m.positions.push((n + u * su + v * sv) * h);
            m.normals.push(n);
            uvs.push(Vec2::new((su + 1.0) * 0.5, (1.0 - sv) * 0.5));
        }
        m.indices.push([base, base + 1, base + 2]);
        m.indices.push([base, base + 2, base + 3]);
    }
    m
}

/// Cylinder along z with the given radius and length: side plus two caps.
pub fn cylinder_mesh(radius: f32, length: f32, material: Material) -> RenderMesh {
    let mut m = empty(material);
    let hz = length * 0.5;
    let uvs = m.uvs.get_or_insert_with(Vec::new);
    // Side: a seam column is duplicated so UVs wrap cleanly.
    for i in 0..=SEGMENTS {
        let t = i as f32 / SEGMENTS as f32;
        let (s, c) = (t * TAU).sin_cos();
        let n = Vec3::new(c, s, 0.0);
        for (z, v) in [(-hz, 1.0), (hz, 0.0)] {
            m.positions.push(Vec3::new(c * radius, s * radius, z));
            m.normals.push(n);
            uvs.push(Vec2::new(t, v));
        }
    }
    for i in 0..SEGMENTS {
        let b = 2 * i;
        m.indices.push([b, b + 2, b + 3]);
        m.indices.push([b, b + 3, b + 1]);
    }
    // Caps: centre plus a ring each.
    for (z, n) in [(hz, Vec3::Z), (-hz, Vec3::NEG_Z)] {
        let centre = m.positions.len() as u32;
        m.positions.push(Vec3::new(0.0, 0.0, z));
        m.normals.push(n);
        uvs.push(Vec2::splat(0.5));
        for i in 0..SEGMENTS {
            let (s, c) = (i as f32 / SEGMENTS as f32 * TAU).sin_cos();
            m.positions.push(Vec3::new(c * radius, s * radius, z));
            m.normals.push(n);
            uvs.push(Vec2::new(0.5 + 0.5 * c, 0.5 - 0.5 * s));
        }
        for i in 0..SEGMENTS {
            let a = centre + 1 + i;
            let b = centre + 1 + (i + 1) % SEGMENTS;
            if n.z > 0.0 {
                m.indices.push([centre, a, b]);
            } else {
                m.indices.push([centre, b, a]);
            }
        }
    }
    m
}

/// UV sphere of the given radius.
pub fn sphere_mesh(radius: f32, material: Material) -> RenderMesh {
    let mut m = empty(material);
    let uvs = m.uvs.get_or_insert_with(Vec::new);
    for stack in 0..=STACKS {
        let v = stack as f32 / STACKS as f32;
        let (st, ct) = (v * PI).sin_cos();
        for seg in 0..=SEGMENTS {
            let u = seg as f32 / SEGMENTS as f32;
            let (sp, cp) = (u * TAU).sin_cos();
            // v = 0 at the north pole (+z).
            let n = Vec3::new(st * cp, st * sp, ct);
            m.positions.push(n * radius);
            m.normals.push(n);
            uvs.push(Vec2::new(u, v));
        }
    }
    let row = SEGMENTS + 1;
    for stack in 0..STACKS {
        for seg in 0..SEGMENTS {
            let a = stack * row + seg;
            let b = a + row;
            // Skip the zero-area triangles at the poles.
            if stack != 0 {
                m.indices.push([a, b, a + 1]);
            }
            if stack != STACKS - 1 {
                m.indices.push([a + 1, b, b + 1]);
            }
        }
    }
    m
}

fn empty(material: Material) -> RenderMesh {
    RenderMesh {
        positions: Vec::new(),
        normals: Vec::new(),
        uvs: Some(Vec::new()),
        colors: None,
        indices: Vec::new(),
        material,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle's right-hand normal points away from the centre (outward, counter-clockwise).
    fn assert_outward(m: &RenderMesh) {
        assert!(!m.indices.is_empty());
        assert_eq!(m.positions.len(), m.normals.len());
        assert_eq!(m.uvs.as_ref().map(Vec::len), Some(m.positions.len()));
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let n = (b - a).cross(c - a);
            let centre = (a + b + c) / 3.0;
            assert!(n.dot(centre) > 0.0, "inward triangle {t:?}");
        }
    }

    #[test]
    fn object_primitives_are_closed_outward_and_sized() {
        let b = box_mesh(Vec3::new(1.0, 2.0, 3.0), Material::default());
        assert_eq!(b.indices.len(), 12);
        assert_outward(&b);
        let max = b.positions.iter().fold(Vec3::ZERO, |m, p| m.max(*p));
        assert_eq!(max, Vec3::new(0.5, 1.0, 1.5));

        let c = cylinder_mesh(0.5, 2.0, Material::default());
        assert_outward(&c);
        assert!(c.positions.iter().all(|p| p.z.abs() <= 1.0 + 1e-6));

        let s = sphere_mesh(2.0, Material::default());
        assert_outward(&s);
        assert!(s.positions.iter().all(|p| (p.length() - 2.0).abs() < 1e-5));
    }
}
