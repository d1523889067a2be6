//! Refuses to export an object holding a number that is not finite, or a configuration that
//! moves a link to one: a URDF with `NaN` in it, or a GLB whose animation or joint extras hold
//! `null`, loads wrongly or not at all in simulators, so the export names the culprit instead.

use glam::{Affine3A, Mat4};

use crate::data::DataError;
use crate::data::finite::{ensure_finite, matrix_values, point_values};
use crate::object::{ArticulatedObject, Geometry, Visual};

fn affine_values(a: &Affine3A) -> [f32; 16] {
    matrix_values(&Mat4::from(*a))
}

/// `Ok` when every number of `object` (joint origins, axes, limits, mimics; link shapes, poses
/// and mesh vertices) is finite and every link lies at a finite pose in each configuration of
/// `configurations` (joint values, before mimic). Errors name `file` and the joint or link.
pub fn ensure_exportable(
    object: &ArticulatedObject,
    configurations: &[&[f32]],
    file: &str,
) -> Result<(), DataError> {
    for joint in &object.joints {
        let field = format!("joint {:?}", joint.name);
        let mut values = affine_values(&joint.origin).to_vec();
        values.extend(joint.axis.to_array());
        if let Some(l) = &joint.limit {
            values.extend([l.lower, l.upper, l.effort, l.velocity]);
        }
        if let Some(m) = &joint.mimic {
            values.extend([m.multiplier, m.offset]);
        }
        ensure_finite(file, &field, values)?;
    }
    for link in &object.links {
        for (kind, list) in [("visual", &link.visuals), ("collision", &link.collisions)] {
            for (i, visual) in list.iter().enumerate() {
                let field = format!("link {:?} {kind} {i}", link.name);
                ensure_finite(file, &field, visual_values(visual))?;
            }
        }
    }
    for q in configurations {
        if let Some((i, v)) = crate::data::finite::first_non_finite(q.iter().copied()) {
            let name = object.joints.get(i).map_or("?", |j| j.name.as_str());
            return Err(DataError::field(
                file,
                format!("joint {name:?}"),
                format!("cannot write: its value is {v}, not a finite number"),
            ));
        }
        let frames = object.forward_kinematics(&object.apply_mimic(q));
        for (link, frame) in object.links.iter().zip(&frames) {
            ensure_finite(
                file,
                &format!("link {:?} pose", link.name),
                affine_values(frame),
            )?;
        }
    }
    Ok(())
}

/// Every number of a visual: its pose, its shape's sizes, and its mesh vertices (scaled).
fn visual_values(visual: &Visual) -> Vec<f32> {
    let mut values = affine_values(&visual.origin).to_vec();
    match &visual.geometry {
        Geometry::Box { size } => values.extend(size.to_array()),
        Geometry::Cylinder { radius, length } => values.extend([*radius, *length]),
        Geometry::Sphere { radius } => values.push(*radius),
        Geometry::Mesh { scale, meshes, .. } => {
            values.extend(scale.to_array());
            for mesh in meshes.iter() {
                let scaled: Vec<_> = mesh.positions.iter().map(|p| *p * *scale).collect();
                values.extend(point_values(&scaled));
            }
        }
    }
    values
}
