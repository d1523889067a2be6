//! Minimal NumPy `.npy` reader/writer for 2-D integer part-id maps (GaussianArt / MPArt-90 semantic maps).
//!
//! Format: magic `\x93NUMPY`, version byte pair (1.0, 2.0, 3.0), little-endian header length (u16 for 1.0,
//! u32 otherwise), then a Python dict literal `{'descr': '<i8', 'fortran_order': False, 'shape': (H, W), }`,
//! then the raw array. Sizes claimed by the header are checked against the bytes present before anything
//! is allocated.

mod header_dict;

use super::error::DataError;
use super::image_io::PartMap;
use header_dict::{Py, parse_dict};

const MAGIC: &[u8] = b"\x93NUMPY";

/// Element types we read (and write).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum NpyDtype {
    /// Signed integer of 1, 2, 4 or 8 bytes.
    Int(u8),
    /// Unsigned integer of 1, 2, 4 or 8 bytes.
    UInt(u8),
    /// IEEE float of 4 or 8 bytes (must hold whole numbers when read as part ids).
    Float(u8),
}

impl NpyDtype {
    fn size(self) -> usize {
        match self {
            NpyDtype::Int(n) | NpyDtype::UInt(n) | NpyDtype::Float(n) => usize::from(n),
        }
    }

    /// NumPy `descr` string, little-endian (`<i8`, `|u1`, ...).
    pub(crate) fn descr(self) -> String {
        let (kind, n) = match self {
            NpyDtype::Int(n) => ('i', n),
            NpyDtype::UInt(n) => ('u', n),
            NpyDtype::Float(n) => ('f', n),
        };
        format!("{}{kind}{n}", if n == 1 { '|' } else { '<' })
    }
}

/// Writes a `.npy` file (version 1.0, or 2.0 if the header needs it) holding `data`, whose bytes must already be
/// in the element type and byte order `descr` names, e.g. `encode_npy("<i8", false, &[h, w], bytes)`.
pub fn encode_npy(descr: &str, fortran_order: bool, shape: &[usize], data: &[u8]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape_text = if dims.len() == 1 {
        format!("({},)", dims.join(", "))
    } else {
        format!("({})", dims.join(", "))
    };
    let order = if fortran_order { "True" } else { "False" };
    let mut header =
        format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape_text}, }}");
    // Pad with spaces so the data starts on a 64-byte boundary; the header ends with a newline.
    let v1 = 10 + header.len() < 65_000;
    let prefix = if v1 { 10 } else { 12 };
    let total = (prefix + header.len() + 1).div_ceil(64) * 64;
    header.push_str(&" ".repeat(total - prefix - header.len() - 1));
    header.push('\n');
    let mut out = Vec::with_capacity(total + data.len());
    out.extend_from_slice(MAGIC);
    if v1 {
        out.extend_from_slice(&[1, 0]);
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    } else {
        out.extend_from_slice(&[2, 0]);
        out.extend_from_slice(&(header.len() as u32).to_le_bytes());
    }
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

/// Parsed header fields.
struct Header {
    dtype: NpyDtype,
    big_endian: bool,
    fortran: bool,
    height: usize,
    width: usize,
    data_start: usize,
}

fn parse_descr(file: &str, descr: &str) -> Result<(NpyDtype, bool), DataError> {
    let err = |what: &str| {
        DataError::field(
            file,
            "descr",
            format!(
                "expected an integer dtype (i1/u1/i2/u2/i4/u4/i8/u8) or float (f4/f8), found '{descr}'{what}"
            ),
        )
    };
    let b = descr.as_bytes();
    let (order, rest) = match b.first() {
        Some(&c @ (b'<' | b'>' | b'|' | b'=')) => (c, &descr[1..]),
        _ => (b'=', descr),
    };
    let mut chars = rest.chars();
    let kind = chars.next().ok_or_else(|| err(""))?;
    let size: u8 = chars.as_str().parse().map_err(|_| err(""))?;
    let dtype = match (kind, size) {
        ('i', 1 | 2 | 4 | 8) => NpyDtype::Int(size),
        ('u', 1 | 2 | 4 | 8) => NpyDtype::UInt(size),
        ('f', 4 | 8) => NpyDtype::Float(size),
        ('b', _) => return Err(err(" (booleans are not part ids)")),
        _ => return Err(err("")),
    };
    Ok((dtype, order == b'>'))
}

/// Parses the header: magic and version, the header dict, and the shape checked against the data present.
fn parse_header(file: &str, bytes: &[u8]) -> Result<Header, DataError> {
    let (start, end) = header_span(file, bytes)?;
    let text = &bytes[start..end];
    let dict = parse_dict(text)
        .map_err(|e| DataError::field(file, "header", format!("not a valid header dict: {e}")))?;
    let (dtype, big_endian, fortran, dims) = header_fields(file, &dict)?;
    let shape_text = format!(
        "({})",
        dims.iter()
            .map(|d| d.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let (h, w) = image_shape(file, &dims, &shape_text)?;
    check_data_size(file, dtype, (h, w), bytes.len() - end, &shape_text)?;
    Ok(Header {
        dtype,
        big_endian,
        fortran,
        height: h as usize,
        width: w as usize,
        data_start: end,
    })
}

/// Checks the magic and version; returns the byte range of the header dict text.
fn header_span(file: &str, bytes: &[u8]) -> Result<(usize, usize), DataError> {
    let found: String = bytes
        .iter()
        .take(6)
        .map(|b| format!("\\x{b:02x}"))
        .collect();
    if bytes.len() < 10 || !bytes.starts_with(MAGIC) {
        return Err(DataError::field(
            file,
            "magic",
            format!("expected a .npy file starting with \\x93NUMPY, found {found}"),
        ));
    }
    let (major, minor) = (bytes[6], bytes[7]);
    let (len, start): (usize, usize) = match major {
        1 => (usize::from(u16::from_le_bytes([bytes[8], bytes[9]])), 10),
        2 | 3 => match bytes.get(8..12) {
            Some(&[a, b, c, d]) => (u32::from_le_bytes([a, b, c, d]) as usize, 12),
            _ => {
                return Err(DataError::field(
                    file,
                    "header",
                    "truncated: the file ends inside the header length",
                ));
            }
        },
        _ => {
            return Err(DataError::field(
                file,
                "version",
                format!("expected .npy format version 1.0, 2.0 or 3.0, found {major}.{minor}"),
            ));
        }
    };
    let end = start
        .checked_add(len)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| {
            DataError::field(
                file,
                "header",
                format!(
                    "truncated: header claims {len} bytes but the file holds only {}",
                    bytes.len().saturating_sub(start)
                ),
            )
        })?;
    Ok((start, end))
}

/// The dict's `descr` (dtype, big-endian), `fortran_order` and `shape` entries.
fn header_fields(
    file: &str,
    dict: &[(String, Py)],
) -> Result<(NpyDtype, bool, bool, Vec<u64>), DataError> {
    let get = |key: &str| {
        dict.iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v)
            .ok_or_else(|| {
                DataError::field(
                    file,
                    "header",
                    format!("missing '{key}' in the header dict"),
                )
            })
    };
    let (dtype, big_endian) = match get("descr")? {
        Py::Str(s) => parse_descr(file, s)?,
        other => {
            return Err(DataError::field(
                file,
                "descr",
                format!(
                    "expected a simple dtype string, found {other:?} (structured arrays are not supported)"
                ),
            ));
        }
    };
    let fortran = match get("fortran_order")? {
        Py::Bool(b) => *b,
        other => {
            return Err(DataError::field(
                file,
                "fortran_order",
                format!("expected True or False, found {other:?}"),
            ));
        }
    };
    let dims: Vec<u64> = match get("shape")? {
        Py::Tuple(items) => items
            .iter()
            .map(|v| match v {
                Py::Int(n) => Ok(*n),
                other => Err(DataError::field(
                    file,
                    "shape",
                    format!("expected whole numbers, found {other:?}"),
                )),
            })
            .collect::<Result<_, _>>()?,
        other => {
            return Err(DataError::field(
                file,
                "shape",
                format!("expected a tuple, found {other:?}"),
            ));
        }
    };
    Ok((dtype, big_endian, fortran, dims))
}

/// Image height and width from a shape (H, W) or (H, W, 1), each non-zero and within `u32`.
fn image_shape(file: &str, dims: &[u64], shape_text: &str) -> Result<(u64, u64), DataError> {
    let (h, w) = match dims {
        [h, w] | [h, w, 1] => (*h, *w),
        _ => {
            return Err(DataError::field(
                file,
                "shape",
                format!("expected (H, W) or (H, W, 1), found {shape_text}"),
            ));
        }
    };
    if h == 0 || w == 0 || h > u64::from(u32::MAX) || w > u64::from(u32::MAX) {
        return Err(DataError::field(
            file,
            "shape",
            format!("expected a non-empty image size, found {shape_text}"),
        ));
    }
    Ok((h, w))
}

/// Checks the claimed size against the `have` bytes present, before anything is allocated.
fn check_data_size(
    file: &str,
    dtype: NpyDtype,
    (h, w): (u64, u64),
    have: usize,
    shape_text: &str,
) -> Result<(), DataError> {
    let need = h
        .checked_mul(w)
        .and_then(|n| n.checked_mul(dtype.size() as u64));
    match need {
        Some(need) if need == have as u64 => Ok(()),
        Some(need) if need < have as u64 => Err(DataError::field(
            file,
            "data",
            format!(
                "expected {need} bytes of data for shape {shape_text}, found {have} (extra bytes at the end)"
            ),
        )),
        _ => Err(DataError::field(
            file,
            "shape",
            format!(
                "header claims shape {shape_text} of {} ({} bytes), but only {have} bytes of data follow",
                dtype.descr(),
                need.map_or("more than 2^64".to_string(), |n| n.to_string())
            ),
        )),
    }
}

/// An element that is no whole number within `i64`; it displays as the offending value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
enum BadElement {
    /// An unsigned value above `i64::MAX`.
    #[error("{0}")]
    TooLarge(u64),
    /// A float that is not a finite whole number below 1e15.
    #[error("{0} (not a whole number)")]
    NotWhole(f64),
}

/// Reads one element as a whole number; `Err` holds the offending value.
fn element(dtype: NpyDtype, big_endian: bool, raw: &[u8]) -> Result<i64, BadElement> {
    let mut b = [0u8; 8];
    let n = raw.len().min(8);
    b[..n].copy_from_slice(&raw[..n]);
    if big_endian {
        b[..n].reverse();
    }
    Ok(match dtype {
        NpyDtype::Int(1) => i64::from(b[0] as i8),
        NpyDtype::Int(2) => i64::from(i16::from_le_bytes([b[0], b[1]])),
        NpyDtype::Int(4) => i64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        NpyDtype::Int(_) => i64::from_le_bytes(b),
        NpyDtype::UInt(1) => i64::from(b[0]),
        NpyDtype::UInt(2) => i64::from(u16::from_le_bytes([b[0], b[1]])),
        NpyDtype::UInt(4) => i64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        NpyDtype::UInt(_) => {
            let v = u64::from_le_bytes(b);
            i64::try_from(v).map_err(|_| BadElement::TooLarge(v))?
        }
        NpyDtype::Float(n) => {
            let x = if n == 4 {
                f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            } else {
                f64::from_le_bytes(b)
            };
            if !(x.is_finite() && x.fract() == 0.0 && x.abs() < 1e15) {
                return Err(BadElement::NotWhole(x));
            }
            x as i64
        }
    })
}

/// Reads a `.npy` part-id map: -1 background, 0.. parts; ids below -1 are errors.
pub(crate) fn decode_parts_npy(file: &str, bytes: &[u8]) -> Result<PartMap, DataError> {
    let h = parse_header(file, bytes)?;
    let size = h.dtype.size();
    let data = &bytes[h.data_start..];
    let mut ids = Vec::with_capacity(h.height * h.width);
    for y in 0..h.height {
        for x in 0..h.width {
            // C order is row-major; Fortran order is column-major.
            let index = if h.fortran {
                x * h.height + y
            } else {
                y * h.width + x
            };
            let raw = data.get(index * size..index * size + size).unwrap_or(&[]);
            let bad = |v: String| {
                DataError::field(
                    file,
                    "part id",
                    format!(
                        "expected -1 (background) or a part id 0..=32767, found {v} at pixel ({x}, {y})"
                    ),
                )
            };
            let v = element(h.dtype, h.big_endian, raw).map_err(|e| bad(e.to_string()))?;
            let id = i16::try_from(v)
                .ok()
                .filter(|&id| id >= -1)
                .ok_or_else(|| bad(v.to_string()))?;
            ids.push(id);
        }
    }
    Ok(PartMap {
        width: h.width as u32,
        height: h.height as u32,
        ids,
    })
}

/// Writes a part map as an `.npy` of `<i4` with -1 background.
pub(crate) fn encode_parts_npy(parts: &PartMap) -> Vec<u8> {
    let data: Vec<u8> = parts
        .ids
        .iter()
        .flat_map(|&id| i32::from(id).to_le_bytes())
        .collect();
    encode_npy(
        "<i4",
        false,
        &[parts.height as usize, parts.width as usize],
        &data,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn npy_i64(shape: &[usize], fortran: bool, v: &[i64]) -> Vec<u8> {
        let data: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        encode_npy("<i8", fortran, shape, &data)
    }

    #[test]
    fn header_is_aligned_and_reads_back() {
        let bytes = npy_i64(&[2, 3], false, &[-1, 0, 1, 2, 3, -1]);
        assert_eq!((bytes.len() - 48) % 64, 0);
        let m = decode_parts_npy("s.npy", &bytes).unwrap();
        assert_eq!((m.width, m.height, m.ids), (3, 2, vec![-1, 0, 1, 2, 3, -1]));
    }

    #[test]
    fn fortran_order_and_hwc_shape() {
        // Column-major storage of [[0, 1, 2], [3, 4, 5]].
        let m = decode_parts_npy("s.npy", &npy_i64(&[2, 3, 1], true, &[0, 3, 1, 4, 2, 5])).unwrap();
        assert_eq!(m.ids, vec![0, 1, 2, 3, 4, 5]);
    }

    #[test]
    fn dtypes_and_rejections() {
        let f: Vec<u8> = [1.0f32, -1.0]
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        assert_eq!(
            decode_parts_npy("s.npy", &encode_npy("<f4", false, &[1, 2], &f))
                .unwrap()
                .ids,
            vec![1, -1]
        );
        let half: Vec<u8> = [0.5f64].iter().flat_map(|x| x.to_le_bytes()).collect();
        assert!(
            decode_parts_npy("s.npy", &encode_npy("<f8", false, &[1, 1], &half))
                .unwrap_err()
                .message
                .contains("whole")
        );
        let be: Vec<u8> = [7u16].iter().flat_map(|x| x.to_be_bytes()).collect();
        assert_eq!(
            decode_parts_npy("s.npy", &encode_npy(">u2", false, &[1, 1], &be))
                .unwrap()
                .ids,
            vec![7]
        );
        assert_eq!(
            decode_parts_npy("s.npy", &encode_npy("|b1", false, &[1, 1], &[1]))
                .unwrap_err()
                .field
                .as_deref(),
            Some("descr")
        );
        assert!(
            decode_parts_npy("s.npy", &npy_i64(&[1, 1], false, &[-2]))
                .unwrap_err()
                .message
                .contains("found -2")
        );
        let huge = npy_i64(&[1_000_000, 1_000_000], false, &[0]);
        let e = decode_parts_npy("s.npy", &huge).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("shape"), "{e}");
        let overflow = npy_i64(&[u32::MAX as usize, u32::MAX as usize], false, &[0]);
        assert!(decode_parts_npy("s.npy", &overflow).is_err());
        assert!(decode_parts_npy("s.npy", &npy_i64(&[4], false, &[0; 4])).is_err());
        assert!(
            decode_parts_npy("s.npy", b"\x93NUMPY\x01\x00\xff\xff{")
                .unwrap_err()
                .message
                .contains("truncated")
        );
        for cut in 0..60 {
            let _ = decode_parts_npy("s.npy", &huge[..cut.min(huge.len())]);
        }
    }
}
