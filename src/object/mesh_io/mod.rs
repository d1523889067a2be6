//! Mesh files from bytes: Wavefront OBJ (+MTL, PNG `map_Kd`), STL (binary or ASCII) and glTF 2.0 (GLB, or
//! `.gltf` JSON with external or `data:` buffers). Every reader returns [`RenderMesh`]es in the file's frame.
//!
//! Untrusted sizes are checked before use (accessor ranges, STL triangle counts, indices), so a corrupt file is
//! an error, never a panic. Problems that still leave a usable mesh (JPEG textures, which the `image` build
//! here cannot decode; a missing MTL or texture file; non-triangle glTF primitives) become warnings.

mod gltf;
mod obj;
mod shared;
mod stl;

use crate::data::{DataError, FileSource};

use super::RenderMesh;
pub(crate) use shared::{Textures, join_relative};

/// Mesh file formats the importer reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront `.obj` (materials from `.mtl`).
    Obj,
    /// `.stl`, binary or ASCII.
    Stl,
    /// Binary glTF `.glb`.
    Glb,
    /// JSON glTF `.gltf`.
    Gltf,
}

impl MeshFormat {
    /// Format from a file name's extension (case-insensitive); `None` for anything else.
    pub(crate) fn from_path(path: &str) -> Option<MeshFormat> {
        let name = path.rsplit('/').next().unwrap_or(path);
        let ext = name.rsplit_once('.')?.1.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(MeshFormat::Obj),
            "stl" => Some(MeshFormat::Stl),
            "glb" => Some(MeshFormat::Glb),
            "gltf" => Some(MeshFormat::Gltf),
            _ => None,
        }
    }
}

/// Reads the mesh file `path` (a key of `files`; its format from the extension). Files it refers to (MTL,
/// textures, glTF buffers) are looked up in `files` relative to its folder. Recoverable problems are pushed to
/// `warnings`. Errors name `path` (or the referenced file at fault).
pub fn load_mesh(
    path: &str,
    files: &dyn FileSource,
    warnings: &mut Vec<String>,
) -> Result<Vec<RenderMesh>, DataError> {
    load_mesh_with(path, files, &mut Textures::default(), warnings)
}

/// [`load_mesh`] within one import: textures already decoded for the object are shared, and its
/// texture budget applies.
pub(crate) fn load_mesh_with(
    path: &str,
    files: &dyn FileSource,
    textures: &mut Textures,
    warnings: &mut Vec<String>,
) -> Result<Vec<RenderMesh>, DataError> {
    let Some(format) = MeshFormat::from_path(path) else {
        let ext = path
            .rsplit('/')
            .next()
            .and_then(|n| n.rsplit_once('.'))
            .map_or("(none)", |(_, e)| e);
        return Err(DataError::file(
            path,
            format!(
                "unsupported mesh format '{ext}': expected .obj, .stl, .glb or .gltf (convert COLLADA .dae and other formats first)"
            ),
        ));
    };
    let Some(bytes) = files.file(path) else {
        return Err(DataError::file(path, "mesh file not found in the dataset"));
    };
    let meshes = match format {
        MeshFormat::Obj => obj::read_obj(path, bytes, files, textures, warnings)?,
        MeshFormat::Stl => stl::read_stl(path, bytes)?,
        MeshFormat::Glb | MeshFormat::Gltf => {
            gltf::read_gltf(path, bytes, files, textures, warnings)?
        }
    };
    if meshes.iter().all(|m| m.indices.is_empty()) {
        return Err(DataError::file(path, "mesh file holds no triangles"));
    }
    Ok(meshes)
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use glam::Vec3;

    use super::gltf::{decode_base64, percent_decode};
    use super::stl::read_stl;
    use super::*;
    use crate::data::FileSet;

    #[test]
    fn object_join_relative_stays_inside() {
        assert_eq!(
            join_relative("a/b/", "../c.obj").as_deref(),
            Some("a/c.obj")
        );
        assert_eq!(join_relative("", "./x/y.stl").as_deref(), Some("x/y.stl"));
        assert_eq!(join_relative("a/", "../../c.obj"), None);
        assert_eq!(join_relative("a/", "/etc/passwd"), None);
    }

    #[test]
    fn object_base64_and_percent() {
        assert_eq!(decode_base64("aGVsbG8=").as_deref(), Some(&b"hello"[..]));
        assert_eq!(decode_base64("aGk"), Some(b"hi".to_vec()));
        assert_eq!(decode_base64("a*"), None);
        assert_eq!(percent_decode("a%20b%zz"), "a b%zz");
    }

    #[test]
    fn object_truncated_stl_is_an_error() {
        let mut bytes = vec![0u8; 84];
        bytes[80..84].copy_from_slice(&1000u32.to_le_bytes());
        let e = read_stl("x.stl", &bytes).unwrap_err();
        assert!(e.message.contains("1000 triangles"), "{e}");
        assert!(read_stl("x.stl", &[1, 2, 3]).is_err());
    }

    #[test]
    fn object_obj_without_mtl_uses_unnamed_material_and_flips_v() {
        let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
        let mut files = FileSet::new();
        files.insert("m/t.obj".into(), obj.to_vec());
        let mut w = Vec::new();
        let meshes = load_mesh("m/t.obj", &files, &mut w).unwrap();
        assert_eq!(meshes.len(), 1);
        assert_eq!(meshes[0].indices, vec![[0, 1, 2]]);
        assert_eq!(meshes[0].material.name, None);
        assert_eq!(meshes[0].uvs.as_ref().unwrap()[0], Vec2::new(0.0, 1.0));
        assert!((meshes[0].normals[0] - Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn object_bad_obj_index_is_an_error_not_a_panic() {
        let mut files = FileSet::new();
        files.insert("t.obj".into(), b"v 0 0 0\nf 1 2 3\n".to_vec());
        assert!(load_mesh("t.obj", &files, &mut Vec::new()).is_err());
    }
}
