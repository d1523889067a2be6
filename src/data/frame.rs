//! One view of the dataset (camera, colour, optional depth and part ids) and the size check shared by the
//! reader and the writer. The bottom of the dataset files: it uses none of them.

use super::camera::Camera;
use super::error::DataError;
use super::image_io::{DepthMap, PartMap, RgbaImage};

/// One view: camera, colour, and optional depth and part ids, all of the same size.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// File stem of the colour image, e.g. `"0000"`; names the frame's files when written.
    pub name: String,
    /// Pose and intrinsics.
    pub camera: Camera,
    /// Articulation time: 0 = start, 1 = end.
    pub time: f32,
    /// Colour; alpha is the foreground mask.
    pub rgba: RgbaImage,
    /// Depth in millimetres, if the dataset has depth.
    pub depth: Option<DepthMap>,
    /// Part ids, if the dataset has semantic maps.
    pub parts: Option<PartMap>,
}

/// The error for an image whose size differs from the one its frame or split requires.
pub(crate) fn size_error(
    file: &str,
    what: &str,
    w: u32,
    h: u32,
    found_w: u32,
    found_h: u32,
) -> DataError {
    DataError::field(
        file,
        "size",
        format!("expected {w}x{h} ({what}), found {found_w}x{found_h}"),
    )
}
