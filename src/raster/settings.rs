//! Settings of one render and the uniform block the rasterizer kernels read: annealed window
//! sharpness and opacity floor, compositing cut-offs, and the split of the radix-sort keys
//! into tile and depth bits.

use glam::{Mat4, Vec3};

use super::field::GpuField;
use super::kernels::{RasterParams, TILE};
use crate::data::Camera;
use crate::gpu::{GpuError, GpuResult};

/// Output planes before the part logits: RGB, depth, alpha.
pub const BASE_CHANNELS: usize = 5;

/// Settings of one render: the annealed quantities and the compositing cut-offs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RasterSettings {
    /// Window sharpness γ: 1 is a soft pyramid, towards 0 a hard opaque triangle.
    pub gamma: f32,
    /// Face opacity = floor + (1 − floor) · mean vertex opacity (annealed to 1 for opaque meshes).
    pub opacity_floor: f32,
    /// Contributions with α below this are skipped (1/255; 0 for smooth gradient checks).
    pub alpha_min: f32,
    /// Compositing stops once the transmittance falls below this (1e-4; 0 for checks).
    pub transmittance_min: f32,
    /// Faces with a vertex closer than this to the camera plane are culled (metres).
    pub near: f32,
    /// Colour behind the mesh.
    pub background: Vec3,
    /// Active SH degree, 0..=3.
    pub sh_degree: u32,
}

impl Default for RasterSettings {
    fn default() -> Self {
        Self {
            gamma: 1.0,
            opacity_floor: 0.0,
            alpha_min: 1.0 / 255.0,
            transmittance_min: 1e-4,
            near: 0.01,
            background: Vec3::ZERO,
            sh_degree: 0,
        }
    }
}

impl RasterSettings {
    /// The same model without the hard cut-offs, so the output is smooth in every parameter
    /// (what finite-difference checks need, as Brush does).
    pub(crate) fn smooth(self) -> Self {
        Self {
            alpha_min: 0.0,
            transmittance_min: 0.0,
            ..self
        }
    }
}

/// Sort-key split for an image: (tile bits, depth bits), tile bits + depth bits a multiple of 8
/// (whole radix passes) with at least 16 depth bits where possible.
pub fn sort_key_bits(width: u32, height: u32) -> GpuResult<(u32, u32)> {
    let tiles = width.div_ceil(TILE) * height.div_ceil(TILE);
    let tile_bits = (32 - tiles.saturating_sub(1).leading_zeros()).max(1);
    if tile_bits > 24 {
        return Err(GpuError::TooManyElements {
            what: format!("image tiles ({width}x{height} pixels)"),
            count: u64::from(tiles),
            max: 1 << 24,
        });
    }
    let total = (tile_bits + 16).next_multiple_of(8).min(32);
    Ok((tile_bits, total - tile_bits))
}

/// The uniform block for one view.
pub(super) fn raster_params(
    camera: &Camera,
    settings: &RasterSettings,
    field: &GpuField,
    depth_bits: u32,
) -> RasterParams {
    let k = camera.intrinsics;
    let view: Mat4 = camera.world_to_camera();
    RasterParams {
        world_to_camera: view.to_cols_array_2d(),
        camera_position: camera.position().extend(1.0).into(),
        focal: [k.fx, k.fy, k.cx, k.cy],
        background: settings.background.extend(0.0).into(),
        width: k.width,
        height: k.height,
        tiles_x: k.width.div_ceil(TILE),
        tiles_y: k.height.div_ceil(TILE),
        num_faces: field.num_faces,
        num_vertices: field.num_vertices,
        num_parts: field.num_parts,
        sh_degree: settings.sh_degree.min(3),
        gamma: settings.gamma,
        opacity_floor: settings.opacity_floor.clamp(0.0, 1.0),
        alpha_min: settings.alpha_min,
        transmittance_min: settings.transmittance_min,
        near: settings.near,
        depth_bits,
        num_pairs: 0,
        _pad: 0,
    }
}
