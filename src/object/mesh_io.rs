//! Mesh files from bytes: Wavefront OBJ (+MTL, PNG `map_Kd`), STL (binary or ASCII) and glTF 2.0 (GLB, or
//! `.gltf` JSON with external or `data:` buffers). Every reader returns [`RenderMesh`]es in the file's frame.
//!
//! Untrusted sizes are checked before use (accessor ranges, STL triangle counts, indices), so a corrupt file is
//! an error, never a panic. Problems that still leave a usable mesh (JPEG textures, which the `image` build
//! here cannot decode; a missing MTL or texture file; non-triangle glTF primitives) become warnings.

use std::collections::HashMap;
use std::io::{BufReader, Cursor};
use std::sync::Arc;

use glam::{Affine3A, Mat4, Vec2, Vec3};

use crate::data::{DataError, FileSet, RgbaImage};

use super::{Material, RenderMesh};

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
    pub fn from_path(path: &str) -> Option<MeshFormat> {
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
    files: &FileSet,
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
    let Some(bytes) = files.get(path) else {
        return Err(DataError::file(path, "mesh file not found in the dataset"));
    };
    let meshes = match format {
        MeshFormat::Obj => read_obj(path, bytes, files, warnings)?,
        MeshFormat::Stl => read_stl(path, bytes)?,
        MeshFormat::Glb | MeshFormat::Gltf => read_gltf(path, bytes, files, warnings)?,
    };
    if meshes.iter().all(|m| m.indices.is_empty()) {
        return Err(DataError::file(path, "mesh file holds no triangles"));
    }
    Ok(meshes)
}

/// Folder part of a '/'-separated path, with a trailing '/' (empty for a top-level file).
fn folder_of(path: &str) -> &str {
    match path.rfind('/') {
        Some(i) => &path[..=i],
        None => "",
    }
}

/// Joins `rel` to `folder` (which ends with '/' or is empty), resolving `.` and `..`; `None` if the result
/// would leave the file-set root or `rel` is absolute.
pub(super) fn join_relative(folder: &str, rel: &str) -> Option<String> {
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

// ---------------------------------------------------------------------------------------------- OBJ

fn read_obj(
    path: &str,
    bytes: &[u8],
    files: &FileSet,
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
        let Some(data) = files.get(&key) else {
            notes.borrow_mut().push(format!(
                "{path}: material library '{key}' not found; using plain colours"
            ));
            return Err(tobj::LoadError::OpenFileFailed);
        };
        *mtl_folder.borrow_mut() = folder_of(&key).to_string();
        tobj::load_mtl_buf(&mut BufReader::new(Cursor::new(data))).inspect_err(|e| {
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

    // Decode each material once, even when many groups use it.
    let mut decoded: Vec<Material> = Vec::with_capacity(materials.len());
    for m in &materials {
        let d = m.diffuse.unwrap_or([0.7, 0.7, 0.7]);
        let alpha = m.dissolve.unwrap_or(1.0);
        let texture = m
            .diffuse_texture
            .as_deref()
            .and_then(|t| load_texture_file(path, &tex_folder, t, files, warnings).map(Arc::new));
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

/// Groups a flat index list in threes, checking every index against the vertex count.
fn triangles(path: &str, flat: &[u32], vertex_count: usize) -> Result<Vec<[u32; 3]>, DataError> {
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
fn vertex_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
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

/// Loads a texture referenced by `referrer`; PNG is decoded, anything else becomes a warning and `None`.
fn load_texture_file(
    referrer: &str,
    folder: &str,
    name: &str,
    files: &FileSet,
    warnings: &mut Vec<String>,
) -> Option<RgbaImage> {
    let Some(key) = join_relative(folder, name) else {
        warnings.push(format!(
            "{referrer}: texture '{name}' is outside the dataset; using the base colour"
        ));
        return None;
    };
    let Some(bytes) = files.get(&key) else {
        warnings.push(format!(
            "{referrer}: texture '{key}' not found; using the base colour"
        ));
        return None;
    };
    decode_texture(&key, bytes, warnings)
}

/// Decodes PNG texture bytes to RGBA; other formats (JPEG: no decoder in this build) give a warning.
pub(super) fn decode_texture(
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

// ---------------------------------------------------------------------------------------------- STL

fn read_stl(path: &str, bytes: &[u8]) -> Result<Vec<RenderMesh>, DataError> {
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

// ---------------------------------------------------------------------------------------------- glTF

/// Nodes nested deeper than this are rejected (guards against cyclic node graphs).
const MAX_NODE_DEPTH: usize = 64;

fn read_gltf(
    path: &str,
    bytes: &[u8],
    files: &FileSet,
    warnings: &mut Vec<String>,
) -> Result<Vec<RenderMesh>, DataError> {
    let gltf = gltf::Gltf::from_slice(bytes)
        .map_err(|e| DataError::file(path, format!("could not read glTF: {e}")))?;
    let folder = folder_of(path);
    let buffers = load_buffers(path, folder, &gltf, files)?;
    let mut reader = GltfReader {
        path,
        folder,
        gltf: &gltf,
        buffers,
        files,
        images: HashMap::new(),
        out: Vec::new(),
    };
    let scene = gltf.default_scene().or_else(|| gltf.scenes().next());
    match scene {
        Some(scene) => {
            for node in scene.nodes() {
                reader.node(&node, Mat4::IDENTITY, 0, warnings)?;
            }
        }
        // No scene: every mesh at the identity.
        None => {
            for mesh in gltf.meshes() {
                reader.mesh(&mesh, &Affine3A::IDENTITY, warnings)?;
            }
        }
    }
    Ok(reader.out)
}

fn load_buffers(
    path: &str,
    folder: &str,
    gltf: &gltf::Gltf,
    files: &FileSet,
) -> Result<Vec<Vec<u8>>, DataError> {
    let mut out = Vec::new();
    for buffer in gltf.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| {
                DataError::file(
                    path,
                    "glTF buffer refers to the GLB binary chunk, which is missing",
                )
            })?,
            gltf::buffer::Source::Uri(uri) => load_uri(path, folder, uri, files)?,
        };
        if data.len() < buffer.length() {
            return Err(DataError::file(
                path,
                format!(
                    "glTF buffer {} declares {} bytes but holds {}",
                    buffer.index(),
                    buffer.length(),
                    data.len()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// Bytes of a glTF URI: a `data:...;base64,` URI or a file relative to the glTF's folder.
fn load_uri(path: &str, folder: &str, uri: &str, files: &FileSet) -> Result<Vec<u8>, DataError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err(DataError::file(
                path,
                "glTF data URI is not base64-encoded (expected 'data:<type>;base64,...')",
            ));
        };
        return decode_base64(payload)
            .ok_or_else(|| DataError::file(path, "glTF data URI holds invalid base64"));
    }
    let key = join_relative(folder, &percent_decode(uri)).ok_or_else(|| {
        DataError::file(
            path,
            format!("glTF URI '{uri}' is absolute or leaves the dataset; expected a relative path"),
        )
    })?;
    files.get(&key).cloned().ok_or_else(|| {
        DataError::file(
            path,
            format!("glTF refers to '{key}', which is not in the dataset"),
        )
    })
}

fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        if b == b'%'
            && let Some(hex) = bytes.get(i + 1..i + 3)
            && let Ok(h) = std::str::from_utf8(hex)
            && let Ok(v) = u8::from_str_radix(h, 16)
        {
            out.push(v);
            i += 3;
        } else {
            out.push(b);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn decode_base64(s: &str) -> Option<Vec<u8>> {
    fn value(c: u8) -> Option<u32> {
        match c {
            b'A'..=b'Z' => Some(u32::from(c - b'A')),
            b'a'..=b'z' => Some(u32::from(c - b'a') + 26),
            b'0'..=b'9' => Some(u32::from(c - b'0') + 52),
            b'+' | b'-' => Some(62),
            b'/' | b'_' => Some(63),
            _ => None,
        }
    }
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    let mut acc = 0u32;
    let mut bits = 0u32;
    for &c in s.as_bytes() {
        if c == b'=' {
            break;
        }
        if c.is_ascii_whitespace() {
            continue;
        }
        acc = (acc << 6) | value(c)?;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

struct GltfReader<'a> {
    path: &'a str,
    folder: &'a str,
    gltf: &'a gltf::Gltf,
    buffers: Vec<Vec<u8>>,
    files: &'a FileSet,
    /// Decoded images by index (`None`: could not decode, already warned).
    images: HashMap<usize, Option<Arc<RgbaImage>>>,
    out: Vec<RenderMesh>,
}

impl GltfReader<'_> {
    fn node(
        &mut self,
        node: &gltf::Node<'_>,
        parent: Mat4,
        depth: usize,
        warnings: &mut Vec<String>,
    ) -> Result<(), DataError> {
        if depth > MAX_NODE_DEPTH {
            return Err(DataError::file(
                self.path,
                format!("glTF nodes nested deeper than {MAX_NODE_DEPTH} (a cycle?)"),
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            self.mesh(&mesh, &Affine3A::from_mat4(world), warnings)?;
        }
        for child in node.children() {
            self.node(&child, world, depth + 1, warnings)?;
        }
        Ok(())
    }

    fn mesh(
        &mut self,
        mesh: &gltf::Mesh<'_>,
        transform: &Affine3A,
        warnings: &mut Vec<String>,
    ) -> Result<(), DataError> {
        for prim in mesh.primitives() {
            let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
            if prim.mode() != gltf::mesh::Mode::Triangles {
                warnings.push(format!(
                    "{}: {what} is drawn as {:?}, not triangles; skipped",
                    self.path,
                    prim.mode()
                ));
                continue;
            }
            let Some(pos_acc) = prim.get(&gltf::Semantic::Positions) else {
                warnings.push(format!("{}: {what} has no POSITION; skipped", self.path));
                continue;
            };
            let positions: Vec<Vec3> = self
                .read_floats(&pos_acc, 3, &what)?
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect();
            let n = positions.len();
            let flat: Vec<u32> = match prim.indices() {
                Some(acc) => self.read_indices(&acc, &what)?,
                None => (0..n as u32).collect(),
            };
            let indices = triangles(self.path, &flat, n)?;
            let normals = match prim.get(&gltf::Semantic::Normals) {
                Some(acc) => {
                    let v: Vec<Vec3> = self
                        .read_floats(&acc, 3, &what)?
                        .chunks_exact(3)
                        .map(|c| Vec3::new(c[0], c[1], c[2]).normalize_or_zero())
                        .collect();
                    if v.len() == n {
                        v
                    } else {
                        vertex_normals(&positions, &indices)
                    }
                }
                None => vertex_normals(&positions, &indices),
            };
            let (material, tex_coord) = self.material(&prim.material(), warnings);
            let uvs = match prim.get(&gltf::Semantic::TexCoords(tex_coord)) {
                Some(acc) => {
                    let v: Vec<Vec2> = self
                        .read_floats(&acc, 2, &what)?
                        .chunks_exact(2)
                        .map(|c| Vec2::new(c[0], c[1]))
                        .collect();
                    (v.len() == n).then_some(v)
                }
                None => None,
            };
            // COLOR_0 is RGB or RGBA; the alpha of vertex colours is dropped.
            let colors = match prim.get(&gltf::Semantic::Colors(0)) {
                Some(acc) => {
                    let comps = acc.dimensions().multiplicity();
                    let v: Vec<[f32; 3]> = self
                        .read_floats(&acc, comps.clamp(3, 4), &what)?
                        .chunks_exact(comps.clamp(3, 4))
                        .map(|c| [c[0], c[1], c[2]])
                        .collect();
                    (v.len() == n).then_some(v)
                }
                None => None,
            };
            let local = RenderMesh {
                positions,
                normals,
                uvs,
                colors,
                indices,
                material,
            };
            self.out.push(local.transformed(transform));
        }
        Ok(())
    }

    /// The primitive's material and the texture-coordinate set its base-colour texture uses.
    fn material(
        &mut self,
        material: &gltf::Material<'_>,
        warnings: &mut Vec<String>,
    ) -> (Material, u32) {
        let pbr = material.pbr_metallic_roughness();
        let name = match (material.name(), material.index()) {
            (Some(n), _) => n.to_string(),
            (None, Some(i)) => format!("material {i}"),
            // glTF's default material (white) still counts as the file's own.
            (None, None) => "glTF default material".to_string(),
        };
        let mut tex_coord = 0;
        let texture = pbr.base_color_texture().and_then(|info| {
            tex_coord = info.tex_coord();
            self.image(info.texture().source().index(), warnings)
        });
        (
            Material {
                name: Some(name),
                base_color: pbr.base_color_factor(),
                texture,
            },
            tex_coord,
        )
    }

    fn image(&mut self, index: usize, warnings: &mut Vec<String>) -> Option<Arc<RgbaImage>> {
        if let Some(cached) = self.images.get(&index) {
            return cached.clone();
        }
        let decoded = self.decode_image(index, warnings).map(Arc::new);
        self.images.insert(index, decoded.clone());
        decoded
    }

    fn decode_image(&self, index: usize, warnings: &mut Vec<String>) -> Option<RgbaImage> {
        // Read the JSON directly: `gltf::Image::source` unwraps an optional MIME type that validation does not check.
        let json = self.gltf.as_json().images.get(index)?;
        let label = format!("{} image {index}", self.path);
        let bytes: Vec<u8> = if let Some(view) = &json.buffer_view {
            let view = self.gltf.views().nth(view.value())?;
            match self.view_bytes(&view) {
                Some(b) => b.to_vec(),
                None => {
                    warnings.push(format!(
                        "{label}: buffer view out of range; using the base colour"
                    ));
                    return None;
                }
            }
        } else if let Some(uri) = &json.uri {
            match load_uri(self.path, self.folder, uri, self.files) {
                Ok(b) => b,
                Err(e) => {
                    warnings.push(format!("{e}; using the base colour"));
                    return None;
                }
            }
        } else {
            return None;
        };
        decode_texture(&label, &bytes, warnings)
    }

    fn view_bytes(&self, view: &gltf::buffer::View<'_>) -> Option<&[u8]> {
        let data = self.buffers.get(view.buffer().index())?;
        let end = view.offset().checked_add(view.length())?;
        data.get(view.offset()..end)
    }

    /// Reads a float accessor with `comps` components per element (normalized integers scaled to [0, 1] / [−1, 1]).
    fn read_floats(
        &self,
        acc: &gltf::Accessor<'_>,
        comps: usize,
        what: &str,
    ) -> Result<Vec<f32>, DataError> {
        use gltf::accessor::DataType;
        let dims = acc.dimensions().multiplicity();
        if dims != comps {
            return Err(self.err(
                what,
                format!("expected a {comps}-component accessor, found {dims}"),
            ));
        }
        let size = acc.data_type().size();
        let normalized = acc.normalized();
        let raw = self.accessor_elements(acc, what)?;
        let mut out = Vec::with_capacity(raw.len() * comps);
        for elem in raw {
            for c in 0..comps {
                let bytes = elem.get(c * size..(c + 1) * size).unwrap_or(&[]);
                let v = match (acc.data_type(), bytes) {
                    (DataType::F32, &[a, b, c, d]) => f32::from_le_bytes([a, b, c, d]),
                    (DataType::U8, &[a]) if normalized => f32::from(a) / 255.0,
                    (DataType::U8, &[a]) => f32::from(a),
                    (DataType::I8, &[a]) if normalized => (f32::from(a as i8) / 127.0).max(-1.0),
                    (DataType::I8, &[a]) => f32::from(a as i8),
                    (DataType::U16, &[a, b]) if normalized => {
                        f32::from(u16::from_le_bytes([a, b])) / 65535.0
                    }
                    (DataType::U16, &[a, b]) => f32::from(u16::from_le_bytes([a, b])),
                    (DataType::I16, &[a, b]) if normalized => {
                        (f32::from(i16::from_le_bytes([a, b])) / 32767.0).max(-1.0)
                    }
                    (DataType::I16, &[a, b]) => f32::from(i16::from_le_bytes([a, b])),
                    (DataType::U32, &[a, b, c, d]) => u32::from_le_bytes([a, b, c, d]) as f32,
                    _ => return Err(self.err(what, "accessor element out of range".into())),
                };
                if !v.is_finite() {
                    return Err(self.err(what, "accessor holds a non-finite number".into()));
                }
                out.push(v);
            }
        }
        Ok(out)
    }

    fn read_indices(&self, acc: &gltf::Accessor<'_>, what: &str) -> Result<Vec<u32>, DataError> {
        use gltf::accessor::DataType;
        if acc.dimensions().multiplicity() != 1 {
            return Err(self.err(what, "index accessor is not scalar".into()));
        }
        let raw = self.accessor_elements(acc, what)?;
        raw.into_iter()
            .map(|b| match (acc.data_type(), b) {
                (DataType::U8, &[a]) => Ok(u32::from(a)),
                (DataType::U16, &[a, b]) => Ok(u32::from(u16::from_le_bytes([a, b]))),
                (DataType::U32, &[a, b, c, d]) => Ok(u32::from_le_bytes([a, b, c, d])),
                (t, _) => Err(self.err(
                    what,
                    format!("indices of type {t:?}: expected u8, u16 or u32"),
                )),
            })
            .collect()
    }

    /// Byte slices of each accessor element, bounds-checked against the buffer view.
    fn accessor_elements<'s>(
        &'s self,
        acc: &gltf::Accessor<'_>,
        what: &str,
    ) -> Result<Vec<&'s [u8]>, DataError> {
        if acc.sparse().is_some() {
            return Err(self.err(what, "sparse accessors are not supported".into()));
        }
        let elem = acc.size();
        let count = acc.count();
        let Some(view) = acc.view() else {
            return Err(self.err(
                what,
                "accessor without a buffer view is not supported".into(),
            ));
        };
        let data = self
            .view_bytes(&view)
            .ok_or_else(|| self.err(what, "buffer view lies outside its buffer".into()))?;
        let stride = view.stride().unwrap_or(elem).max(elem);
        let last = match count.checked_sub(1) {
            None => return Ok(Vec::new()),
            Some(l) => l,
        };
        let end = last
            .checked_mul(stride)
            .and_then(|x| x.checked_add(acc.offset()))
            .and_then(|x| x.checked_add(elem));
        if end.is_none_or(|e| e > data.len()) {
            return Err(self.err(
                what,
                format!(
                    "accessor {} ({count} elements) runs past its buffer view",
                    acc.index()
                ),
            ));
        }
        Ok((0..count)
            .filter_map(|i| {
                let start = acc.offset() + i * stride;
                data.get(start..start + elem)
            })
            .collect())
    }

    fn err(&self, what: &str, message: String) -> DataError {
        DataError::field(self.path, what, message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
