//! Datasets that arrive as one `.zip` (the page accepts a dropped archive as well as a folder).

use std::io::{Cursor, Read};

use super::paths::{normalize, rebase_on_dataset_root};
use super::{DataError, FileSet};

/// The files of the zip archive `bytes` (named `name` in errors), re-rooted at the dataset folder
/// inside it ([`rebase_on_dataset_root`]). Folder entries and macOS `__MACOSX/` resource forks are
/// skipped; an entry whose path is absolute or leaves the archive is an error, as is anything
/// that is not a readable zip.
pub fn read_zip(name: &str, bytes: &[u8]) -> Result<FileSet, DataError> {
    let not_zip = |e: ::zip::result::ZipError| {
        DataError::file(
            name,
            format!("cannot read it as a zip archive ({e}); expected a .zip of a dataset folder"),
        )
    };
    let mut archive = ::zip::ZipArchive::new(Cursor::new(bytes)).map_err(not_zip)?;
    let mut files = FileSet::new();
    for i in 0..archive.len() {
        let mut entry = archive.by_index(i).map_err(not_zip)?;
        let raw = entry.name().map_err(not_zip)?.into_owned();
        if entry.is_dir() || raw.starts_with("__MACOSX/") {
            continue;
        }
        let path = normalize(&raw)
            .map_err(|e| DataError::field(name, format!("entry {i}"), e.to_string()))?;
        let mut contents = Vec::with_capacity(entry.size().min(1 << 30) as usize);
        entry
            .read_to_end(&mut contents)
            .map_err(|e| DataError::field(name, path.clone(), format!("cannot decompress: {e}")))?;
        files.insert(path, contents);
    }
    if files.is_empty() {
        return Err(DataError::file(
            name,
            "the archive holds no files; expected a .zip of a dataset folder",
        ));
    }
    Ok(rebase_on_dataset_root(files))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{Dataset, fixture};

    #[test]
    fn a_zipped_dataset_folder_reads_back() {
        let dataset = fixture::small_dataset(fixture::FixtureParams::default());
        let files = dataset.to_files().unwrap();
        let bytes = crate::export::write_zip(&files, "my-scan", "scan.zip").unwrap();
        let back = read_zip("scan.zip", &bytes).unwrap();
        assert_eq!(back, files);
        assert_eq!(Dataset::from_files(&back).unwrap(), dataset);
    }

    #[test]
    fn bad_archives_name_the_file() {
        let e = read_zip("notes.zip", b"not a zip at all").unwrap_err();
        assert_eq!(e.file, "notes.zip");
        assert!(e.message.contains("expected a .zip"), "{e}");
        let empty = crate::export::write_zip(&FileSet::new(), "x", "empty.zip");
        if let Ok(bytes) = empty {
            assert!(read_zip("empty.zip", &bytes).is_err());
        }
    }
}
