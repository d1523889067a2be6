//! File references in a URDF: paths relative to the URDF, `package://NAME/...` through the dataset's
//! `package.xml` files; anything that would leave the dataset is an error.

use std::collections::HashMap;

use roxmltree::Node;

use crate::data::{DataError, FileSource};
use crate::object::mesh_io::join_relative;

use super::reader::{Reader, child};

/// Why a `package://NAME/...` reference names no single package folder.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
enum PackageError {
    /// No `package.xml` declares the name.
    #[error(
        "no package.xml in the dataset declares <name>{0}</name> (needed for package://{0}/...)"
    )]
    Undeclared(String),
    /// Several do, and none of their folders contains the URDF.
    #[error(
        "package '{name}' is declared by several package.xml files ({folders}) and none contains the URDF"
    )]
    Ambiguous {
        /// The package name.
        name: String,
        /// The declaring folders, comma-separated.
        folders: String,
    },
}

impl Reader<'_, '_> {
    /// Resolves a URDF file reference to a key of the file set.
    pub(super) fn resolve(
        &mut self,
        filename: &str,
        node: Node,
        path: &str,
    ) -> Result<String, DataError> {
        let bad = |cx: &Self, msg: String| cx.err(node, path, Some("filename"), msg);
        if let Some(rest) = filename.strip_prefix("package://") {
            let Some((package, rel)) = rest.split_once('/') else {
                return Err(bad(
                    self,
                    format!("expected 'package://NAME/path', found {filename:?}"),
                ));
            };
            let folder = self
                .package_folder(package)
                .map_err(|m| bad(self, m.to_string()))?;
            return join_relative(&folder, rel)
                .ok_or_else(|| bad(self, format!("'{filename}' leaves the dataset folder")));
        }
        if filename.starts_with("file://") || filename.starts_with('/') {
            return Err(bad(
                self,
                format!(
                    "absolute path {filename:?} points outside the dataset: use a path relative to the URDF or package://"
                ),
            ));
        }
        if let Some((scheme, _)) = filename.split_once("://") {
            return Err(bad(
                self,
                format!(
                    "unsupported URI scheme '{scheme}://': expected a relative path or package://"
                ),
            ));
        }
        join_relative(self.folder, filename).ok_or_else(|| {
            bad(
                self,
                format!(
                    "'{filename}' leaves the dataset folder (relative to '{}')",
                    self.folder
                ),
            )
        })
    }

    /// Folder (with trailing '/') of the package named `name`: the `package.xml` declaring it; when several do,
    /// the one closest above the URDF.
    fn package_folder(&mut self, name: &str) -> Result<String, PackageError> {
        let packages = self
            .packages
            .get_or_insert_with(|| find_packages(self.files));
        let Some(folders) = packages.get(name) else {
            return Err(PackageError::Undeclared(name.to_string()));
        };
        let above: Vec<&String> = folders
            .iter()
            .filter(|f| self.folder.starts_with(f.as_str()))
            .collect();
        match (folders.as_slice(), above.iter().max_by_key(|f| f.len())) {
            ([only], _) => Ok(only.clone()),
            (_, Some(best)) => Ok((*best).clone()),
            _ => Err(PackageError::Ambiguous {
                name: name.to_string(),
                folders: folders.join(", "),
            }),
        }
    }
}

/// package name → folders (with trailing '/') of every `package.xml` in the file set that names it.
fn find_packages(files: &dyn FileSource) -> HashMap<String, Vec<String>> {
    let mut out: HashMap<String, Vec<String>> = HashMap::new();
    for key in files.paths() {
        let folder = if key == "package.xml" {
            ""
        } else if let Some(f) = key.strip_suffix("/package.xml") {
            f
        } else {
            continue;
        };
        let Some(bytes) = files.file(key) else {
            continue;
        };
        let Ok(text) = std::str::from_utf8(bytes) else {
            continue;
        };
        let Ok(doc) = roxmltree::Document::parse(text) else {
            continue;
        };
        let Some(name) = child(doc.root_element(), "name").and_then(|n| n.text()) else {
            continue;
        };
        let folder = if folder.is_empty() {
            String::new()
        } else {
            format!("{folder}/")
        };
        out.entry(name.trim().to_string()).or_default().push(folder);
    }
    out
}
