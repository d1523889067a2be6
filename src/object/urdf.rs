//! URDF (XML) → [`ArticulatedObject`].
//!
//! Reads `<robot>` with its `<material>`, `<link>` (visual/collision with origin, geometry, material) and
//! `<joint>` (type, parent, child, origin, axis, limit, mimic) elements; every other element or attribute
//! (`<inertial>`, `<gazebo>`, `<transmission>`, `<dynamics>`, `<contact>`, `group=`, ...) is ignored, as URDF
//! readers do. Errors name the file, an element path such as `robot/joint[name=door_hinge]/limit@lower` and
//! its line, and what was expected.
//!
//! Numbers: vectors are whitespace-separated, as the URDF spec says. The one exception is mesh `scale`, where
//! commas between the numbers (`scale="1, 1, 1"`) are accepted because habitat-sim's assets write them that way
//! throughout and habitat's reader takes them; elsewhere (`origin@xyz="0.01, -0.33, 0"`) a comma is an error.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{Affine3A, EulerRot, Quat, Vec3};
use roxmltree::Node;

use crate::data::{DataError, FileSet};

use super::mesh_io::{self, MeshFormat, join_relative};
use super::{
    ArticulatedObject, Geometry, Joint, JointKind, Limit, Link, Material, Mimic, RenderMesh, Visual,
};

pub(super) fn read_urdf(urdf_path: &str, files: &FileSet) -> Result<ArticulatedObject, DataError> {
    let bytes = files
        .get(urdf_path)
        .ok_or_else(|| DataError::file(urdf_path, "URDF file not found in the dataset"))?;
    let text = std::str::from_utf8(bytes)
        .map_err(|e| DataError::file(urdf_path, format!("URDF is not valid UTF-8: {e}")))?;
    let doc = roxmltree::Document::parse(text)
        .map_err(|e| DataError::file(urdf_path, format!("URDF is not well-formed XML: {e}")))?;
    let robot = doc.root_element();
    let mut cx = Reader {
        file: urdf_path,
        doc: &doc,
        files,
        folder: match urdf_path.rfind('/') {
            Some(i) => &urdf_path[..=i],
            None => "",
        },
        packages: None,
        meshes: HashMap::new(),
        materials: HashMap::new(),
        warnings: Vec::new(),
    };
    if robot.tag_name().name() != "robot" {
        return Err(cx.err(
            robot,
            robot.tag_name().name(),
            None,
            "expected the root element <robot>",
        ));
    }
    let name = robot.attribute("name").unwrap_or_default().to_string();

    // Robot-level materials first: visuals may refer to materials defined after them.
    for node in children(robot, "material") {
        let mname = cx.required(node, "robot/material", "name")?.to_string();
        let path = format!("robot/material[name={mname}]");
        if let Some(m) = cx.material_body(node, &path, &mname)? {
            cx.materials.insert(mname, m);
        }
    }

    let mut links = Vec::new();
    let mut link_index: HashMap<String, usize> = HashMap::new();
    for node in children(robot, "link") {
        let lname = cx.required(node, "robot/link", "name")?.to_string();
        let path = format!("robot/link[name={lname}]");
        if link_index.contains_key(&lname) {
            return Err(cx.err(node, &path, Some("name"), "duplicate link name"));
        }
        let mut visuals = Vec::new();
        for (i, v) in children(node, "visual").enumerate() {
            visuals.push(cx.visual(v, &format!("{path}/visual[{i}]"), true)?);
        }
        let mut collisions = Vec::new();
        for (i, v) in children(node, "collision").enumerate() {
            collisions.push(cx.visual(v, &format!("{path}/collision[{i}]"), false)?);
        }
        link_index.insert(lname.clone(), links.len());
        links.push(Link {
            name: lname,
            visuals,
            collisions,
        });
    }
    if links.is_empty() {
        return Err(cx.err(robot, "robot", None, "the robot has no <link>"));
    }

    let mut joints = Vec::new();
    let mut joint_nodes = Vec::new();
    for node in children(robot, "joint") {
        let joint = cx.joint(node, &link_index)?;
        if joints.iter().any(|j: &Joint| j.name == joint.name) {
            let path = format!("robot/joint[name={}]", joint.name);
            return Err(cx.err(node, &path, Some("name"), "duplicate joint name"));
        }
        joints.push(joint);
        joint_nodes.push(node);
    }
    cx.resolve_mimics(&mut joints, &joint_nodes)?;
    let root = cx.check_tree(robot, &links, &joints, &joint_nodes)?;

    Ok(ArticulatedObject {
        name,
        links,
        joints,
        root,
        warnings: cx.warnings,
    })
}

/// Child elements of `node` named `tag`.
fn children<'a, 'input>(
    node: Node<'a, 'input>,
    tag: &'static str,
) -> impl Iterator<Item = Node<'a, 'input>> {
    node.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == tag)
}

fn child<'a, 'input>(node: Node<'a, 'input>, tag: &'static str) -> Option<Node<'a, 'input>> {
    children(node, tag).next()
}

struct Reader<'a, 'input> {
    file: &'a str,
    doc: &'a roxmltree::Document<'input>,
    files: &'a FileSet,
    /// The URDF's folder, with a trailing '/' (empty at the top level).
    folder: &'a str,
    /// package name → folder (with trailing '/'), read from `package.xml` files on first use.
    packages: Option<HashMap<String, Vec<String>>>,
    /// Loaded mesh files by key, shared between visuals.
    meshes: HashMap<String, Arc<[RenderMesh]>>,
    /// Robot-level materials by name.
    materials: HashMap<String, Material>,
    warnings: Vec<String>,
}

impl Reader<'_, '_> {
    /// An error at `node` (or its attribute `attr`): field = `path@attr (line N)`.
    fn err(
        &self,
        node: Node,
        path: &str,
        attr: Option<&str>,
        message: impl Into<String>,
    ) -> DataError {
        let pos = attr
            .and_then(|a| node.attribute_node(a))
            .map_or(node.range().start, |a| a.range_value().start);
        let line = self.doc.text_pos_at(pos).row;
        let field = match attr {
            Some(a) => format!("{path}@{a} (line {line})"),
            None => format!("{path} (line {line})"),
        };
        DataError::field(self.file, field, message)
    }

    fn required<'n>(
        &self,
        node: Node<'n, '_>,
        path: &str,
        attr: &str,
    ) -> Result<&'n str, DataError> {
        node.attribute(attr)
            .ok_or_else(|| self.err(node, path, None, format!("missing attribute '{attr}'")))
    }

    fn number(&self, node: Node, path: &str, attr: &str) -> Result<Option<f32>, DataError> {
        let Some(text) = node.attribute(attr) else {
            return Ok(None);
        };
        match parse_finite(text) {
            Some(v) => Ok(Some(v)),
            None => Err(self.err(
                node,
                path,
                Some(attr),
                format!("expected a finite number, found {text:?}"),
            )),
        }
    }

    /// `n` whitespace-separated finite numbers (commas also accepted when `commas`).
    fn numbers<const N: usize>(
        &self,
        node: Node,
        path: &str,
        attr: &str,
        commas: bool,
    ) -> Result<Option<[f32; N]>, DataError> {
        let Some(text) = node.attribute(attr) else {
            return Ok(None);
        };
        let tokens: Vec<&str> = if commas {
            text.split(|c: char| c.is_whitespace() || c == ',')
                .filter(|t| !t.is_empty())
                .collect()
        } else {
            text.split_whitespace().collect()
        };
        let values: Vec<f32> = tokens.iter().filter_map(|t| parse_finite(t)).collect();
        let words = ["zero", "one", "two", "three", "four"];
        let count = words.get(N).copied().unwrap_or("several");
        let sep = if commas {
            "separated by spaces or commas"
        } else {
            "separated by spaces"
        };
        match <[f32; N]>::try_from(values) {
            Ok(v) if tokens.len() == N => Ok(Some(v)),
            _ => Err(self.err(
                node,
                path,
                Some(attr),
                format!("expected {count} finite numbers {sep}, found {text:?}"),
            )),
        }
    }

    /// `<origin xyz rpy>` child of `node`, or the identity.
    fn origin(&self, node: Node, path: &str) -> Result<Affine3A, DataError> {
        let Some(o) = child(node, "origin") else {
            return Ok(Affine3A::IDENTITY);
        };
        let path = format!("{path}/origin");
        let xyz = self
            .numbers::<3>(o, &path, "xyz", false)?
            .unwrap_or([0.0; 3]);
        let [roll, pitch, yaw] = self
            .numbers::<3>(o, &path, "rpy", false)?
            .unwrap_or([0.0; 3]);
        // URDF rpy: fixed-axis roll about x, then pitch about y, then yaw about z = Rz * Ry * Rx.
        let rotation = Quat::from_euler(EulerRot::ZYX, yaw, pitch, roll);
        Ok(Affine3A::from_rotation_translation(
            rotation,
            Vec3::from_array(xyz),
        ))
    }

    fn visual(&mut self, node: Node, path: &str, with_material: bool) -> Result<Visual, DataError> {
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

    /// A required non-negative number.
    fn positive(&self, node: Node, path: &str, attr: &str) -> Result<f32, DataError> {
        let v = self
            .number(node, path, attr)?
            .ok_or_else(|| self.err(node, path, None, format!("missing attribute '{attr}'")))?;
        if v < 0.0 {
            return Err(self.err(
                node,
                path,
                Some(attr),
                format!("expected a non-negative number, found {v}"),
            ));
        }
        Ok(v)
    }

    fn mesh(&mut self, node: Node, path: &str) -> Result<Geometry, DataError> {
        let filename = self.required(node, path, "filename")?;
        let scale = self
            .numbers::<3>(node, path, "scale", true)?
            .map_or(Vec3::ONE, Vec3::from_array);
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
        if !self.files.contains_key(&key) {
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
                let loaded: Arc<[RenderMesh]> =
                    match mesh_io::load_mesh(&key, self.files, &mut self.warnings) {
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
        Ok(Geometry::Mesh {
            path: key,
            scale,
            meshes,
        })
    }

    /// Resolves a URDF file reference to a key of the file set.
    fn resolve(&mut self, filename: &str, node: Node, path: &str) -> Result<String, DataError> {
        let bad = |cx: &Self, msg: String| cx.err(node, path, Some("filename"), msg);
        if let Some(rest) = filename.strip_prefix("package://") {
            let Some((package, rel)) = rest.split_once('/') else {
                return Err(bad(
                    self,
                    format!("expected 'package://NAME/path', found {filename:?}"),
                ));
            };
            let folder = self.package_folder(package).map_err(|m| bad(self, m))?;
            return join_relative(&folder, rel)
                .ok_or_else(|| bad(self, format!("'{filename}' leaves the dataset folder")));
        }
        if filename.starts_with("file://") || filename.starts_with('/') {
            return Err(bad(
                self,
                format!(
                    "absolute path {filename:?} points outside the dataset: use a path relative to the URDF or package://"
                ),
            ));
        }
        if let Some((scheme, _)) = filename.split_once("://") {
            return Err(bad(
                self,
                format!(
                    "unsupported URI scheme '{scheme}://': expected a relative path or package://"
                ),
            ));
        }
        join_relative(self.folder, filename).ok_or_else(|| {
            bad(
                self,
                format!(
                    "'{filename}' leaves the dataset folder (relative to '{}')",
                    self.folder
                ),
            )
        })
    }

    /// Folder (with trailing '/') of the package named `name`: the `package.xml` declaring it; when several do,
    /// the one closest above the URDF.
    fn package_folder(&mut self, name: &str) -> Result<String, String> {
        let packages = self
            .packages
            .get_or_insert_with(|| find_packages(self.files));
        let Some(folders) = packages.get(name) else {
            return Err(format!(
                "no package.xml in the dataset declares <name>{name}</name> (needed for package://{name}/...)"
            ));
        };
        let above: Vec<&String> = folders
            .iter()
            .filter(|f| self.folder.starts_with(f.as_str()))
            .collect();
        match (folders.as_slice(), above.iter().max_by_key(|f| f.len())) {
            ([only], _) => Ok(only.clone()),
            (_, Some(best)) => Ok((*best).clone()),
            _ => Err(format!(
                "package '{name}' is declared by several package.xml files ({}) and none contains the URDF",
                folders.join(", ")
            )),
        }
    }

    /// `<material>` inside a visual: inline colour/texture, else a reference to a robot-level material.
    fn visual_material(&mut self, node: Node, path: &str) -> Result<Option<Material>, DataError> {
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
    fn material_body(
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
            match self.files.get(&key) {
                Some(bytes) => {
                    material.texture =
                        mesh_io::decode_texture(&key, bytes, &mut self.warnings).map(Arc::new);
                }
                None => self.warnings.push(format!(
                    "{}: {tpath}: texture '{key}' not found; using the colour",
                    self.file
                )),
            }
        }
        Ok(Some(material))
    }

    fn joint(
        &mut self,
        node: Node,
        link_index: &HashMap<String, usize>,
    ) -> Result<Joint, DataError> {
        let name = self.required(node, "robot/joint", "name")?.to_string();
        let path = format!("robot/joint[name={name}]");
        let kind = match self.required(node, &path, "type")? {
            "fixed" => JointKind::Fixed,
            "revolute" => JointKind::Revolute,
            "continuous" => JointKind::Continuous,
            "prismatic" => JointKind::Prismatic,
            t @ ("floating" | "planar") => {
                return Err(self.err(
                    node,
                    &path,
                    Some("type"),
                    format!("joint type '{t}' is not supported: parts move on one axis (fixed, revolute, continuous or prismatic)"),
                ));
            }
            t => {
                return Err(self.err(
                    node,
                    &path,
                    Some("type"),
                    format!("expected fixed, revolute, continuous or prismatic, found {t:?}"),
                ));
            }
        };
        let link_of = |cx: &Self, tag: &'static str| -> Result<usize, DataError> {
            let lpath = format!("{path}/{tag}");
            let Some(n) = child(node, tag) else {
                return Err(cx.err(node, &path, None, format!("missing <{tag} link=...>")));
            };
            let lname = cx.required(n, &lpath, "link")?;
            link_index
                .get(lname)
                .copied()
                .ok_or_else(|| cx.err(n, &lpath, Some("link"), format!("no link named {lname:?}")))
        };
        let parent = link_of(self, "parent")?;
        let child_link = link_of(self, "child")?;
        if parent == child_link {
            return Err(self.err(node, &path, None, "parent and child are the same link"));
        }
        let origin = self.origin(node, &path)?;
        let axis = match child(node, "axis") {
            Some(a) => {
                let apath = format!("{path}/axis");
                let v = Vec3::from_array(
                    self.numbers::<3>(a, &apath, "xyz", false)?
                        .unwrap_or([1.0, 0.0, 0.0]),
                );
                match v.try_normalize() {
                    Some(u) => u,
                    None if kind == JointKind::Fixed => Vec3::X,
                    None => return Err(self.err(a, &apath, Some("xyz"), "axis must not be zero")),
                }
            }
            None => Vec3::X,
        };
        let limit = match child(node, "limit") {
            Some(l) => {
                let lpath = format!("{path}/limit");
                let lower = self.number(l, &lpath, "lower")?.unwrap_or(0.0);
                let upper = self.number(l, &lpath, "upper")?.unwrap_or(0.0);
                if lower > upper && matches!(kind, JointKind::Revolute | JointKind::Prismatic) {
                    return Err(self.err(
                        l,
                        &lpath,
                        Some("lower"),
                        format!("lower limit {lower} is above upper limit {upper}"),
                    ));
                }
                Some(Limit {
                    lower,
                    upper,
                    effort: self.number(l, &lpath, "effort")?.unwrap_or(0.0),
                    velocity: self.number(l, &lpath, "velocity")?.unwrap_or(0.0),
                })
            }
            None if matches!(kind, JointKind::Revolute | JointKind::Prismatic) => {
                return Err(self.err(
                    node,
                    &path,
                    None,
                    "revolute and prismatic joints need <limit lower=... upper=...>: URDF requires it, and it gives the range of states",
                ));
            }
            None => None,
        };
        Ok(Joint {
            name,
            kind,
            parent,
            child: child_link,
            origin,
            axis,
            limit,
            // Filled in by `resolve_mimics` once every joint is known.
            mimic: None,
        })
    }

    fn resolve_mimics(&self, joints: &mut [Joint], nodes: &[Node]) -> Result<(), DataError> {
        for (j, node) in nodes.iter().enumerate() {
            let Some(m) = child(*node, "mimic") else {
                continue;
            };
            let name = joints.get(j).map(|x| x.name.clone()).unwrap_or_default();
            let path = format!("robot/joint[name={name}]/mimic");
            let leader = self.required(m, &path, "joint")?;
            let Some(target) = joints.iter().position(|x| x.name == leader) else {
                return Err(self.err(
                    m,
                    &path,
                    Some("joint"),
                    format!("no joint named {leader:?}"),
                ));
            };
            if target == j {
                return Err(self.err(m, &path, Some("joint"), "a joint cannot mimic itself"));
            }
            let mimic = Mimic {
                joint: target,
                multiplier: self.number(m, &path, "multiplier")?.unwrap_or(1.0),
                offset: self.number(m, &path, "offset")?.unwrap_or(0.0),
            };
            if let Some(joint) = joints.get_mut(j) {
                joint.mimic = Some(mimic);
            }
        }
        Ok(())
    }

    /// Checks the links form one tree (each link the child of at most one joint, one root, no cycles) and
    /// returns the root.
    fn check_tree(
        &self,
        robot: Node,
        links: &[Link],
        joints: &[Joint],
        nodes: &[Node],
    ) -> Result<usize, DataError> {
        let mut parent_joint: Vec<Option<usize>> = vec![None; links.len()];
        for (j, joint) in joints.iter().enumerate() {
            let Some(slot) = parent_joint.get_mut(joint.child) else {
                continue;
            };
            if let Some(other) = *slot {
                let node = nodes.get(j).copied().unwrap_or(robot);
                let path = format!("robot/joint[name={}]/child", joint.name);
                let other_name = joints.get(other).map_or("?", |o| o.name.as_str());
                let child_name = links.get(joint.child).map_or("?", |l| l.name.as_str());
                return Err(self.err(
                    child(node, "child").unwrap_or(node),
                    &path,
                    Some("link"),
                    format!("link {child_name:?} is already the child of joint {other_name:?}: URDF links form a tree"),
                ));
            }
            *slot = Some(j);
        }
        let roots: Vec<usize> = (0..links.len())
            .filter(|&l| parent_joint[l].is_none())
            .collect();
        let root = match roots.as_slice() {
            [r] => *r,
            [] => {
                return Err(self.err(
                    robot,
                    "robot",
                    None,
                    "every link is some joint's child: the joints form a cycle",
                ));
            }
            many => {
                let names: Vec<&str> = many
                    .iter()
                    .filter_map(|&l| links.get(l).map(|x| x.name.as_str()))
                    .collect();
                return Err(self.err(
                    robot,
                    "robot",
                    None,
                    format!(
                        "expected one root link, found {} unconnected ones: {}",
                        names.len(),
                        names.join(", ")
                    ),
                ));
            }
        };
        // With one root and one parent per link, an unreachable link means a cycle.
        let mut reached = vec![false; links.len()];
        let mut stack = vec![root];
        while let Some(l) = stack.pop() {
            match reached.get_mut(l) {
                Some(r) if !*r => *r = true,
                _ => continue,
            }
            stack.extend(joints.iter().filter(|j| j.parent == l).map(|j| j.child));
        }
        if let Some(l) = reached.iter().position(|r| !r) {
            let lname = links.get(l).map_or("?", |x| x.name.as_str());
            return Err(self.err(
                robot,
                "robot",
                None,
                format!(
                    "link {lname:?} is not connected to the root link (the joints form a cycle)"
                ),
            ));
        }
        Ok(root)
    }
}

/// A finite number, or `None`.
fn parse_finite(text: &str) -> Option<f32> {
    text.trim().parse::<f32>().ok().filter(|v| v.is_finite())
}

/// package name → folders (with trailing '/') of every `package.xml` in the file set that names it.
fn find_packages(files: &FileSet) -> HashMap<String, Vec<String>> {
    let mut out: HashMap<String, Vec<String>> = HashMap::new();
    for (key, bytes) in files {
        let folder = if key == "package.xml" {
            ""
        } else if let Some(f) = key.strip_suffix("/package.xml") {
            f
        } else {
            continue;
        };
        let Ok(text) = std::str::from_utf8(bytes) else {
            continue;
        };
        let Ok(doc) = roxmltree::Document::parse(text) else {
            continue;
        };
        let Some(name) = child(doc.root_element(), "name").and_then(|n| n.text()) else {
            continue;
        };
        let folder = if folder.is_empty() {
            String::new()
        } else {
            format!("{folder}/")
        };
        out.entry(name.trim().to_string()).or_default().push(folder);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn files(urdf: &str) -> FileSet {
        let mut f = FileSet::new();
        f.insert("r/robot.urdf".into(), urdf.as_bytes().to_vec());
        f
    }

    #[test]
    fn object_urdf_rpy_is_fixed_axis_xyz() {
        let urdf = r#"<robot name="t"><link name="a"/><link name="b"/>
            <joint name="j" type="fixed"><parent link="a"/><child link="b"/>
            <origin xyz="1 2 3" rpy="0 0 1.5707963"/></joint></robot>"#;
        let o = read_urdf("r/robot.urdf", &files(urdf)).unwrap();
        let t = o.joints[0].origin;
        assert!((t.transform_vector3(Vec3::X) - Vec3::Y).length() < 1e-6);
        assert!((t.translation - glam::Vec3A::new(1.0, 2.0, 3.0)).length() < 1e-6);
        // Roll then pitch: rpy = (π/2, π/2, 0) maps z → x (Ry(π/2) after Rx(π/2)).
        let urdf2 = urdf.replace("0 0 1.5707963", "1.5707963 1.5707963 0");
        let o2 = read_urdf("r/robot.urdf", &files(&urdf2)).unwrap();
        let y = o2.joints[0].origin.transform_vector3(Vec3::Y);
        assert!((y - Vec3::X).length() < 1e-5, "{y}");
    }

    #[test]
    fn object_urdf_errors_carry_path_and_line() {
        let urdf = "<robot name=\"t\">\n<link name=\"a\"/><link name=\"b\"/>\n<joint name=\"j\" type=\"revolute\">\n<parent link=\"a\"/><child link=\"b\"/>\n<limit lower=\"x\" upper=\"1\"/></joint></robot>";
        let e = read_urdf("r/robot.urdf", &files(urdf)).unwrap_err();
        assert_eq!(e.file, "r/robot.urdf");
        assert_eq!(
            e.field.as_deref(),
            Some("robot/joint[name=j]/limit@lower (line 5)")
        );
        assert!(e.message.contains("finite number"), "{e}");
    }

    #[test]
    fn object_urdf_structure_errors() {
        let cases = [
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"a\"/></robot>",
                "duplicate link",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/></robot>",
                "one root link",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/></joint></robot>",
                "need <limit",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"planar\"><parent link=\"a\"/><child link=\"b\"/></joint></robot>",
                "not supported",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"c\"/></joint></robot>",
                "no link named",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint><joint name=\"k\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint></robot>",
                "cycle",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"><visual><geometry><capsule/></geometry></visual></link></robot>",
                "unsupported geometry",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"><visual><geometry><mesh filename=\"file:///x.obj\"/></geometry></visual></link></robot>",
                "absolute path",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"><visual><geometry><mesh filename=\"../../x.obj\"/></geometry></visual></link></robot>",
                "leaves the dataset",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"><visual><geometry><mesh filename=\"package://nope/x.obj\"/></geometry></visual></link></robot>",
                "no package.xml",
            ),
            ("<robot><link", "well-formed"),
            ("<model/>", "<robot>"),
        ];
        for (urdf, expected) in cases {
            let e = read_urdf("r/robot.urdf", &files(urdf)).unwrap_err();
            assert!(e.to_string().contains(expected), "{urdf}: {e}");
        }
    }

    #[test]
    fn object_urdf_primitives_and_materials() {
        let urdf = r#"<robot name="t">
            <material name="red"><color rgba="1 0 0 1"/></material>
            <link name="a">
              <visual><origin xyz="0 0 1"/><geometry><box size="1 2 3"/></geometry><material name="red"/></visual>
              <visual><geometry><cylinder radius="0.5" length="2"/></geometry><material name="blue"><color rgba="0 0 1 1"/></material></visual>
              <visual><geometry><sphere radius="1"/></geometry><material name="undefined"/></visual>
              <collision><geometry><box size="1 1 1"/></geometry></collision>
              <gazebo><plugin name="x"/></gazebo>
            </link></robot>"#;
        let o = read_urdf("r/robot.urdf", &files(urdf)).unwrap();
        let l = &o.links[0];
        assert_eq!(l.visuals.len(), 3);
        assert_eq!(l.collisions.len(), 1);
        assert_eq!(
            l.visuals[0].material.as_ref().unwrap().base_color,
            [1.0, 0.0, 0.0, 1.0]
        );
        assert_eq!(
            l.visuals[1].material.as_ref().unwrap().base_color,
            [0.0, 0.0, 1.0, 1.0]
        );
        assert!(l.visuals[2].material.is_none());
        assert_eq!(o.warnings.len(), 1, "{:?}", o.warnings);
        let meshes = o.link_meshes(0);
        assert_eq!(meshes.len(), 3);
        assert_eq!(meshes[0].material.base_color, [1.0, 0.0, 0.0, 1.0]);
        let top = meshes[0]
            .positions
            .iter()
            .map(|p| p.z)
            .fold(f32::MIN, f32::max);
        assert!((top - 2.5).abs() < 1e-6);
    }
}
