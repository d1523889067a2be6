//! A short description of a dataset for the CLI, the web page and logs.

use std::fmt;

use super::dataset::Dataset;
use super::gt::JointKind;
use super::{Split, State};

/// What one view set holds.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ViewSummary {
    /// Articulation state.
    pub state: State,
    /// Train or test.
    pub split: Split,
    /// Number of frames.
    pub frames: usize,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Whether the frames have depth maps.
    pub depth: bool,
    /// Whether the frames have semantic maps.
    pub semantic: bool,
}

/// What a dataset holds: views per state and split, resolution, parts, depth range, ground truth.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Summary {
    /// One entry per present view set, in dataset order.
    pub views: Vec<ViewSummary>,
    /// Static base + movable parts.
    pub num_parts: usize,
    /// Smallest and largest valid depth over all frames, in metres.
    pub depth_range_m: Option<[f32; 2]>,
    /// Any depth maps present.
    pub has_depth: bool,
    /// Any semantic maps present.
    pub has_semantic: bool,
    /// `gt/trans.json` present.
    pub has_gt_joints: bool,
    /// Joint types from `gt/trans.json`, in part order (empty without it).
    pub gt_joint_kinds: Vec<JointKind>,
    /// States with ground-truth meshes.
    pub gt_mesh_states: Vec<State>,
    /// Any ground-truth meshes present.
    pub has_gt_meshes: bool,
}

impl Dataset {
    /// Summarises the dataset (cheap: one pass over the depth maps).
    pub fn summary(&self) -> Summary {
        let views: Vec<ViewSummary> = self
            .views
            .iter()
            .map(|v| {
                let first = v.frames.first();
                ViewSummary {
                    state: v.state,
                    split: v.split,
                    frames: v.frames.len(),
                    width: first.map_or(0, |f| f.rgba.width),
                    height: first.map_or(0, |f| f.rgba.height),
                    depth: !v.frames.is_empty() && v.frames.iter().all(|f| f.depth.is_some()),
                    semantic: !v.frames.is_empty() && v.frames.iter().all(|f| f.parts.is_some()),
                }
            })
            .collect();
        let depth_range_mm = self
            .frames()
            .filter_map(|f| f.depth.as_ref()?.range_mm())
            .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)));
        let gt_mesh_states: Vec<State> = State::ALL
            .into_iter()
            .filter(|s| self.gt_meshes[s.index()].is_some())
            .collect();
        Summary {
            num_parts: self.num_parts,
            depth_range_m: depth_range_mm
                .map(|(lo, hi)| [f32::from(lo) / 1000.0, f32::from(hi) / 1000.0]),
            has_depth: self.frames().any(|f| f.depth.is_some()),
            has_semantic: self.frames().any(|f| f.parts.is_some()),
            has_gt_joints: self.gt_joints.is_some(),
            gt_joint_kinds: self.gt_joints.iter().flatten().map(|j| j.kind).collect(),
            has_gt_meshes: !gt_mesh_states.is_empty(),
            gt_mesh_states,
            views,
        }
    }
}

fn yes_no(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for v in &self.views {
            let mut extras = Vec::new();
            if v.depth {
                extras.push("depth");
            }
            if v.semantic {
                extras.push("semantic");
            }
            let extras = if extras.is_empty() {
                String::new()
            } else {
                format!(", {}", extras.join(" + "))
            };
            let plural = if v.frames == 1 { "" } else { "s" };
            writeln!(
                f,
                "{}/{}: {} view{plural}, {}x{}{extras}",
                v.state, v.split, v.frames, v.width, v.height
            )?;
        }
        writeln!(
            f,
            "parts: {} (static base + {} movable)",
            self.num_parts,
            self.num_parts.saturating_sub(1)
        )?;
        match self.depth_range_m {
            Some([lo, hi]) => writeln!(f, "depth: {lo:.3} m to {hi:.3} m")?,
            None => writeln!(
                f,
                "depth: {}",
                if self.has_depth {
                    "no valid pixels"
                } else {
                    "none"
                }
            )?,
        }
        writeln!(f, "semantic maps: {}", yes_no(self.has_semantic))?;
        if self.has_gt_joints {
            let kinds: Vec<&str> = self
                .gt_joint_kinds
                .iter()
                .map(|k| match k {
                    JointKind::Revolute => "revolute",
                    JointKind::Prismatic => "prismatic",
                })
                .collect();
            writeln!(f, "GT joints: {} ({})", kinds.len(), kinds.join(", "))?;
        } else {
            writeln!(f, "GT joints: none")?;
        }
        if self.has_gt_meshes {
            let states: Vec<&str> = self.gt_mesh_states.iter().map(|s| s.name()).collect();
            write!(f, "GT meshes: {}", states.join(", "))
        } else {
            write!(f, "GT meshes: none")
        }
    }
}
