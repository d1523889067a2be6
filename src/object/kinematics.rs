//! Forward kinematics: link world transforms from joint values, following URDF's
//! `child = parent * origin * motion(axis, q)`; and the name of the joint that moves a part.

use glam::{Affine3A, Quat, Vec3};

use super::{ArticulatedObject, JointKind};

/// Name of the joint that moves movable part `k` (1 ..= K): what the exported URDF and GLB call
/// it and what `joints.json` lists it as.
pub fn part_joint(k: usize) -> String {
    format!("joint_{k}")
}

/// Motion of a joint's child frame relative to the joint frame at value `q`.
pub(super) fn joint_motion(kind: JointKind, axis: Vec3, q: f32) -> Affine3A {
    // Non-finite values would poison every transform below; treat them as the rest value.
    let q = if q.is_finite() { q } else { 0.0 };
    let axis = axis.normalize_or_zero();
    match kind {
        JointKind::Fixed => Affine3A::IDENTITY,
        JointKind::Revolute | JointKind::Continuous => {
            if axis == Vec3::ZERO {
                Affine3A::IDENTITY
            } else {
                Affine3A::from_quat(Quat::from_axis_angle(axis, q))
            }
        }
        JointKind::Prismatic => Affine3A::from_translation(axis * q),
    }
}

/// Joint indices in an order where each joint's parent link is placed before it (breadth-first from the root),
/// and the per-link flag of being reached. Joints whose parent is never reached are left out.
pub(super) fn joint_order(object: &ArticulatedObject) -> (Vec<usize>, Vec<bool>) {
    let n_links = object.links.len();
    let mut reached = vec![false; n_links];
    let mut order = Vec::with_capacity(object.joints.len());
    let mut queue = std::collections::VecDeque::new();
    if object.root < n_links {
        reached[object.root] = true;
        queue.push_back(object.root);
    }
    while let Some(link) = queue.pop_front() {
        for (j, joint) in object.joints.iter().enumerate() {
            if joint.parent != link {
                continue;
            }
            // A second path to a link (not possible after import) is ignored rather than looping.
            match reached.get_mut(joint.child) {
                Some(seen) if !*seen => {
                    *seen = true;
                    order.push(j);
                    queue.push_back(joint.child);
                }
                _ => {}
            }
        }
    }
    (order, reached)
}

pub(super) fn forward_kinematics(object: &ArticulatedObject, q: &[f32]) -> Vec<Affine3A> {
    let mut world = vec![Affine3A::IDENTITY; object.links.len()];
    let (order, _) = joint_order(object);
    for j in order {
        let Some(joint) = object.joints.get(j) else {
            continue;
        };
        let value = q.get(j).copied().unwrap_or(0.0);
        let parent = world
            .get(joint.parent)
            .copied()
            .unwrap_or(Affine3A::IDENTITY);
        if let Some(child) = world.get_mut(joint.child) {
            *child = parent * joint.origin * joint.motion(value);
        }
    }
    world
}

pub(super) fn apply_mimic(object: &ArticulatedObject, q: &[f32]) -> Vec<f32> {
    let mut out: Vec<f32> = (0..object.joints.len())
        .map(|j| q.get(j).copied().unwrap_or(0.0))
        .collect();
    // Chains of mimics settle after at most one pass per joint; cycles (rejected on import) just stop.
    for _ in 0..object.joints.len() {
        let mut changed = false;
        for (j, joint) in object.joints.iter().enumerate() {
            let Some(m) = joint.mimic else { continue };
            let Some(&leader) = out.get(m.joint) else {
                continue;
            };
            let value = m.multiplier * leader + m.offset;
            if let Some(slot) = out.get_mut(j)
                && *slot != value
            {
                *slot = value;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    out
}
