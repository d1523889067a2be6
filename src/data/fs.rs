//! Native-only bridge between a folder on disk and a [`FileSet`]. Never overwrites anything.

use std::collections::BTreeMap;
use std::fs;
use std::io::{Read, Write};
use std::path::{Component, Path, PathBuf};

use super::FileSet;
use super::archive::{FileLimits, Listing};
use super::error::{DataError, DatasetErrors};

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
/// semantic siblings), chosen as for an archive ([`Listing`]). An unrelated video beside the
/// frames, a name that is not UTF-8 or a dangling symlink elsewhere in the folder is never read
/// and never an error. Refuses a folder past the default [`FileLimits`].
pub fn read_dataset_files(root: &Path) -> Result<FileSet, DataError> {
    let mut found = Found::new();
    list(&folder(root)?, "", 0, Strictness::Lenient, &mut found)?;
    let sizes = found
        .iter()
        .map(|(rel, (_, size))| (rel.clone(), *size))
        .collect();
    let listing = Listing::new(&root.display().to_string(), sizes, FileLimits::default())?;
    listing.read(|rel, at_most| {
        let cannot = |e: std::io::Error| DataError::file(rel, format!("cannot read: {e}"));
        let (path, _) = found
            .get(rel)
            .ok_or_else(|| cannot(std::io::ErrorKind::NotFound.into()))?;
        let mut bytes = Vec::new();
        fs::File::open(path)
            .and_then(|f| f.take(at_most.saturating_add(1)).read_to_end(&mut bytes))
            .map_err(cannot)?;
        Ok(bytes)
    })
}

/// `root` as a folder to read, or why it is not one.
pub(super) fn folder(root: &Path) -> Result<PathBuf, DataError> {
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

/// Non-hidden files below a folder, by `'/'`-separated relative path: where each is and its size.
pub(super) type Found = BTreeMap<String, (PathBuf, u64)>;

/// What [`list`] does with an entry it cannot use.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Strictness {
    /// A name that is not UTF-8 or an entry that cannot be inspected (a dangling symlink) is an
    /// error: [`read_dir`] reads everything, so it must be able to name everything.
    Strict,
    /// Such entries are left out: no transforms file can refer to them.
    Lenient,
}

/// Lists the non-hidden files below `dir` without reading them. Follows symlinks, so linked
/// folders and files are listed like real ones.
pub(super) fn list(
    dir: &Path,
    prefix: &str,
    depth: usize,
    strictness: Strictness,
    out: &mut Found,
) -> Result<(), DataError> {
    let shown = if prefix.is_empty() { "." } else { prefix };
    if depth > MAX_DEPTH {
        return Err(DataError::file(
            shown,
            format!("folders nested more than {MAX_DEPTH} deep (a symlink loop?)"),
        ));
    }
    let strict = strictness == Strictness::Strict;
    let cannot_list =
        |e: std::io::Error| DataError::file(shown, format!("cannot list folder: {e}"));
    for entry in fs::read_dir(dir).map_err(cannot_list)? {
        let entry = match entry {
            Ok(entry) => entry,
            Err(e) if strict => return Err(cannot_list(e)),
            Err(_) => continue,
        };
        let name = match entry.file_name().into_string() {
            Ok(name) => name,
            Err(raw) if strict => {
                return Err(DataError::file(
                    shown,
                    format!("file name {raw:?} is not valid UTF-8"),
                ));
            }
            Err(_) => continue,
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
            Ok(meta) if meta.is_dir() => list(&path, &rel, depth + 1, strictness, out)?,
            Ok(meta) if meta.is_file() => {
                out.insert(rel, (path, meta.len()));
            }
            Ok(_) => {}
            Err(e) if strict => return Err(DataError::file(&rel, format!("cannot read: {e}"))),
            Err(_) => {}
        }
    }
    Ok(())
}

/// Folders nested deeper than this are not followed (guards against symlink loops).
const MAX_DEPTH: usize = 32;

/// Reads every non-hidden file below `root` into a [`FileSet`] keyed by `'/'`-separated relative path.
/// Hidden files and folders (name starting with `.`) are skipped. Read-only.
pub fn read_dir(root: &Path) -> Result<FileSet, DataError> {
    let mut found = Found::new();
    list(&folder(root)?, "", 0, Strictness::Strict, &mut found)?;
    let mut files = FileSet::new();
    for (rel, (path, _)) in &found {
        let bytes =
            fs::read(path).map_err(|e| DataError::file(rel, format!("cannot read: {e}")))?;
        files.insert(rel.clone(), bytes);
    }
    Ok(files)
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
