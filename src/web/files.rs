//! What the page reads of a dropped folder: it sends the files' paths and sizes first, and reads
//! only the files [`Listing::needed`] asks for (the selection the native folder and zip readers
//! make), so a video beside the dataset is never read; and the budgets the page checks before it
//! reads anything (`Dataset.file_limits`).

use std::collections::BTreeMap;

use wasm_bindgen::prelude::*;

use super::app::WebDataset;
use super::js_error;
use crate::data::{FileLimits, FileSet, Listing, dataset_paths};

/// Largest `.zip` the page reads: it is copied into wasm memory whole, beside the entries taken
/// out of it (up to [`FileLimits::max_bytes`]) and later the decoded images.
const MAX_ZIP_BYTES: u64 = 1 << 30;

#[wasm_bindgen(js_class = Dataset)]
impl WebDataset {
    /// The page's budgets as JSON: `{max_listed_files, max_file_bytes, max_zip_bytes}`.
    pub fn file_limits() -> String {
        let limits = FileLimits::default();
        serde_json::json!({
            "max_listed_files": limits.max_listed,
            "max_file_bytes": limits.max_bytes,
            "max_zip_bytes": MAX_ZIP_BYTES,
        })
        .to_string()
    }

    /// Which of the dropped folder's files (`paths[i]` of `sizes[i]` bytes; the folder named
    /// `folder` in errors) the dataset needs besides `read_paths` (read already, holding
    /// `read_contents`): with nothing read, the transforms files and `gt/`; given those, the
    /// images they name. Throws when the folder lists too many files or the needed ones add up
    /// past the budget.
    pub fn files_needed(
        folder: String,
        paths: Vec<String>,
        sizes: Vec<f64>,
        read_paths: Vec<String>,
        read_contents: Vec<js_sys::Uint8Array>,
    ) -> Result<Vec<String>, JsError> {
        let limits = FileLimits::default();
        limits
            .check_listed(&folder, paths.len())
            .map_err(js_error)?;
        if paths.len() != sizes.len() || read_paths.len() != read_contents.len() {
            return Err(JsError::new(&format!(
                "files_needed: {} paths for {} sizes, {} read paths for {} contents",
                paths.len(),
                sizes.len(),
                read_paths.len(),
                read_contents.len()
            )));
        }
        let size_of: BTreeMap<&str, u64> = paths
            .iter()
            .map(String::as_str)
            .zip(sizes.iter().map(|&s| s.max(0.0) as u64))
            .collect();
        // Dataset path → path as dropped, and back.
        let rooted = dataset_paths(paths.iter().cloned());
        let dropped: BTreeMap<&str, &str> = rooted
            .iter()
            .map(|(path, given)| (given.as_str(), path.as_str()))
            .collect();
        let listed = rooted
            .iter()
            .map(|(path, given)| {
                (
                    path.clone(),
                    size_of.get(given.as_str()).copied().unwrap_or(0),
                )
            })
            .collect();
        let read: FileSet = read_paths
            .iter()
            .zip(&read_contents)
            .filter_map(|(given, bytes)| {
                Some((dropped.get(given.as_str())?.to_string(), bytes.to_vec()))
            })
            .collect();
        let needed = Listing::new(&folder, listed, limits)
            .and_then(|listing| listing.needed(&read))
            .map_err(js_error)?;
        Ok(needed
            .iter()
            .filter_map(|path| rooted.get(path).cloned())
            .collect())
    }
}
