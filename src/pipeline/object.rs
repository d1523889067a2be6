//! A user's own object: a `.zip` of a URDF with its meshes (the page takes one besides datasets
//! and the demo's catalogue). It is imported as `artmesh render` imports a URDF (mesh paths
//! relative to the URDF or `package://` through the archive's `package.xml` files), then captured
//! in both states as the demo's objects are ([`super::demo::capture_object`]: the start and end
//! states drawn from the joints' limits, ground truth included), so its fit is scored.

use super::demo::capture_object;
use super::{FitInput, PipelineError, UNKNOWN_CATEGORY};
use crate::data::{DataError, FileLimits, FileSet, is_urdf_path, read_zip_object};
use crate::gpu::GpuContext;
use crate::object::ArticulatedObject;
use crate::render::{RenderProgress, RenderSpec};

/// An object read from an archive: the object and where it came from, for errors and names.
#[derive(Debug, Clone)]
pub struct ZippedObject {
    /// The imported object.
    pub object: ArticulatedObject,
    /// The archive's name, as given.
    pub archive: String,
    /// The URDF's path inside the archive.
    pub urdf: String,
}

/// The URDF of `files` (the archive `archive`'s entries): the only one, or an error saying there
/// is none or listing several.
fn the_urdf<'a>(archive: &str, files: &'a FileSet) -> Result<&'a str, PipelineError> {
    let urdfs: Vec<&str> = files
        .keys()
        .map(String::as_str)
        .filter(|p| is_urdf_path(p))
        .collect();
    match urdfs.as_slice() {
        [one] => Ok(one),
        [] => Err(PipelineError::Object(format!(
            "{archive}: holds no .urdf file; expected a .zip of a URDF with its meshes (or of a dataset folder)"
        ))),
        many => Err(PipelineError::Object(format!(
            "{archive}: holds {} URDF files ({}); expected one object, so one .urdf per archive",
            many.len(),
            many.join(", ")
        ))),
    }
}

/// Imports the object in `files` (the entries of the archive `archive`): its one URDF and every
/// mesh and texture that refers to. Errors name the archive, the URDF and the element at fault:
/// a mesh the archive lacks, XML that is not well-formed, an object with no movable joint.
pub fn object_from_files(archive: &str, files: &FileSet) -> Result<ZippedObject, PipelineError> {
    let urdf = the_urdf(archive, files)?;
    let at = |e: DataError| PipelineError::Object(format!("{archive}: {e}"));
    let mut object = ArticulatedObject::from_urdf(urdf, files).map_err(at)?;
    // Checked here, before any GPU work, with the URDF's name (the capture would also refuse it).
    if object.parts().movable_count() == 0 {
        return Err(at(DataError::file(
            urdf,
            format!(
                "the robot '{}' has no movable joint ({} joint(s), none of them revolute, continuous or prismatic): expected at least one, whose motion the two captured states show",
                object.name,
                object.joints.len()
            ),
        )));
    }
    if object.name.trim().is_empty() {
        // The fit's files and report are named after the object.
        object.name = archive_stem(archive).to_string();
    }
    Ok(ZippedObject {
        object,
        archive: archive.to_string(),
        urdf: urdf.to_string(),
    })
}

/// [`object_from_files`] on the zip archive `bytes` named `archive`, read whole within `limits`
/// (the budgets of a dataset's archive: a zip bomb is refused before it fills the memory).
pub fn object_from_zip(
    archive: &str,
    bytes: &[u8],
    limits: &FileLimits,
) -> Result<ZippedObject, PipelineError> {
    let files = read_zip_object(archive, bytes, limits)
        .map_err(|e| PipelineError::Object(e.to_string()))?;
    object_from_files(archive, &files)
}

/// Captures the zipped object in both states as `spec` says (the demo's capture for the fit's
/// preset, [`crate::fit::object::FitConfig::demo_capture`]); `on_view` hears the views rendered.
/// The dataset is named after the archive (what the user dropped), not the URDF's robot, which
/// exporters often call "Scene" or "robot".
/// Errors (an object the part model cannot describe, a GPU failure) name the archive and URDF.
pub async fn capture_zipped(
    ctx: &GpuContext,
    zipped: &ZippedObject,
    spec: &RenderSpec,
    on_view: &mut dyn FnMut(RenderProgress),
) -> Result<FitInput, PipelineError> {
    let mut input = capture_object(ctx, &zipped.object, UNKNOWN_CATEGORY, spec, on_view)
        .await
        .map_err(|e| PipelineError::Object(format!("{}: {}: {e}", zipped.archive, zipped.urdf)))?;
    input.id = archive_stem(&zipped.archive).to_string();
    Ok(input)
}

/// The archive's file name without its folders and its `.zip`: "objects/dishwasher.zip" →
/// "dishwasher" (the whole name when nothing is left).
pub fn archive_stem(archive: &str) -> &str {
    let name = archive.rsplit(['/', '\\']).next().unwrap_or(archive);
    let stem = name
        .len()
        .checked_sub(4)
        .filter(|&n| name.is_char_boundary(n) && name[n..].eq_ignore_ascii_case(".zip"))
        .map_or(name, |n| &name[..n]);
    if stem.is_empty() { archive } else { stem }
}

#[cfg(test)]
mod tests {
    use super::archive_stem;

    #[test]
    fn a_dropped_archive_names_its_dataset() {
        assert_eq!(archive_stem("dishwasher.zip"), "dishwasher");
        assert_eq!(archive_stem("objects/Range Oven.ZIP"), "Range Oven");
        assert_eq!(archive_stem("C:\\captures\\fridge.zip"), "fridge");
        assert_eq!(archive_stem("cabinet"), "cabinet");
        assert_eq!(archive_stem(".zip"), ".zip");
    }
}
