//! The GLB's `extras`: each joint's record on its child node, and each link's collision pieces on
//! its own node, so a glTF consumer gets what the URDF says (`super::glb` writes them).

use glam::EulerRot;

use crate::object::{ArticulatedObject, JointKind, RenderMesh};

/// Most collision vertices of one link written into its node's `extras` (an imported object's
/// collision meshes can be any size; a twin's convex pieces are a few thousand).
const MAX_COLLISION_EXTRAS_VERTICES: usize = 20_000;

/// `extras` (the joint's, if any) plus `extras.collision`: the link's mesh collision elements in
/// the link frame, one `{positions, indices}` per element (flat arrays, metres), as the URDF's
/// collision STLs hold them, so a GLB consumer gets the same convex pieces.
pub(crate) fn with_collision(
    extras: Option<serde_json::Value>,
    obj: &ArticulatedObject,
    link: usize,
) -> Option<serde_json::Value> {
    let elements: Vec<Vec<RenderMesh>> = obj.links[link]
        .collisions
        .iter()
        .filter(|c| matches!(c.geometry, crate::object::Geometry::Mesh { .. }))
        .map(|c| c.link_frame_meshes())
        .collect();
    let vertices: usize = elements.iter().flatten().map(|m| m.positions.len()).sum();
    if elements.is_empty() || vertices > MAX_COLLISION_EXTRAS_VERTICES {
        return extras;
    }
    let pieces: Vec<serde_json::Value> = elements
        .iter()
        .map(|meshes| {
            let (positions, indices) = super::urdf::merged(meshes);
            serde_json::json!({
                "positions": positions.iter().flat_map(|p| p.to_array()).collect::<Vec<f32>>(),
                "indices": indices.iter().flatten().copied().collect::<Vec<u32>>(),
            })
        })
        .collect();
    let mut extras = extras.unwrap_or_else(|| serde_json::json!({}));
    extras["collision"] = serde_json::Value::Array(pieces);
    Some(extras)
}

/// `extras.joint` of a child node.
pub(crate) fn joint(obj: &ArticulatedObject, j: usize, start: f32, end: f32) -> serde_json::Value {
    let joint = &obj.joints[j];
    let (_, rotation, xyz) = joint.origin.to_scale_rotation_translation();
    let (yaw, pitch, roll) = rotation.to_euler(EulerRot::ZYX);
    let rpy = [roll, pitch, yaw].map(|a| a + 0.0); // -0 → 0
    let kind = match joint.kind {
        JointKind::Fixed => "fixed",
        JointKind::Revolute => "revolute",
        JointKind::Continuous => "continuous",
        JointKind::Prismatic => "prismatic",
    };
    let name = |l: usize| obj.links.get(l).map(|l| l.name.clone());
    serde_json::json!({
        "joint": {
            "name": joint.name,
            "type": kind,
            "parent": name(joint.parent),
            "child": name(joint.child),
            "axis": joint.axis.to_array(),
            "origin": { "xyz": xyz.to_array(), "rpy": rpy },
            "limit": joint.limit.map(|l| serde_json::json!({
                "lower": l.lower, "upper": l.upper, "effort": l.effort, "velocity": l.velocity,
            })),
            "start": start,
            "end": end,
            "units": if joint.kind == JointKind::Prismatic { "m" } else { "rad" },
        }
    })
}
