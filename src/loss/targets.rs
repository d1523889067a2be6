//! Target views (colour + mask, depth, part labels) packed once into GPU buffers for [`super::ImageLoss`].
//!
//! Each pixel is two u32: word 0 = RGBA8 (`r | g << 8 | b << 16 | a << 24`, alpha = foreground mask),
//! word 1 = depth in millimetres (low 16 bits, 0 = invalid) | label (high 16 bits, 0 = background or
//! unknown, k + 1 = part k). A view is `8 · width · height` bytes; views are stored whole and back to
//! back in as few buffers as the storage-binding limit allows, so the loss binds one buffer and reads
//! its view at a word offset.

use crate::data::{DepthMap, Frame, PartMap, RgbaImage};
use crate::gpu::{GpuContext, GpuError, GpuResult};

/// Bytes one packed pixel takes.
pub const TARGET_PIXEL_BYTES: u64 = 8;

/// The images of one target view, borrowed from a [`Frame`] or from anywhere else.
#[derive(Debug, Clone, Copy)]
pub struct TargetView<'a> {
    /// Colour; alpha is the foreground mask.
    pub rgba: &'a RgbaImage,
    /// Depth in millimetres (0 = invalid); `None` = no depth term for this view.
    pub depth: Option<&'a DepthMap>,
    /// Part ids (-1 = background); `None` = no part term for this view.
    pub parts: Option<&'a PartMap>,
}

impl<'a> From<&'a Frame> for TargetView<'a> {
    fn from(frame: &'a Frame) -> Self {
        Self {
            rgba: &frame.rgba,
            depth: frame.depth.as_ref(),
            parts: frame.parts.as_ref(),
        }
    }
}

/// Where one view lives on the GPU, plus the per-view counts the loss normalises by.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ViewSlot {
    pub buffer: usize,
    /// First u32 of the view inside its buffer.
    pub offset_words: u32,
    pub depth_pixels: u32,
    pub label_pixels: u32,
    /// Largest label (0 when no pixel is labelled): must not exceed the loss's part count.
    pub max_label: u32,
}

/// A set of same-sized target views uploaded once; the loss reads any of them by index.
pub struct TargetImages {
    width: u32,
    height: u32,
    buffers: Vec<wgpu::Buffer>,
    views: Vec<ViewSlot>,
}

impl TargetImages {
    /// Packs and uploads `views` (all `width`×`height`). Errors name the offending view.
    pub fn upload(
        ctx: &GpuContext,
        width: u32,
        height: u32,
        views: &[TargetView<'_>],
    ) -> GpuResult<Self> {
        Self::upload_with_limit(ctx, width, height, views, u64::MAX)
    }

    /// [`TargetImages::upload`] with buffers of at most `max_buffer_bytes` (further capped by the
    /// adapter's binding limit): lets tests force the multi-buffer layout at small sizes.
    pub fn upload_with_limit(
        ctx: &GpuContext,
        width: u32,
        height: u32,
        views: &[TargetView<'_>],
        max_buffer_bytes: u64,
    ) -> GpuResult<Self> {
        let npix = checked_pixels(width, height)?;
        let view_bytes = npix * TARGET_PIXEL_BYTES;
        // Offsets are u32 words: keep each buffer under 16 GiB whatever the adapter allows.
        let limit = max_buffer_bytes
            .min(ctx.limits.max_storage_buffer_binding_size)
            .min(ctx.limits.max_buffer_size)
            .min(u64::from(u32::MAX) * 4);
        if !views.is_empty() && view_bytes > limit {
            return Err(GpuError::BindingTooLarge {
                what: format!(
                    "target view 0 ({width}×{height}, {TARGET_PIXEL_BYTES} bytes per pixel)"
                ),
                bytes: view_bytes,
                limit,
            });
        }
        let per_buffer = (limit / view_bytes.max(1)).max(1) as usize;

        // Pack and upload view by view: host memory stays at one packed view.
        let mut buffers = Vec::new();
        let mut slots = Vec::with_capacity(views.len());
        for (chunk_index, chunk) in views.chunks(per_buffer).enumerate() {
            let buffer = ctx.storage_buffer_zeroed(
                &format!("loss.targets[{chunk_index}]"),
                view_bytes * chunk.len() as u64,
            )?;
            for (k, view) in chunk.iter().enumerate() {
                let (words, slot) = pack_view(chunk_index * per_buffer + k, width, height, view)?;
                let offset_bytes = view_bytes * k as u64;
                ctx.queue
                    .write_buffer(&buffer, offset_bytes, bytemuck::cast_slice(&words));
                slots.push(ViewSlot {
                    buffer: buffers.len(),
                    offset_words: (offset_bytes / 4) as u32,
                    ..slot
                });
            }
            buffers.push(buffer);
        }
        ctx.check()?;
        Ok(Self {
            width,
            height,
            buffers,
            views: slots,
        })
    }

    /// Width of every view.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height of every view.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Number of views.
    pub fn len(&self) -> usize {
        self.views.len()
    }

    /// True when no view was uploaded.
    pub fn is_empty(&self) -> bool {
        self.views.is_empty()
    }

    /// Number of GPU buffers the views were split over.
    pub fn buffer_count(&self) -> usize {
        self.buffers.len()
    }

    /// Pixels of `view` with valid depth, `None` past the end.
    pub fn depth_pixels(&self, view: usize) -> Option<u32> {
        self.views.get(view).map(|s| s.depth_pixels)
    }

    /// Pixels of `view` with a part label, `None` past the end.
    pub fn label_pixels(&self, view: usize) -> Option<u32> {
        self.views.get(view).map(|s| s.label_pixels)
    }

    /// The buffer holding `view` and the view's slot in it.
    pub(crate) fn slot(&self, view: usize) -> GpuResult<(&wgpu::Buffer, ViewSlot)> {
        let slot = self.views.get(view).copied().ok_or_else(|| {
            GpuError::InvalidInput(format!(
                "target view {view} requested, but only {} views were uploaded",
                self.views.len()
            ))
        })?;
        Ok((&self.buffers[slot.buffer], slot))
    }
}

/// `width · height` as u64, refusing zero sizes and sizes past 32-bit pixel indexing.
pub(crate) fn checked_pixels(width: u32, height: u32) -> GpuResult<u64> {
    let npix = u64::from(width) * u64::from(height);
    if npix == 0 {
        return Err(GpuError::InvalidInput(format!(
            "image size {width}×{height} has no pixels"
        )));
    }
    // The kernels index planar maps as c · npix + pix in u32.
    if npix * 32 > u64::from(u32::MAX) {
        return Err(GpuError::TooManyElements {
            what: format!("image of {width}×{height} pixels"),
            count: npix,
            max: u64::from(u32::MAX) / 32,
        });
    }
    Ok(npix)
}

/// Packs one view, checking every image against the expected size.
fn pack_view(
    index: usize,
    width: u32,
    height: u32,
    view: &TargetView<'_>,
) -> GpuResult<(Vec<u32>, ViewSlot)> {
    let npix = (width as usize) * (height as usize);
    let size_error = |what: &str, w: u32, h: u32, len: usize, per_pixel: usize| {
        GpuError::InvalidInput(format!(
            "target view {index}: the {what} is {w}×{h} with {len} values, but the loss expects \
             {width}×{height} ({} values)",
            npix * per_pixel
        ))
    };
    let rgba = view.rgba;
    if rgba.width != width || rgba.height != height || rgba.pixels.len() != npix * 4 {
        return Err(size_error(
            "colour image",
            rgba.width,
            rgba.height,
            rgba.pixels.len(),
            4,
        ));
    }
    if let Some(d) = view.depth
        && (d.width != width || d.height != height || d.millimetres.len() != npix)
    {
        return Err(size_error(
            "depth map",
            d.width,
            d.height,
            d.millimetres.len(),
            1,
        ));
    }
    if let Some(p) = view.parts
        && (p.width != width || p.height != height || p.ids.len() != npix)
    {
        return Err(size_error("part map", p.width, p.height, p.ids.len(), 1));
    }

    let mut words = Vec::with_capacity(npix * 2);
    let mut slot = ViewSlot {
        buffer: 0,
        offset_words: 0,
        depth_pixels: 0,
        label_pixels: 0,
        max_label: 0,
    };
    for pix in 0..npix {
        let c = &rgba.pixels[pix * 4..pix * 4 + 4];
        words.push(u32::from_le_bytes([c[0], c[1], c[2], c[3]]));
        let depth = view.depth.map_or(0, |d| d.millimetres[pix]);
        let id = view.parts.map_or(-1, |p| p.ids[pix]);
        if id < -1 {
            return Err(GpuError::InvalidInput(format!(
                "target view {index}: part id {id} at pixel ({}, {}); expected -1 (background) or a part index",
                pix % width as usize,
                pix / width as usize
            )));
        }
        // i16 ids ≤ 32767, so k + 1 always fits the 16-bit label.
        let label = (i32::from(id) + 1) as u32;
        slot.depth_pixels += u32::from(depth != 0);
        slot.label_pixels += u32::from(label != 0);
        slot.max_label = slot.max_label.max(label);
        words.push(u32::from(depth) | (label << 16));
    }
    Ok((words, slot))
}
