//! Datasets that are listed before anything is read: a `.zip` (the page accepts a dropped
//! archive), a folder dropped into the page (listed by the page first) and a folder on disk
//! (`fs.rs`). A [`Listing`] picks the files a dataset is made of, the same way for all three, and
//! holds the budgets, so an unrelated huge file beside the dataset costs nothing and a zip bomb
//! or a folder of a million files is refused with an error instead of filling the memory.

use std::collections::{BTreeMap, BTreeSet};
use std::io::{Cursor, Read};

use super::error::Errors;
use super::paths::{self, normalize, rebase_on_dataset_root};
use super::{DataError, FileSet, Split, State};

/// How much a dataset's folder or archive may hold, checked before its files are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FileLimits {
    /// Files (or archive entries) listed, related to the dataset or not.
    pub max_listed: usize,
    /// Bytes of the files the dataset needs together, as they are stored (a zip entry
    /// decompressed); each read is also cut off there, so a size that lies does not get past.
    pub max_bytes: u64,
}

impl Default for FileLimits {
    /// 50 000 files: the paper's largest layout (240 frames, three images each) holds about a
    /// thousand. 8 GiB natively (as `ReadLimits`); 1 GiB in the browser, whose 4 GiB of wasm
    /// memory also holds the decoded images (1.5 GiB) and the fit.
    fn default() -> Self {
        let gib = if cfg!(target_arch = "wasm32") { 1 } else { 8 };
        FileLimits {
            max_listed: 50_000,
            max_bytes: gib << 30,
        }
    }
}

impl FileLimits {
    /// Refuses a folder or archive `name` that lists `count` files, past [`Self::max_listed`].
    pub fn check_listed(&self, name: &str, count: usize) -> Result<(), DataError> {
        if count <= self.max_listed {
            return Ok(());
        }
        Err(DataError::file(
            name,
            format!(
                "holds more than the {} files a dataset may come with ({count} found); expected a dataset folder (transforms files, images, gt/)",
                self.max_listed
            ),
        ))
    }
}

/// Megabytes, as errors show sizes.
fn mb(bytes: u64) -> String {
    format!("{:.0} MB", bytes as f64 / 1e6)
}

/// The files of a dataset folder or archive by path relative to the dataset folder, with their
/// sizes, before any is read; says which of them the dataset needs ([`Listing::needed`]).
#[derive(Debug, Clone)]
pub struct Listing {
    name: String,
    sizes: BTreeMap<String, u64>,
    limits: FileLimits,
}

impl Listing {
    /// The listing of the folder or archive `name` (used in errors): each file's size by its
    /// dataset path. Refuses more than `limits.max_listed` files.
    pub fn new(
        name: &str,
        sizes: BTreeMap<String, u64>,
        limits: FileLimits,
    ) -> Result<Self, DataError> {
        limits.check_listed(name, sizes.len())?;
        Ok(Listing {
            name: name.to_string(),
            sizes,
            limits,
        })
    }

    /// The listed files the dataset needs that are not in `read` yet: first (with nothing read)
    /// the transforms files and `gt/`, then, once they are read, the images the transforms files
    /// name with their depth and semantic siblings; then nothing. Refuses, before anything is
    /// read, when the needed files' listed sizes add up past the budget.
    pub fn needed(&self, read: &FileSet) -> Result<Vec<String>, DataError> {
        let mut wanted: BTreeSet<&str> = self
            .sizes
            .keys()
            .map(String::as_str)
            .filter(|p| super::is_dataset_index(p))
            .collect();
        for path in referenced_paths(read) {
            if let Some((listed, _)) = self.sizes.get_key_value(&path) {
                wanted.insert(listed);
            }
        }
        self.check_budget(&wanted)?;
        Ok(wanted
            .into_iter()
            .filter(|p| !read.contains_key(*p))
            .map(String::from)
            .collect())
    }

    fn check_budget(&self, wanted: &BTreeSet<&str>) -> Result<(), DataError> {
        let size = |p: &str| self.sizes.get(p).copied().unwrap_or(0);
        let total = wanted
            .iter()
            .map(|p| size(p))
            .fold(0u64, u64::saturating_add);
        if total <= self.limits.max_bytes {
            return Ok(());
        }
        let largest = wanted
            .iter()
            .copied()
            .max_by_key(|p| size(p))
            .unwrap_or_default();
        Err(DataError::file(
            &self.name,
            format!(
                "the {} files the dataset needs take {} (the largest: {largest}, {}), over the budget of {} for a dataset's files",
                wanted.len(),
                mb(total),
                mb(size(largest)),
                mb(self.limits.max_bytes)
            ),
        ))
    }

    /// Reads the files the dataset needs with `read(path, at_most)`, which may stop after
    /// `at_most + 1` bytes: a file that turns out larger than what is left of the budget (a zip
    /// entry whose header lies) is refused as soon as that is known.
    pub(crate) fn read(
        &self,
        mut read: impl FnMut(&str, u64) -> Result<Vec<u8>, DataError>,
    ) -> Result<FileSet, DataError> {
        let mut files = FileSet::new();
        let mut total = 0u64;
        loop {
            let wanted = self.needed(&files)?;
            if wanted.is_empty() {
                return Ok(files);
            }
            for path in wanted {
                let left = self.limits.max_bytes.saturating_sub(total);
                let bytes = read(&path, left)?;
                total = total.saturating_add(bytes.len() as u64);
                if bytes.len() as u64 > left {
                    let listed = self.sizes.get(&path).copied().unwrap_or(0);
                    return Err(DataError::field(
                        &self.name,
                        path,
                        format!(
                            "holds more than the {listed} bytes listed for it and more than the {} left of the budget of {} for a dataset's files",
                            mb(left),
                            mb(self.limits.max_bytes)
                        ),
                    ));
                }
                files.insert(path, bytes);
            }
        }
    }
}

/// Every path the transforms files in `files` refer to, with each image's depth and semantic
/// siblings under every name the reader tries. Malformed transforms files contribute what they
/// can; their errors are the reader's to report.
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
                for image in paths::image_candidates(&fs.file_path) {
                    for (kind, exts) in paths::SIBLINGS {
                        wanted.extend(exts.iter().filter_map(|e| paths::sibling(&image, kind, e)));
                    }
                    wanted.insert(image);
                }
            }
        }
    }
    wanted
}

/// Each path's place in the dataset folder ([`rebase_on_dataset_root`]: hidden files and files
/// outside the folder holding the train transforms file left out) → the path as given.
pub fn dataset_paths(given: impl IntoIterator<Item = String>) -> BTreeMap<String, String> {
    // Each file's contents carry its path as given, so it survives the re-rooting.
    let files: FileSet = given
        .into_iter()
        .map(|p| (p.clone(), p.into_bytes()))
        .collect();
    rebase_on_dataset_root(files)
        .into_iter()
        .filter_map(|(path, given)| Some((path, String::from_utf8(given).ok()?)))
        .collect()
}

/// A zip archive read from memory.
pub(super) type MemoryZip<'a> = ::zip::ZipArchive<Cursor<&'a [u8]>>;

/// The files of `archive` (named `name` in errors) by normalised path → (entry index, size by
/// its header); folder entries and macOS `__MACOSX/` resource forks are skipped. An entry whose
/// path is absolute or leaves the archive is an error, as is an unreadable one (`not_zip`).
pub(super) fn zip_entries(
    name: &str,
    archive: &mut MemoryZip,
    not_zip: &dyn Fn(::zip::result::ZipError) -> DataError,
) -> Result<BTreeMap<String, (usize, u64)>, DataError> {
    let mut entries = BTreeMap::new();
    for i in 0..archive.len() {
        let entry = archive.by_index_data(i).map_err(not_zip)?;
        let raw = entry.name().map_err(not_zip)?;
        if entry.is_dir() || raw.starts_with("__MACOSX/") {
            continue;
        }
        let path = normalize(&raw)
            .map_err(|e| DataError::field(name, format!("entry {i}"), e.to_string()))?;
        entries.insert(path, (i, entry.size()));
    }
    Ok(entries)
}

/// The dataset's files in the zip archive `bytes` (named `name` in errors), re-rooted at the
/// dataset folder inside it, within the default [`FileLimits`]: see [`read_zip_within`].
pub fn read_zip(name: &str, bytes: &[u8]) -> Result<FileSet, DataError> {
    read_zip_within(name, bytes, &FileLimits::default())
}

/// The files of the zip archive `bytes` that the dataset inside needs ([`Listing::needed`]),
/// re-rooted at the dataset folder ([`dataset_paths`]); other entries are never decompressed.
/// Folder entries and macOS `__MACOSX/` resource forks are skipped; an entry whose path is
/// absolute or leaves the archive is an error, as is anything that is not a readable zip, an
/// archive of more than `limits.max_listed` entries, and needed entries that decompress past
/// `limits.max_bytes` (by their headers, or while decompressing when a header lies).
pub fn read_zip_within(
    name: &str,
    bytes: &[u8],
    limits: &FileLimits,
) -> Result<FileSet, DataError> {
    let not_zip = |e: ::zip::result::ZipError| {
        DataError::file(
            name,
            format!("cannot read it as a zip archive ({e}); expected a .zip of a dataset folder"),
        )
    };
    let mut archive = ::zip::ZipArchive::new(Cursor::new(bytes)).map_err(not_zip)?;
    limits.check_listed(name, archive.len())?;
    let entries = zip_entries(name, &mut archive, &not_zip)?;
    if entries.is_empty() {
        return Err(DataError::file(
            name,
            "the archive holds no files; expected a .zip of a dataset folder",
        ));
    }
    let rooted = dataset_paths(entries.keys().cloned());
    let entry = |path: &str| rooted.get(path).and_then(|given| entries.get(given));
    let sizes = rooted
        .keys()
        .filter_map(|path| Some((path.clone(), entry(path)?.1)))
        .collect();
    Listing::new(name, sizes, *limits)?.read(|path, at_most| {
        let cannot = |e: &dyn std::fmt::Display| {
            DataError::field(name, path, format!("cannot decompress: {e}"))
        };
        let (index, _) = entry(path).ok_or_else(|| cannot(&"not in the archive"))?;
        let file = archive.by_index(*index).map_err(|e| cannot(&e))?;
        let mut contents = Vec::new();
        file.take(at_most.saturating_add(1))
            .read_to_end(&mut contents)
            .map_err(|e| cannot(&e))?;
        Ok(contents)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{Dataset, fixture};

    fn dataset_files() -> FileSet {
        fixture::small_dataset(fixture::FixtureParams::default())
            .to_files()
            .unwrap()
    }

    /// A zip of `files` under `my-scan/`, plus `copies` entries `my-scan/{stem}{i}.bin` of
    /// `size` zero bytes each.
    fn zip_with(files: &FileSet, stem: &str, copies: usize, size: usize) -> Vec<u8> {
        crate::fixtures::hostile::inputs::zip_with_zeros(files, "my-scan", stem, copies, size)
            .unwrap()
    }

    fn total(files: &FileSet) -> u64 {
        files.values().map(|b| b.len() as u64).sum()
    }

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
    fn unrelated_entries_are_neither_decompressed_nor_counted() {
        let files = dataset_files();
        // 20 entries of 50 MB beside the dataset; the budget leaves room for the dataset only.
        let bytes = zip_with(&files, "capture", 20, 50 << 20);
        let limits = FileLimits {
            max_listed: 100,
            max_bytes: total(&files),
        };
        let back = read_zip_within("scan.zip", &bytes, &limits).unwrap();
        assert_eq!(back, files);
    }

    #[test]
    fn a_zip_bomb_is_refused_by_its_headers() {
        // gt/ is read whole, so a bomb there is needed: 30 entries of 10 MB of zeros (10 kB each).
        let mut files = dataset_files();
        files.retain(|path, _| !path.starts_with("gt/"));
        let bytes = zip_with(&files, "gt/bomb", 30, 10 << 20);
        assert!(bytes.len() < 2 << 20, "{} bytes", bytes.len());
        let limits = FileLimits {
            max_listed: 100,
            max_bytes: 100 << 20,
        };
        let t0 = std::time::Instant::now();
        let e = read_zip_within("bomb.zip", &bytes, &limits).unwrap_err();
        assert!(t0.elapsed().as_secs_f64() < 1.0, "{:?}", t0.elapsed());
        assert_eq!(e.file, "bomb.zip");
        let text = e.to_string();
        assert!(text.contains("take 315 MB"), "{text}");
        assert!(text.contains("gt/bomb"), "{text}");
        assert!(text.contains("over the budget of 105 MB"), "{text}");
    }

    #[test]
    fn an_entry_whose_header_lies_is_cut_off() {
        let transforms = [("transforms_train_start.json".to_string(), b"{}".to_vec())].into();
        let bytes = zip_with(&transforms, "gt/bomb", 1, 20 << 20);
        // The entry's uncompressed size in its local header (8 bytes before its name) and its
        // central header (22 before): 100 bytes.
        let name = b"my-scan/gt/bomb0.bin";
        let at: Vec<usize> = (0..bytes.len() - name.len())
            .filter(|&i| &bytes[i..i + name.len()] == name)
            .collect();
        assert_eq!(at.len(), 2);
        let mut lying = bytes.clone();
        for size in [at[0] - 8, at[1] - 22] {
            lying[size..size + 4].copy_from_slice(&100u32.to_le_bytes());
        }
        let limits = FileLimits {
            max_listed: 100,
            max_bytes: 1 << 20,
        };
        let e = read_zip_within("bomb.zip", &lying, &limits).unwrap_err();
        assert_eq!(e.file, "bomb.zip");
        assert_eq!(e.field.as_deref(), Some("gt/bomb0.bin"), "{e}");
        // The zip crate stops at the declared size; our cut-off would stop at the budget.
        assert!(e.message.contains("larger than its declared"), "{e}");
        // The same entry honestly labelled is refused by its header.
        let e = read_zip_within("bomb.zip", &bytes, &limits).unwrap_err();
        assert!(e.to_string().contains("take 21 MB"), "{e}");
    }

    #[test]
    fn too_many_entries_are_refused_before_any_is_read() {
        let files: FileSet = (0..11).map(|i| (format!("f{i}"), vec![1])).collect();
        let bytes = crate::export::write_zip(&files, "x", "many.zip").unwrap();
        let limits = FileLimits {
            max_listed: 10,
            max_bytes: 1 << 20,
        };
        let e = read_zip_within("many.zip", &bytes, &limits).unwrap_err();
        assert_eq!(e.file, "many.zip");
        assert!(
            e.message
                .contains("more than the 10 files a dataset may come with (11 found)"),
            "{e}"
        );
    }

    #[test]
    fn a_listing_asks_for_the_index_then_the_frames() {
        let files = dataset_files();
        let mut sizes: BTreeMap<String, u64> = files
            .iter()
            .map(|(p, b)| (p.clone(), b.len() as u64))
            .collect();
        sizes.insert("capture.mp4".into(), 4 << 30);
        let listing = Listing::new("scan", sizes, FileLimits::default()).unwrap();
        let index = listing.needed(&FileSet::new()).unwrap();
        assert!(
            index.iter().all(|p| super::super::is_dataset_index(p)),
            "{index:?}"
        );
        let read: FileSet = index
            .iter()
            .map(|p| (p.clone(), files[p].clone()))
            .collect();
        let frames = listing.needed(&read).unwrap();
        let all: BTreeSet<&String> = index.iter().chain(&frames).collect();
        assert_eq!(all, files.keys().collect());
        // A file that grew past its listed size and the budget is cut off while it is read.
        let small = FileLimits {
            max_listed: 100,
            max_bytes: total(&files) + 10,
        };
        let grown = Listing::new("scan", listing.sizes.clone(), small).unwrap();
        let e = grown
            .read(|p, at_most| match p == index[0] {
                true => Ok(vec![0; at_most as usize + 1]),
                false => Ok(files[p].clone()),
            })
            .unwrap_err();
        assert!(e.to_string().contains("holds more than"), "{e}");
        let tight = FileLimits {
            max_listed: 100,
            max_bytes: 1000,
        };
        let sizes = [("gt/trans.json".to_string(), 1001)].into();
        let e = Listing::new("scan", sizes, tight)
            .unwrap()
            .needed(&FileSet::new());
        assert!(e.unwrap_err().to_string().contains("gt/trans.json"));
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

    #[test]
    fn dataset_paths_remember_the_given_names() {
        let given = [
            "top/chair/transforms_train_start.json",
            "top/.DS_Store",
            "top/x",
        ];
        let rooted = dataset_paths(given.map(String::from));
        assert_eq!(
            rooted.into_iter().collect::<Vec<_>>(),
            [(
                "transforms_train_start.json".to_string(),
                given[0].to_string()
            )]
        );
    }
}
