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
    let positions = (0..8)
        .map(|i| {
            let s = Vec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            center + s * half
        })
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let triangles = quads
        .iter()
        .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
        .collect();
    TriMesh {
        positions,
        triangles,
    }
}
