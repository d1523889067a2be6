//! Relative-path handling for `file_path` entries and the rgba → depth / semantic sibling rule.

use super::FileSet;

/// Why a `file_path` cannot name a file inside the dataset; each variant holds the path as written.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub(crate) enum PathError {
    /// An absolute path (`/x`, `C:/x`).
    #[error("expected a path relative to the dataset folder, found the absolute path \"{0}\"")]
    Absolute(String),
    /// A path whose `..` climbs above the dataset root.
    #[error("\"{0}\" points outside the dataset folder")]
    Outside(String),
    /// A path with no component left (`./`).
    #[error("expected a path to an image, found \"{0}\"")]
    Empty(String),
}

/// Cleans a `file_path` from a transforms file into a dataset-relative path with `'/'` separators:
/// drops `./` and empty components, accepts `\` separators, resolves `a/../b`. Errors on
/// absolute paths and on paths that leave the dataset root.
pub(crate) fn normalize(raw: &str) -> Result<String, PathError> {
    let unified = raw.replace('\\', "/");
    if unified.starts_with('/') || unified.as_bytes().get(1) == Some(&b':') {
        return Err(PathError::Absolute(raw.to_string()));
    }
    let mut parts: Vec<&str> = Vec::new();
    for part in unified.split('/') {
        match part {
            "" | "." => {}
            ".." => {
                if parts.pop().is_none() {
                    return Err(PathError::Outside(raw.to_string()));
                }
            }
            p => parts.push(p),
        }
    }
    if parts.is_empty() {
        return Err(PathError::Empty(raw.to_string()));
    }
    Ok(parts.join("/"))
}

/// File name without directories and without a `.png` extension: the frame name (`start/train/rgba/0000.png` → `0000`).
pub(crate) fn frame_name(path: &str) -> &str {
    let file = path.rsplit('/').next().unwrap_or(path);
    strip_png(file)
}

fn strip_png(s: &str) -> &str {
    match s.len().checked_sub(4) {
        Some(cut) if s.is_char_boundary(cut) && s[cut..].eq_ignore_ascii_case(".png") => &s[..cut],
        _ => s,
    }
}

/// The optional maps beside a frame's rgba image: each kind's folder name and the extensions
/// tried, in order (depth is index 0, semantic 1 everywhere a reader counts them).
pub(crate) const SIBLINGS: [(&str, &[&str]); 2] =
    [("depth", &[".png"]), ("semantic", &[".png", ".npy"])];

/// The depth or semantic file belonging to an rgba image: the last directory component named `rgba` is replaced
/// by `kind`, and the extension by `ext` (ArtGS does `path.replace('rgba', 'depth')`; we do it per component so
/// a file called `rgba_0.png` is left alone). `None` when the path has no `rgba` directory.
pub(crate) fn sibling(rgba_path: &str, kind: &str, ext: &str) -> Option<String> {
    let mut parts: Vec<&str> = rgba_path.split('/').collect();
    let file = parts.pop()?;
    let dir = parts.iter().rposition(|p| *p == "rgba")?;
    let slot = parts.get_mut(dir)?;
    *slot = kind;
    parts.push(file);
    let joined = parts.join("/");
    Some(format!("{}{}", strip_png(&joined), ext))
}

/// Paths to try for a `file_path` entry: as given when it already ends in `.png`, else with `.png` appended
/// first (ArtGS appends it when missing) and as given second.
pub(crate) fn image_candidates(path: &str) -> Vec<String> {
    if strip_png(path).len() != path.len() {
        vec![path.to_string()]
    } else {
        vec![format!("{path}.png"), path.to_string()]
    }
}

/// Re-roots a file set at the dataset folder: files dropped into a browser carry their top folder
/// (`chair/transforms_train_start.json`). The root is the shallowest folder holding a train transforms file;
/// files outside it are dropped, as are hidden files and folders (`.DS_Store`, `.git/...`) anywhere.
/// Without any train transforms file the set is returned minus hidden entries.
pub fn rebase_on_dataset_root(files: FileSet) -> FileSet {
    let markers = ["transforms_train_start.json", "transforms_train_end.json"];
    let hidden = |k: &str| k.split('/').any(|c| c.starts_with('.'));
    let root = files
        .keys()
        .filter(|k| !hidden(k))
        .filter_map(|k| {
            markers.iter().find_map(|m| {
                let prefix = k.strip_suffix(m)?;
                (prefix.is_empty() || prefix.ends_with('/')).then(|| prefix.to_string())
            })
        })
        .min_by_key(|p| (p.matches('/').count(), p.clone()))
        .unwrap_or_default();
    files
        .into_iter()
        .filter_map(|(k, v)| Some((k.strip_prefix(root.as_str())?.to_string(), v)))
        .filter(|(k, _)| !k.is_empty() && !hidden(k))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rebase_strips_the_dropped_folder() {
        let files: FileSet = [
            "chair/transforms_train_start.json",
            "chair/start/train/rgba/0000.png",
            "chair/.DS_Store",
            "other.txt",
        ]
        .into_iter()
        .map(|k| (k.to_string(), vec![]))
        .collect();
        let keys: Vec<String> = rebase_on_dataset_root(files).into_keys().collect();
        assert_eq!(
            keys,
            ["start/train/rgba/0000.png", "transforms_train_start.json"]
        );
        let flat: FileSet = [
            ("transforms_train_end.json".to_string(), vec![]),
            (".x".to_string(), vec![]),
        ]
        .into();
        assert_eq!(rebase_on_dataset_root(flat).len(), 1);
    }

    #[test]
    fn normalize_handles_dots_and_rejects_escapes() {
        assert_eq!(
            normalize("./start/train/rgba/0000").unwrap(),
            "start/train/rgba/0000"
        );
        assert_eq!(normalize("a\\b/../c.png").unwrap(), "a/c.png");
        assert!(
            normalize("../x")
                .unwrap_err()
                .to_string()
                .contains("outside")
        );
        assert!(normalize("a/../../x").is_err());
        assert!(
            normalize("/etc/passwd")
                .unwrap_err()
                .to_string()
                .contains("absolute")
        );
        assert!(normalize("C:/x.png").is_err());
        assert!(normalize("./").is_err());
    }

    #[test]
    fn siblings_replace_the_rgba_directory() {
        assert_eq!(
            sibling("start/train/rgba/0000.png", "depth", ".png").unwrap(),
            "start/train/depth/0000.png"
        );
        assert_eq!(
            sibling("rgba/x/rgba/r.png", "semantic", ".npy").unwrap(),
            "rgba/x/semantic/r.npy"
        );
        assert_eq!(
            sibling("start/train/rgba/0000", "depth", ".png").unwrap(),
            "start/train/depth/0000.png"
        );
        assert_eq!(sibling("train/rgba_0.png", "depth", ".png"), None);
        assert_eq!(frame_name("a/b/0007.PNG"), "0007");
        assert_eq!(frame_name("r_0"), "r_0");
        assert_eq!(
            image_candidates("a/0"),
            vec!["a/0.png".to_string(), "a/0".to_string()]
        );
    }
}
