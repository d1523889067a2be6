//! Helpers shared by the mesh readers: paths inside the file set, checked triangle lists, vertex normals and
//! PNG textures (decoded once per import, under a budget).

use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Arc;

use glam::Vec3;

use crate::data::{DataError, FileSource, RgbaImage, png_claimed_pixels};

/// Pixels all the textures of one import may decode to (1 GiB of RGBA): past it a texture is
/// skipped with a warning, as an unreadable one is.
pub(crate) const MAX_TEXTURE_PIXELS: u64 = 1 << 28;

/// The textures of one import (an object's URDF and every mesh file it names), decoded once per
/// file however many materials name it.
#[derive(Default)]
pub(crate) struct Textures {
    decoded: HashMap<String, Option<Arc<RgbaImage>>>,
    pixels: u64,
}

impl Textures {
    /// The texture `key` (a file key, or a label unique within the import) decoded from `bytes`,
    /// or the one decoded earlier under that key; `None` (with a warning) when it cannot be used.
    pub(crate) fn get<'b>(
        &mut self,
        key: &str,
        bytes: impl FnOnce() -> Option<Cow<'b, [u8]>>,
        warnings: &mut Vec<String>,
    ) -> Option<Arc<RgbaImage>> {
        if let Some(cached) = self.decoded.get(key) {
            return cached.clone();
        }
        let decoded = bytes().and_then(|b| self.decode_within_budget(key, &b, warnings));
        self.decoded.insert(key.to_string(), decoded.clone());
        decoded
    }

    fn decode_within_budget(
        &mut self,
        key: &str,
        bytes: &[u8],
        warnings: &mut Vec<String>,
    ) -> Option<Arc<RgbaImage>> {
        let claimed = png_claimed_pixels(bytes);
        if self.pixels.saturating_add(claimed) > MAX_TEXTURE_PIXELS {
            warnings.push(format!(
                "{key}: texture of {claimed} pixels would take this object's textures past {} MB decoded; using the base colour",
                (4 * MAX_TEXTURE_PIXELS) >> 20
            ));
            return None;
        }
        let image = decode_texture(key, bytes, warnings)?;
        self.pixels += u64::from(image.width) * u64::from(image.height);
        Some(Arc::new(image))
    }
}

/// Folder part of a '/'-separated path, with a trailing '/' (empty for a top-level file).
pub(super) fn folder_of(path: &str) -> &str {
    match path.rfind('/') {
        Some(i) => &path[..=i],
        None => "",
    }
}

/// Joins `rel` to `folder` (which ends with '/' or is empty), resolving `.` and `..`; `None` if the result
/// would leave the file-set root or `rel` is absolute.
pub(crate) fn join_relative(folder: &str, rel: &str) -> Option<String> {
    // Backslashes and ':' (Windows separators and drive letters) would escape the '/'-keyed file set's rules.
    if rel.starts_with('/') || rel.contains('\\') || rel.contains(':') {
        return None;
    }
    let mut parts: Vec<&str> = folder.split('/').filter(|s| !s.is_empty()).collect();
    for piece in rel.split('/') {
        match piece {
            "" | "." => {}
            ".." => {
                parts.pop()?;
            }
            p => parts.push(p),
        }
    }
    if parts.is_empty() {
        return None;
    }
    Some(parts.join("/"))
}

/// Groups a flat index list in threes, checking every index against the vertex count.
pub(super) fn triangles(
    path: &str,
    flat: &[u32],
    vertex_count: usize,
) -> Result<Vec<[u32; 3]>, DataError> {
    let mut out = Vec::with_capacity(flat.len() / 3);
    for t in flat.chunks_exact(3) {
        let tri = [t[0], t[1], t[2]];
        if let Some(bad) = tri.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(DataError::file(
                path,
                format!(
                    "triangle refers to vertex {bad}, but the mesh has {vertex_count} vertices"
                ),
            ));
        }
        out.push(tri);
    }
    Ok(out)
}

/// Area-weighted vertex normals.
pub(super) fn vertex_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in indices {
        let [a, b, c] = t.map(|i| positions.get(i as usize).copied().unwrap_or(Vec3::ZERO));
        let n = (b - a).cross(c - a);
        for &i in t {
            if let Some(slot) = normals.get_mut(i as usize) {
                *slot += n;
            }
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

/// Loads a texture referenced by `referrer`; PNG is decoded (once per import), anything else becomes
/// a warning and `None`.
pub(super) fn load_texture_file(
    referrer: &str,
    folder: &str,
    name: &str,
    files: &dyn FileSource,
    textures: &mut Textures,
    warnings: &mut Vec<String>,
) -> Option<Arc<RgbaImage>> {
    let Some(key) = join_relative(folder, name) else {
        warnings.push(format!(
            "{referrer}: texture '{name}' is outside the dataset; using the base colour"
        ));
        return None;
    };
    let Some(bytes) = files.file(&key) else {
        warnings.push(format!(
            "{referrer}: texture '{key}' not found; using the base colour"
        ));
        return None;
    };
    textures.get(&key, || Some(Cow::Borrowed(bytes)), warnings)
}

/// Decodes PNG texture bytes to RGBA; other formats (JPEG: no decoder in this build) give a warning.
pub(crate) fn decode_texture(
    name: &str,
    bytes: &[u8],
    warnings: &mut Vec<String>,
) -> Option<RgbaImage> {
    const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";
    if !bytes.starts_with(PNG_MAGIC) {
        let kind = if bytes.starts_with(&[0xFF, 0xD8]) {
            "JPEG"
        } else {
            "an unknown format"
        };
        warnings.push(format!(
            "{name}: texture is {kind}; only PNG textures are decoded, using the base colour"
        ));
        return None;
    }
    match image::load_from_memory_with_format(bytes, image::ImageFormat::Png) {
        Ok(img) => {
            let rgba = img.to_rgba8();
            Some(RgbaImage {
                width: rgba.width(),
                height: rgba.height(),
                pixels: rgba.into_raw(),
            })
        }
        Err(e) => {
            warnings.push(format!(
                "{name}: could not decode PNG texture ({e}); using the base colour"
            ));
            None
        }
    }
}
