//! A [`FileSet`] as one zip archive (the twin's download), with every path checked so that
//! unpacking it cannot write outside the folder it is unpacked in.

use std::io::Write as _;

use zip::write::SimpleFileOptions;

use crate::data::{DataError, FileSet};

/// Why `path` may not be stored in an archive (`None` when it may): relative, `/`-separated, no
/// empty, `.` or `..` components, no backslashes, drive letters or control characters.
pub(crate) fn unsafe_path(path: &str) -> Option<&'static str> {
    if path.is_empty() {
        return Some("the path is empty");
    }
    if path.starts_with('/') {
        return Some("the path is absolute");
    }
    if path.contains('\\') {
        return Some("the path has a backslash (a folder separator on Windows)");
    }
    if path.contains(':') {
        return Some("the path has a ':' (a drive letter on Windows)");
    }
    if path.chars().any(char::is_control) {
        return Some("the path has a control character");
    }
    if path
        .split('/')
        .any(|c| c.is_empty() || c == "." || c == "..")
    {
        return Some("the path has an empty, '.' or '..' component");
    }
    None
}

/// `files` zipped (deflate), each under `folder/` (itself checked like a path). `archive` names the
/// zip in errors. Entry times are fixed (1980-01-01), so equal inputs give equal bytes.
pub fn write_zip(files: &FileSet, folder: &str, archive: &str) -> Result<Vec<u8>, DataError> {
    if let Some(why) = unsafe_path(folder) {
        return Err(DataError::field(archive, folder, why));
    }
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    let failed = |path: &str, e: &dyn std::fmt::Display| {
        DataError::field(archive, path, format!("could not add it to the zip: {e}"))
    };
    for (path, bytes) in files {
        if let Some(why) = unsafe_path(path) {
            return Err(DataError::field(archive, path.as_str(), why));
        }
        let name = format!("{folder}/{path}");
        zip.start_file(name.as_str(), options)
            .map_err(|e| failed(&name, &e))?;
        zip.write_all(bytes).map_err(|e| failed(&name, &e))?;
    }
    let cursor = zip
        .finish()
        .map_err(|e| DataError::file(archive, format!("could not finish the zip: {e}")))?;
    Ok(cursor.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_paths_are_refused() {
        for bad in [
            "",
            "/etc/passwd",
            "../x",
            "a/../../x",
            "a//b",
            "./a",
            "a\\b",
            "C:/x",
            "a\u{0}b",
        ] {
            assert!(unsafe_path(bad).is_some(), "{bad:?}");
            let mut files = FileSet::new();
            files.insert(bad.into(), vec![1]);
            let err = write_zip(&files, "twin", "twin.zip").unwrap_err();
            assert_eq!(err.file, "twin.zip");
            assert!(
                write_zip(&FileSet::new(), bad, "twin.zip").is_err(),
                "{bad:?}"
            );
        }
        for good in ["a", "meshes/part_1.obj", "Tür & <Tor>/ü.obj", "a.b/c..d"] {
            assert_eq!(unsafe_path(good), None, "{good:?}");
        }
    }

    #[test]
    fn archive_reads_back_under_its_folder() {
        let mut files = FileSet::new();
        files.insert("twin.urdf".into(), b"<robot/>".to_vec());
        files.insert("meshes/a.obj".into(), vec![7; 5000]);
        let bytes = write_zip(&files, "twin", "twin.zip").unwrap();
        assert_eq!(bytes, write_zip(&files, "twin", "twin.zip").unwrap());
        let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
        let mut names: Vec<String> = zip.file_names().map(|n| n.unwrap().to_string()).collect();
        names.sort();
        assert_eq!(names, ["twin/meshes/a.obj", "twin/twin.urdf"]);
        let mut back = Vec::new();
        std::io::Read::read_to_end(&mut zip.by_name("twin/meshes/a.obj").unwrap(), &mut back)
            .unwrap();
        assert_eq!(back, vec![7; 5000]);
        for i in 0..zip.len() {
            assert!(zip.by_index(i).unwrap().enclosed_name().is_some());
        }
    }
}
