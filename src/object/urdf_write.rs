//! [`ArticulatedObject`] → URDF + meshes, the inverse of the importer.
//!
//! Each link's visuals become one Wavefront OBJ (`meshes/<link>.obj`, one group per material) with an MTL
//! and PNG base-colour textures beside it, so textures survive (URDF primitives cannot carry UVs). Primitive
//! collisions stay primitives; mesh collisions become an untextured OBJ. Every link gets an `<inertial>`
//! (uniform density over its collision bounding box) so physics engines treat movable links as bodies rather
//! than as massless, static ones. Numbers are written in Rust's shortest round-trip form, so reading the
//! files back gives the same `f32` values (UV `v` goes through OBJ's flip and may differ in the last bit).

use std::collections::{BTreeSet, HashMap};
use std::fmt::Write as _;
use std::sync::Arc;

use glam::{Affine3A, EulerRot, Vec3};

use super::{ArticulatedObject, Geometry, JointKind, Material, RenderMesh, Visual, mesh_bounds};
use crate::data::{DataError, FileSet, PngPixels, RgbaImage, encode_png};

/// Density (kg/m³) used for the written inertials: light wood.
const DENSITY: f32 = 500.0;

/// Writes `obj` as `urdf_name` (e.g. `object.urdf` or `object/model.urdf`) plus `meshes/…` files in the URDF's
/// folder, which the URDF references relatively.
pub fn write_urdf(obj: &ArticulatedObject, urdf_name: &str) -> Result<FileSet, DataError> {
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
        let mut collision_meshes = Vec::new();
        for c in &link.collisions {
            match &c.geometry {
                Geometry::Mesh { .. } => collision_meshes.extend(c.link_frame_meshes()),
                primitive => {
                    let _ = writeln!(
                        xml,
                        "    <collision>\n      {}\n      <geometry>{}</geometry>\n    </collision>",
                        origin_xml(&c.origin),
                        primitive_xml(primitive)
                    );
                }
            }
        }
        if !collision_meshes.is_empty() {
            let stem = format!("{stem}_collision");
            write_obj(
                &collision_meshes,
                &stem,
                false,
                &mut files,
                folder,
                urdf_name,
            )?;
            let _ = writeln!(
                xml,
                "    <collision>\n      <geometry><mesh filename=\"meshes/{stem}.obj\"/></geometry>\n    </collision>"
            );
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
    let (yaw, pitch, roll) = rotation.to_euler(EulerRot::ZYX);
    format!(
        "<origin xyz=\"{} {} {}\" rpy=\"{roll} {pitch} {yaw}\"/>",
        translation.x, translation.y, translation.z
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

/// Mass and inertia of a uniform box filling the link's collision (or visual) bounds; `None` without geometry.
fn inertial_xml(link: &super::Link) -> Option<String> {
    let elements = if link.collisions.is_empty() {
        &link.visuals
    } else {
        &link.collisions
    };
    let meshes: Vec<RenderMesh> = elements
        .iter()
        .flat_map(Visual::link_frame_meshes)
        .collect();
    let (lo, hi) = mesh_bounds(&meshes)?;
    let size = (hi - lo).max(Vec3::splat(1e-3));
    let centre = (lo + hi) * 0.5;
    let mass = (DENSITY * size.x * size.y * size.z).max(0.01);
    let sq = size * size;
    let (ixx, iyy, izz) = (
        mass * (sq.y + sq.z) / 12.0,
        mass * (sq.x + sq.z) / 12.0,
        mass * (sq.x + sq.y) / 12.0,
    );
    Some(format!(
        "    <inertial>\n      <origin xyz=\"{} {} {}\" rpy=\"0 0 0\"/>\n      <mass value=\"{mass}\"/>\n      \
         <inertia ixx=\"{ixx}\" ixy=\"0\" ixz=\"0\" iyy=\"{iyy}\" iyz=\"0\" izz=\"{izz}\"/>\n    </inertial>\n",
        centre.x, centre.y, centre.z
    ))
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
    let mut written: Vec<(Material, String)> = Vec::new();
    let mut textures: HashMap<*const RgbaImage, String> = HashMap::new();
    let mut base = 1usize; // OBJ indices are 1-based and global to the file
    for (g, mesh) in meshes.iter().enumerate() {
        let _ = writeln!(obj, "o group_{g}");
        for p in &mesh.positions {
            let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
        }
        for n in &mesh.normals {
            let _ = writeln!(obj, "vn {} {} {}", n.x, n.y, n.z);
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
            let name = match written.iter().find(|(m, _)| *m == mesh.material) {
                Some((_, name)) => name.clone(),
                None => {
                    let name = names.file_stem(mesh.material.name.as_deref().unwrap_or("material"));
                    let c = mesh.material.base_color;
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
                    written.push((mesh.material.clone(), name.clone()));
                    name
                }
            };
            let _ = writeln!(obj, "usemtl {name}");
        }
        let has_normals = mesh.normals.len() == mesh.positions.len();
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
                let k = base + i as usize;
                match (uvs.is_some(), has_normals) {
                    (true, true) => format!("{k}/{k}/{k}"),
                    (true, false) => format!("{k}/{k}"),
                    (false, true) => format!("{k}//{k}"),
                    (false, false) => format!("{k}"),
                }
            };
            let _ = writeln!(obj, "f {} {} {}", corner(t[0]), corner(t[1]), corner(t[2]));
        }
        base += mesh.positions.len();
    }
    files.insert(format!("{folder}meshes/{stem}.obj"), obj.into_bytes());
    if materials {
        files.insert(format!("{folder}meshes/{stem}.mtl"), mtl.into_bytes());
    }
    Ok(())
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

    #[test]
    fn names_are_sanitised_and_unique() {
        let mut n = UniqueNames::default();
        assert_eq!(n.file_stem("door/left"), "door_left");
        assert_eq!(n.file_stem("door_left"), "door_left_1");
        assert_eq!(n.file_stem(""), "unnamed");
    }
}
