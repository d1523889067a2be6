//! Joints: `<joint>` type, parent/child links, origin, axis and limits; `<mimic>` links between joints; and
//! the check that links and joints form one tree.

use std::collections::HashMap;

use glam::Vec3;
use roxmltree::Node;

use crate::data::DataError;
use crate::object::{Joint, JointKind, Limit, Link, Mimic};

use super::reader::{Reader, child};

impl Reader<'_, '_> {
    /// One `<joint>` element; its `mimic` is filled in later by `resolve_mimics`.
    pub(super) fn joint(
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

    /// Sets each joint's `<mimic>` leader, once every joint name is known.
    pub(super) fn resolve_mimics(
        &self,
        joints: &mut [Joint],
        nodes: &[Node],
    ) -> Result<(), DataError> {
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
        // A chain of leaders must end at a joint that moves on its own.
        for (j, node) in nodes.iter().enumerate() {
            let mut chain = vec![j];
            let mut at = j;
            while let Some(next) = joints.get(at).and_then(|x| x.mimic).map(|m| m.joint) {
                if next == j {
                    let names: Vec<&str> = chain
                        .iter()
                        .chain([&j])
                        .filter_map(|&i| joints.get(i).map(|x| x.name.as_str()))
                        .collect();
                    let name = names.first().copied().unwrap_or_default();
                    return Err(self.err(
                        child(*node, "mimic").unwrap_or(*node),
                        &format!("robot/joint[name={name}]/mimic"),
                        Some("joint"),
                        format!(
                            "the mimic joints {} follow each other in a cycle: one of them must move on its own",
                            names.join(" → ")
                        ),
                    ));
                }
                if chain.len() > joints.len() {
                    break; // a cycle further up the chain, reported from its own joint
                }
                chain.push(next);
                at = next;
            }
        }
        Ok(())
    }

    /// Checks the links form one tree (each link the child of at most one joint, one root, no cycles) and
    /// returns the root.
    pub(super) fn check_tree(
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
