//! Where commands write: new files and new folders only. Nothing is replaced, nothing is written
//! through a symlink at an output path, and a command that fails leaves nothing behind: a folder
//! is built under a hidden temporary name beside its destination and renamed into place at the end.

use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Refuses `path` when anything is there: a file, a folder, or a symlink (even a dangling one).
pub fn check_new_file(path: &Path) -> Result<(), String> {
    match fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => Err(format!(
            "{} is a symlink; outputs are never written through one, choose a new file",
            path.display()
        )),
        Ok(_) => Err(format!(
            "{} already exists; choose a new file",
            path.display()
        )),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(format!("{}: {e}", path.display())),
    }
}

/// Refuses two outputs at one path (as given, or the same file name in the same folder).
pub fn check_distinct(paths: &[&Path]) -> Result<(), String> {
    let key = |p: &Path| {
        let parent = p.parent().filter(|d| !d.as_os_str().is_empty());
        let folder = parent.map_or_else(|| fs::canonicalize("."), fs::canonicalize);
        (folder.ok(), p.file_name().map(|n| n.to_os_string()))
    };
    for (i, a) in paths.iter().enumerate() {
        for b in &paths[..i] {
            if a == b || key(a) == key(b) && key(a).0.is_some() {
                return Err(format!(
                    "{} is given as two outputs; give each output its own path",
                    a.display()
                ));
            }
        }
    }
    Ok(())
}

/// Writes `bytes` to a new file, created exclusively at write time (so a file or symlink that
/// appeared since [`check_new_file`] is refused, not replaced); a partly written file is removed.
pub fn write_new_file(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let mut file = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::AlreadyExists => format!(
                "{} appeared while this command ran; nothing was replaced",
                path.display()
            ),
            _ => format!("{}: cannot create: {e}", path.display()),
        })?;
    file.write_all(bytes).map_err(|e| {
        let _ = fs::remove_file(path);
        format!("{}: cannot write: {e}", path.display())
    })
}

/// A new output folder under construction: written at [`NewFolder::path`] (a hidden sibling of
/// the destination), moved to the destination by [`NewFolder::finish`], removed if dropped first.
pub struct NewFolder {
    destination: PathBuf,
    staging: PathBuf,
    /// Ancestors of the destination this created, deepest first: removed again if empty.
    created: Vec<PathBuf>,
    finished: bool,
}

impl NewFolder {
    /// Starts a folder at `destination`, which must not exist or be an empty real folder.
    pub fn create(destination: &Path) -> Result<NewFolder, String> {
        check_free_folder(destination)?;
        let name = destination
            .file_name()
            .filter(|n| !n.is_empty() && *n != "." && *n != "..")
            .ok_or_else(|| format!("{}: expected a folder name", destination.display()))?;
        let parent = match destination.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let mut created = Vec::new();
        let mut missing = Some(parent.as_path());
        while let Some(dir) = missing.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
            created.push(dir.to_path_buf());
            missing = dir.parent();
        }
        fs::create_dir_all(&parent).map_err(|e| format!("{}: {e}", parent.display()))?;
        let staging = parent.join(format!(
            ".{}.partial-{}",
            name.to_string_lossy(),
            std::process::id()
        ));
        let folder = NewFolder {
            destination: destination.to_path_buf(),
            staging,
            created,
            finished: false,
        };
        fs::create_dir(&folder.staging)
            .map_err(|e| format!("{}: {e}", folder.staging.display()))?;
        Ok(folder)
    }

    /// Where to write while the command runs.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Moves the folder into place. Refuses (and removes what was written) if something other
    /// than an empty folder appeared at the destination meanwhile.
    pub fn finish(mut self) -> Result<PathBuf, String> {
        check_free_folder(&self.destination)?;
        // rename(2) replaces an empty folder and fails on anything else: nothing is clobbered.
        fs::rename(&self.staging, &self.destination).map_err(|e| {
            format!(
                "{}: cannot move the finished output into place: {e}",
                self.destination.display()
            )
        })?;
        self.finished = true;
        Ok(self.destination.clone())
    }
}

impl Drop for NewFolder {
    fn drop(&mut self) {
        if !self.finished {
            let _ = fs::remove_dir_all(&self.staging);
            for dir in &self.created {
                let _ = fs::remove_dir(dir);
            }
        }
    }
}

/// Refuses a destination folder that is a symlink, a file, or a folder with anything in it.
pub fn check_free_folder(out: &Path) -> Result<(), String> {
    match fs::symlink_metadata(out) {
        Ok(meta) if meta.file_type().is_symlink() => Err(format!(
            "{} is a symlink; outputs are never written through one, choose a new folder",
            out.display()
        )),
        Ok(meta) if !meta.is_dir() => {
            Err(format!("{} is a file; choose a new folder", out.display()))
        }
        Ok(_) => match fs::read_dir(out).map(|mut entries| entries.next().is_some()) {
            Ok(false) => Ok(()),
            Ok(true) => Err(format!(
                "{} already exists and is not empty; choose a new folder",
                out.display()
            )),
            Err(e) => Err(format!("{}: {e}", out.display())),
        },
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(format!("{}: {e}", out.display())),
    }
}
