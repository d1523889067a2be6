//! Streaming dataset writer: frames go in one at a time and come out as encoded files at once, so a dataset of
//! hundreds of 800² frames never has to sit in memory as pixels. [`Dataset::to_files_with`] writes through it
//! too, so both paths check and encode the same way.
//!
//! [`Dataset::to_files_with`]: super::Dataset::to_files_with

use std::collections::{BTreeMap, BTreeSet};

use super::error::DataError;
use super::finite::{ensure_finite, matrix_values};
use super::frame::{Frame, size_error};
use super::gt::{GtJoint, GtMeshes, implied_num_parts, write_ground_truth};
use super::image_io;
use super::npy;
use super::transforms::{self, FrameMeta};
use super::{FileSet, GT_TRANS_PATH, Split, State, transforms_file_name};

/// How [`Dataset::to_files_with`](super::Dataset::to_files_with) writes semantic maps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SemanticFormat {
    /// Our 16-bit PNG (0 = background, k+1 = part k).
    #[default]
    Png,
    /// GaussianArt-style `.npy` of `<i4` part ids (-1 = background).
    Npy,
}

/// Options of the writer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WriteOptions {
    /// Semantic map encoding.
    pub semantic: SemanticFormat,
}

/// What the writer remembers of one view set: frame metadata for its transforms file and the first frame's
/// image size and channels, which every later frame must match.
struct ViewSetLog {
    frames: Vec<FrameMeta>,
    names: BTreeSet<String>,
    size: (u32, u32),
    has_depth: bool,
    has_parts: bool,
}

/// Writes a dataset frame by frame: [`DatasetWriter::add_frame`] returns the frame's image files,
/// [`DatasetWriter::finish`] the transforms files and ground truth.
pub struct DatasetWriter {
    options: WriteOptions,
    views: BTreeMap<(State, Split), ViewSetLog>,
    max_id: Option<i16>,
}

impl DatasetWriter {
    /// A writer with nothing written yet.
    pub fn new(options: WriteOptions) -> Self {
        DatasetWriter {
            options,
            views: BTreeMap::new(),
            max_id: None,
        }
    }

    /// Checks `frame` against the frames already added to its view set (unique plain name; same image size
    /// as the first frame and as its intrinsics; depth and part maps present for all frames or none, of
    /// matching size; part ids ≥ −1) and returns its encoded images (RGBA, depth and semantic maps).
    pub(crate) fn add_frame(
        &mut self,
        state: State,
        split: Split,
        frame: &Frame,
    ) -> Result<FileSet, DataError> {
        let file = transforms_file_name(split, state);
        let size = (frame.rgba.width, frame.rgba.height);
        let log = self
            .views
            .entry((state, split))
            .or_insert_with(|| ViewSetLog {
                frames: Vec::new(),
                names: BTreeSet::new(),
                size,
                has_depth: frame.depth.is_some(),
                has_parts: frame.parts.is_some(),
            });
        let field = format!("frames[{}]", log.frames.len());
        let bad_name = frame.name.is_empty()
            || frame.name.contains(['/', '\\'])
            || frame.name == "."
            || frame.name == ".."
            || frame.name.to_ascii_lowercase().ends_with(".png");
        if bad_name || log.names.contains(&frame.name) {
            return Err(DataError::field(
                &file,
                format!("{field}.name"),
                format!(
                    "cannot write: frame name \"{}\" is empty, a duplicate, or not a plain file stem",
                    frame.name
                ),
            ));
        }
        let rgba_path = transforms::frame_path(state, split, "rgba", &frame.name, ".png");
        let k = &frame.camera.intrinsics;
        let pose = matrix_values(&frame.camera.camera_to_world);
        ensure_finite(&file, &format!("{field}.transform_matrix"), pose)?;
        ensure_finite(
            &file,
            &format!("{field} intrinsics"),
            [k.fx, k.fy, k.cx, k.cy],
        )?;
        if size != log.size || (k.width, k.height) != size {
            return Err(size_error(
                &rgba_path,
                "the first image and the intrinsics",
                log.size.0,
                log.size.1,
                size.0,
                size.1,
            ));
        }
        if frame.depth.is_some() != log.has_depth || frame.parts.is_some() != log.has_parts {
            return Err(DataError::field(
                &file,
                field,
                "cannot write: depth and semantic maps must be present for all frames of a split or for none",
            ));
        }
        let mut out = FileSet::new();
        out.insert(
            rgba_path.clone(),
            image_io::encode_png(
                &rgba_path,
                size.0,
                size.1,
                image_io::PngPixels::Rgba8(&frame.rgba.pixels),
            )?,
        );
        // Depth and part maps must match their colour frame pixel for pixel.
        let same_size = |path: &str, width: u32, height: u32| -> Result<(), DataError> {
            if (width, height) == size {
                return Ok(());
            }
            let expected = format!("the size of {rgba_path}");
            Err(size_error(path, &expected, size.0, size.1, width, height))
        };
        if let Some(d) = &frame.depth {
            let path = transforms::frame_path(state, split, "depth", &frame.name, ".png");
            same_size(&path, d.width, d.height)?;
            let png = image_io::encode_png(
                &path,
                d.width,
                d.height,
                image_io::PngPixels::Gray16(&d.millimetres),
            )?;
            out.insert(path, png);
        }
        if let Some(m) = &frame.parts {
            let ext = match self.options.semantic {
                SemanticFormat::Png => ".png",
                SemanticFormat::Npy => ".npy",
            };
            let path = transforms::frame_path(state, split, "semantic", &frame.name, ext);
            same_size(&path, m.width, m.height)?;
            let expected_len = u64::from(m.width) * u64::from(m.height);
            if m.ids.len() as u64 != expected_len || m.ids.iter().any(|&id| id < -1) {
                return Err(DataError::field(
                    &path,
                    "part id",
                    format!(
                        "cannot write: expected {expected_len} ids of at least -1, found {} ids",
                        m.ids.len()
                    ),
                ));
            }
            let bytes = match self.options.semantic {
                SemanticFormat::Png => image_io::encode_parts_png(&path, m)?,
                SemanticFormat::Npy => npy::encode_parts_npy(m),
            };
            out.insert(path, bytes);
            self.max_id = self.max_id.max(m.max_id());
        }
        log.names.insert(frame.name.clone());
        log.frames.push(FrameMeta::of(frame));
        Ok(out)
    }

    /// The transforms files of every view set and the ground truth. Fails when a state lacks train views or
    /// when `num_parts` disagrees with what the joints, part ids and GT meshes imply.
    pub fn finish(
        self,
        num_parts: usize,
        gt_joints: Option<&[GtJoint]>,
        gt_meshes: &[Option<GtMeshes>; 2],
    ) -> Result<FileSet, DataError> {
        for state in State::ALL {
            if !self.views.contains_key(&(state, Split::Train)) {
                return Err(DataError::file(
                    transforms_file_name(Split::Train, state),
                    "cannot write: the train views of both states are required",
                ));
            }
        }
        let implied = implied_num_parts(gt_joints, self.max_id, gt_meshes);
        if implied != num_parts {
            return Err(DataError::field(
                GT_TRANS_PATH,
                "num_parts",
                format!(
                    "cannot write: num_parts is {num_parts}, but the joints, part ids and GT meshes imply {implied}"
                ),
            ));
        }
        let mut out = FileSet::new();
        for ((state, split), log) in &self.views {
            out.insert(
                transforms_file_name(*split, *state),
                transforms::write(*state, *split, &log.frames),
            );
        }
        write_ground_truth(gt_joints, gt_meshes, &mut out)?;
        Ok(out)
    }
}
