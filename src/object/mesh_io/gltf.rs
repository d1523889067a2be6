//! glTF 2.0 reader (GLB or `.gltf` JSON with external or `data:` buffers): walks the default scene's node
//! tree, reads triangle primitives through bounds-checked accessors, and decodes PNG base-colour textures.

use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Arc;

use glam::{Affine3A, Mat4, Vec2, Vec3};

use crate::data::{DataError, FileSource, RgbaImage};
use crate::object::{Material, RenderMesh};

use super::shared::{Textures, folder_of, join_relative, triangles, vertex_normals};

/// Nodes nested deeper than this are rejected (guards against cyclic node graphs).
const MAX_NODE_DEPTH: usize = 64;

/// Node instances a scene may expand to. A node listed by several parents is instanced once per
/// path to it, so a small file can describe 2⁴⁰ instances; real assets stay far below this.
pub(crate) const MAX_NODE_INSTANCES: usize = 200_000;

/// Triangles one glTF file may instance, over all its nodes (20 M: about 1 GB of vertex data).
pub(crate) const MAX_GLTF_TRIANGLES: usize = 20_000_000;

/// Reads a GLB or `.gltf` file; meshes come out in the scene's frame (node transforms applied).
pub(super) fn read_gltf(
    path: &str,
    bytes: &[u8],
    files: &dyn FileSource,
    textures: &mut Textures,
    warnings: &mut Vec<String>,
) -> Result<Vec<RenderMesh>, DataError> {
    let gltf = parse(path, bytes)?;
    let folder = folder_of(path);
    let buffers = load_buffers(path, folder, &gltf, files)?;
    let mut reader = GltfReader {
        path,
        folder,
        gltf: &gltf,
        buffers,
        files,
        textures,
        meshes: HashMap::new(),
        instances: 0,
        triangles: 0,
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

/// Parses and validates a GLB or `.gltf`. The gltf crate's validation indexes a primitive's
/// accessors before checking them (a panic on an out-of-range index), so they are checked first.
fn parse(path: &str, bytes: &[u8]) -> Result<gltf::Gltf, DataError> {
    let cannot = |e: gltf::Error| DataError::file(path, format!("could not read glTF: {e}"));
    let unchecked = gltf::Gltf::from_slice_without_validation(bytes).map_err(cannot)?;
    let json = unchecked.document.into_json();
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let used = prim.attributes.values().chain(prim.indices.as_ref());
            if let Some(bad) = used.map(|a| a.value()).find(|&a| a >= accessors) {
                return Err(DataError::file(
                    path,
                    format!(
                        "could not read glTF: mesh {m} primitive {p} uses accessor {bad}, but the file has {accessors}"
                    ),
                ));
            }
        }
    }
    let document = gltf::Document::from_json(json).map_err(cannot)?;
    Ok(gltf::Gltf {
        document,
        blob: unchecked.blob,
    })
}

/// Bytes of every buffer (GLB chunk, external file or data URI), each checked against its declared
/// length. Files and the GLB chunk are borrowed, so many buffers naming one file cost nothing.
fn load_buffers<'a>(
    path: &str,
    folder: &str,
    gltf: &'a gltf::Gltf,
    files: &'a dyn FileSource,
) -> Result<Vec<Cow<'a, [u8]>>, DataError> {
    let mut out = Vec::new();
    for buffer in gltf.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => {
                gltf.blob.as_deref().map(Cow::Borrowed).ok_or_else(|| {
                    DataError::file(
                        path,
                        "glTF buffer refers to the GLB binary chunk, which is missing",
                    )
                })?
            }
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

/// Bytes of a glTF URI: a `data:...;base64,` URI or a file relative to the glTF's folder (borrowed).
fn load_uri<'a>(
    path: &str,
    folder: &str,
    uri: &str,
    files: &'a dyn FileSource,
) -> Result<Cow<'a, [u8]>, DataError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err(DataError::file(
                path,
                "glTF data URI is not base64-encoded (expected 'data:<type>;base64,...')",
            ));
        };
        return decode_base64(payload)
            .map(Cow::Owned)
            .ok_or_else(|| DataError::file(path, "glTF data URI holds invalid base64"));
    }
    let key = join_relative(folder, &percent_decode(uri)).ok_or_else(|| {
        DataError::file(
            path,
            format!("glTF URI '{uri}' is absolute or leaves the dataset; expected a relative path"),
        )
    })?;
    files.file(&key).map(Cow::Borrowed).ok_or_else(|| {
        DataError::file(
            path,
            format!("glTF refers to '{key}', which is not in the dataset"),
        )
    })
}

/// Decodes `%XX` escapes in a URI (invalid escapes are kept as written).
pub(super) fn percent_decode(s: &str) -> String {
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

/// Decodes standard or URL-safe base64 (padding optional); `None` on an invalid character.
pub(super) fn decode_base64(s: &str) -> Option<Vec<u8>> {
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

/// Walks one glTF document, collecting its triangle meshes in `out`.
struct GltfReader<'a> {
    path: &'a str,
    folder: &'a str,
    gltf: &'a gltf::Gltf,
    buffers: Vec<Cow<'a, [u8]>>,
    files: &'a dyn FileSource,
    textures: &'a mut Textures,
    /// Each mesh's primitives in the mesh's own frame, read on its first instance.
    meshes: HashMap<usize, Arc<[RenderMesh]>>,
    /// Node instances and triangles so far, against [`MAX_NODE_INSTANCES`] and [`MAX_GLTF_TRIANGLES`].
    instances: usize,
    triangles: usize,
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
        self.instances += 1;
        if self.instances > MAX_NODE_INSTANCES {
            return Err(DataError::file(
                self.path,
                format!(
                    "the scene expands to more than {MAX_NODE_INSTANCES} node instances (a node listed by several parents is repeated once per path to it); expected a scene tree of real size"
                ),
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

    /// Places one instance of `mesh` (read on first use) in the scene.
    fn mesh(
        &mut self,
        mesh: &gltf::Mesh<'_>,
        transform: &Affine3A,
        warnings: &mut Vec<String>,
    ) -> Result<(), DataError> {
        let local = match self.meshes.get(&mesh.index()) {
            Some(m) => m.clone(),
            None => {
                let m: Arc<[RenderMesh]> = self.read_mesh(mesh, warnings)?.into();
                self.meshes.insert(mesh.index(), m.clone());
                m
            }
        };
        self.triangles += local.iter().map(|m| m.indices.len()).sum::<usize>();
        if self.triangles > MAX_GLTF_TRIANGLES {
            return Err(DataError::file(
                self.path,
                format!(
                    "the scene instances more than {MAX_GLTF_TRIANGLES} triangles (mesh {} is one of them); simplify the mesh first",
                    mesh.index()
                ),
            ));
        }
        self.out
            .extend(local.iter().map(|m| m.transformed(transform)));
        Ok(())
    }

    /// A mesh's triangle primitives in its own frame.
    fn read_mesh(
        &mut self,
        mesh: &gltf::Mesh<'_>,
        warnings: &mut Vec<String>,
    ) -> Result<Vec<RenderMesh>, DataError> {
        let mut out = Vec::new();
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

    /// Image `index`, decoded once per import: an external file is shared with every other
    /// image, material and mesh file of the object that names it.
    fn image(&mut self, index: usize, warnings: &mut Vec<String>) -> Option<Arc<RgbaImage>> {
        // Read the JSON directly: `gltf::Image::source` unwraps an optional MIME type that validation does not check.
        let json = self.gltf.as_json().images.get(index)?;
        let label = format!("{} image {index}", self.path);
        if let Some(view) = &json.buffer_view {
            let bytes = self
                .gltf
                .views()
                .nth(view.value())
                .and_then(|v| view_bytes(&self.buffers, &v));
            if bytes.is_none() {
                warnings.push(format!(
                    "{label}: buffer view out of range; using the base colour"
                ));
            }
            let key = format!("{label} (buffer view {})", view.value());
            return self
                .textures
                .get(&key, || bytes.map(Cow::Borrowed), warnings);
        }
        let uri = json.uri.as_deref()?;
        let key = match join_relative(self.folder, &percent_decode(uri)) {
            Some(file) if !uri.starts_with("data:") => file,
            _ => label,
        };
        let bytes = load_uri(self.path, self.folder, uri, self.files)
            .map_err(|e| warnings.push(format!("{e}; using the base colour")))
            .ok();
        self.textures.get(&key, || bytes, warnings)
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
        let data = view_bytes(&self.buffers, &view)
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

/// The bytes of a buffer view, if it lies inside its buffer.
fn view_bytes<'b>(buffers: &'b [Cow<'_, [u8]>], view: &gltf::buffer::View<'_>) -> Option<&'b [u8]> {
    let data = buffers.get(view.buffer().index())?;
    let end = view.offset().checked_add(view.length())?;
    data.get(view.offset()..end)
}
