//! The URDF reading state ([`Reader`]) and element navigation; the bottom of the URDF files, which add
//! `Reader` methods by concern.

use std::collections::HashMap;
use std::sync::Arc;

use roxmltree::Node;

use crate::data::FileSource;
use crate::object::mesh_io::Textures;
use crate::object::{Material, RenderMesh};

/// Child elements of `node` named `tag`.
pub(super) fn children<'a, 'input>(
    node: Node<'a, 'input>,
    tag: &'static str,
) -> impl Iterator<Item = Node<'a, 'input>> {
    node.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == tag)
}

/// First child element of `node` named `tag`.
pub(super) fn child<'a, 'input>(
    node: Node<'a, 'input>,
    tag: &'static str,
) -> Option<Node<'a, 'input>> {
    children(node, tag).next()
}

/// Reading state for one URDF: the document, where its files are, and what has been loaded so far. Its
/// methods are spread by concern: `attributes.rs` (numbers, origins, errors), `links.rs` (visuals, geometry,
/// materials), `resolve.rs` (file references and packages), `joints.rs` (joints, mimics, the link tree).
pub(super) struct Reader<'a, 'input> {
    pub(super) file: &'a str,
    pub(super) doc: &'a roxmltree::Document<'input>,
    pub(super) files: &'a dyn FileSource,
    /// The URDF's folder, with a trailing '/' (empty at the top level).
    pub(super) folder: &'a str,
    /// package name → folder (with trailing '/'), read from `package.xml` files on first use.
    pub(super) packages: Option<HashMap<String, Vec<String>>>,
    /// Loaded mesh files by key, shared between visuals.
    pub(super) meshes: HashMap<String, Arc<[RenderMesh]>>,
    /// Textures decoded so far, shared by every material and mesh file of the object.
    pub(super) textures: Textures,
    /// Triangles of the visuals and collisions read so far (a mesh counts once per use).
    pub(super) triangles: usize,
    /// Robot-level materials by name.
    pub(super) materials: HashMap<String, Material>,
    pub(super) warnings: Vec<String>,
}
