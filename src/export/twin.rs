//! The digital twin the exports describe: one coloured mesh per part in the start state and one
//! joint per movable part, turned into an [`ArticulatedObject`] that the URDF and GLB writers take.
//!
//! Conventions (docs/design.md §8):
//! - Link `base` is part 0 and the root; link `part_k` hangs from it by joint `joint_k`.
//! - The start state is the rest pose: every joint is 0 there and `motion` (radians / metres) at
//!   the end; limits span both, `[min(0, motion), max(0, motion)]`. A joint with no motion at all
//!   is written as fixed (an empty range would read as unlimited in MuJoCo).
//! - A movable link's frame is its joint frame: at the joint origin (a point on the axis), with
//!   the world's orientation, so the URDF axis is the world axis and the meshes are the world
//!   meshes shifted by the origin.

use std::sync::Arc;

use glam::{Affine3A, Vec3};

use super::collision::ConvexPiece;
use crate::data::{GtJoint, GtMeshes, JointKind as GtKind, State, TriMesh};
use crate::fit::object::ObjectFit;
use crate::object::{
    ArticulatedObject, Geometry, Joint, JointKind, Limit, Link, Material, RenderMesh, Visual,
    part_joint,
};

/// Name of the root link (part 0).
pub(crate) const BASE_LINK: &str = "base";
/// Effort limit written on every joint (N·m or N): URDF requires one, and simulators cap motors by it.
pub(crate) const JOINT_EFFORT: f32 = 50.0;
/// Velocity limit written on every joint (rad/s or m/s).
pub(crate) const JOINT_VELOCITY: f32 = 1.0;

/// Link name of movable part `k` (1 ..= K).
pub fn part_link(k: usize) -> String {
    format!("part_{k}")
}

/// One part of a twin.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TwinPart {
    /// The part's surface in the start state (world frame).
    pub mesh: TriMesh,
    /// Linear RGB per vertex (a fit's colours), if any.
    pub colors: Option<Vec<[f32; 3]>>,
}

/// Why [`Twin::from_fit`] has no meshes to take: the fit lacks its start-state reconstruction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("the fit has no start-state reconstruction")]
pub struct NoStartState;

/// An articulated twin: parts (base first) and one joint per movable part.
#[derive(Debug, Clone, PartialEq)]
pub struct Twin {
    /// Robot name (any text; escaped where written).
    pub name: String,
    pub parts: Vec<TwinPart>,
    /// Joint of part k at index k − 1, in `trans.json` units (degrees, metres).
    pub joints: Vec<GtJoint>,
}

impl Twin {
    /// The twin of a fit: the start state's part meshes with their fitted colours (the SH DC term,
    /// decoded from the images' sRGB), and the fitted joints.
    pub fn from_fit(fit: &ObjectFit, name: &str) -> Result<Twin, NoStartState> {
        let state = fit
            .reconstruction
            .states
            .iter()
            .find(|s| s.state == State::Start)
            .ok_or(NoStartState)?;
        let field = &state.field;
        let subs = crate::mesh::part_submeshes(&field.faces, &state.parts, field.num_parts);
        let parts = subs
            .into_iter()
            .map(|sub| TwinPart {
                mesh: TriMesh {
                    positions: sub
                        .vertices
                        .iter()
                        .map(|&v| field.positions[v as usize])
                        .collect(),
                    triangles: sub.triangles,
                },
                colors: Some(
                    sub.vertices
                        .iter()
                        .map(|&v| field.dc_color(v as usize).to_array().map(srgb_to_linear))
                        .collect(),
                ),
            })
            .collect();
        Ok(Twin {
            name: name.to_string(),
            parts,
            joints: fit.articulation.gt_joints(),
        })
    }

    /// The twin of a ground truth (uncoloured): its start-state meshes and joints.
    pub fn from_truth(name: &str, start: &GtMeshes, joints: &[GtJoint]) -> Twin {
        let parts = std::iter::once(&start.static_part)
            .chain(&start.movable)
            .map(|m| TwinPart {
                mesh: m.clone(),
                colors: None,
            })
            .collect();
        Twin {
            name: name.to_string(),
            parts,
            joints: joints.to_vec(),
        }
    }

    /// The twin with its parts' meshes decimated ([`crate::mesh::decimate`]) to `max_faces` over
    /// all parts, each part's share in proportion to its faces (0: unchanged). A part whose rims
    /// and islands allow no further collapse stops above its share, so the total can exceed the
    /// budget by that much. Colours follow the vertices they were on.
    pub fn with_visual_budget(&self, max_faces: usize) -> Twin {
        let total: usize = self.parts.iter().map(|p| p.mesh.triangles.len()).sum();
        if max_faces == 0 || total <= max_faces {
            return self.clone();
        }
        let parts = self
            .parts
            .iter()
            .map(|part| {
                let share = part.mesh.triangles.len() * max_faces / total;
                let d = crate::mesh::decimate(&part.mesh.positions, &part.mesh.triangles, share);
                TwinPart {
                    colors: part.colors.as_ref().map(|c| {
                        d.source
                            .iter()
                            .map(|&s| c.get(s as usize).copied().unwrap_or([1.0; 3]))
                            .collect()
                    }),
                    mesh: TriMesh {
                        positions: d.positions,
                        triangles: d.triangles,
                    },
                }
            })
            .collect();
        Twin {
            name: self.name.clone(),
            parts,
            joints: self.joints.clone(),
        }
    }

    /// Joint values at the end state (radians / metres), one per joint of [`Twin::object`].
    pub fn end_configuration(&self) -> Vec<f32> {
        self.joints.iter().map(GtJoint::urdf_motion).collect()
    }

    /// The twin as an articulated object (see the module docs for its layout), each link colliding
    /// as convex pieces cleared along the joints ([`super::collision`]): what the exports write.
    pub fn object(&self) -> ArticulatedObject {
        let meshes: Vec<&TriMesh> = self.parts.iter().map(|p| &p.mesh).collect();
        let pieces = super::collision::part_collisions(&meshes, &self.joints, &Default::default());
        self.object_with(Some(&pieces))
    }

    /// The twin as an articulated object with visuals only (no collision shapes): for viewers,
    /// which do not need the convex decomposition's time.
    pub fn visual_object(&self) -> ArticulatedObject {
        self.object_with(None)
    }

    fn object_with(&self, collisions: Option<&[Vec<ConvexPiece>]>) -> ArticulatedObject {
        let pieces = |k: usize| {
            collisions
                .and_then(|c| c.get(k))
                .map_or(&[][..], |c| c.as_slice())
        };
        let mut links = vec![link(
            BASE_LINK.into(),
            self.parts.first(),
            Vec3::ZERO,
            pieces(0),
        )];
        let mut joints = Vec::new();
        for (i, joint) in self.joints.iter().enumerate() {
            let k = i + 1;
            let origin = joint.origin;
            links.push(link(part_link(k), self.parts.get(k), origin, pieces(k)));
            let motion = joint.urdf_motion();
            joints.push(Joint {
                name: part_joint(k),
                // A joint that did not move has an empty range, which MuJoCo reads as unlimited.
                kind: match joint.kind {
                    _ if motion == 0.0 => JointKind::Fixed,
                    GtKind::Revolute => JointKind::Revolute,
                    GtKind::Prismatic => JointKind::Prismatic,
                },
                parent: 0,
                child: k,
                origin: Affine3A::from_translation(origin),
                axis: joint.unit_direction(),
                limit: Some(Limit {
                    lower: motion.min(0.0),
                    upper: motion.max(0.0),
                    effort: JOINT_EFFORT,
                    velocity: JOINT_VELOCITY,
                }),
                mimic: None,
            });
        }
        ArticulatedObject {
            name: self.name.clone(),
            links,
            joints,
            root: 0,
            warnings: Vec::new(),
        }
    }
}

/// World pose of each link frame of [`Twin::object`] when part k has moved by `motions[k − 1]`
/// (the fitted start → end transforms): `motion · frame(start)`. What a simulator must reproduce.
pub fn moved_link_frames(twin: &Twin, motions: &[Affine3A]) -> Vec<Affine3A> {
    std::iter::once(Affine3A::IDENTITY)
        .chain(twin.joints.iter().enumerate().map(|(i, j)| {
            motions.get(i).copied().unwrap_or(Affine3A::IDENTITY)
                * Affine3A::from_translation(j.origin)
        }))
        .collect()
}

/// A link whose frame sits at `origin` (world orientation) with `part`'s mesh as visual and
/// `pieces` (world frame) as collisions.
fn link(name: String, part: Option<&TwinPart>, origin: Vec3, pieces: &[ConvexPiece]) -> Link {
    let geometry = |file: String, m: RenderMesh| Visual {
        name: None,
        origin: Affine3A::IDENTITY,
        geometry: Geometry::Mesh {
            path: file,
            scale: Vec3::ONE,
            meshes: Arc::from(vec![m]),
        },
        material: None,
    };
    let visuals = match part.map(|p| render_mesh(p, origin)) {
        Some(m) if !m.indices.is_empty() => vec![geometry(format!("meshes/{name}.obj"), m)],
        _ => Vec::new(),
    };
    let collisions = pieces
        .iter()
        .enumerate()
        .map(|(i, piece)| {
            let part = TwinPart {
                mesh: TriMesh {
                    positions: piece.positions.clone(),
                    triangles: piece.triangles.clone(),
                },
                colors: None,
            };
            geometry(
                format!("meshes/{name}_collision_{i}.stl"),
                render_mesh(&part, origin),
            )
        })
        .collect();
    Link {
        name,
        visuals,
        collisions,
    }
}

/// `part`'s mesh in a frame at `origin`, with area-weighted normals and its colours.
fn render_mesh(part: &TwinPart, origin: Vec3) -> RenderMesh {
    let positions: Vec<Vec3> = part.mesh.positions.iter().map(|p| *p - origin).collect();
    let normals = crate::mesh::topology::vertex_normals(&part.mesh.positions, &part.mesh.triangles)
        .into_iter()
        .map(Vec3::normalize_or_zero)
        .collect();
    RenderMesh {
        positions,
        normals,
        uvs: None,
        colors: part
            .colors
            .clone()
            .filter(|c| c.len() == part.mesh.positions.len()),
        indices: part.mesh.triangles.clone(),
        material: Material {
            name: Some("fitted".into()),
            base_color: [1.0; 4],
            texture: None,
        },
    }
}

/// sRGB-encoded value → linear (the images store sRGB; glTF vertex colours are linear).
pub(crate) fn srgb_to_linear(v: f32) -> f32 {
    let v = if v.is_finite() {
        v.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// The start → end transform a joint implies: a revolute joint's rotation by its motion about its
/// axis through its origin, or a prismatic joint's shift by its motion along its axis.
pub fn joint_transform(joint: &GtJoint) -> Affine3A {
    joint.pose_at(joint.urdf_motion())
}
