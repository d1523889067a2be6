//! PLY triangle meshes (ground-truth part meshes): ascii and binary (little/big endian) reading, writing.
//!
//! Only vertex positions and faces are kept; other properties and elements are skipped. Polygons are
//! triangulated as fans. Element counts from the header are checked against the bytes present before
//! anything is allocated.

use glam::Vec3;

use super::error::DataError;

/// Indexed triangle mesh.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriMesh {
    /// Vertex positions (metres).
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

/// PLY encoding to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyFormat {
    /// Human-readable text.
    Ascii,
    /// `binary_little_endian 1.0` (what [`Dataset::to_files`](super::Dataset::to_files) writes).
    BinaryLittleEndian,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_int(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Debug, Clone)]
enum Property {
    Scalar(String, Scalar),
    List(String, Scalar, Scalar),
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Binary { big_endian: bool },
}

/// Parses the header; returns the encoding, the elements and the offset of the body.
fn parse_header(file: &str, bytes: &[u8]) -> Result<(Encoding, Vec<Element>, usize), DataError> {
    let herr = |msg: String| DataError::field(file, "header", msg);
    let mut pos = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut line_no = 0;
    loop {
        let rest = bytes.get(pos..).unwrap_or(&[]);
        let Some(nl) = rest.iter().position(|&b| b == b'\n') else {
            return Err(herr("truncated: no end_header line".into()));
        };
        let line = String::from_utf8_lossy(&rest[..nl]);
        let line = line.trim_end_matches('\r').trim();
        pos += nl + 1;
        line_no += 1;
        let words: Vec<&str> = line.split_whitespace().collect();
        if line_no == 1 {
            if line != "ply" {
                return Err(DataError::field(
                    file,
                    "magic",
                    format!(
                        "expected a PLY file starting with \"ply\", found \"{}\"",
                        line.chars().take(20).collect::<String>()
                    ),
                ));
            }
            continue;
        }
        match words.as_slice() {
            [] => {}
            ["comment" | "obj_info", ..] => {}
            ["format", fmt, _version] => {
                encoding = Some(match *fmt {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Binary { big_endian: false },
                    "binary_big_endian" => Encoding::Binary { big_endian: true },
                    other => {
                        return Err(DataError::field(
                            file,
                            "format",
                            format!(
                                "expected ascii, binary_little_endian or binary_big_endian, found {other}"
                            ),
                        ));
                    }
                })
            }
            ["element", name, count] => {
                let count = count.parse::<usize>().map_err(|_| {
                    herr(format!(
                        "line {line_no}: expected an element count, found \"{count}\""
                    ))
                })?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", "list", count_t, item_t, name] => {
                let (Some(c), Some(i)) = (Scalar::parse(count_t), Scalar::parse(item_t)) else {
                    return Err(herr(format!(
                        "line {line_no}: unknown property type in \"{line}\""
                    )));
                };
                if !c.is_int() {
                    return Err(herr(format!(
                        "line {line_no}: list count type must be an integer, found {count_t}"
                    )));
                }
                let el = elements
                    .last_mut()
                    .ok_or_else(|| herr(format!("line {line_no}: property before any element")))?;
                el.properties.push(Property::List(name.to_string(), c, i));
            }
            ["property", ty, name] => {
                let t = Scalar::parse(ty).ok_or_else(|| {
                    herr(format!("line {line_no}: unknown property type \"{ty}\""))
                })?;
                let el = elements
                    .last_mut()
                    .ok_or_else(|| herr(format!("line {line_no}: property before any element")))?;
                el.properties.push(Property::Scalar(name.to_string(), t));
            }
            ["end_header"] => break,
            _ => {
                return Err(herr(format!(
                    "line {line_no}: unexpected \"{}\"",
                    line.chars().take(60).collect::<String>()
                )));
            }
        }
    }
    let encoding =
        encoding.ok_or_else(|| DataError::field(file, "format", "missing format line"))?;
    Ok((encoding, elements, pos))
}

/// Sequential reader over the body, ascii tokens or binary scalars, read as f64 (exact for every PLY type).
enum Body<'a> {
    Ascii(std::str::SplitAsciiWhitespace<'a>),
    Binary {
        data: &'a [u8],
        pos: usize,
        big_endian: bool,
    },
}

impl Body<'_> {
    fn read(&mut self, t: Scalar) -> Option<f64> {
        match self {
            Body::Ascii(tokens) => {
                let x: f64 = tokens.next()?.parse().ok()?;
                (!t.is_int() || x.fract() == 0.0).then_some(x)
            }
            Body::Binary {
                data,
                pos,
                big_endian,
            } => {
                let n = t.size();
                let raw = data.get(*pos..pos.checked_add(n)?)?;
                *pos += n;
                let mut b = [0u8; 8];
                b[..n].copy_from_slice(raw);
                if *big_endian {
                    b[..n].reverse();
                }
                Some(match t {
                    Scalar::I8 => f64::from(b[0] as i8),
                    Scalar::U8 => f64::from(b[0]),
                    Scalar::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
                    Scalar::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
                    Scalar::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Scalar::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Scalar::F64 => f64::from_le_bytes(b),
                })
            }
        }
    }
}

/// The body reader for `encoding`; an ascii body must be text.
fn body_reader<'a>(file: &str, encoding: Encoding, body: &'a [u8]) -> Result<Body<'a>, DataError> {
    Ok(match encoding {
        Encoding::Ascii => Body::Ascii(
            std::str::from_utf8(body)
                .map_err(|_| DataError::field(file, "format", "ascii PLY body is not text"))?
                .split_ascii_whitespace(),
        ),
        Encoding::Binary { big_endian } => Body::Binary {
            data: body,
            pos: 0,
            big_endian,
        },
    })
}

/// A GT mesh needs both a vertex and a face element.
fn check_required_elements(file: &str, elements: &[Element]) -> Result<(), DataError> {
    if !elements.iter().any(|e| e.name == "vertex") {
        return Err(DataError::field(
            file,
            "element vertex",
            "missing (expected a vertex element)",
        ));
    }
    if !elements.iter().any(|e| e.name == "face") {
        return Err(DataError::field(
            file,
            "element face",
            "missing (expected a face element: a GT mesh needs triangles)",
        ));
    }
    Ok(())
}

/// Rejects element counts the body cannot hold, before anything is allocated.
fn check_counts_fit(
    file: &str,
    encoding: Encoding,
    elements: &[Element],
    body_len: usize,
) -> Result<(), DataError> {
    // Every entry takes at least one byte (binary: its fixed-size scalars; ascii: a digit or separator),
    // so a count beyond the body size is a lie.
    let mut min_total: usize = 0;
    for el in elements {
        let per = match encoding {
            Encoding::Ascii => el.properties.len().max(1),
            Encoding::Binary { .. } => el
                .properties
                .iter()
                .map(|p| match p {
                    Property::Scalar(_, t) | Property::List(_, t, _) => t.size(),
                })
                .sum::<usize>()
                .max(1),
        };
        min_total = el
            .count
            .checked_mul(per)
            .and_then(|n| n.checked_add(min_total))
            .unwrap_or(usize::MAX);
        if min_total > body_len {
            return Err(DataError::field(
                file,
                format!("element {}", el.name),
                format!(
                    "truncated: header claims {} entries, but only {} bytes of data follow",
                    el.count, body_len
                ),
            ));
        }
    }
    Ok(())
}

/// Where an element's data of interest sits: the x, y, z property indices of `vertex`, the index list of
/// `face` (`None` for other elements, whose entries are read and skipped).
fn element_layout(
    file: &str,
    el: &Element,
) -> Result<(Option<[usize; 3]>, Option<usize>), DataError> {
    let field = format!("element {}", el.name);
    let axis = |n: &str| {
        el.properties
            .iter()
            .position(|p| matches!(p, Property::Scalar(name, _) if name == n))
    };
    let xyz = if el.name == "vertex" {
        match (axis("x"), axis("y"), axis("z")) {
            (Some(x), Some(y), Some(z)) => Some([x, y, z]),
            _ => {
                return Err(DataError::field(
                    file,
                    field.as_str(),
                    "expected properties x, y and z",
                ));
            }
        }
    } else {
        None
    };
    let face_list = (el.name == "face")
        .then(|| {
            el.properties
                .iter()
                .position(|p| matches!(p, Property::List(n, _, _) if n == "vertex_indices" || n == "vertex_index"))
        })
        .flatten();
    if el.name == "face" && face_list.is_none() {
        return Err(DataError::field(
            file,
            field.as_str(),
            "expected a list property vertex_indices (or vertex_index)",
        ));
    }
    Ok((xyz, face_list))
}

/// Reads every entry of `el`: vertices into `mesh.positions`, faces (fan-triangulated) into
/// `mesh.triangles`; other elements are consumed and dropped.
fn read_element(
    file: &str,
    el: &Element,
    reader: &mut Body<'_>,
    mesh: &mut TriMesh,
) -> Result<(), DataError> {
    let field = format!("element {}", el.name);
    let truncated = |i: usize| {
        DataError::field(
            file,
            field.as_str(),
            format!(
                "truncated or malformed: could not read entry {i} of {}",
                el.count
            ),
        )
    };
    let (xyz, face_list) = element_layout(file, el)?;
    if el.name == "vertex" {
        mesh.positions.reserve(el.count);
    }
    let mut polygon = Vec::new();
    for i in 0..el.count {
        let mut p = [0.0f64; 3];
        for (k, prop) in el.properties.iter().enumerate() {
            match prop {
                Property::Scalar(_, t) => {
                    let v = reader.read(*t).ok_or_else(|| truncated(i))?;
                    if let Some(slot) = xyz.and_then(|xyz| xyz.iter().position(|&a| a == k)) {
                        p[slot] = v;
                    }
                }
                Property::List(_, count_t, item_t) => {
                    let n = reader.read(*count_t).ok_or_else(|| truncated(i))?;
                    let is_faces = face_list == Some(k);
                    polygon.clear();
                    for _ in 0..(n.max(0.0) as u64) {
                        let v = reader.read(*item_t).ok_or_else(|| truncated(i))?;
                        if is_faces {
                            if !(v >= 0.0 && v <= f64::from(u32::MAX)) {
                                return Err(DataError::field(
                                    file,
                                    field.as_str(),
                                    format!(
                                        "face {i} refers to vertex {v}; expected a non-negative index"
                                    ),
                                ));
                            }
                            polygon.push(v as u32);
                        }
                    }
                    if is_faces {
                        if polygon.len() < 3 {
                            return Err(DataError::field(
                                file,
                                field.as_str(),
                                format!(
                                    "face {i} has {} vertices; expected at least 3",
                                    polygon.len()
                                ),
                            ));
                        }
                        for w in 1..polygon.len() - 1 {
                            mesh.triangles
                                .push([polygon[0], polygon[w], polygon[w + 1]]);
                        }
                    }
                }
            }
        }
        if xyz.is_some() {
            let v = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
            if !v.is_finite() {
                return Err(DataError::field(
                    file,
                    field.as_str(),
                    format!("vertex {i} is not finite: {v}"),
                ));
            }
            mesh.positions.push(v);
        }
    }
    Ok(())
}

/// Every triangle index must name a vertex; checked after reading so the element order does not matter.
fn check_face_indices(file: &str, mesh: &TriMesh) -> Result<(), DataError> {
    let n = mesh.positions.len();
    if let Some((i, t)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v as usize >= n))
    {
        return Err(DataError::field(
            file,
            "element face",
            format!(
                "triangle {i} refers to vertex {}, but there are {n} vertices",
                t.iter().max().copied().unwrap_or(0)
            ),
        ));
    }
    Ok(())
}

impl TriMesh {
    /// Reads a PLY mesh (ascii or binary). `file` names the file in errors.
    pub fn from_ply(file: &str, bytes: &[u8]) -> Result<TriMesh, DataError> {
        let (encoding, elements, body_start) = parse_header(file, bytes)?;
        let body = bytes.get(body_start..).unwrap_or(&[]);
        let mut reader = body_reader(file, encoding, body)?;
        check_required_elements(file, &elements)?;
        check_counts_fit(file, encoding, &elements, body.len())?;
        let mut mesh = TriMesh::default();
        for el in &elements {
            read_element(file, el, &mut reader, &mut mesh)?;
        }
        check_face_indices(file, &mesh)?;
        Ok(mesh)
    }

    /// Writes the mesh as PLY (float x y z; faces as `uchar`-counted `int` lists).
    pub fn to_ply(&self, format: PlyFormat) -> Vec<u8> {
        let name = match format {
            PlyFormat::Ascii => "ascii",
            PlyFormat::BinaryLittleEndian => "binary_little_endian",
        };
        let mut out = format!(
            "ply\nformat {name} 1.0\ncomment artmesh ground-truth part mesh\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
            self.positions.len(),
            self.triangles.len()
        )
        .into_bytes();
        match format {
            PlyFormat::Ascii => {
                let mut text = String::new();
                for p in &self.positions {
                    // `{}` on f32 prints the shortest text that reads back to the same value.
                    text.push_str(&format!("{} {} {}\n", p.x, p.y, p.z));
                }
                for t in &self.triangles {
                    text.push_str(&format!("3 {} {} {}\n", t[0], t[1], t[2]));
                }
                out.extend_from_slice(text.as_bytes());
            }
            PlyFormat::BinaryLittleEndian => {
                for p in &self.positions {
                    for c in p.to_array() {
                        out.extend_from_slice(&c.to_le_bytes());
                    }
                }
                for t in &self.triangles {
                    out.push(3);
                    for &i in t {
                        // Indices beyond i32 cannot be written as `int`; such meshes are far beyond PLY use here.
                        out.extend_from_slice(&(i.min(i32::MAX as u32) as i32).to_le_bytes());
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> TriMesh {
        TriMesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::new(1.0, 1.0, 0.1),
                Vec3::new(0.0, 1.0, -0.3),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    #[test]
    fn round_trips_both_formats() {
        for f in [PlyFormat::Ascii, PlyFormat::BinaryLittleEndian] {
            assert_eq!(
                TriMesh::from_ply("m.ply", &quad().to_ply(f)).unwrap(),
                quad()
            );
        }
    }

    #[test]
    fn polygons_fans_extra_properties_and_big_endian() {
        let mut b = b"ply\r\nformat binary_big_endian 1.0\r\nelement vertex 4\r\nproperty double x\r\nproperty double y\r\nproperty double z\r\nproperty uchar red\r\nelement face 1\r\nproperty list uchar uint vertex_index\r\nproperty list uchar int other\r\nend_header\r\n".to_vec();
        for p in quad().positions {
            for c in p.to_array() {
                b.extend_from_slice(&f64::from(c).to_be_bytes());
            }
            b.push(200);
        }
        b.push(4);
        for i in [0u32, 1, 2, 3] {
            b.extend_from_slice(&i.to_be_bytes());
        }
        b.push(1);
        b.extend_from_slice(&9i32.to_be_bytes());
        assert_eq!(TriMesh::from_ply("m.ply", &b).unwrap(), quad());
    }

    #[test]
    fn malformed_inputs_are_errors() {
        let good = quad().to_ply(PlyFormat::BinaryLittleEndian);
        for cut in 0..good.len() {
            assert!(
                TriMesh::from_ply("m.ply", &good[..cut]).is_err(),
                "cut at {cut}"
            );
        }
        let huge = b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n";
        assert!(
            TriMesh::from_ply("m.ply", huge)
                .unwrap_err()
                .message
                .contains("claims")
        );
        let bad_index = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n3 0 0 5\n";
        assert!(
            TriMesh::from_ply("m.ply", bad_index)
                .unwrap_err()
                .message
                .contains("refers to vertex 5")
        );
        assert!(
            TriMesh::from_ply("m.ply", b"obj\n")
                .unwrap_err()
                .field
                .as_deref()
                == Some("magic")
        );
    }
}
