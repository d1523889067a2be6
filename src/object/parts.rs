//! Part view: rigid parts = groups of links connected by fixed joints, each movable joint starting a part.
//!
//! ArtMesh reconstructs a static base plus K parts, each moving rigidly on one revolute or prismatic joint.
//! URDFs sometimes chain joints: IsaacGym's Sektion cabinet (in versions of the file where the chain is not
//! commented out) hangs each door hinge behind a prismatic "shift" joint that slides 1.5 cm as the door opens
//! (a `<mimic>` of the hinge). A part-level model cannot represent two motions per part, so we **merge** such a
//! joint: a movable, non-continuous joint whose motion span is tiny (prismatic: `upper − lower <`
//! [`MERGE_PRISMATIC_SPAN`]; revolute: `<` [`MERGE_REVOLUTE_SPAN`]) and whose child's rigid group is the parent
//! of another movable joint is treated as fixed at its rest value (0 clamped into its limits). Its child links
//! join the parent's part and the following joint — the dominant one — starts the part. A tiny joint with no
//! movable joint after it (a push button) still starts its own part: it is the only motion there is.
//! Merging costs at most the tiny span in accuracy (1.5 cm of door travel for Sektion), well inside what the
//! reconstruction resolves.

use super::{ArticulatedObject, JointKind, kinematics};

/// Prismatic joints spanning less than this (metres) are merged when another movable joint follows them.
pub const MERGE_PRISMATIC_SPAN: f32 = 0.02;

/// Revolute joints spanning less than this (radians, 2°) are merged when another movable joint follows them.
pub const MERGE_REVOLUTE_SPAN: f32 = 2.0 * std::f32::consts::PI / 180.0;

/// One rigid part.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Part {
    /// Links of the part, in breadth-first order from the root.
    pub links: Vec<usize>,
    /// The movable joint whose child starts this part; `None` for part 0 (the static base).
    pub joint: Option<usize>,
}

/// The object's parts. Part 0 holds the root link; the others follow the file order of the joints that start
/// them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Parts {
    /// The parts; `parts[0]` is the static base.
    pub parts: Vec<Part>,
    /// Part index of every link (links not reachable from the root, impossible after import, are in part 0).
    pub link_part: Vec<usize>,
    /// Movable joints merged into their parent's part (treated as fixed at [`super::Joint::rest_value`]).
    pub merged_joints: Vec<usize>,
}

impl Parts {
    /// Number of movable parts (all parts but the base).
    pub fn movable_count(&self) -> usize {
        self.parts.len().saturating_sub(1)
    }

    /// Joint values for a part-level state: `part_values[k]` drives the joint of part `k` (the entry for
    /// part 0 is ignored; missing entries mean the joint's rest value); every other joint, merged ones
    /// included, sits at its rest value. The result has one value per joint of `object`.
    pub fn configuration(&self, object: &ArticulatedObject, part_values: &[f32]) -> Vec<f32> {
        let mut q = object.rest_configuration();
        for (k, part) in self.parts.iter().enumerate().skip(1) {
            if let (Some(j), Some(&v)) = (part.joint, part_values.get(k))
                && let Some(slot) = q.get_mut(j)
            {
                *slot = v;
            }
        }
        q
    }
}

/// True if joint `j` is a short joint in a chain that the part view merges (see the module docs).
pub fn is_merged_chain_joint(object: &ArticulatedObject, j: usize) -> bool {
    let Some(joint) = object.joints.get(j) else {
        return false;
    };
    let Some((lower, upper)) = joint.range() else {
        return false;
    };
    let span = upper - lower;
    let tiny = match joint.kind {
        JointKind::Prismatic => span < MERGE_PRISMATIC_SPAN,
        JointKind::Revolute => span < MERGE_REVOLUTE_SPAN,
        JointKind::Fixed | JointKind::Continuous => false,
    };
    if !tiny {
        return false;
    }
    // Walk the child's rigid group (fixed joints only) looking for a movable joint leaving it.
    let mut stack = vec![joint.child];
    let mut seen = vec![false; object.links.len()];
    while let Some(link) = stack.pop() {
        match seen.get_mut(link) {
            Some(s) if !*s => *s = true,
            _ => continue,
        }
        for (k, next) in object.joints.iter().enumerate() {
            if k == j || next.parent != link {
                continue;
            }
            if next.kind.is_movable() {
                return true;
            }
            stack.push(next.child);
        }
    }
    false
}

pub(super) fn parts(object: &ArticulatedObject) -> Parts {
    let (order, _) = kinematics::joint_order(object);
    // Part numbers follow the file order of the joints that start them, whatever their depth in the tree.
    let mut part_of_joint = vec![None; object.joints.len()];
    let mut parts = vec![Part {
        links: Vec::new(),
        joint: None,
    }];
    let mut merged_joints = Vec::new();
    for (j, joint) in object.joints.iter().enumerate() {
        if !joint.kind.is_movable() {
            continue;
        }
        if is_merged_chain_joint(object, j) {
            merged_joints.push(j);
        } else {
            part_of_joint[j] = Some(parts.len());
            parts.push(Part {
                links: Vec::new(),
                joint: Some(j),
            });
        }
    }
    let mut link_part = vec![0usize; object.links.len()];
    if object.root < object.links.len() {
        parts[0].links.push(object.root);
    }
    for j in order {
        let Some(joint) = object.joints.get(j) else {
            continue;
        };
        let part = part_of_joint
            .get(j)
            .copied()
            .flatten()
            .unwrap_or_else(|| link_part.get(joint.parent).copied().unwrap_or(0));
        if let Some(slot) = link_part.get_mut(joint.child) {
            *slot = part;
        }
        if let Some(p) = parts.get_mut(part) {
            p.links.push(joint.child);
        }
    }
    Parts {
        parts,
        link_part,
        merged_joints,
    }
}
