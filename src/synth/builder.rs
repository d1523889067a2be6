//! Building blocks of the procedural categories: shapes with UVs in metres, and an [`ObjectBuilder`] that
//! assembles links and joints into an [`ArticulatedObject`].
//!
//! Every shape is a [`RenderMesh`] with outward counter-clockwise winding, unit normals and UVs of
//! `position / TILE_METRES` along the face, so a texture keeps its scale whatever the part's size. A link's
//! meshes become one visual (`Geometry::Mesh` at `meshes/<link>.obj`, what the URDF export writes), and
//! one box collision per link fitted to its bounds.

use std::f32::consts::TAU;
use std::sync::Arc;

use glam::{Affine3A, Quat, Vec2, Vec3};

use super::texture::TILE_METRES;
use crate::object::{
    ArticulatedObject, BOX_FACES, Geometry, Joint, JointKind, Limit, Link, Material, RenderMesh,
    Visual, mesh_bounds,
};

/// Segments around round shapes.
const SEGMENTS: u32 = 24;

/// A mesh with no vertices yet (and an empty UV list), to push shapes into.
pub(crate) fn empty(material: &Material) -> RenderMesh {
    RenderMesh {
        positions: Vec::new(),
        normals: Vec::new(),
        uvs: Some(Vec::new()),
        colors: None,
        indices: Vec::new(),
        material: material.clone(),
    }
}

/// Appends a planar quad `corner + s·u + t·v` (s, t in [0, 1]) facing `u × v`.
fn push_quad(m: &mut RenderMesh, corner: Vec3, u: Vec3, v: Vec3) {
    let n = u.cross(v).normalize_or_zero();
    let base = m.positions.len() as u32;
    let (lu, lv) = (u.length() / TILE_METRES, v.length() / TILE_METRES);
    // Offset UVs by the corner so neighbouring faces do not all start at the same texel.
    let o = Vec2::new(corner.x + corner.z, corner.y + corner.z) / TILE_METRES;
    let uvs = m.uvs.get_or_insert_with(Vec::new);
    for (s, t) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
        m.positions.push(corner + u * s + v * t);
        m.normals.push(n);
        uvs.push(o + Vec2::new(s * lu, t * lv));
    }
    m.indices.push([base, base + 1, base + 2]);
    m.indices.push([base, base + 2, base + 3]);
}

/// Axis-aligned box from its centre and full side lengths.
pub fn cuboid(centre: Vec3, size: Vec3, material: &Material) -> RenderMesh {
    oriented_cuboid(Affine3A::from_translation(centre), size, material)
}

/// Box of full side lengths `size` centred on the origin of `pose`.
pub(crate) fn oriented_cuboid(pose: Affine3A, size: Vec3, material: &Material) -> RenderMesh {
    let mut m = empty(material);
    let h = size * 0.5;
    for (n, u, v) in BOX_FACES {
        let corner = (n - u - v) * h;
        push_quad(&mut m, corner, 2.0 * u * h, 2.0 * v * h);
    }
    m.transformed(&pose)
}

/// A rotation taking +z to the unit direction `d`.
fn z_to(d: Vec3) -> Quat {
    Quat::from_rotation_arc(Vec3::Z, d.normalize_or(Vec3::Z))
}

/// Capped truncated cone from `a` (radius `ra`) to `b` (radius `rb`); a cylinder when `ra == rb`.
pub(crate) fn frustum(a: Vec3, b: Vec3, ra: f32, rb: f32, material: &Material) -> RenderMesh {
    let mut m = empty(material);
    let length = (b - a).length();
    let slope = (ra - rb) / length.max(1e-9);
    let uvs = m.uvs.get_or_insert_with(Vec::new);
    for i in 0..=SEGMENTS {
        let t = i as f32 / SEGMENTS as f32;
        let (s, c) = (t * TAU).sin_cos();
        let n = Vec3::new(c, s, slope).normalize();
        for (z, r) in [(0.0, ra), (length, rb)] {
            m.positions.push(Vec3::new(c * r, s * r, z));
            m.normals.push(n);
            uvs.push(Vec2::new(t * TAU * ra.max(rb), z) / TILE_METRES);
        }
    }
    for i in 0..SEGMENTS {
        let k = 2 * i;
        m.indices.push([k, k + 2, k + 3]);
        m.indices.push([k, k + 3, k + 1]);
    }
    for (z, r, normal) in [(0.0, ra, Vec3::NEG_Z), (length, rb, Vec3::Z)] {
        if r <= 0.0 {
            continue;
        }
        let centre = m.positions.len() as u32;
        m.positions.push(Vec3::new(0.0, 0.0, z));
        m.normals.push(normal);
        uvs.push(Vec2::ZERO);
        for i in 0..SEGMENTS {
            let (s, c) = (i as f32 / SEGMENTS as f32 * TAU).sin_cos();
            m.positions.push(Vec3::new(c * r, s * r, z));
            m.normals.push(normal);
            uvs.push(Vec2::new(c * r, s * r) / TILE_METRES);
        }
        for i in 0..SEGMENTS {
            let (p, q) = (centre + 1 + i, centre + 1 + (i + 1) % SEGMENTS);
            m.indices.push(if normal.z > 0.0 {
                [centre, p, q]
            } else {
                [centre, q, p]
            });
        }
    }
    m.transformed(&Affine3A::from_rotation_translation(z_to(b - a), a))
}

/// Capped cylinder of radius `r` from `a` to `b`.
pub(crate) fn cylinder(a: Vec3, b: Vec3, r: f32, material: &Material) -> RenderMesh {
    frustum(a, b, r, r, material)
}

/// UV sphere of radius `r` at `centre`.
pub fn sphere(centre: Vec3, r: f32, material: &Material) -> RenderMesh {
    let mut m = empty(material);
    let stacks = SEGMENTS / 2;
    let uvs = m.uvs.get_or_insert_with(Vec::new);
    for j in 0..=stacks {
        let phi = j as f32 / stacks as f32 * std::f32::consts::PI;
        for i in 0..=SEGMENTS {
            let theta = i as f32 / SEGMENTS as f32 * TAU;
            let n = Vec3::new(phi.sin() * theta.cos(), phi.sin() * theta.sin(), phi.cos());
            m.positions.push(centre + n * r);
            m.normals.push(n);
            uvs.push(Vec2::new(theta * r, phi * r) / TILE_METRES);
        }
    }
    grid_triangles(&mut m, stacks, SEGMENTS);
    m
}

/// Two triangles per cell of a `(rows + 1) × (cols + 1)` vertex grid stored row by row.
fn grid_triangles(m: &mut RenderMesh, rows: u32, cols: u32) {
    let row = cols + 1;
    for j in 0..rows {
        for i in 0..cols {
            let (a, b) = (j * row + i, (j + 1) * row + i);
            m.indices.push([a, b, b + 1]);
            m.indices.push([a, b + 1, a + 1]);
        }
    }
}

/// Torus around `axis` through `centre`: ring radius `major`, tube radius `minor`.
pub(crate) fn torus(
    centre: Vec3,
    axis: Vec3,
    major: f32,
    minor: f32,
    material: &Material,
) -> RenderMesh {
    let mut m = empty(material);
    let tube = SEGMENTS / 2;
    let uvs = m.uvs.get_or_insert_with(Vec::new);
    for i in 0..=SEGMENTS {
        let theta = i as f32 / SEGMENTS as f32 * TAU;
        let radial = Vec3::new(theta.cos(), theta.sin(), 0.0);
        for j in 0..=tube {
            let phi = j as f32 / tube as f32 * TAU;
            let n = radial * phi.cos() + Vec3::Z * phi.sin();
            m.positions.push(radial * major + n * minor);
            m.normals.push(n);
            uvs.push(Vec2::new(theta * major, phi * minor) / TILE_METRES);
        }
    }
    grid_triangles(&mut m, SEGMENTS, tube);
    m.transformed(&Affine3A::from_rotation_translation(z_to(axis), centre))
}

/// Assembles an [`ArticulatedObject`]: link 0 is the static base; every other link hangs on one joint.
///
/// Geometry is given in the **object frame at the rest pose** (all joints at 0); the builder moves each
/// link's meshes into its own frame, so categories can place parts where they appear, then hinge them.
pub struct ObjectBuilder {
    name: String,
    links: Vec<Link>,
    joints: Vec<Joint>,
    /// Object-frame pose of every link's frame at rest.
    link_poses: Vec<Affine3A>,
    /// Meshes of every link, object frame.
    meshes: Vec<Vec<RenderMesh>>,
}

impl ObjectBuilder {
    /// A builder with one link, `base`, at the origin.
    pub fn new(name: &str) -> Self {
        ObjectBuilder {
            name: name.to_string(),
            links: vec![Link {
                name: "base".into(),
                visuals: Vec::new(),
                collisions: Vec::new(),
            }],
            joints: Vec::new(),
            link_poses: vec![Affine3A::IDENTITY],
            meshes: vec![Vec::new()],
        }
    }

    /// The static base link.
    pub const BASE: usize = 0;

    /// Adds `mesh` (object frame, rest pose) to `link`.
    pub fn add(&mut self, link: usize, mesh: RenderMesh) {
        self.meshes[link].push(mesh);
    }

    /// Adds a link hanging from `parent` on a joint of `kind` whose axis passes through `pivot` along `axis`
    /// (object frame, rest pose), with limits `lower..upper` (radians or metres). Returns the new link.
    /// The link frame sits at the pivot with the object's orientation; the joint axis is `axis` normalised.
    #[allow(clippy::too_many_arguments)]
    pub fn joint(
        &mut self,
        name: &str,
        parent: usize,
        kind: JointKind,
        pivot: Vec3,
        axis: Vec3,
        lower: f32,
        upper: f32,
    ) -> usize {
        let child = self.links.len();
        let parent_pose = self.link_poses[parent];
        let pose = Affine3A::from_translation(pivot);
        self.links.push(Link {
            name: name.to_string(),
            visuals: Vec::new(),
            collisions: Vec::new(),
        });
        self.link_poses.push(pose);
        self.meshes.push(Vec::new());
        self.joints.push(Joint {
            name: format!("{name}_joint"),
            kind,
            parent,
            child,
            origin: parent_pose.inverse() * pose,
            axis: axis.normalize_or(Vec3::X),
            limit: Some(Limit {
                lower,
                upper,
                effort: 10.0,
                velocity: 1.0,
            }),
            mimic: None,
        });
        child
    }

    /// The finished object: each link's meshes moved into its frame as one visual, plus a box collision.
    pub fn build(self) -> ArticulatedObject {
        let mut links = self.links;
        for (k, meshes) in self.meshes.into_iter().enumerate() {
            if meshes.is_empty() {
                continue;
            }
            let to_link = self.link_poses[k].inverse();
            let local: Vec<RenderMesh> = meshes.iter().map(|m| m.transformed(&to_link)).collect();
            if let Some((lo, hi)) = mesh_bounds(&local) {
                links[k].collisions.push(Visual {
                    name: None,
                    origin: Affine3A::from_translation((lo + hi) * 0.5),
                    geometry: Geometry::Box { size: hi - lo },
                    material: None,
                });
            }
            let name = links[k].name.clone();
            links[k].visuals.push(Visual {
                name: Some(name.clone()),
                origin: Affine3A::IDENTITY,
                geometry: Geometry::Mesh {
                    path: format!("meshes/{name}.obj"),
                    scale: Vec3::ONE,
                    meshes: Arc::from(local),
                },
                material: None,
            });
        }
        ArticulatedObject {
            name: self.name,
            links,
            joints: self.joints,
            root: 0,
            warnings: Vec::new(),
        }
    }
}

/// Checks shared by the shape tests of the builder and the category shapes.
#[cfg(test)]
pub(crate) mod test_support {
    use crate::object::RenderMesh;

    /// The mesh has triangles, a normal and a UV per vertex, unit normals, and every triangle's winding
    /// agrees with its vertex normals.
    pub(crate) fn assert_outward(m: &RenderMesh) {
        assert!(!m.indices.is_empty());
        assert_eq!(m.positions.len(), m.normals.len());
        assert_eq!(m.uvs.as_ref().map(Vec::len), Some(m.positions.len()));
        for n in &m.normals {
            assert!((n.length() - 1.0).abs() < 1e-4);
        }
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            if face.length() < 1e-9 {
                continue;
            }
            let n = m.normals[t[0] as usize] + m.normals[t[1] as usize] + m.normals[t[2] as usize];
            assert!(
                face.dot(n) > 0.0,
                "triangle {t:?} winds against its normals"
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::assert_outward;
    use super::*;

    #[test]
    fn shapes_wind_outward() {
        let mat = Material::default();
        let pose = Affine3A::from_rotation_translation(
            Quat::from_rotation_y(0.4),
            Vec3::new(1.0, 2.0, 3.0),
        );
        assert_outward(&cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0), &mat));
        assert_outward(&oriented_cuboid(pose, Vec3::new(0.1, 0.2, 0.3), &mat));
        assert_outward(&cylinder(Vec3::ZERO, Vec3::new(0.3, -0.2, 0.5), 0.1, &mat));
        assert_outward(&frustum(Vec3::ZERO, Vec3::X, 0.3, 0.1, &mat));
        assert_outward(&sphere(Vec3::ONE, 0.2, &mat));
        assert_outward(&torus(Vec3::ZERO, Vec3::Y, 0.5, 0.05, &mat));
    }

    #[test]
    fn builder_keeps_rest_geometry_in_place() {
        let mat = Material::default();
        let mut b = ObjectBuilder::new("test");
        b.add(ObjectBuilder::BASE, cuboid(Vec3::ZERO, Vec3::ONE, &mat));
        let door = b.joint(
            "door",
            ObjectBuilder::BASE,
            JointKind::Revolute,
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::Z,
            0.0,
            1.5,
        );
        b.add(
            door,
            cuboid(Vec3::new(0.55, 0.0, 0.0), Vec3::new(0.02, 1.0, 1.0), &mat),
        );
        let obj = b.build();
        let poses = obj.forward_kinematics(&[0.0]);
        let world: Vec<Vec3> = obj
            .link_meshes(door)
            .iter()
            .flat_map(|m| m.positions.iter().map(|p| poses[door].transform_point3(*p)))
            .collect();
        let (lo, hi) = world
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| {
                (l.min(*p), h.max(*p))
            });
        assert!((lo - Vec3::new(0.54, -0.5, -0.5)).abs().max_element() < 1e-5);
        assert!((hi - Vec3::new(0.56, 0.5, 0.5)).abs().max_element() < 1e-5);
        assert_eq!(obj.parts().movable_count(), 1);
    }
}
