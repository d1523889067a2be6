//! The dataset: reading and validating a [`FileSet`], and writing one back in the same layout.

use std::collections::BTreeSet;

use super::camera::Camera;
use super::error::{DataError, DatasetErrors, Errors};
use super::frame::{Frame, size_error};
use super::gt::{self, GtJoint, GtMeshes, implied_num_parts, write_ground_truth};
use super::image_io::{self, DepthMap, PartMap, RgbaImage};
use super::npy;
use super::parallel;
use super::paths;
use super::ply::TriMesh;
use super::transforms::{self, FrameSpec};
use super::writer::{DatasetWriter, WriteOptions};
use super::{FileSet, GT_TRANS_PATH, Split, State, transforms_file_name};

/// The frames of one state and split.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewSet {
    /// Articulation state.
    pub state: State,
    /// Train or test.
    pub split: Split,
    /// Frames in file order (never empty in a dataset read from files).
    pub frames: Vec<Frame>,
}

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

/// Frames of one split seen so far, for checks across frames.
#[derive(Default)]
struct SplitChecks {
    /// Size of the first readable image and its path.
    reference: Option<(u32, u32, String)>,
    /// Per kind (depth, semantic): paths found, and expected paths that were missing.
    present: [Vec<String>; 2],
    missing: [Vec<String>; 2],
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

/// How much memory a dataset's decoded images may take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadLimits {
    /// Bytes of all decoded colour, depth and semantic images together (RGBA is 4 bytes a pixel,
    /// depth and part ids 2).
    pub max_decoded_bytes: u64,
}

impl Default for ReadLimits {
    /// 8 GiB natively (the paper's 800² × 240 frames take 1.2 GB); 1.5 GiB in the browser, whose
    /// wasm memory also holds the files themselves and the fit.
    fn default() -> Self {
        let gib = if cfg!(target_arch = "wasm32") {
            1.5
        } else {
            8.0
        };
        ReadLimits {
            max_decoded_bytes: (gib * (1u64 << 30) as f64) as u64,
        }
    }
}

/// What the view sets of one dataset share while they are read.
struct ViewSetContext {
    /// Part ids must stay below this (from `gt/trans.json`), if given.
    part_limit: Option<usize>,
    max_decoded_bytes: u64,
    /// Decoded bytes of the view sets read so far.
    decoded_bytes: u64,
}

/// Bytes a frame's images decode to, from their headers (0 for an image whose header does not
/// read: its decoder names the problem).
fn decoded_size(files: &FileSet, fs: &FrameSpec) -> u64 {
    let png_pixels = |bytes: &[u8]| -> u64 {
        match bytes.get(12..24) {
            Some(h) if &h[..4] == b"IHDR" => {
                let be = |b: &[u8]| u64::from(u32::from_be_bytes([b[0], b[1], b[2], b[3]]));
                be(&h[4..8]) * be(&h[8..12])
            }
            _ => 0,
        }
    };
    let Some((rgba_path, bytes)) = paths::image_candidates(&fs.file_path)
        .into_iter()
        .find_map(|p| files.get(&p).map(|b| (p, b)))
    else {
        return 0;
    };
    let mut total = 4 * png_pixels(bytes);
    for (kind, exts) in [
        ("depth", &[".png"][..]),
        ("semantic", &[".png", ".npy"][..]),
    ] {
        if let Ok((path, b)) = find_sibling(files, &rgba_path, kind, exts) {
            // An .npy holds its values uncompressed: it decodes to about its own size.
            total += if path.ends_with(".npy") {
                b.len() as u64
            } else {
                2 * png_pixels(b)
            };
        }
    }
    total
}

/// Reads one transforms file and the images it refers to.
fn read_view_set(
    files: &FileSet,
    file: &str,
    bytes: &[u8],
    state: State,
    split: Split,
    context: &mut ViewSetContext,
    errs: &mut Errors,
) -> Option<ViewSet> {
    let spec = transforms::parse(file, bytes, errs)?;
    // Refused before decoding: a few kilobytes of PNG can claim gigapixels, and one small image
    // named by thousands of frames decodes once per frame.
    let size: u64 = spec.frames.iter().map(|fs| decoded_size(files, fs)).sum();
    context.decoded_bytes = context.decoded_bytes.saturating_add(size);
    if context.decoded_bytes > context.max_decoded_bytes {
        let mb = |b: u64| b as f64 / 1e6;
        errs.push(DataError::file(
            file,
            format!(
                "its {} frames' images decode to {:.0} MB, bringing the dataset to {:.0} MB, over the budget of {:.0} MB for a whole dataset's decoded images (--max-decoded-mb raises it)",
                spec.frames.len(),
                mb(size),
                mb(context.decoded_bytes),
                mb(context.max_decoded_bytes)
            ),
        ));
        return None;
    }
    let part_limit = context.part_limit;
    let mut checks = SplitChecks::default();
    let mut frames = Vec::with_capacity(spec.frames.len());
    // Decoding is most of a large dataset's reading: all frames at once, then checked in order.
    let decoded = parallel::map(&spec.frames, |fs| decode_frame(files, fs));
    for (fs, decoded) in spec.frames.iter().zip(decoded) {
        if let Some(frame) = read_frame(file, fs, decoded, state, part_limit, &mut checks, errs) {
            frames.push(frame);
        }
    }
    // Depth and semantic maps are optional per dataset, but all-or-nothing within a split.
    for (k, kind) in ["depth maps", "semantic maps"].iter().enumerate() {
        if let Some(example) = checks.present[k].first() {
            for missing in &checks.missing[k] {
                errs.push(DataError::file(
                    missing.clone(),
                    format!(
                        "missing: other frames of {}/{} have {kind} (e.g. {example}), so every frame needs one",
                        state.name(),
                        split.name()
                    ),
                ));
            }
        }
    }
    (!frames.is_empty()).then_some(ViewSet {
        state,
        split,
        frames,
    })
}

/// Every path the transforms files in `files` refer to, with each image's depth and semantic
/// siblings under every name the reader tries: what a reader of a folder needs to read besides
/// the transforms files and `gt/`. Malformed transforms files contribute what they can; their
/// errors are the reader's to report.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn referenced_paths(files: &FileSet) -> BTreeSet<String> {
    let mut wanted = BTreeSet::new();
    for state in State::ALL {
        for split in Split::ALL {
            let file = transforms_file_name(split, state);
            let Some(bytes) = files.get(&file) else {
                continue;
            };
            let Some(spec) = transforms::parse(&file, bytes, &mut Errors::default()) else {
                continue;
            };
            for fs in &spec.frames {
                for image in paths::image_candidates(&fs.file_path) {
                    for (kind, ext) in [
                        ("depth", ".png"),
                        ("semantic", ".png"),
                        ("semantic", ".npy"),
                    ] {
                        wanted.extend(paths::sibling(&image, kind, ext));
                    }
                    wanted.insert(image);
                }
            }
        }
    }
    wanted
}

/// A found-and-decoded optional file of a frame (its path and decoding, each `Err` naming the
/// file), or the path it was expected at.
type Found<T> = Result<(String, Result<T, DataError>), String>;

/// A frame's files found and decoded, before any check.
struct DecodedFrame {
    /// The colour image's path and decoding, or every path it was looked for under.
    rgba: Result<(String, Result<RgbaImage, DataError>), Vec<String>>,
    /// Depth and semantic map; none when the colour image itself is missing.
    depth: Option<Found<DepthMap>>,
    parts: Option<Found<PartMap>>,
}

/// Finds and decodes a frame's colour image and its optional depth and semantic maps.
fn decode_frame(files: &FileSet, fs: &FrameSpec) -> DecodedFrame {
    let candidates = paths::image_candidates(&fs.file_path);
    let Some((rgba_path, bytes)) = candidates
        .iter()
        .find_map(|p| files.get(p).map(|b| (p.clone(), b)))
    else {
        return DecodedFrame {
            rgba: Err(candidates),
            depth: None,
            parts: None,
        };
    };
    let depth = find_sibling(files, &rgba_path, "depth", &[".png"])
        .map(|(path, b)| (path.clone(), image_io::decode_depth(&path, b)));
    let parts = find_sibling(files, &rgba_path, "semantic", &[".png", ".npy"]).map(|(path, b)| {
        let map = if path.ends_with(".npy") {
            npy::decode_parts_npy(&path, b)
        } else {
            image_io::decode_parts_png(&path, b)
        };
        (path, map)
    });
    DecodedFrame {
        rgba: Ok((rgba_path.clone(), image_io::decode_rgba(&rgba_path, bytes))),
        depth: Some(depth),
        parts: Some(parts),
    }
}

/// The optional `kind` file of a frame (`depth`, `semantic`) under the first of `exts` present,
/// or the path it was expected at.
fn find_sibling<'a>(
    files: &'a FileSet,
    rgba_path: &str,
    kind: &str,
    exts: &[&str],
) -> Result<(String, &'a [u8]), String> {
    let candidates: Vec<String> = exts
        .iter()
        .filter_map(|e| paths::sibling(rgba_path, kind, e))
        .collect();
    candidates
        .iter()
        .find_map(|p| files.get(p).map(|b| (p.clone(), b.as_slice())))
        .ok_or_else(|| {
            candidates
                .into_iter()
                .next()
                .unwrap_or_else(|| rgba_path.to_string())
        })
}

/// Records in `checks` whether a frame has its optional map `k` (0 depth, 1 semantic); returns it.
fn note_sibling<T>(
    found: Option<Found<T>>,
    k: usize,
    checks: &mut SplitChecks,
) -> Option<(String, Result<T, DataError>)> {
    match found? {
        Ok((path, map)) => {
            checks.present[k].push(path.clone());
            Some((path, map))
        }
        Err(expected) => {
            checks.missing[k].push(expected);
            None
        }
    }
}

/// Checks a decoded frame against its transforms entry and its split, and assembles it.
fn read_frame(
    file: &str,
    fs: &FrameSpec,
    decoded: DecodedFrame,
    state: State,
    part_limit: Option<usize>,
    checks: &mut SplitChecks,
    errs: &mut Errors,
) -> Option<Frame> {
    let (rgba_path, rgba) = match decoded.rgba {
        Ok(found) => found,
        Err(candidates) => {
            errs.push(DataError::field(
                file,
                format!("{}.file_path", fs.field),
                format!(
                    "refers to {}, which is not in the dataset",
                    candidates.join(" or ")
                ),
            ));
            return None;
        }
    };
    let rgba = errs.keep(rgba);

    // Size agreement: with w/h from the transforms file when given, else with the first image of the split.
    if let Some(img) = &rgba {
        let reference = checks
            .reference
            .get_or_insert_with(|| (img.width, img.height, rgba_path.clone()));
        let (w, h) = (
            fs.intrinsics.w.unwrap_or(reference.0),
            fs.intrinsics.h.unwrap_or(reference.1),
        );
        if (img.width, img.height) != (w, h) {
            let what = if fs.intrinsics.w.is_some() || fs.intrinsics.h.is_some() {
                format!("w/h in {file}")
            } else {
                format!("the size of {}, the first image of this split", reference.2)
            };
            errs.push(size_error(&rgba_path, &what, w, h, img.width, img.height));
        }
    }

    let depth = note_sibling(decoded.depth, 0, checks).and_then(|(path, d)| {
        let d = errs.keep(d)?;
        if let Some(img) = &rgba
            && (d.width, d.height) != (img.width, img.height)
        {
            errs.push(size_error(
                &path,
                &format!("the size of {rgba_path}"),
                img.width,
                img.height,
                d.width,
                d.height,
            ));
        }
        Some(d)
    });

    let parts = note_sibling(decoded.parts, 1, checks).and_then(|(path, m)| {
        let m = errs.keep(m)?;
        if let Some(img) = &rgba
            && (m.width, m.height) != (img.width, img.height)
        {
            errs.push(size_error(&path, &format!("the size of {rgba_path}"), img.width, img.height, m.width, m.height));
        }
        if let Some(limit) = part_limit
            && let Some(i) = m.ids.iter().position(|&id| usize::try_from(id).is_ok_and(|id| id >= limit))
        {
            let w = m.width.max(1) as usize;
            errs.push(DataError::field(
                &path,
                "part id",
                format!(
                    "part id {} at pixel ({}, {}) is out of range: expected -1 (background) to {} ({GT_TRANS_PATH} has {} joints, so {limit} parts)",
                    m.ids[i],
                    i % w,
                    i / w,
                    limit - 1,
                    limit - 1
                ),
            ));
        }
        Some(m)
    });

    let rgba = rgba?;
    let camera_to_world = fs.camera_to_world?;
    let intrinsics = fs.intrinsics.resolve(rgba.width, rgba.height)?;
    Some(Frame {
        name: paths::frame_name(&rgba_path).to_string(),
        camera: Camera {
            camera_to_world,
            intrinsics,
        },
        time: fs.time.unwrap_or(state.default_time()),
        rgba,
        depth,
        parts,
    })
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
    pub fn to_files(&self) -> FileSet {
        let mut out = FileSet::new();
        write_ground_truth(self.joints.as_deref(), &self.meshes, &mut out);
        out
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
