//! In-memory images (colour, depth, part ids) and their PNG encoding, via the `image` crate.
//!
//! Readers check the PNG's colour type before converting so a wrong file (an 8-bit depth map, an RGB
//! semantic map) is reported instead of being silently reinterpreted.

use image::{ColorType, DynamicImage, ExtendedColorType, ImageEncoder, ImageFormat};

use super::error::DataError;

/// 8-bit RGBA image, row-major, 4 bytes per pixel; alpha is the foreground mask.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbaImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes, RGBA, row-major from the top-left corner.
    pub pixels: Vec<u8>,
}

/// Depth map: z-depth in millimetres, 0 = no measurement.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DepthMap {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` values, row-major.
    pub millimetres: Vec<u16>,
}

/// Part-id map: -1 background, 0 static base, k movable part k.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PartMap {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` ids, row-major.
    pub ids: Vec<i16>,
}

impl RgbaImage {
    /// Pixel at (x, y), `None` outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> Option<[u8; 4]> {
        let i = pixel_index(self.width, self.height, x, y)?.checked_mul(4)?;
        let p = self.pixels.get(i..i.checked_add(4)?)?;
        Some([p[0], p[1], p[2], p[3]])
    }
}

impl DepthMap {
    /// Depth in metres at (x, y); `None` outside the image or where the depth is invalid (0).
    pub fn metres(&self, x: u32, y: u32) -> Option<f32> {
        let mm = *self
            .millimetres
            .get(pixel_index(self.width, self.height, x, y)?)?;
        (mm != 0).then(|| f32::from(mm) / 1000.0)
    }

    /// Smallest and largest valid depth (millimetres), `None` when no pixel is valid.
    pub fn range_mm(&self) -> Option<(u16, u16)> {
        let mut valid = self.millimetres.iter().copied().filter(|&d| d != 0);
        let first = valid.next()?;
        Some(valid.fold((first, first), |(lo, hi), d| (lo.min(d), hi.max(d))))
    }
}

impl PartMap {
    /// Part id at (x, y), `None` outside the image.
    pub fn id(&self, x: u32, y: u32) -> Option<i16> {
        self.ids
            .get(pixel_index(self.width, self.height, x, y)?)
            .copied()
    }

    /// Largest id in the map (-1 when all background), `None` when empty.
    pub(crate) fn max_id(&self) -> Option<i16> {
        self.ids.iter().copied().max()
    }
}

fn pixel_index(width: u32, height: u32, x: u32, y: u32) -> Option<usize> {
    if x >= width || y >= height {
        return None;
    }
    (y as usize)
        .checked_mul(width as usize)?
        .checked_add(x as usize)
}

/// Pixel data to encode as PNG; 16-bit samples are given as numbers (byte order is handled by the encoder).
#[derive(Debug, Clone, Copy)]
pub enum PngPixels<'a> {
    /// 8-bit grey.
    Gray8(&'a [u8]),
    /// 16-bit grey (depth maps, semantic maps).
    Gray16(&'a [u16]),
    /// 8-bit RGB.
    Rgb8(&'a [u8]),
    /// 8-bit RGBA.
    Rgba8(&'a [u8]),
    /// 16-bit RGB.
    Rgb16(&'a [u16]),
    /// 16-bit RGBA.
    Rgba16(&'a [u16]),
}

/// Encodes pixels as a PNG. `file` only names the output in errors (wrong buffer length, zero size).
pub fn encode_png(
    file: &str,
    width: u32,
    height: u32,
    pixels: PngPixels<'_>,
) -> Result<Vec<u8>, DataError> {
    let (bytes, channels, color): (&[u8], u64, ExtendedColorType) = match pixels {
        PngPixels::Gray8(p) => (p, 1, ExtendedColorType::L8),
        PngPixels::Rgb8(p) => (p, 3, ExtendedColorType::Rgb8),
        PngPixels::Rgba8(p) => (p, 4, ExtendedColorType::Rgba8),
        PngPixels::Gray16(p) => (bytemuck::cast_slice(p), 1, ExtendedColorType::L16),
        PngPixels::Rgb16(p) => (bytemuck::cast_slice(p), 3, ExtendedColorType::Rgb16),
        PngPixels::Rgba16(p) => (bytemuck::cast_slice(p), 4, ExtendedColorType::Rgba16),
    };
    let bytes_per_sample = if matches!(
        color,
        ExtendedColorType::L16 | ExtendedColorType::Rgb16 | ExtendedColorType::Rgba16
    ) {
        2
    } else {
        1
    };
    let expected = u64::from(width) * u64::from(height) * channels * bytes_per_sample;
    if width == 0 || height == 0 {
        return Err(DataError::field(
            file,
            "size",
            format!("cannot write an empty {width}x{height} image"),
        ));
    }
    // The encoder asserts on a length mismatch; check first so bad input is an error, not a panic.
    if bytes.len() as u64 != expected {
        return Err(DataError::field(
            file,
            "pixels",
            format!(
                "expected {expected} bytes for a {width}x{height} image with {channels} channel(s), found {}",
                bytes.len()
            ),
        ));
    }
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(bytes, width, height, color)
        .map_err(|e| DataError::file(file, format!("could not encode PNG: {e}")))?;
    Ok(out)
}

/// Human description of a decoded colour type, for "found ..." messages.
fn describe(color: ColorType) -> String {
    let depth = color.bits_per_pixel() / u16::from(color.channel_count());
    let layout = match color {
        ColorType::L8 | ColorType::L16 => "single-channel",
        ColorType::La8 | ColorType::La16 => "grey+alpha",
        ColorType::Rgb8 | ColorType::Rgb16 | ColorType::Rgb32F => "RGB",
        ColorType::Rgba8 | ColorType::Rgba16 | ColorType::Rgba32F => "RGBA",
        _ => "unknown-layout",
    };
    format!("{depth}-bit {layout}")
}

fn decode(file: &str, bytes: &[u8]) -> Result<DynamicImage, DataError> {
    image::load_from_memory_with_format(bytes, ImageFormat::Png)
        .map_err(|e| DataError::file(file, format!("could not decode PNG: {e}")))
}

/// Field to blame for a colour-type mismatch: the bit depth when that is what differs, else the channels.
fn format_error(file: &str, color: ColorType, expected_bits: u16, expected: &str) -> DataError {
    let bits = color.bits_per_pixel() / u16::from(color.channel_count());
    let field = if bits != expected_bits {
        "bit depth"
    } else {
        "channels"
    };
    DataError::field(
        file,
        field,
        format!("expected {expected}, found {}", describe(color)),
    )
}

/// The pixel count a PNG's header claims (width × height, read before any decoding: a few
/// kilobytes of PNG can claim gigapixels); 0 when `bytes` has no PNG header, whose decoder then
/// names the problem.
pub fn png_claimed_pixels(bytes: &[u8]) -> u64 {
    match bytes.get(12..24) {
        Some(h) if &h[..4] == b"IHDR" => {
            let be = |b: &[u8]| u64::from(u32::from_be_bytes([b[0], b[1], b[2], b[3]]));
            be(&h[4..8]) * be(&h[8..12])
        }
        _ => 0,
    }
}

/// Reads an 8-bit RGBA (or RGB, taken as opaque) PNG.
pub(crate) fn decode_rgba(file: &str, bytes: &[u8]) -> Result<RgbaImage, DataError> {
    let img = decode(file, bytes)?;
    let (width, height) = (img.width(), img.height());
    let pixels = match img {
        DynamicImage::ImageRgba8(buf) => buf.into_raw(),
        DynamicImage::ImageRgb8(buf) => buf
            .into_raw()
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect(),
        other => {
            return Err(format_error(
                file,
                other.color(),
                8,
                "an 8-bit RGBA or RGB PNG",
            ));
        }
    };
    Ok(RgbaImage {
        width,
        height,
        pixels,
    })
}

/// Reads a 16-bit single-channel depth PNG (millimetres).
pub(crate) fn decode_depth(file: &str, bytes: &[u8]) -> Result<DepthMap, DataError> {
    match decode(file, bytes)? {
        DynamicImage::ImageLuma16(buf) => Ok(DepthMap {
            width: buf.width(),
            height: buf.height(),
            millimetres: buf.into_raw(),
        }),
        other => Err(format_error(
            file,
            other.color(),
            16,
            "a 16-bit single-channel PNG",
        )),
    }
}

/// Reads a semantic PNG (16-bit, or 8-bit, single channel; 0 = background, k+1 = part k).
pub(crate) fn decode_parts_png(file: &str, bytes: &[u8]) -> Result<PartMap, DataError> {
    let img = decode(file, bytes)?;
    let (width, height) = (img.width(), img.height());
    let raw: Vec<u16> = match img {
        DynamicImage::ImageLuma16(buf) => buf.into_raw(),
        DynamicImage::ImageLuma8(buf) => buf.into_raw().into_iter().map(u16::from).collect(),
        other => {
            return Err(format_error(
                file,
                other.color(),
                16,
                "a 16-bit single-channel PNG",
            ));
        }
    };
    let mut ids = Vec::with_capacity(raw.len());
    for (i, v) in raw.into_iter().enumerate() {
        // Stored value v means part v-1; part ids must fit i16.
        let id = i16::try_from(i32::from(v) - 1).map_err(|_| {
            DataError::field(
                file,
                "part id",
                format!(
                    "value {v} at pixel ({}, {}) is too large: expected at most {} (part {})",
                    i % width as usize,
                    i / width as usize,
                    i16::MAX as i32 + 1,
                    i16::MAX
                ),
            )
        })?;
        ids.push(id);
    }
    Ok(PartMap { width, height, ids })
}

/// Encodes a part map as our semantic PNG (16-bit, 0 = background, k+1 = part k).
pub(crate) fn encode_parts_png(file: &str, parts: &PartMap) -> Result<Vec<u8>, DataError> {
    let mut raw = Vec::with_capacity(parts.ids.len());
    for (i, &id) in parts.ids.iter().enumerate() {
        let v = u16::try_from(i32::from(id) + 1).map_err(|_| {
            DataError::field(
                file,
                "part id",
                format!("expected ids >= -1, found {id} at index {i}"),
            )
        })?;
        raw.push(v);
    }
    encode_png(file, parts.width, parts.height, PngPixels::Gray16(&raw))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_round_trip_and_format_errors() {
        let mm: Vec<u16> = (0..12).map(|i| i * 1000 + 7).collect();
        let png = encode_png("d.png", 4, 3, PngPixels::Gray16(&mm)).unwrap();
        let d = decode_depth("d.png", &png).unwrap();
        assert_eq!((d.width, d.height, d.millimetres.clone()), (4, 3, mm));
        assert_eq!(d.range_mm(), Some((7, 11007)));

        let rgb = encode_png("d.png", 2, 2, PngPixels::Rgb8(&[0; 12])).unwrap();
        let e = decode_depth("d.png", &rgb).unwrap_err();
        assert_eq!(
            e.to_string(),
            "d.png: bit depth: expected a 16-bit single-channel PNG, found 8-bit RGB"
        );
        let rgb16 = encode_png("d.png", 1, 1, PngPixels::Rgb16(&[1, 2, 3])).unwrap();
        assert_eq!(
            decode_depth("d.png", &rgb16).unwrap_err().field.as_deref(),
            Some("channels")
        );
        assert!(encode_png("d.png", 4, 4, PngPixels::Gray8(&[0; 3])).is_err());
    }

    #[test]
    fn rgb_is_opaque_rgba() {
        let png = encode_png("c.png", 1, 2, PngPixels::Rgb8(&[1, 2, 3, 4, 5, 6])).unwrap();
        assert_eq!(
            decode_rgba("c.png", &png).unwrap().pixels,
            vec![1, 2, 3, 255, 4, 5, 6, 255]
        );
        let grey = encode_png("c.png", 1, 1, PngPixels::Gray8(&[0])).unwrap();
        assert!(
            decode_rgba("c.png", &grey)
                .unwrap_err()
                .message
                .contains("found 8-bit single-channel")
        );
    }

    #[test]
    fn parts_png_offsets_ids() {
        let parts = PartMap {
            width: 3,
            height: 1,
            ids: vec![-1, 0, 4],
        };
        let png = encode_parts_png("s.png", &parts).unwrap();
        assert_eq!(decode_parts_png("s.png", &png).unwrap(), parts);
        let big = encode_png("s.png", 1, 1, PngPixels::Gray16(&[40000])).unwrap();
        assert!(
            decode_parts_png("s.png", &big)
                .unwrap_err()
                .message
                .contains("too large")
        );
    }
}
