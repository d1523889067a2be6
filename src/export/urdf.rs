//! [`ArticulatedObject`] → URDF + meshes, the inverse of the importer (`object::urdf`).
//!
//! - Each link's visuals become one Wavefront OBJ (`meshes/<link>.obj`, one group per material) with an
//!   MTL and PNG base-colour textures beside it, so textures survive (URDF primitives cannot carry UVs).
//!   Vertex colours are written as `v x y z r g b` (read by MeshLab, Open3D, tinyobjloader) and their
//!   mean becomes the MTL colour for viewers that ignore them.
//! - Primitive collisions stay primitives; each mesh collision element becomes a binary STL (a
//!   twin's are its convex pieces, `super::collision`).
//! - Every link with geometry gets an `<inertial>` from its collision (else visual) meshes at
//!   [`DENSITY`]: a solid when they are closed, else a 5 mm shell (see [`super::inertia`]), so physics
//!   engines treat movable links as bodies rather than as massless, static ones.
//! - Names are XML-escaped in the URDF; file names are reduced to `[A-Za-z0-9_-]` and made unique.
//! - Numbers are written in Rust's shortest round-trip form, so reading the files back gives the same
//!   `f32` values (UV `v` goes through OBJ's flip and may differ in the last bit).

use std::collections::{BTreeSet, HashMap};
use std::fmt::Write as _;
use std::sync::Arc;

use glam::{Affine3A, EulerRot};

use super::inertia::{DENSITY, mass_properties};
use crate::data::{DataError, FileSet, PngPixels, RgbaImage, encode_png};
use crate::object::{ArticulatedObject, Geometry, JointKind, Material, RenderMesh, Visual};

/// Writes `obj` as `urdf_name` (e.g. `object.urdf` or `object/model.urdf`) plus `meshes/…` files in the URDF's
/// folder, which the URDF references relatively.
pub fn write_urdf(obj: &ArticulatedObject, urdf_name: &str) -> Result<FileSet, DataError> {
    super::ensure_exportable(obj, &[&obj.rest_configuration()], urdf_name)?;
    let folder = urdf_name.rfind('/').map_or("", |i| &urdf_name[..=i]);
    let mut files = FileSet::new();
    let mut names = UniqueNames::default();
    let mut xml = String::new();
    let _ = writeln!(xml, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        xml,
        "<!-- Written by artmesh {}. -->",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(xml, "<robot name=\"{}\">", escape(&obj.name));
    // MuJoCo's URDF import would fuse the fixed root (and fixed-joint links) into the world, and older
    // versions strip mesh folders; other readers ignore this element. MuJoCo still discards the visuals
    // (its default), so it needs only the collision STLs.
    let _ = writeln!(
        xml,
        "  <mujoco>\n    <compiler strippath=\"false\" fusestatic=\"false\"/>\n  </mujoco>"
    );
    for link in &obj.links {
        let stem = names.file_stem(&link.name);
        let _ = writeln!(xml, "  <link name=\"{}\">", escape(&link.name));
        let visual_meshes: Vec<RenderMesh> = link
            .visuals
            .iter()
            .flat_map(Visual::link_frame_meshes)
            .collect();
        if !visual_meshes.is_empty() {
            let obj_path = format!("meshes/{stem}.obj");
            write_obj(&visual_meshes, &stem, true, &mut files, folder, urdf_name)?;
            let _ = writeln!(
                xml,
                "    <visual>\n      <geometry><mesh filename=\"{obj_path}\"/></geometry>\n    </visual>"
            );
        }
        let mesh_collisions: Vec<Vec<RenderMesh>> = link
            .collisions
            .iter()
            .filter_map(|c| match &c.geometry {
                Geometry::Mesh { .. } => Some(c.link_frame_meshes()),
                primitive => {
                    xml.push_str(&primitive_collision_xml(&c.origin, primitive));
                    None
                }
            })
            .collect();
        // One STL per mesh collision element: a simulator collides with each one's convex hull.
        let single = mesh_collisions.len() == 1;
        for (i, meshes) in mesh_collisions.iter().enumerate() {
            let (positions, triangles) = merged(meshes);
            if triangles.is_empty() {
                continue;
            }
            match flat_bounds(&positions, &triangles) {
                // MuJoCo cannot take the convex hull of a flat (or tiny) mesh: a thin box instead.
                Some((lo, hi)) => {
                    let size = (hi - lo).max(glam::Vec3::splat(MIN_BOX_SIDE));
                    let centre = (lo + hi) * 0.5;
                    xml.push_str(&primitive_collision_xml(
                        &Affine3A::from_translation(centre),
                        &Geometry::Box { size },
                    ));
                }
                None => {
                    let path = if single {
                        format!("meshes/{stem}_collision.stl")
                    } else {
                        format!("meshes/{stem}_collision_{i}.stl")
                    };
                    files.insert(format!("{folder}{path}"), stl(&positions, &triangles));
                    let _ = writeln!(
                        xml,
                        "    <collision>\n      <geometry><mesh filename=\"{path}\"/></geometry>\n    </collision>"
                    );
                }
            }
        }
        if let Some(inertial) = inertial_xml(link) {
            xml.push_str(&inertial);
        }
        let _ = writeln!(xml, "  </link>");
    }
    for joint in &obj.joints {
        let kind = match joint.kind {
            JointKind::Fixed => "fixed",
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
        };
        let link_name = |i: usize| {
            obj.links.get(i).map(|l| escape(&l.name)).ok_or_else(|| {
                DataError::field(
                    urdf_name,
                    format!("joint {}", joint.name),
                    format!("link index {i} does not exist"),
                )
            })
        };
        let _ = writeln!(
            xml,
            "  <joint name=\"{}\" type=\"{kind}\">",
            escape(&joint.name)
        );
        let _ = writeln!(xml, "    <parent link=\"{}\"/>", link_name(joint.parent)?);
        let _ = writeln!(xml, "    <child link=\"{}\"/>", link_name(joint.child)?);
        let _ = writeln!(xml, "    {}", origin_xml(&joint.origin));
        let a = joint.axis;
        let _ = writeln!(xml, "    <axis xyz=\"{} {} {}\"/>", a.x, a.y, a.z);
        if let Some(l) = joint.limit {
            let _ = writeln!(
                xml,
                "    <limit lower=\"{}\" upper=\"{}\" effort=\"{}\" velocity=\"{}\"/>",
                l.lower, l.upper, l.effort, l.velocity
            );
        }
        if let Some(m) = joint.mimic {
            let followed = obj
                .joints
                .get(m.joint)
                .map(|j| escape(&j.name))
                .unwrap_or_default();
            let _ = writeln!(
                xml,
                "    <mimic joint=\"{followed}\" multiplier=\"{}\" offset=\"{}\"/>",
                m.multiplier, m.offset
            );
        }
        let _ = writeln!(xml, "  </joint>");
    }
    let _ = writeln!(xml, "</robot>");
    files.insert(urdf_name.to_string(), xml.into_bytes());
    Ok(files)
}

/// `<origin xyz rpy>` of a rigid transform (URDF rpy = fixed-axis x, y, z = `Rz·Ry·Rx`).
fn origin_xml(t: &Affine3A) -> String {
    let (_, rotation, translation) = t.to_scale_rotation_translation();
    // Adding 0 turns -0 into 0, which reads better and means the same.
    let (yaw, pitch, roll) = rotation.to_euler(EulerRot::ZYX);
    let (yaw, pitch, roll) = (yaw + 0.0, pitch + 0.0, roll + 0.0);
    format!(
        "<origin xyz=\"{} {} {}\" rpy=\"{roll} {pitch} {yaw}\"/>",
        translation.x, translation.y, translation.z
    )
}

/// A `<collision>` element (with its line break) holding primitive `g` at `origin`.
fn primitive_collision_xml(origin: &Affine3A, g: &Geometry) -> String {
    format!(
        "    <collision>\n      {}\n      <geometry>{}</geometry>\n    </collision>\n",
        origin_xml(origin),
        primitive_xml(g)
    )
}

fn primitive_xml(g: &Geometry) -> String {
    match g {
        Geometry::Box { size } => format!("<box size=\"{} {} {}\"/>", size.x, size.y, size.z),
        Geometry::Cylinder { radius, length } => {
            format!("<cylinder radius=\"{radius}\" length=\"{length}\"/>")
        }
        Geometry::Sphere { radius } => format!("<sphere radius=\"{radius}\"/>"),
        Geometry::Mesh { .. } => String::new(),
    }
}

/// `<inertial>` from the link's collision (or, without collisions, visual) meshes in the link frame;
/// `None` without geometry.
fn inertial_xml(link: &crate::object::Link) -> Option<String> {
    let elements = if link.collisions.is_empty() {
        &link.visuals
    } else {
        &link.collisions
    };
    let (positions, triangles) = merged(
        &elements
            .iter()
            .flat_map(Visual::link_frame_meshes)
            .collect::<Vec<_>>(),
    );
    let m = mass_properties(&positions, &triangles, DENSITY)?;
    let (c, i) = (m.center, m.inertia);
    Some(format!(
        "    <inertial>\n      <!-- {:?} at {DENSITY} kg/m³ -->\n      <origin xyz=\"{} {} {}\" rpy=\"0 0 0\"/>\n      \
         <mass value=\"{}\"/>\n      <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>\n    </inertial>\n",
        m.model,
        c.x,
        c.y,
        c.z,
        m.mass,
        i.x_axis.x,
        i.y_axis.x,
        i.z_axis.x,
        i.y_axis.y,
        i.z_axis.y,
        i.z_axis.z
    ))
}

/// All triangles of `meshes` as one indexed list (the mass properties weld equal positions, so an
/// indexed OBJ and a triangle-soup STL of one surface get the same inertial).
pub(crate) fn merged(meshes: &[RenderMesh]) -> (Vec<glam::Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for m in meshes {
        let base = positions.len() as u32;
        let n = m.positions.len() as u32;
        positions.extend_from_slice(&m.positions);
        triangles.extend(
            m.indices
                .iter()
                .filter(|t| t.iter().all(|&i| i < n))
                .map(|t| t.map(|i| i + base)),
        );
    }
    (positions, triangles)
}

/// Smallest side (m) of a collision box standing in for a flat mesh.
const MIN_BOX_SIDE: f32 = 2e-3;

/// The bounds of a collision mesh too flat or small for a convex hull (fewer than 4 used vertices,
/// or a thinnest principal extent under 0.1 mm); `None` for a mesh with volume.
fn flat_bounds(
    positions: &[glam::Vec3],
    triangles: &[[u32; 3]],
) -> Option<(glam::Vec3, glam::Vec3)> {
    let used: BTreeSet<u32> = triangles.iter().flatten().copied().collect();
    let points: Vec<glam::Vec3> = used
        .iter()
        .map(|&i| positions[i as usize])
        .filter(|p| p.is_finite())
        .collect();
    let (lo, hi) = points
        .iter()
        .fold(None, |acc: Option<(glam::Vec3, glam::Vec3)>, &p| {
            Some(acc.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))))
        })?;
    let thinnest = crate::articulation::init::principal_frame(&points)
        .map_or(0.0, |f| f.variances.z.max(0.0).sqrt());
    (points.len() < 4 || thinnest < 1e-4).then_some((lo, hi))
}

/// Binary STL of a triangle list (facet normals from the winding).
fn stl(positions: &[glam::Vec3], triangles: &[[u32; 3]]) -> Vec<u8> {
    let mut out = Vec::with_capacity(84 + 50 * triangles.len());
    let mut header = [0u8; 80];
    let text = b"artmesh collision mesh";
    header[..text.len()].copy_from_slice(text);
    out.extend_from_slice(&header);
    out.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        for v in [n, a, b, c] {
            for x in v.to_array() {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    out
}

/// Writes `meshes/<stem>.obj` (and, with `materials`, `<stem>.mtl` and textures) into `files`.
fn write_obj(
    meshes: &[RenderMesh],
    stem: &str,
    materials: bool,
    files: &mut FileSet,
    folder: &str,
    urdf_name: &str,
) -> Result<(), DataError> {
    let mut obj = String::new();
    let mut mtl = String::new();
    if materials {
        let _ = writeln!(obj, "mtllib {stem}.mtl");
    }
    let mut names = UniqueNames::default();
    // Materials written so far, keyed by their content, so groups sharing a material share its entry.
    let mut written: Vec<(Material, [f32; 4], String)> = Vec::new();
    let mut textures: HashMap<*const RgbaImage, String> = HashMap::new();
    // OBJ indices are 1-based and global to the file, counted apart for v, vt and vn (a group
    // without uvs or normals writes none, so one counter would point later groups astray).
    let (mut v_base, mut vt_base, mut vn_base) = (1usize, 1usize, 1usize);
    for (g, mesh) in meshes.iter().enumerate() {
        let _ = writeln!(obj, "o group_{g}");
        let colors = mesh
            .colors
            .as_ref()
            .filter(|c| c.len() == mesh.positions.len());
        match colors {
            Some(colors) => {
                for (p, c) in mesh.positions.iter().zip(colors) {
                    let _ = writeln!(obj, "v {} {} {} {} {} {}", p.x, p.y, p.z, c[0], c[1], c[2]);
                }
            }
            None => {
                for p in &mesh.positions {
                    let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
                }
            }
        }
        let has_normals = mesh.normals.len() == mesh.positions.len();
        if has_normals {
            for n in &mesh.normals {
                let _ = writeln!(obj, "vn {} {} {}", n.x, n.y, n.z);
            }
        }
        let uvs = mesh
            .uvs
            .as_ref()
            .filter(|u| u.len() == mesh.positions.len());
        if let Some(uvs) = uvs {
            for t in uvs {
                let _ = writeln!(obj, "vt {} {}", t.x, 1.0 - t.y);
            }
        }
        if materials {
            let shown = shown_color(mesh);
            let name = match written
                .iter()
                .find(|(m, c, _)| *m == mesh.material && *c == shown)
            {
                Some((_, _, name)) => name.clone(),
                None => {
                    let name = names.file_stem(mesh.material.name.as_deref().unwrap_or("material"));
                    let c = shown;
                    let _ = writeln!(
                        mtl,
                        "newmtl {name}\nKd {} {} {}\nd {}",
                        c[0], c[1], c[2], c[3]
                    );
                    if let Some(texture) = &mesh.material.texture {
                        let key = Arc::as_ptr(texture);
                        let file = match textures.get(&key) {
                            Some(f) => f.clone(),
                            None => {
                                let file = format!("{stem}_{name}.png");
                                let path = format!("{folder}meshes/{file}");
                                let png = encode_png(
                                    &path,
                                    texture.width,
                                    texture.height,
                                    PngPixels::Rgba8(&texture.pixels),
                                )?;
                                files.insert(path, png);
                                textures.insert(key, file.clone());
                                file
                            }
                        };
                        let _ = writeln!(mtl, "map_Kd {file}");
                    }
                    written.push((mesh.material.clone(), shown, name.clone()));
                    name
                }
            };
            let _ = writeln!(obj, "usemtl {name}");
        }
        for t in &mesh.indices {
            if t.iter().any(|&i| i as usize >= mesh.positions.len()) {
                return Err(DataError::field(
                    urdf_name,
                    format!("meshes/{stem}.obj"),
                    format!(
                        "triangle {t:?} indexes past the {} vertices of its mesh",
                        mesh.positions.len()
                    ),
                ));
            }
            let corner = |i: u32| {
                let [v, t, n] = [v_base, vt_base, vn_base].map(|b| b + i as usize);
                match (uvs.is_some(), has_normals) {
                    (true, true) => format!("{v}/{t}/{n}"),
                    (true, false) => format!("{v}/{t}"),
                    (false, true) => format!("{v}//{n}"),
                    (false, false) => format!("{v}"),
                }
            };
            let _ = writeln!(obj, "f {} {} {}", corner(t[0]), corner(t[1]), corner(t[2]));
        }
        v_base += mesh.positions.len();
        vt_base += uvs.map_or(0, Vec::len);
        vn_base += if has_normals { mesh.normals.len() } else { 0 };
    }
    files.insert(format!("{folder}meshes/{stem}.obj"), obj.into_bytes());
    if materials {
        files.insert(format!("{folder}meshes/{stem}.mtl"), mtl.into_bytes());
    }
    Ok(())
}

/// The MTL colour of `mesh`: its material's, or the mean of its vertex colours when it has them.
fn shown_color(mesh: &RenderMesh) -> [f32; 4] {
    let mut c = mesh.material.base_color;
    if let Some(colors) = mesh.colors.as_ref().filter(|c| !c.is_empty()) {
        let n = colors.len() as f32;
        for (k, value) in c.iter_mut().take(3).enumerate() {
            *value = colors.iter().map(|v| v[k]).sum::<f32>() / n;
        }
    }
    c
}

/// `name` made safe as a file or folder name: letters, digits, `_` and `-` kept, anything else `_`.
pub(crate) fn file_stem(name: &str) -> String {
    UniqueNames::default().file_stem(name)
}

/// Names made safe for file names and MTL (letters, digits, `_`, `-`) and unique within one writer.
#[derive(Default)]
struct UniqueNames(BTreeSet<String>);

impl UniqueNames {
    fn file_stem(&mut self, name: &str) -> String {
        let clean: String = name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let clean = if clean.is_empty() {
            "unnamed".to_string()
        } else {
            clean
        };
        let mut candidate = clean.clone();
        let mut k = 1;
        while !self.0.insert(candidate.clone()) {
            candidate = format!("{clean}_{k}");
            k += 1;
        }
        candidate
    }
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A link whose only surface is `positions` (one fan of triangles), as visual and collision.
    fn one_link(positions: Vec<glam::Vec3>) -> ArticulatedObject {
        let indices = (1..positions.len() as u32 - 1)
            .map(|i| [0, i, i + 1])
            .collect();
        let mesh = RenderMesh {
            normals: vec![glam::Vec3::Z; positions.len()],
            positions,
            uvs: None,
            colors: None,
            indices,
            material: Material::default(),
        };
        let element = Visual {
            name: None,
            origin: Affine3A::IDENTITY,
            geometry: Geometry::Mesh {
                path: "m.obj".into(),
                scale: glam::Vec3::ONE,
                meshes: Arc::from(vec![mesh]),
            },
            material: None,
        };
        ArticulatedObject {
            name: "a <b> & \"c\"".into(),
            links: vec![crate::object::Link {
                name: "plate ü".into(),
                visuals: vec![element.clone()],
                collisions: vec![element],
            }],
            joints: Vec::new(),
            root: 0,
            warnings: Vec::new(),
        }
    }

    #[test]
    fn flat_collision_meshes_become_thin_boxes() {
        use glam::Vec3;
        let flat = one_link(vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]);
        let files = write_urdf(&flat, "o.urdf").unwrap();
        let xml = String::from_utf8(files["o.urdf"].clone()).unwrap();
        assert!(xml.contains("<box size=\"1 1 0.002\"/>"), "{xml}");
        assert!(!files.keys().any(|k| k.ends_with(".stl")));
        assert!(
            xml.contains("<robot name=\"a &lt;b&gt; &amp; &quot;c&quot;\">"),
            "{xml}"
        );
        assert!(xml.contains("<link name=\"plate ü\">") && xml.contains("meshes/plate__.obj"));
        assert!(xml.contains("<inertial>"));
        let back = ArticulatedObject::from_urdf("o.urdf", &files).unwrap();
        assert_eq!(
            (back.name.as_str(), back.links[0].name.as_str()),
            ("a <b> & \"c\"", "plate ü")
        );

        let tent = one_link(vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.3), Vec3::Y]);
        let files = write_urdf(&tent, "o.urdf").unwrap();
        assert!(
            files.contains_key("meshes/plate___collision.stl"),
            "{:?}",
            files.keys()
        );
        // 80-byte header, count, 50 bytes a facet.
        assert_eq!(files["meshes/plate___collision.stl"].len(), 84 + 2 * 50);
    }

    #[test]
    fn names_are_sanitised_and_unique() {
        let mut n = UniqueNames::default();
        assert_eq!(n.file_stem("door/left"), "door_left");
        assert_eq!(n.file_stem("door_left"), "door_left_1");
        assert_eq!(n.file_stem(""), "unnamed");
    }
}
