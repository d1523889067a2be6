//! Articulated object model: links with geometry, joints with limits, forward kinematics and the part view.
//!
//! An [`ArticulatedObject`] is what a URDF describes: a tree of [`Link`]s (each with visual and collision
//! geometry) connected by [`Joint`]s (fixed, revolute, continuous, prismatic). It is read from bytes with
//! [`ArticulatedObject::from_urdf`] (URDF + OBJ/MTL, STL, GLB/glTF meshes, all taken from a [`FileSource`](crate::data::FileSource)),
//! posed with [`ArticulatedObject::forward_kinematics`], and grouped into rigid **parts** with
//! [`ArticulatedObject::parts`]: the unit the ArtMesh pipeline reconstructs (part 0 = static base, one part
//! per movable joint).
//!
//! Conventions:
//! - URDF frames: `child = parent * joint.origin * motion(axis, q)`; `origin` rpy is fixed-axis roll-pitch-yaw
//!   (`Rz(yaw) * Ry(pitch) * Rx(roll)`), metres and radians.
//! - Mesh data is kept in the mesh file's own frame, unscaled ([`Geometry::Mesh`] carries the URDF `scale`);
//!   [`Visual::link_frame_meshes`] applies scale and origin.
//! - Texture coordinates follow glTF: `v = 0` is the top row of the texture image (OBJ's `v` is flipped on import).
//! - Joint values `q` hold one value per joint (fixed joints ignore theirs). Continuous joints have no limits;
//!   [`Joint::range`] gives them the documented sampling range [`CONTINUOUS_RANGE`] = [−π, π].
//! - Revolute and prismatic joints without `<limit>` are an error (the URDF spec requires one, and without it
//!   there is no state range to sample); missing `lower`/`upper` default to 0 and missing `effort`/`velocity`
//!   to 0, as in the URDF spec's defaults.
//! - Numbers in vectors are whitespace-separated (URDF spec). Only mesh `scale` also accepts commas
//!   (`"1, 1, 1"`, written throughout habitat-sim's assets); `origin@xyz="0.01, -0.33, 0"` is an error.
//! - Chained joints (a hinge behind a tiny slider) are merged in the part view; see [`Parts`] / `parts.rs`.
//!
//! The module is I/O-free: bytes in, structs out, so it runs natively and in wasm. Bad input never panics:
//! every problem is a [`DataError`] naming the file, the element path (`robot/joint[name=hinge]/limit@lower`)
//! with its line, and what was expected. Recoverable problems (a JPEG texture, a missing MTL file, an
//! undefined URDF material) fall back to a plain colour and are listed in [`ArticulatedObject::warnings`].

mod kinematics;
mod mesh_io;
mod parts;
mod primitives;
pub mod sampling;
mod urdf;

use std::sync::Arc;

use glam::{Affine3A, Vec2, Vec3};

use crate::data::{DataError, FileSource, RgbaImage};

pub use kinematics::part_joint;
pub use mesh_io::{MeshFormat, load_mesh};
pub use parts::{MERGE_PRISMATIC_SPAN, MERGE_REVOLUTE_SPAN, Part, Parts, is_merged_chain_joint};
pub(crate) use primitives::BOX_FACES;
pub use primitives::{box_mesh, cylinder_mesh, sphere_mesh};

/// Sampling range (radians) for continuous joints, which have no limits: one full turn centred on the rest pose.
pub(crate) const CONTINUOUS_RANGE: (f32, f32) = (-std::f32::consts::PI, std::f32::consts::PI);

/// Colour and optional base-colour texture of a surface.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Name in the source file (URDF `<material name>`, MTL `newmtl`, glTF material name or `material N`).
    /// For meshes read from files, `None` means the file gave the mesh no material (STL, OBJ without MTL), so
    /// the URDF material applies.
    pub name: Option<String>,
    /// Linear RGBA factor; multiplies the texture when there is one.
    pub base_color: [f32; 4],
    /// Base-colour texture (8-bit RGBA as stored in the file, usually sRGB); shared between meshes that use it.
    pub texture: Option<Arc<RgbaImage>>,
}

impl Default for Material {
    /// Light grey, untextured: used where neither the mesh nor the URDF gives a colour.
    fn default() -> Self {
        Material {
            name: None,
            base_color: [0.7, 0.7, 0.7, 1.0],
            texture: None,
        }
    }
}

/// An indexed triangle mesh with one material, ready to render.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals, one per position (computed from the triangles when the file has none).
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per position, glTF convention (`v = 0` at the top of the image).
    pub uvs: Option<Vec<Vec2>>,
    /// Linear RGB per vertex (a fitted twin's colours; glTF `COLOR_0`, OBJ `v x y z r g b`). When present
    /// they replace the material's RGB, which is then only a fallback for viewers that ignore them. The
    /// ground-truth renderer ignores them.
    pub colors: Option<Vec<[f32; 3]>>,
    /// Counter-clockwise triangles (outward normal by the right-hand rule), indices into `positions`.
    pub indices: Vec<[u32; 3]>,
    /// Surface material.
    pub material: Material,
}

impl RenderMesh {
    /// The mesh moved by `transform` (normals by its inverse transpose; winding flipped for mirroring transforms).
    pub fn transformed(&self, transform: &Affine3A) -> RenderMesh {
        let linear = transform.matrix3;
        let det = linear.determinant();
        let normal_matrix = if det.abs() > 1e-20 {
            linear.inverse().transpose()
        } else {
            linear
        };
        let positions = self
            .positions
            .iter()
            .map(|p| transform.transform_point3(*p))
            .collect();
        let normals = self
            .normals
            .iter()
            .map(|n| (normal_matrix * *n).normalize_or_zero())
            .collect();
        let indices = if det < 0.0 {
            self.indices.iter().map(|t| [t[0], t[2], t[1]]).collect()
        } else {
            self.indices.clone()
        };
        RenderMesh {
            positions,
            normals,
            uvs: self.uvs.clone(),
            colors: self.colors.clone(),
            indices,
            material: self.material.clone(),
        }
    }
}

/// Axis-aligned bounds of the finite vertices of `meshes`; `None` when there are none.
pub(crate) fn mesh_bounds<'a>(
    meshes: impl IntoIterator<Item = &'a RenderMesh>,
) -> Option<(Vec3, Vec3)> {
    meshes
        .into_iter()
        .flat_map(|m| m.positions.iter())
        .filter(|p| p.is_finite())
        .fold(None, |acc, &p| match acc {
            None => Some((p, p)),
            Some((lo, hi)) => Some((lo.min(p), hi.max(p))),
        })
}

/// Shape of a visual or collision element.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    /// Axis-aligned box centred on the origin, full side lengths.
    Box {
        /// Side lengths along x, y, z.
        size: Vec3,
    },
    /// Cylinder along z, centred on the origin.
    Cylinder {
        /// Radius.
        radius: f32,
        /// Length along z.
        length: f32,
    },
    /// Sphere centred on the origin.
    Sphere {
        /// Radius.
        radius: f32,
    },
    /// Mesh file, loaded.
    Mesh {
        /// Key of the mesh file in the [`FileSource`] (after `package://` and relative-path resolution).
        path: String,
        /// Per-axis scale from the URDF (applied by [`Visual::link_frame_meshes`], not baked into `meshes`).
        scale: Vec3,
        /// The file's meshes, one per material group / glTF primitive, in the file's frame; shared between
        /// visuals that use the same file.
        meshes: Arc<[RenderMesh]>,
    },
}

/// A visual or collision element of a link.
#[derive(Debug, Clone, PartialEq)]
pub struct Visual {
    /// `name` attribute, if any.
    pub name: Option<String>,
    /// Pose of the geometry in the link frame.
    pub origin: Affine3A,
    /// The shape.
    pub geometry: Geometry,
    /// URDF material, resolved against the robot-level `<material>` list (`None` if the element has none;
    /// always `None` for collisions).
    pub material: Option<Material>,
}

impl Visual {
    /// Triangle meshes of this element in the link frame: primitives tessellated, mesh files scaled, all moved
    /// by `origin`. Material: the URDF material for primitives and for mesh groups that carry none of their own
    /// (STL, OBJ without MTL), else the mesh's own; [`Material::default`] when neither exists.
    pub(crate) fn link_frame_meshes(&self) -> Vec<RenderMesh> {
        let urdf_material = self.material.clone().unwrap_or_default();
        match &self.geometry {
            Geometry::Box { size } => {
                vec![box_mesh(*size, urdf_material).transformed(&self.origin)]
            }
            Geometry::Cylinder { radius, length } => {
                vec![cylinder_mesh(*radius, *length, urdf_material).transformed(&self.origin)]
            }
            Geometry::Sphere { radius } => {
                vec![sphere_mesh(*radius, urdf_material).transformed(&self.origin)]
            }
            Geometry::Mesh { scale, meshes, .. } => {
                let transform = self.origin * Affine3A::from_scale(*scale);
                meshes
                    .iter()
                    .map(|m| {
                        let mut out = m.transformed(&transform);
                        // Mesh materials are unnamed only when the file gave the mesh none.
                        if m.material.name.is_none()
                            && let Some(urdf) = &self.material
                        {
                            out.material = urdf.clone();
                        }
                        out
                    })
                    .collect()
            }
        }
    }
}

/// A rigid body of the object.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// Unique link name.
    pub name: String,
    /// What is rendered.
    pub visuals: Vec<Visual>,
    /// What collides (often simplified boxes or convex pieces).
    pub collisions: Vec<Visual>,
}

/// Kind of joint motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// No motion.
    Fixed,
    /// Rotation about `axis` within limits (radians).
    Revolute,
    /// Unlimited rotation about `axis`; see [`CONTINUOUS_RANGE`].
    Continuous,
    /// Translation along `axis` within limits (metres).
    Prismatic,
}

impl JointKind {
    /// True for every kind but [`JointKind::Fixed`].
    pub fn is_movable(self) -> bool {
        self != JointKind::Fixed
    }
}

/// URDF `<limit>`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Limit {
    /// Lowest joint value (radians or metres).
    pub lower: f32,
    /// Highest joint value.
    pub upper: f32,
    /// Maximum effort (N or N·m); 0 if not given.
    pub effort: f32,
    /// Maximum velocity; 0 if not given.
    pub velocity: f32,
}

/// URDF `<mimic>`: this joint's value is `multiplier * q[joint] + offset`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mimic {
    /// Index of the joint followed.
    pub joint: usize,
    /// Scale applied to the followed joint's value.
    pub multiplier: f32,
    /// Added after scaling.
    pub offset: f32,
}

/// A joint between a parent and a child link.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Unique joint name.
    pub name: String,
    /// Motion kind.
    pub kind: JointKind,
    /// Index of the parent link.
    pub parent: usize,
    /// Index of the child link.
    pub child: usize,
    /// Pose of the joint frame in the parent link frame (the child frame at `q = 0`).
    pub origin: Affine3A,
    /// Unit motion axis in the joint frame (URDF default `1 0 0`).
    pub axis: Vec3,
    /// Limits as written (revolute and prismatic joints always have them; continuous and fixed may).
    pub limit: Option<Limit>,
    /// Coupling to another joint, if any.
    pub mimic: Option<Mimic>,
}

impl Joint {
    /// Range of joint values to sample states from: the limits for revolute/prismatic joints,
    /// [`CONTINUOUS_RANGE`] for continuous joints, `None` for fixed joints.
    pub fn range(&self) -> Option<(f32, f32)> {
        match self.kind {
            JointKind::Fixed => None,
            JointKind::Continuous => Some(CONTINUOUS_RANGE),
            JointKind::Revolute | JointKind::Prismatic => {
                Some(self.limit.map_or((0.0, 0.0), |l| (l.lower, l.upper)))
            }
        }
    }

    /// The rest value: 0 clamped into [`Joint::range`] (0 for fixed joints).
    pub(crate) fn rest_value(&self) -> f32 {
        self.range()
            .map_or(0.0, |(lo, hi)| 0.0f32.clamp(lo, hi.max(lo)))
    }

    /// Motion of the child relative to the joint frame at value `q` (identity for fixed joints).
    pub fn motion(&self, q: f32) -> Affine3A {
        kinematics::joint_motion(self.kind, self.axis, q)
    }
}

/// An articulated object: links, joints, the root link, and import warnings.
#[derive(Debug, Clone, PartialEq)]
pub struct ArticulatedObject {
    /// `<robot name>`.
    pub name: String,
    /// Links in file order.
    pub links: Vec<Link>,
    /// Joints in file order.
    pub joints: Vec<Joint>,
    /// Index of the root link (the one link that is no joint's child).
    pub root: usize,
    /// Recoverable problems met while importing (unsupported texture formats, missing MTL files, ...).
    pub warnings: Vec<String>,
}

impl ArticulatedObject {
    /// Reads a URDF and the meshes it references. `urdf_path` is a key of `files`; relative mesh paths resolve
    /// against the URDF's folder, `package://NAME/rest` against the folder of the `package.xml` whose `<name>`
    /// is `NAME`. `file://` and absolute paths, and paths leaving the [`FileSource`]'s root, are errors.
    pub fn from_urdf(
        urdf_path: &str,
        files: &dyn FileSource,
    ) -> Result<ArticulatedObject, DataError> {
        urdf::read_urdf(urdf_path, files)
    }

    /// Index of the link named `name`.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    /// Index of the joint named `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Indices of the movable (non-fixed) joints, in file order.
    pub fn movable_joints(&self) -> Vec<usize> {
        (0..self.joints.len())
            .filter(|&j| self.joints[j].kind.is_movable())
            .collect()
    }

    /// The rest configuration: every joint at [`Joint::rest_value`].
    pub fn rest_configuration(&self) -> Vec<f32> {
        self.joints.iter().map(Joint::rest_value).collect()
    }

    /// Overwrites the value of every mimic joint with `multiplier * q[followed] + offset` (chains of mimics
    /// resolve in order; a missing entry of `q` counts as 0). Returns a vector as long as `joints`.
    pub fn apply_mimic(&self, q: &[f32]) -> Vec<f32> {
        kinematics::apply_mimic(self, q)
    }

    /// World transform of every link at joint values `q` (one per joint; fixed joints ignore theirs; missing
    /// entries count as 0, extra ones are ignored). The root link sits at the identity. Links not reachable
    /// from the root (impossible for imported objects) stay at the identity.
    pub fn forward_kinematics(&self, q: &[f32]) -> Vec<Affine3A> {
        kinematics::forward_kinematics(self, q)
    }

    /// Joint indices, parents before children (breadth-first from the root); joints not reachable from
    /// the root are left out.
    pub(crate) fn joint_order(&self) -> Vec<usize> {
        kinematics::joint_order(self).0
    }

    /// Visual meshes of link `link` in its own frame (see [`Visual::link_frame_meshes`]); empty for a bad index.
    pub fn link_meshes(&self, link: usize) -> Vec<RenderMesh> {
        self.links
            .get(link)
            .map(|l| {
                l.visuals
                    .iter()
                    .flat_map(Visual::link_frame_meshes)
                    .collect()
            })
            .unwrap_or_default()
    }

    /// Rigid parts: groups of links connected by fixed joints, one per movable joint, with short chained
    /// joints merged (see [`Parts`] for the rule).
    pub fn parts(&self) -> Parts {
        parts::parts(self)
    }
}
