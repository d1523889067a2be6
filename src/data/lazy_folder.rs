//! A folder read on demand: listed once (names and sizes; nothing read), each file read the first
//! time a reader asks for it. `render` imports a URDF through it, so a recording or any other
//! unrelated file in the package folder is never read, and an unreadable entry there (a name that
//! is not UTF-8, a dangling symlink) is never an error.

use std::cell::OnceCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::FileSource;
use super::error::DataError;
use super::fs::{Found, Strictness, folder, list};

/// Where a listed file is, and its bytes once asked for (`None`: it could not be read).
type Entry = (PathBuf, OnceCell<Option<Vec<u8>>>);

/// The files below a folder, each read when first asked for.
pub struct LazyFolder {
    files: BTreeMap<String, Entry>,
}

impl LazyFolder {
    /// Lists the non-hidden files below `root` (following symlinks, skipping entries that cannot
    /// be named or inspected) without reading any.
    pub fn list(root: &Path) -> Result<LazyFolder, DataError> {
        let mut found = Found::new();
        list(&folder(root)?, "", 0, Strictness::Lenient, &mut found)?;
        let files = found
            .into_iter()
            .map(|(rel, (path, _))| (rel, (path, OnceCell::new())))
            .collect();
        Ok(LazyFolder { files })
    }

    /// The paths read so far (a file that could not be read counts as read).
    pub fn read_so_far(&self) -> Vec<&str> {
        self.files
            .iter()
            .filter(|(_, (_, cell))| cell.get().is_some())
            .map(|(rel, _)| rel.as_str())
            .collect()
    }
}

impl FileSource for LazyFolder {
    fn file(&self, path: &str) -> Option<&[u8]> {
        let (on_disk, cell) = self.files.get(path)?;
        cell.get_or_init(|| std::fs::read(on_disk).ok()).as_deref()
    }

    fn paths(&self) -> Vec<&str> {
        self.files.keys().map(String::as_str).collect()
    }
}
