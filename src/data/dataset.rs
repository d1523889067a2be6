//! The dataset: reading and validating a [`FileSet`], and writing one back in the same layout.

use std::collections::BTreeSet;

use super::error::{DataError, DatasetErrors, Errors};
use super::frame::Frame;
use super::gt::{self, GtJoint, GtMeshes, implied_num_parts, write_ground_truth};
use super::ply::TriMesh;
use super::view_set::{ReadLimits, ViewSet, ViewSetContext, read_view_set};
use super::writer::{DatasetWriter, WriteOptions};
use super::{FileSet, GT_TRANS_PATH, Split, State, transforms_file_name};

/// A whole dataset: views of both states, part count, optional ground truth.
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset {
    /// Present (state, split) combinations, in the order start/train, start/test, end/train, end/test.
    pub views: Vec<ViewSet>,
    /// Number of parts: the static base plus the movable parts. 1 + the number of joints when
    /// `gt/trans.json` exists; otherwise 1 + the largest part id seen, or 1 + the number of movable GT
    /// meshes if that is larger; at least 1.
    pub num_parts: usize,
    /// Ground-truth joints (one per movable part, in part order), from `gt/trans.json`.
    pub gt_joints: Option<Vec<GtJoint>>,
    /// Ground-truth meshes per state, indexed by [`State::index`].
    pub gt_meshes: [Option<GtMeshes>; 2],
}

impl Dataset {
    /// Reads and validates a dataset, reporting every problem found (not just the first).
    ///
    /// Checks: train transforms of both states present (test optional); JSON well-formed and typed;
    /// `frames` non-empty; every referenced image exists and decodes with the expected pixel format;
    /// matrices finite and rigid (orthonormal rotation with det +1 within 1e-3, last row 0 0 0 1);
    /// `time` finite; angles in (0, π); focal lengths positive; images of a split agree in size with each
    /// other and with `w`/`h`; depth and semantic maps match their image's size and are present for all
    /// frames of a split or none; part ids are -1..num_parts-1; GT meshes cover every movable part.
    pub fn from_files(files: &FileSet) -> Result<Dataset, DatasetErrors> {
        Self::from_files_within(files, &ReadLimits::default())
    }

    /// [`Dataset::from_files`] within `limits`: a dataset whose images would decode to more than
    /// the budget is refused before any is decoded, with the sizes and how to raise it.
    pub fn from_files_within(
        files: &FileSet,
        limits: &ReadLimits,
    ) -> Result<Dataset, DatasetErrors> {
        let mut errs = Errors::default();
        let gt_joints = files
            .get(GT_TRANS_PATH)
            .and_then(|b| gt::parse_trans(b, &mut errs));
        let mut context = ViewSetContext {
            part_limit: gt_joints.as_ref().map(|j| j.len() + 1),
            max_decoded_bytes: limits.max_decoded_bytes,
            decoded_bytes: 0,
        };

        let mut views = Vec::new();
        for state in State::ALL {
            for split in Split::ALL {
                let file = transforms_file_name(split, state);
                match files.get(&file) {
                    Some(bytes) => {
                        if let Some(v) = read_view_set(files, &file, bytes, state, split, &mut context, &mut errs) {
                            views.push(v);
                        }
                    }
                    None if split == Split::Train => errs.push(DataError::file(
                        file,
                        format!("missing: the train views of both states are required (found no {} state)", state.name()),
                    )),
                    None => {} // Test views are optional.
                }
            }
        }

        let meshes = State::ALL.map(|s| read_gt_meshes(files, s, &mut errs));
        let max_id = views
            .iter()
            .flat_map(|v| &v.frames)
            .filter_map(|f| f.parts.as_ref()?.max_id())
            .max();
        let num_parts = implied_num_parts(gt_joints.as_deref(), max_id, &meshes);
        check_mesh_counts(&meshes, num_parts, gt_joints.is_some(), &mut errs);
        errs.finish(Dataset {
            views,
            num_parts,
            gt_joints,
            gt_meshes: meshes,
        })
    }

    /// Writes the dataset in the layout it is read from (PNG semantic maps).
    pub fn to_files(&self) -> Result<FileSet, DataError> {
        self.to_files_with(&WriteOptions::default())
    }

    /// Writes the dataset with the given options. Fails on data the reader would reject or that cannot be
    /// encoded (empty view sets, mismatched sizes, duplicate frame names, inconsistent part count).
    pub fn to_files_with(&self, options: &WriteOptions) -> Result<FileSet, DataError> {
        let mut writer = DatasetWriter::new(*options);
        let mut out = FileSet::new();
        let mut seen = BTreeSet::new();
        for view in &self.views {
            let file = transforms_file_name(view.split, view.state);
            if !seen.insert((view.state, view.split)) {
                return Err(DataError::file(
                    file,
                    "cannot write: two view sets for the same state and split",
                ));
            }
            if view.frames.is_empty() {
                return Err(DataError::field(
                    &file,
                    "frames",
                    "cannot write an empty view set: expected at least one frame",
                ));
            }
            for frame in &view.frames {
                out.extend(writer.add_frame(view.state, view.split, frame)?);
            }
        }
        out.extend(writer.finish(self.num_parts, self.gt_joints.as_deref(), &self.gt_meshes)?);
        Ok(out)
    }

    /// The views of one state and split, if the dataset has them.
    pub fn views(&self, state: State, split: Split) -> Option<&ViewSet> {
        self.views
            .iter()
            .find(|v| v.state == state && v.split == split)
    }

    /// Ground-truth meshes of one state, if present.
    pub fn gt_meshes_for(&self, state: State) -> Option<&GtMeshes> {
        self.gt_meshes[state.index()].as_ref()
    }

    /// Number of movable parts (`num_parts - 1`).
    pub fn num_movable(&self) -> usize {
        self.num_parts.saturating_sub(1)
    }

    /// All frames of all view sets.
    pub fn frames(&self) -> impl Iterator<Item = &Frame> {
        self.views.iter().flat_map(|v| &v.frames)
    }
}

/// Joints and part meshes alone, in the layout of a dataset's `gt/` folder: the ground truth of a
/// dataset, or a prediction written the same way. `artmesh eval` reads both sides with it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GroundTruth {
    /// Joints from `gt/trans.json`, one per movable part.
    pub joints: Option<Vec<GtJoint>>,
    /// Part meshes per state, indexed by [`State::index`].
    pub meshes: [Option<GtMeshes>; 2],
}

impl GroundTruth {
    /// Reads `gt/trans.json` and the `gt/{state}/` meshes, ignoring every other file. With joints
    /// present, each state's meshes must cover exactly the movable parts they describe.
    pub fn from_files(files: &FileSet) -> Result<GroundTruth, DatasetErrors> {
        let mut errs = Errors::default();
        let joints = files
            .get(GT_TRANS_PATH)
            .and_then(|b| gt::parse_trans(b, &mut errs));
        let meshes = State::ALL.map(|s| read_gt_meshes(files, s, &mut errs));
        if let Some(joints) = &joints {
            check_mesh_counts(&meshes, joints.len() + 1, true, &mut errs);
        }
        if joints.is_none() && meshes.iter().all(Option::is_none) {
            errs.push(DataError::file(
                GT_TRANS_PATH,
                "missing: found neither joints nor part meshes (gt/trans.json, gt/{start,end}/*.ply)",
            ));
        }
        errs.finish(GroundTruth { joints, meshes })
    }

    /// Writes `gt/trans.json` and the meshes (binary PLY) in the layout [`GroundTruth::from_files`] reads.
    /// Refuses (naming the file) a joint or vertex that is not a finite number.
    pub fn to_files(&self) -> Result<FileSet, DataError> {
        let mut out = FileSet::new();
        write_ground_truth(self.joints.as_deref(), &self.meshes, &mut out)?;
        Ok(out)
    }
}

/// Reads `gt/{state}/...ply`; `None` when the state has no GT mesh files.
fn read_gt_meshes(files: &FileSet, state: State, errs: &mut Errors) -> Option<GtMeshes> {
    let prefix = format!("gt/{0}/{0}_dynamic_", state.name());
    let mut indexed: BTreeSet<usize> = BTreeSet::new();
    for key in files
        .range(prefix.clone()..)
        .map(|(k, _)| k)
        .take_while(|k| k.starts_with(&prefix))
    {
        if let Some(i) = key
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix("_rotate.ply"))
            .and_then(|n| n.parse().ok())
        {
            indexed.insert(i);
        }
    }
    let single = gt::single_movable_mesh_path(state);
    let static_path = gt::static_mesh_path(state);
    let mut movable_paths: Vec<String> = match indexed.last() {
        Some(&last) => (0..=last)
            .map(|i| gt::movable_mesh_path(state, i))
            .collect(),
        None if files.contains_key(&single) => vec![single],
        None => Vec::new(),
    };
    if movable_paths.is_empty() && !files.contains_key(&static_path) {
        return None;
    }
    let before = errs.len();
    let read = |path: &str, errs: &mut Errors| match files.get(path) {
        Some(b) => errs.keep(TriMesh::from_ply(path, b)),
        None => {
            errs.push(DataError::file(
                path,
                "missing: other ground-truth meshes of this state exist",
            ));
            None
        }
    };
    let static_part = read(&static_path, errs);
    let movable: Vec<TriMesh> = movable_paths
        .drain(..)
        .filter_map(|p| read(&p, errs))
        .collect();
    (errs.len() == before).then(|| GtMeshes {
        static_part: static_part.unwrap_or_default(),
        movable,
    })
}

/// A state's GT meshes must cover every movable part, and no more.
/// Each state's GT meshes must cover exactly the `num_parts - 1` movable parts.
fn check_mesh_counts(
    meshes: &[Option<GtMeshes>; 2],
    num_parts: usize,
    from_joints: bool,
    errs: &mut Errors,
) {
    for (state, m) in State::ALL.into_iter().zip(meshes) {
        if let Some(m) = m {
            check_mesh_count(state, m.movable.len(), num_parts, from_joints, errs);
        }
    }
}

fn check_mesh_count(
    state: State,
    count: usize,
    num_parts: usize,
    from_joints: bool,
    errs: &mut Errors,
) {
    let expected = num_parts.saturating_sub(1);
    let why = if from_joints {
        format!("{GT_TRANS_PATH} has {expected} joints")
    } else {
        format!("the part ids show {num_parts} parts")
    };
    for i in count..expected {
        errs.push(DataError::file(
            gt::movable_mesh_path(state, i),
            format!("missing: {why}, so every movable part needs a mesh"),
        ));
    }
    for i in expected..count {
        errs.push(DataError::file(
            gt::movable_mesh_path(state, i),
            format!("unexpected: {why}, so there is no movable part {i}"),
        ));
    }
}
