//! Link contents: `<visual>` / `<collision>` elements, their geometry (box, cylinder, sphere, mesh files
//! loaded once and shared) and materials (inline or robot-level, with optional PNG texture).

use std::borrow::Cow;
use std::sync::Arc;

use glam::Vec3;
use roxmltree::Node;

use crate::data::DataError;
use crate::object::mesh_io::{self, MeshFormat};
use crate::object::{Geometry, Material, RenderMesh, Visual};

use super::reader::{Reader, child};

/// Triangles an imported object may hold over all its visuals and collisions, a mesh counted once
/// per use (20 M: about 1 GB of vertex data; scanned parts have a few hundred thousand).
pub const MAX_OBJECT_TRIANGLES: usize = 20_000_000;

impl Reader<'_, '_> {
    /// A `<visual>` or `<collision>` element (collisions keep no material).
    pub(super) fn visual(
        &mut self,
        node: Node,
        path: &str,
        with_material: bool,
    ) -> Result<Visual, DataError> {
        let origin = self.origin(node, path)?;
        let gpath = format!("{path}/geometry");
        let Some(g) = child(node, "geometry") else {
            return Err(self.err(node, path, None, "missing <geometry>"));
        };
        let geometry = self.geometry(g, &gpath)?;
        let material = match (with_material, child(node, "material")) {
            (true, Some(m)) => self.visual_material(m, &format!("{path}/material"))?,
            _ => None,
        };
        Ok(Visual {
            name: node.attribute("name").map(str::to_string),
            origin,
            geometry,
            material,
        })
    }

    /// The one shape inside `<geometry>`.
    fn geometry(&mut self, g: Node, path: &str) -> Result<Geometry, DataError> {
        let Some(shape) = g.children().find(Node::is_element) else {
            return Err(self.err(
                g,
                path,
                None,
                "empty <geometry>: expected <box>, <cylinder>, <sphere> or <mesh>",
            ));
        };
        let tag = shape.tag_name().name();
        let spath = format!("{path}/{tag}");
        match tag {
            "box" => {
                let size = self
                    .numbers::<3>(shape, &spath, "size", false)?
                    .ok_or_else(|| self.err(shape, &spath, None, "missing attribute 'size'"))?;
                if size.iter().any(|&s| s < 0.0) {
                    return Err(self.err(
                        shape,
                        &spath,
                        Some("size"),
                        "box sizes must not be negative",
                    ));
                }
                Ok(Geometry::Box {
                    size: Vec3::from_array(size),
                })
            }
            "cylinder" => Ok(Geometry::Cylinder {
                radius: self.positive(shape, &spath, "radius")?,
                length: self.positive(shape, &spath, "length")?,
            }),
            "sphere" => Ok(Geometry::Sphere {
                radius: self.positive(shape, &spath, "radius")?,
            }),
            "mesh" => self.mesh(shape, &spath),
            other => Err(self.err(
                shape,
                &spath,
                None,
                format!(
                    "unsupported geometry <{other}>: expected <box>, <cylinder>, <sphere> or <mesh>"
                ),
            )),
        }
    }

    /// A `<mesh filename scale>`: the file is resolved, checked, and loaded once per key.
    fn mesh(&mut self, node: Node, path: &str) -> Result<Geometry, DataError> {
        let filename = self.required(node, path, "filename")?;
        let scale = self
            .numbers::<3>(node, path, "scale", true)?
            .map_or(Vec3::ONE, Vec3::from_array);
        if scale.to_array().contains(&0.0) {
            return Err(self.err(
                node,
                path,
                Some("scale"),
                format!(
                    "a scale of 0 flattens the mesh to nothing (found {} {} {}); expected non-zero factors",
                    scale.x, scale.y, scale.z
                ),
            ));
        }
        let key = self.resolve(filename, node, path)?;
        if MeshFormat::from_path(&key).is_none() {
            let ext = key.rsplit_once('.').map_or("(none)", |(_, e)| e);
            return Err(self.err(
                node,
                path,
                Some("filename"),
                format!(
                    "unsupported mesh format '.{ext}' in '{filename}': expected .obj, .stl, .glb or .gltf"
                ),
            ));
        }
        if self.files.file(&key).is_none() {
            return Err(self.err(
                node,
                path,
                Some("filename"),
                format!("mesh file '{key}' (from '{filename}') is not in the dataset"),
            ));
        }
        let meshes = match self.meshes.get(&key) {
            Some(m) => m.clone(),
            None => {
                let loaded: Arc<[RenderMesh]> = match mesh_io::load_mesh_with(
                    &key,
                    self.files,
                    &mut self.textures,
                    &mut self.warnings,
                ) {
                    Ok(m) => m.into(),
                    Err(mut e) => {
                        // The mesh file is at fault; say where the URDF refers to it.
                        let line = self.doc.text_pos_at(node.range().start).row;
                        e.message = format!(
                            "{} (mesh of {} at {path}, line {line})",
                            e.message, self.file
                        );
                        return Err(e);
                    }
                };
                self.meshes.insert(key.clone(), loaded.clone());
                loaded
            }
        };
        // Shared meshes cost nothing to read but are drawn once per use: a few links naming a
        // large file many times would make an object no capture can hold.
        self.triangles += meshes.iter().map(|m| m.indices.len()).sum::<usize>();
        if self.triangles > MAX_OBJECT_TRIANGLES {
            return Err(self.err(
                node,
                path,
                Some("filename"),
                format!(
                    "with '{key}' the object's visuals and collisions reach more than {MAX_OBJECT_TRIANGLES} triangles; simplify its meshes first"
                ),
            ));
        }
        Ok(Geometry::Mesh {
            path: key,
            scale,
            meshes,
        })
    }

    /// `<material>` inside a visual: inline colour/texture, else a reference to a robot-level material.
    pub(super) fn visual_material(
        &mut self,
        node: Node,
        path: &str,
    ) -> Result<Option<Material>, DataError> {
        let name = node.attribute("name").unwrap_or_default().to_string();
        if let Some(m) = self.material_body(node, path, &name)? {
            return Ok(Some(m));
        }
        match self.materials.get(&name) {
            Some(m) => Ok(Some(m.clone())),
            None => {
                self.warnings.push(format!(
                    "{}: {path}: material {name:?} is not defined at robot level; using the mesh's own or a default colour",
                    self.file
                ));
                Ok(None)
            }
        }
    }

    /// Reads `<color rgba>` / `<texture filename>` children; `None` if there are neither.
    pub(super) fn material_body(
        &mut self,
        node: Node,
        path: &str,
        name: &str,
    ) -> Result<Option<Material>, DataError> {
        let color = child(node, "color");
        let texture = child(node, "texture");
        if color.is_none() && texture.is_none() {
            return Ok(None);
        }
        let mut material = Material {
            name: (!name.is_empty()).then(|| name.to_string()),
            base_color: [1.0; 4],
            texture: None,
        };
        if let Some(c) = color {
            let cpath = format!("{path}/color");
            material.base_color = self
                .numbers::<4>(c, &cpath, "rgba", false)?
                .ok_or_else(|| self.err(c, &cpath, None, "missing attribute 'rgba'"))?;
        }
        if let Some(t) = texture
            && let Some(filename) = t.attribute("filename")
        {
            let tpath = format!("{path}/texture");
            let key = self.resolve(filename, t, &tpath)?;
            match self.files.file(&key) {
                Some(bytes) => {
                    material.texture =
                        self.textures
                            .get(&key, || Some(Cow::Borrowed(bytes)), &mut self.warnings);
                }
                None => self.warnings.push(format!(
                    "{}: {tpath}: texture '{key}' not found; using the colour",
                    self.file
                )),
            }
        }
        Ok(Some(material))
    }
}
