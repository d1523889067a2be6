//! Shapes and joints shared by the evaluation metric tests (`eval_metrics.rs`,
//! `eval_metrics_objects.rs`).
#![allow(dead_code)]

use artmesh::data::{GtJoint, JointKind, TriMesh};
use glam::Vec3;

/// A revolute GT joint turning from `start` to `end` (degrees).
pub fn revolute(origin: Vec3, direction: Vec3, start: f32, end: f32) -> GtJoint {
    GtJoint {
        kind: JointKind::Revolute,
        origin,
        direction,
        start,
        end,
    }
}

/// A prismatic GT joint sliding from `start` to `end` (metres).
pub fn prismatic(origin: Vec3, direction: Vec3, start: f32, end: f32) -> GtJoint {
    GtJoint {
        kind: JointKind::Prismatic,
        origin,
        direction,
        start,
        end,
    }
}

/// Axis-aligned box with 12 outward triangles.
pub fn cuboid(center: Vec3, half: Vec3) -> TriMesh {
    artmesh::data::fixture::box_mesh(center - half, center + half)
}
