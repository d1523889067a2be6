//! Reading one view set (a transforms file and the frames it names): the decoded-size budget,
//! finding and decoding each frame's colour, depth and semantic images on every core, and the
//! checks within a frame and across a split, in frame order.

use super::camera::Camera;
use super::error::{DataError, Errors};
use super::frame::{Frame, size_error};
use super::image_io::{self, DepthMap, PartMap, RgbaImage};
use super::npy;
use super::parallel;
use super::paths;
use super::transforms::{self, FrameSpec};
use super::{FileSet, GT_TRANS_PATH, Split, State};

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

/// Frames of one split seen so far, for checks across frames.
#[derive(Default)]
struct SplitChecks {
    /// Size of the first readable image and its path.
    reference: Option<(u32, u32, String)>,
    /// Per kind (depth, semantic): paths found, and expected paths that were missing.
    present: [Vec<String>; 2],
    missing: [Vec<String>; 2],
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
pub(super) struct ViewSetContext {
    /// Part ids must stay below this (from `gt/trans.json`), if given.
    pub(super) part_limit: Option<usize>,
    pub(super) max_decoded_bytes: u64,
    /// Decoded bytes of the view sets read so far.
    pub(super) decoded_bytes: u64,
}

/// Reads one transforms file and the images it refers to.
pub(super) fn read_view_set(
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
    let found: Vec<FrameFiles> = spec.frames.iter().map(|fs| find_frame(files, fs)).collect();
    let size = found
        .iter()
        .map(FrameFiles::decoded_size)
        .fold(0, u64::saturating_add);
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
    let decoded = parallel::map(&found, FrameFiles::decode);
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

/// An optional file of a frame found in the file set (path and bytes), or the path it was
/// expected at.
type Located<'a> = Result<(String, &'a [u8]), String>;

/// A frame's files as found in the file set, before decoding.
struct FrameFiles<'a> {
    /// The colour image's path and bytes, or every path it was looked for under.
    rgba: Result<(String, &'a [u8]), Vec<String>>,
    /// Depth and semantic map ([`paths::SIBLINGS`] order): the file found, or the path it was
    /// expected at; none when the colour image itself is missing.
    siblings: Option<[Located<'a>; 2]>,
}

/// Finds a frame's colour image and its optional depth and semantic maps.
fn find_frame<'a>(files: &'a FileSet, fs: &FrameSpec) -> FrameFiles<'a> {
    let candidates = paths::image_candidates(&fs.file_path);
    let Some((rgba_path, bytes)) = candidates
        .iter()
        .find_map(|p| files.get(p).map(|b| (p.clone(), b.as_slice())))
    else {
        return FrameFiles {
            rgba: Err(candidates),
            siblings: None,
        };
    };
    let siblings = [0, 1].map(|k| find_sibling(files, &rgba_path, k));
    FrameFiles {
        rgba: Ok((rgba_path, bytes)),
        siblings: Some(siblings),
    }
}

impl FrameFiles<'_> {
    /// Bytes the images decode to, from their headers (0 for an image whose header does not
    /// read: its decoder names the problem).
    fn decoded_size(&self) -> u64 {
        let png_pixels = image_io::png_claimed_pixels;
        let rgba = self
            .rgba
            .as_ref()
            .map_or(0, |(_, b)| png_pixels(b).saturating_mul(4));
        let siblings = self.siblings.iter().flatten().flatten().map(|(path, b)| {
            // An .npy holds its values uncompressed: it decodes to about its own size.
            if path.ends_with(".npy") {
                b.len() as u64
            } else {
                png_pixels(b).saturating_mul(2)
            }
        });
        // Saturating: two u32 sides can claim 2⁶⁴ pixels, which must not wrap under the budget.
        siblings.fold(rgba, u64::saturating_add)
    }

    /// Decodes every image found.
    fn decode(&self) -> DecodedFrame {
        let rgba = match &self.rgba {
            Ok((path, bytes)) => Ok((path.clone(), image_io::decode_rgba(path, bytes))),
            Err(candidates) => Err(candidates.clone()),
        };
        let [depth, parts] = match &self.siblings {
            Some([depth, parts]) => [Some(depth), Some(parts)],
            None => [None, None],
        };
        let depth = depth.map(|found| {
            found.clone().map(|(path, b)| {
                let map = image_io::decode_depth(&path, b);
                (path, map)
            })
        });
        let parts = parts.map(|found| {
            found.clone().map(|(path, b)| {
                let map = if path.ends_with(".npy") {
                    npy::decode_parts_npy(&path, b)
                } else {
                    image_io::decode_parts_png(&path, b)
                };
                (path, map)
            })
        });
        DecodedFrame { rgba, depth, parts }
    }
}

/// The optional map `k` of a frame ([`paths::SIBLINGS`]: 0 depth, 1 semantic) under the first of
/// its extensions present, or the path it was expected at.
fn find_sibling<'a>(files: &'a FileSet, rgba_path: &str, k: usize) -> Located<'a> {
    let (kind, exts) = paths::SIBLINGS[k];
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
