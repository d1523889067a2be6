//! Native-only bridge between a folder on disk and a [`FileSet`]. Never overwrites anything.

use std::fs;
use std::io::Write;
use std::path::{Component, Path};

use std::collections::BTreeSet;

use super::FileSet;
use super::error::{DataError, DatasetErrors, Errors};
use super::{Split, State};

/// Why [`read_dataset`] found no valid dataset.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReadDatasetError {
    /// The folder could not be read.
    #[error(transparent)]
    Folder(#[from] DataError),
    /// The folder was read but is not a valid dataset; lists every problem after the folder's name.
    #[error("{root}: {} problem(s):\n{errors}", .errors.0.len())]
    Invalid {
        /// The folder as given.
        root: String,
        /// Every problem found.
        errors: DatasetErrors,
    },
}

/// Reads the dataset folder `root` (see [`read_dataset_files`]) and validates it; every problem
/// found is listed in the error, after the folder's name.
pub fn read_dataset(root: &Path) -> Result<super::Dataset, ReadDatasetError> {
    let files = read_dataset_files(root)?;
    super::Dataset::from_files(&files).map_err(|errors| ReadDatasetError::Invalid {
        root: root.display().to_string(),
        errors,
    })
}

/// The files of the dataset folder `root` that a dataset is made of, and nothing else: the
/// transforms files, `gt/`, and the images the transforms files refer to (with their depth and
/// semantic siblings). An unrelated video beside the frames, a name that is not UTF-8 or a
/// dangling symlink elsewhere in the folder is never read and never an error.
pub fn read_dataset_files(root: &Path) -> Result<FileSet, DataError> {
    let mut listing = std::collections::BTreeMap::new();
    list(&folder(root)?, "", 0, &mut listing)?;
    let read = |rel: &str, path: &Path, files: &mut FileSet| -> Result<(), DataError> {
        let bytes =
            fs::read(path).map_err(|e| DataError::file(rel, format!("cannot read: {e}")))?;
        files.insert(rel.to_string(), bytes);
        Ok(())
    };
    // First what names the rest: the transforms files and the ground truth.
    let mut files = FileSet::new();
    for (rel, path) in &listing {
        if super::is_dataset_index(rel) {
            read(rel, path, &mut files)?;
        }
    }
    for rel in referenced_paths(&files) {
        if let Some(path) = listing.get(&rel) {
            read(&rel, path, &mut files)?;
        }
    }
    Ok(files)
}

/// Every path the transforms files in `files` refer to, with each image's depth and semantic
/// siblings under every name the reader tries: what a reader of a folder needs to read besides
/// the transforms files and `gt/`. Malformed transforms files contribute what they can; their
/// errors are the reader's to report.
fn referenced_paths(files: &FileSet) -> BTreeSet<String> {
    let mut wanted = BTreeSet::new();
    for state in State::ALL {
        for split in Split::ALL {
            let file = super::transforms_file_name(split, state);
            let Some(bytes) = files.get(&file) else {
                continue;
            };
            let Some(spec) = super::transforms::parse(&file, bytes, &mut Errors::default()) else {
                continue;
            };
            for fs in &spec.frames {
                for image in super::paths::image_candidates(&fs.file_path) {
                    for (kind, ext) in [
                        ("depth", ".png"),
                        ("semantic", ".png"),
                        ("semantic", ".npy"),
                    ] {
                        wanted.extend(super::paths::sibling(&image, kind, ext));
                    }
                    wanted.insert(image);
                }
            }
        }
    }
    wanted
}

/// `root` as a folder to read, or why it is not one.
fn folder(root: &Path) -> Result<std::path::PathBuf, DataError> {
    let shown = root.display().to_string();
    let meta = fs::metadata(root)
        .map_err(|e| DataError::file(&shown, format!("cannot open the dataset folder: {e}")))?;
    if !meta.is_dir() {
        return Err(DataError::file(
            &shown,
            "expected a dataset folder, found a file",
        ));
    }
    Ok(root.to_path_buf())
}

/// Lists the non-hidden files below `dir` by relative path without reading them; names that
/// are not UTF-8 and entries that cannot be inspected (a dangling symlink) are left out, since
/// no transforms file can refer to them.
fn list(
    dir: &Path,
    prefix: &str,
    depth: usize,
    out: &mut std::collections::BTreeMap<String, std::path::PathBuf>,
) -> Result<(), DataError> {
    let shown = if prefix.is_empty() { "." } else { prefix };
    if depth > MAX_DEPTH {
        return Err(DataError::file(
            shown,
            format!("folders nested more than {MAX_DEPTH} deep (a symlink loop?)"),
        ));
    }
    let entries = fs::read_dir(dir)
        .map_err(|e| DataError::file(shown, format!("cannot list folder: {e}")))?;
    for entry in entries.flatten() {
        let Ok(name) = entry.file_name().into_string() else {
            continue;
        };
        if name.starts_with('.') {
            continue;
        }
        let rel = if prefix.is_empty() {
            name
        } else {
            format!("{prefix}/{name}")
        };
        let path = entry.path();
        match fs::metadata(&path) {
            Ok(meta) if meta.is_dir() => list(&path, &rel, depth + 1, out)?,
            Ok(meta) if meta.is_file() => {
                out.insert(rel, path);
            }
            _ => {}
        }
    }
    Ok(())
}

/// Folders nested deeper than this are not followed (guards against symlink loops).
const MAX_DEPTH: usize = 32;

/// Reads every non-hidden file below `root` into a [`FileSet`] keyed by `'/'`-separated relative path.
/// Hidden files and folders (name starting with `.`) are skipped. Read-only.
pub fn read_dir(root: &Path) -> Result<FileSet, DataError> {
    let shown = root.display().to_string();
    let meta = fs::metadata(root)
        .map_err(|e| DataError::file(&shown, format!("cannot open the dataset folder: {e}")))?;
    if !meta.is_dir() {
        return Err(DataError::file(
            &shown,
            "expected a dataset folder, found a file",
        ));
    }
    let mut files = FileSet::new();
    walk(root, "", 0, &mut files)?;
    Ok(files)
}

fn walk(dir: &Path, prefix: &str, depth: usize, files: &mut FileSet) -> Result<(), DataError> {
    let shown = if prefix.is_empty() {
        ".".to_string()
    } else {
        prefix.to_string()
    };
    if depth > MAX_DEPTH {
        return Err(DataError::file(
            shown,
            format!("folders nested more than {MAX_DEPTH} deep (a symlink loop?)"),
        ));
    }
    let entries = fs::read_dir(dir)
        .map_err(|e| DataError::file(&shown, format!("cannot list folder: {e}")))?;
    for entry in entries {
        let entry =
            entry.map_err(|e| DataError::file(&shown, format!("cannot list folder: {e}")))?;
        let name = entry.file_name();
        let Some(name) = name.to_str() else {
            return Err(DataError::file(
                &shown,
                format!("file name {:?} is not valid UTF-8", entry.file_name()),
            ));
        };
        if name.starts_with('.') {
            continue;
        }
        let rel = if prefix.is_empty() {
            name.to_string()
        } else {
            format!("{prefix}/{name}")
        };
        let path = entry.path();
        // Follows symlinks, so linked folders and files are read like real ones.
        let meta =
            fs::metadata(&path).map_err(|e| DataError::file(&rel, format!("cannot read: {e}")))?;
        if meta.is_dir() {
            walk(&path, &rel, depth + 1, files)?;
        } else if meta.is_file() {
            let bytes =
                fs::read(&path).map_err(|e| DataError::file(&rel, format!("cannot read: {e}")))?;
            files.insert(rel, bytes);
        }
    }
    Ok(())
}

/// Writes a [`FileSet`] below `root` (created if needed). Refuses to overwrite: if any file already exists,
/// nothing is written and the error names it. Paths must be relative and stay inside `root`.
pub fn write_dir(files: &FileSet, root: &Path) -> Result<(), DataError> {
    for rel in files.keys() {
        let ok = !rel.is_empty()
            && Path::new(rel)
                .components()
                .all(|c| matches!(c, Component::Normal(_)))
            && !rel.contains('\\');
        if !ok {
            return Err(DataError::file(
                rel,
                "expected a relative path inside the output folder",
            ));
        }
        // A dangling symlink counts: `exists()` would follow it and say no.
        if fs::symlink_metadata(root.join(rel)).is_ok() {
            return Err(DataError::file(
                rel,
                format!(
                    "already exists in {}; refusing to overwrite",
                    root.display()
                ),
            ));
        }
    }
    for (rel, bytes) in files {
        let path = root.join(rel);
        if let Some(parent) = path.parent() {
            fs::create_dir_all(parent)
                .map_err(|e| DataError::file(rel, format!("cannot create folder: {e}")))?;
        }
        // `create_new` also refuses a file that appeared since the check above.
        let mut f = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
            .map_err(|e| DataError::file(rel, format!("cannot create: {e}")))?;
        f.write_all(bytes)
            .map_err(|e| DataError::file(rel, format!("cannot write: {e}")))?;
    }
    Ok(())
}
