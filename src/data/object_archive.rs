//! An object, not a dataset, in a `.zip`: a URDF with its meshes and textures, which the page
//! imports and captures itself. [`zip_holds_object`] tells the two kinds of archive apart by their
//! entry names alone; [`read_zip_object`] reads an object's archive within the same
//! [`FileLimits`] as a dataset's, so a zip bomb is refused instead of filling the memory.

use std::io::{Cursor, Read};

use super::archive::{MemoryZip, zip_entries};
use super::{DataError, FileLimits, FileSet, Split, State, transforms_file_name};

/// Whether `path` names a URDF file (any case of the extension).
pub fn is_urdf_path(path: &str) -> bool {
    path.rsplit_once('.')
        .is_some_and(|(_, ext)| ext.eq_ignore_ascii_case("urdf"))
}

/// Whether the zip archive `bytes` holds an object rather than a dataset: a `.urdf` file and no
/// dataset transforms file (a zipped `artmesh synth` folder holds both and is a dataset). Only the
/// entry names are read; an archive that cannot be read holds no object (the dataset reader then
/// says what is wrong with it).
pub fn zip_holds_object(bytes: &[u8]) -> bool {
    let Ok(archive) = MemoryZip::new(Cursor::new(bytes)) else {
        return false;
    };
    let transforms: Vec<String> = State::ALL
        .into_iter()
        .flat_map(|state| Split::ALL.map(|split| transforms_file_name(split, state)))
        .collect();
    let mut urdf = false;
    for name in archive.file_names() {
        let Ok(name) = name else { continue };
        if name.starts_with("__MACOSX/") || name.ends_with('/') {
            continue;
        }
        let file = name.rsplit('/').next().unwrap_or(&name);
        if transforms.iter().any(|t| t == file) {
            return false;
        }
        urdf |= is_urdf_path(file);
    }
    urdf
}

/// Every file of the zip archive `bytes` (named `name` in errors) by its path in the archive: an
/// object's URDF, meshes, textures and `package.xml` files, which the URDF names in ways only the
/// importer knows (relative paths, `package://`), so all are read. Refused, before anything is
/// decompressed, past `limits.max_listed` entries or when the entries' sizes by their headers add
/// up past `limits.max_bytes`; an entry whose header lies is cut off at what is left of the budget.
pub fn read_zip_object(
    name: &str,
    bytes: &[u8],
    limits: &FileLimits,
) -> Result<FileSet, DataError> {
    let not_zip = |e: ::zip::result::ZipError| {
        DataError::file(
            name,
            format!(
                "cannot read it as a zip archive ({e}); expected a .zip of a URDF with its meshes"
            ),
        )
    };
    let mut archive = MemoryZip::new(Cursor::new(bytes)).map_err(not_zip)?;
    limits.check_listed(name, archive.len())?;
    let entries = zip_entries(name, &mut archive, &not_zip)?;
    let listed = entries
        .values()
        .map(|(_, size)| *size)
        .fold(0u64, u64::saturating_add);
    let mb = |b: u64| format!("{:.0} MB", b as f64 / 1e6);
    if listed > limits.max_bytes {
        return Err(DataError::file(
            name,
            format!(
                "its {} files take {} unpacked, over the budget of {} for an object's files",
                entries.len(),
                mb(listed),
                mb(limits.max_bytes)
            ),
        ));
    }
    let mut files = FileSet::new();
    let mut total = 0u64;
    for (path, (index, _)) in entries {
        let cannot = |e: &dyn std::fmt::Display| {
            DataError::field(name, path.as_str(), format!("cannot decompress: {e}"))
        };
        let left = limits.max_bytes - total;
        let mut contents = Vec::new();
        archive
            .by_index(index)
            .map_err(|e| cannot(&e))?
            .take(left.saturating_add(1))
            .read_to_end(&mut contents)
            .map_err(|e| cannot(&e))?;
        if contents.len() as u64 > left {
            return Err(DataError::field(
                name,
                path,
                format!(
                    "holds more than its header says and more than the {} left of the budget of {} for an object's files",
                    mb(left),
                    mb(limits.max_bytes)
                ),
            ));
        }
        total += contents.len() as u64;
        files.insert(path, contents);
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::write_zip;

    fn urdf_files() -> FileSet {
        let mut files = FileSet::new();
        files.insert("robot.urdf".into(), b"<robot name=\"r\"/>".to_vec());
        files.insert("meshes/a.obj".into(), b"v 0 0 0\n".to_vec());
        files
    }

    #[test]
    fn an_object_zip_is_told_from_a_dataset_zip() {
        let object = write_zip(&urdf_files(), "cab", "cab.zip").unwrap();
        assert!(zip_holds_object(&object));
        let mut dataset = urdf_files();
        dataset.insert("transforms_train_start.json".into(), b"{}".to_vec());
        assert!(!zip_holds_object(
            &write_zip(&dataset, "d", "d.zip").unwrap()
        ));
        let mut meshes = urdf_files();
        meshes.remove("robot.urdf");
        assert!(!zip_holds_object(
            &write_zip(&meshes, "m", "m.zip").unwrap()
        ));
        assert!(!zip_holds_object(b"not a zip"));
    }

    #[test]
    fn an_object_zip_reads_whole_and_within_budget() {
        let bytes = write_zip(&urdf_files(), "cab", "cab.zip").unwrap();
        let files = read_zip_object("cab.zip", &bytes, &FileLimits::default()).unwrap();
        let paths: Vec<&str> = files.keys().map(String::as_str).collect();
        assert_eq!(paths, ["cab/meshes/a.obj", "cab/robot.urdf"]);
        let tight = FileLimits {
            max_listed: 10,
            max_bytes: 10,
        };
        let e = read_zip_object("cab.zip", &bytes, &tight).unwrap_err();
        assert!(e.to_string().contains("over the budget"), "{e}");
        let e = read_zip_object("x.zip", b"nope", &FileLimits::default()).unwrap_err();
        assert!(e.to_string().starts_with("x.zip: cannot read"), "{e}");
    }
}
