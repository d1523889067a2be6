//! Wavefront OBJ reader: geometry through `tobj`, materials from the `.mtl` library, PNG `map_Kd` textures.
//! OBJ's `v` texture coordinate is flipped so that `v = 0` is the top row, as in glTF.

use std::borrow::Cow;
use std::io::{BufReader, Cursor};

use glam::{Vec2, Vec3};

use crate::data::{DataError, FileSource};
use crate::object::{Material, RenderMesh};

use super::shared::{
    Textures, folder_of, join_relative, load_texture_file, triangles, vertex_normals,
};

/// Reads an OBJ file and the MTL library and textures it names (looked up in `files` next to it).
pub(super) fn read_obj(
    path: &str,
    bytes: &[u8],
    files: &dyn FileSource,
    textures: &mut Textures,
    warnings: &mut Vec<String>,
) -> Result<Vec<RenderMesh>, DataError> {
    let folder = folder_of(path);
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // The loader closure is `Fn`; collect its notes and the MTL's location through cells.
    let notes = std::cell::RefCell::new(Vec::<String>::new());
    let mtl_folder = std::cell::RefCell::new(folder.to_string());
    let loader = |mtl: &std::path::Path| -> tobj::MTLLoadResult {
        let name = mtl.to_string_lossy();
        let Some(key) = join_relative(folder, &name) else {
            notes.borrow_mut().push(format!(
                "{path}: material library '{name}' is outside the dataset; using plain colours"
            ));
            return Err(tobj::LoadError::OpenFileFailed);
        };
        let Some(data) = files.file(&key) else {
            notes.borrow_mut().push(format!(
                "{path}: material library '{key}' not found; using plain colours"
            ));
            return Err(tobj::LoadError::OpenFileFailed);
        };
        *mtl_folder.borrow_mut() = folder_of(&key).to_string();
        let data = full_colours(data);
        tobj::load_mtl_buf(&mut BufReader::new(Cursor::new(&data[..]))).inspect_err(|e| {
            notes.borrow_mut().push(format!(
                "{key}: could not read material library ({e}); using plain colours"
            ));
        })
    };
    let (models, materials) =
        tobj::load_obj_buf(&mut BufReader::new(Cursor::new(bytes)), &options, loader)
            .map_err(|e| DataError::file(path, format!("could not read OBJ: {e}")))?;
    warnings.extend(notes.into_inner());
    let materials = materials.unwrap_or_default();
    let tex_folder = mtl_folder.into_inner();

    // Each material once, even when many groups use it; each texture once, even when many
    // materials name it.
    let mut decoded: Vec<Material> = Vec::with_capacity(materials.len());
    for m in &materials {
        let d = m.diffuse.unwrap_or([0.7, 0.7, 0.7]);
        let alpha = m.dissolve.unwrap_or(1.0);
        let texture = m
            .diffuse_texture
            .as_deref()
            .and_then(|t| load_texture_file(path, &tex_folder, t, files, textures, warnings));
        decoded.push(Material {
            name: Some(m.name.clone()),
            base_color: [d[0], d[1], d[2], alpha],
            texture,
        });
    }

    let mut out = Vec::with_capacity(models.len());
    for model in models {
        let mesh = model.mesh;
        let n = mesh.positions.len() / 3;
        let positions: Vec<Vec3> = mesh
            .positions
            .chunks_exact(3)
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect();
        let indices = triangles(path, &mesh.indices, n)?;
        if indices.is_empty() {
            continue;
        }
        let normals = if mesh.normals.len() == mesh.positions.len() {
            mesh.normals
                .chunks_exact(3)
                .map(|v| Vec3::new(v[0], v[1], v[2]).normalize_or_zero())
                .collect()
        } else {
            vertex_normals(&positions, &indices)
        };
        let uvs = (mesh.texcoords.len() == 2 * n).then(|| {
            mesh.texcoords
                .chunks_exact(2)
                .map(|t| Vec2::new(t[0], 1.0 - t[1]))
                .collect()
        });
        let colors = (mesh.vertex_color.len() == 3 * n).then(|| {
            mesh.vertex_color
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect()
        });
        let material = mesh
            .material_id
            .and_then(|i| decoded.get(i).cloned())
            .unwrap_or(Material {
                name: None,
                ..Material::default()
            });
        out.push(RenderMesh {
            positions,
            normals,
            uvs,
            colors,
            indices,
            material,
        });
    }
    Ok(out)
}

/// The MTL text with every `Ka`/`Kd`/`Ks`/`Ke` colour given as three numbers. The format lets
/// `g` and `b` be left out (they then equal `r`); tobj panics on such a line instead, and on one
/// with no number at all, which is dropped.
fn full_colours(mtl: &[u8]) -> Cow<'_, [u8]> {
    let short = |line: &str| -> Option<String> {
        let mut words = line.split_whitespace();
        let key = words.next()?;
        let rgb: Vec<&str> = words.collect();
        let numbers = rgb.iter().all(|w| w.parse::<f32>().is_ok());
        if !matches!(key, "Ka" | "Kd" | "Ks" | "Ke") || !numbers || rgb.len() >= 3 {
            return None;
        }
        // No number at all: the colour is not given (the line is dropped).
        Some(rgb.first().map_or(String::new(), |r| {
            format!("{key} {r} {} {r}", rgb.get(1).unwrap_or(r))
        }))
    };
    // Line by line on bytes: a line that is not UTF-8 (tobj's error to report) must not stop the
    // lines before it from being completed.
    let fixed = |line: &[u8]| std::str::from_utf8(line).ok().and_then(short);
    if !mtl.split(|&b| b == b'\n').any(|l| fixed(l).is_some()) {
        return Cow::Borrowed(mtl);
    }
    let lines: Vec<Vec<u8>> = mtl
        .split(|&b| b == b'\n')
        .map(|l| fixed(l).map_or_else(|| l.to_vec(), String::into_bytes))
        .collect();
    Cow::Owned(lines.join(&b'\n'))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_mtl_colours_are_completed() {
        let mtl = b"newmtl a\nKd 0.7\nKa 0.1 0.2\nKs 1 1 1\nKe spectral x.rfl\nKe\n";
        let full = full_colours(mtl);
        assert_eq!(
            std::str::from_utf8(&full).unwrap(),
            "newmtl a\nKd 0.7 0.7 0.7\nKa 0.1 0.2 0.1\nKs 1 1 1\nKe spectral x.rfl\n\n"
        );
        // tobj reads the completed colours (it refuses the spectral form, as before: an error).
        let readable = full_colours(b"newmtl a\nKd 0.7\n");
        let materials = tobj::load_mtl_buf(&mut BufReader::new(Cursor::new(&readable[..])));
        assert_eq!(materials.unwrap().0[0].diffuse, Some([0.7; 3]));
    }
}
