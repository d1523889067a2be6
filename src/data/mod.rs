//! Dataset layer: cameras, frames and the on-disk layout shared with ArtGS / GaussianArt (MPArt-90) / PARIS.
//!
//! Everything here works on bytes ([`FileSet`]: relative path → contents), so the same reader and writer run
//! natively and in the browser. Only [`read_dir`] and [`write_dir`] touch the file system, and they are native-only.
//! Bad input never panics: readers collect every problem they find as a [`DataError`] naming the file, the field
//! and what was expected.
//!
//! Layout (paths relative to the dataset root; metres; z-up world):
//! ```text
//! transforms_{train,test}_{start,end}.json     cameras + frame list (train required for both states)
//! {start,end}/{train,test}/rgba/0000.png       8-bit RGBA, alpha = foreground mask
//! {start,end}/{train,test}/depth/0000.png      optional, 16-bit grey, millimetres, z-depth, 0 = invalid
//! {start,end}/{train,test}/semantic/0000.png   optional, 16-bit grey, 0 = background, k+1 = part k (or .npy, -1 = background)
//! gt/trans.json                                optional ground-truth joints
//! gt/{state}/{state}_static_rotate.ply, gt/{state}/{state}_dynamic_{i}_rotate.ply   optional GT part meshes
//! ```

mod archive;
mod camera;
mod dataset;
pub mod degrade;
mod error;
pub mod finite;
pub mod fixture;
mod frame;
#[cfg(not(target_arch = "wasm32"))]
mod fs;
mod gt;
mod image_io;
mod json;
#[cfg(not(target_arch = "wasm32"))]
mod lazy_folder;
mod npy;
mod object_archive;
pub(crate) mod parallel;
mod paths;
mod ply;
pub mod sensor;
mod summary;
mod transforms;
mod view_set;
mod writer;

use std::collections::BTreeMap;

pub use archive::{FileLimits, Listing, dataset_paths, read_zip, read_zip_within};
pub use camera::{Camera, Intrinsics, look_at};
pub use dataset::{Dataset, GroundTruth};
pub use error::{DataError, DatasetErrors};
pub use frame::Frame;
#[cfg(not(target_arch = "wasm32"))]
pub use fs::{ReadDatasetError, read_dataset, read_dataset_files, read_dir, write_dir};
pub use gt::{GtJoint, GtMeshes, JointKind};
pub use image_io::{DepthMap, PartMap, PngPixels, RgbaImage, encode_png, png_claimed_pixels};
#[cfg(not(target_arch = "wasm32"))]
pub use lazy_folder::LazyFolder;
pub use npy::encode_npy;
pub use object_archive::{is_urdf_path, read_zip_object, zip_holds_object};
pub use paths::rebase_on_dataset_root;
pub use ply::{PlyFormat, TriMesh};
pub use sensor::SensorModel;
pub use summary::{Summary, ViewSummary};
pub use view_set::{ReadLimits, ViewSet};
pub use writer::{DatasetWriter, SemanticFormat, WriteOptions};

/// A dataset as bytes: relative path (`'/'` separators, e.g. `start/train/rgba/0000.png`) → file contents.
pub type FileSet = BTreeMap<String, Vec<u8>>;

/// Files by relative path (`'/'` separators) that a reader asks for one at a time: a [`FileSet`]
/// held in memory, or a folder read on demand, so that only what is asked for is ever read.
pub trait FileSource {
    /// The bytes of `path`, or `None` when there is no such (readable) file.
    fn file(&self, path: &str) -> Option<&[u8]>;
    /// Every path present, in order, without reading any.
    fn paths(&self) -> Vec<&str>;
}

impl FileSource for FileSet {
    fn file(&self, path: &str) -> Option<&[u8]> {
        self.get(path).map(Vec::as_slice)
    }

    fn paths(&self) -> Vec<&str> {
        self.keys().map(String::as_str).collect()
    }
}

/// Articulation state of the object.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum State {
    /// First observed state (`time` 0).
    Start,
    /// Second observed state (`time` 1).
    End,
}

impl State {
    /// Both states, in file order.
    pub const ALL: [State; 2] = [State::Start, State::End];

    /// Name used in paths and file names: `"start"` / `"end"`.
    pub fn name(self) -> &'static str {
        match self {
            State::Start => "start",
            State::End => "end",
        }
    }

    /// 0 for start, 1 for end (index into per-state arrays).
    pub fn index(self) -> usize {
        match self {
            State::Start => 0,
            State::End => 1,
        }
    }

    /// Default frame `time` for this state when the file gives none.
    pub(crate) fn default_time(self) -> f32 {
        match self {
            State::Start => 0.0,
            State::End => 1.0,
        }
    }
}

/// Train or test views.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Split {
    /// Views used for fitting (required for both states).
    Train,
    /// Held-out views (optional).
    Test,
}

impl Split {
    /// Both splits, in file order.
    pub const ALL: [Split; 2] = [Split::Train, Split::Test];

    /// Name used in paths and file names: `"train"` / `"test"`.
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Test => "test",
        }
    }
}

impl std::fmt::Display for State {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::fmt::Display for Split {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Name of the transforms file for a split and state, e.g. `transforms_train_start.json`.
pub(crate) fn transforms_file_name(split: Split, state: State) -> String {
    format!("transforms_{}_{}.json", split.name(), state.name())
}

/// Whether a dataset path is one that names the others or stands alone: a transforms file at the
/// root, or anything under `gt/`.
pub(crate) fn is_dataset_index(rel: &str) -> bool {
    rel.starts_with("gt/")
        || State::ALL
            .into_iter()
            .flat_map(|state| Split::ALL.map(|split| transforms_file_name(split, state)))
            .any(|name| name == rel)
}

/// Path of the ground-truth joints file.
pub(crate) const GT_TRANS_PATH: &str = "gt/trans.json";
