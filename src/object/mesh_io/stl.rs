//! STL reader (binary or ASCII): one mesh with flat per-face normals and no material of its own.

use std::io::Cursor;

use glam::Vec3;

use crate::data::DataError;
use crate::object::{Material, RenderMesh};

/// Reads a binary or ASCII STL file; a binary triangle count larger than the file is an error.
pub(super) fn read_stl(path: &str, bytes: &[u8]) -> Result<Vec<RenderMesh>, DataError> {
    // Binary STL: 80-byte header, u32 count, 50 bytes per triangle. Check the count against the size first so
    // a corrupt count cannot trigger a huge allocation. Some binary files start with "solid" too, so only
    // text that parses as ASCII is treated as ASCII.
    let is_ascii = bytes.starts_with(b"solid")
        && bytes
            .get(..bytes.len().min(512))
            .is_some_and(|h| h.iter().all(|b| b.is_ascii()));
    if !is_ascii {
        let count = bytes
            .get(80..84)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as u64)
            .ok_or_else(|| DataError::file(path, "STL file shorter than its 84-byte header"))?;
        let need = 84 + 50 * count;
        if (bytes.len() as u64) < need {
            return Err(DataError::file(
                path,
                format!(
                    "binary STL declares {count} triangles ({need} bytes), but the file has {} bytes",
                    bytes.len()
                ),
            ));
        }
    }
    let mesh = stl_io::read_stl(&mut Cursor::new(bytes))
        .map_err(|e| DataError::file(path, format!("could not read STL: {e}")))?;
    // Split vertices per face: STL models are mostly hard-edged, so flat normals look right.
    let mut positions = Vec::with_capacity(mesh.faces.len() * 3);
    let mut normals = Vec::with_capacity(mesh.faces.len() * 3);
    let mut indices = Vec::with_capacity(mesh.faces.len());
    for face in &mesh.faces {
        let mut corners = [Vec3::ZERO; 3];
        for (corner, &v) in corners.iter_mut().zip(face.vertices.iter()) {
            let p = mesh.vertices.get(v).ok_or_else(|| {
                DataError::file(path, format!("triangle refers to missing vertex {v}"))
            })?;
            *corner = Vec3::from_array(p.0);
        }
        let n = (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .normalize_or_zero();
        let base = positions.len() as u32;
        positions.extend_from_slice(&corners);
        normals.extend_from_slice(&[n; 3]);
        indices.push([base, base + 1, base + 2]);
    }
    Ok(vec![RenderMesh {
        positions,
        normals,
        uvs: None,
        colors: None,
        indices,
        material: Material {
            name: None,
            ..Material::default()
        },
    }])
}
