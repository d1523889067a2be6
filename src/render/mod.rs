//! Ground-truth renderer: a plain wgpu render pipeline (not the differentiable rasterizer) that turns posed
//! meshes and a [`Camera`] into the three images a dataset frame holds: RGBA (alpha = coverage mask), z-depth
//! and part ids.
//!
//! Conventions:
//! - The projection comes from the pinhole [`Intrinsics`]: a world point lands exactly where
//!   [`Camera::project`] puts it, with pixel centres at `+0.5`.
//! - Depth is the camera-space z-depth in metres (distance along the viewing axis, not ray length, not NDC),
//!   interpolated perspective-correctly from the vertices, so it is exact on planar faces up to `f32` rounding.
//!   [`RenderedView::depth`] holds it in millimetres, rounded, 0 where nothing is covered; depths of 65.535 m
//!   and more are **clamped** to 65 535 mm. [`RenderedView::depth_metres`] keeps the unrounded values.
//! - The depth buffer uses reversed z (`Depth32Float`, near → 1, far → 0, compare `Greater`) with near/far
//!   fitted to the scene's vertices for every view; it only decides visibility.
//! - Shading is deterministic: base colour (the mesh's vertex colours when it has them, else its material's;
//!   × texture, bilinear, repeat) × (0.3 ambient + 0.7 two-sided Lambert
//!   from a headlight at the camera), written sRGB-encoded to `Rgba8Unorm`. Material alpha is ignored: every
//!   surface is opaque. Background is transparent black, part id −1.
//! - No back-face culling: imported meshes do not always wind consistently.
//!
//! The module is async and I/O-free, so it runs natively and in the browser.

mod dataset;
mod sheet;
pub mod viewer;

pub use dataset::{
    CaptureTruth, DatasetRenderError, MIN_OBJECT_SIZE, ObjectProblem, RenderProgress, RenderSpec,
    RenderedDataset, capture_dataset, capture_truth, render_dataset,
};
pub use sheet::{SheetEntry, contact_sheet, overview_camera};

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

use crate::data::{Camera, DepthMap, PartMap, RgbaImage, look_at};
use crate::gpu::{GpuContext, GpuError, GpuResult};
use crate::object::{ArticulatedObject, RenderMesh};
use crate::rng::Rng;

const SHADER: &str = include_str!("../../shaders/render_gt.wgsl");

const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
const PART_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Sint;
const ZBUFFER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Bytes per texel of each of the three read-back targets (all 32-bit).
const TEXEL_BYTES: u32 = 4;

/// A world-space mesh tagged with the part it belongs to.
#[derive(Debug, Clone, PartialEq)]
pub struct PartMesh {
    /// Geometry and material in world coordinates.
    pub mesh: RenderMesh,
    /// Part id written to the part map (0 = static base, k = movable part k).
    pub part: i16,
}

/// The three images of one rendered view.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderedView {
    /// Shaded colour (sRGB-encoded), alpha 255 where a surface covers the pixel centre, else transparent black.
    pub rgba: RgbaImage,
    /// z-depth in millimetres, rounded; 0 where not covered; clamped to 65 535 (65.535 m).
    pub depth: DepthMap,
    /// Part id of the visible surface, −1 for background.
    pub parts: PartMap,
    /// Unrounded z-depth in metres, row-major, 0 where not covered.
    pub depth_metres: Vec<f32>,
}

/// Per-view uniform shared with `render_gt.wgsl` (`Frame`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct FrameParams {
    world_to_camera: [[f32; 4]; 4],
    proj: [f32; 4],
    depth: [f32; 4],
}

/// Per-mesh uniform shared with `render_gt.wgsl` (`MeshParams`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MeshParams {
    part: i32,
    textured: u32,
    _pad: [u32; 2],
}
const _: () = assert!(size_of::<MeshParams>() == 16);

/// Interleaved vertex: position, normal, uv, linear base colour (the mesh's vertex colours, or
/// its material's colour on every vertex).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
    color: [f32; 3],
}
const _: () = assert!(size_of::<Vertex>() == 44);

/// Renders colour, z-depth and part ids at a fixed image size; reusable across views and scenes.
pub struct GtRenderer {
    width: u32,
    height: u32,
    /// Bytes per row of one target in the readback buffer (padded to `COPY_BYTES_PER_ROW_ALIGNMENT`).
    padded_row: u32,
    pipeline: wgpu::RenderPipeline,
    frame_layout: wgpu::BindGroupLayout,
    mesh_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    /// 1×1 white texture bound for untextured meshes.
    white: wgpu::TextureView,
    color: wgpu::Texture,
    depth: wgpu::Texture,
    part: wgpu::Texture,
    zbuffer: wgpu::Texture,
    readback: wgpu::Buffer,
}

fn invalid(msg: String) -> GpuError {
    GpuError::Device(msg)
}

impl GtRenderer {
    /// Builds the pipeline and the `width`×`height` targets. Errors when the size is zero or beyond the
    /// adapter's texture or buffer limits.
    pub fn new(ctx: &GpuContext, width: u32, height: u32) -> GpuResult<Self> {
        let max_dim = ctx.limits.max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max_dim || height > max_dim {
            return Err(invalid(format!(
                "render size {width}x{height} is not supported: both sides must be between 1 and {max_dim} \
                 (this adapter's max_texture_dimension_2d)"
            )));
        }
        let padded_row = (width * TEXEL_BYTES).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let readback_bytes = 3 * padded_row as u64 * height as u64;
        if readback_bytes > ctx.limits.max_buffer_size {
            return Err(GpuError::TooManyElements {
                what: format!("readback buffer for {width}x{height} renders (bytes)"),
                count: readback_bytes,
                max: ctx.limits.max_buffer_size,
            });
        }
        let device = &ctx.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("render_gt"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("render_gt frame"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let mesh_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("render_gt mesh"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("render_gt"),
            bind_group_layouts: &[Some(&frame_layout), Some(&mesh_layout)],
            immediate_size: 0,
        });
        let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x3];
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("render_gt"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: size_of::<Vertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &attributes,
                })],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: ZBUFFER_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[
                    Some(COLOR_FORMAT.into()),
                    Some(DEPTH_FORMAT.into()),
                    Some(PART_FORMAT.into()),
                ],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("render_gt texture"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let white_image = RgbaImage {
            width: 1,
            height: 1,
            pixels: vec![255; 4],
        };
        let white = upload_texture(ctx, &white_image)?;
        let target = |label: &str, format: wgpu::TextureFormat, copy: bool| {
            let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
            if copy {
                usage |= wgpu::TextureUsages::COPY_SRC;
            }
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let color = target("render_gt colour", COLOR_FORMAT, true);
        let depth = target("render_gt depth", DEPTH_FORMAT, true);
        let part = target("render_gt part", PART_FORMAT, true);
        let zbuffer = target("render_gt zbuffer", ZBUFFER_FORMAT, false);
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("render_gt readback"),
            size: readback_bytes,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        ctx.check()?;
        Ok(GtRenderer {
            width,
            height,
            padded_row,
            pipeline,
            frame_layout,
            mesh_layout,
            sampler,
            white,
            color,
            depth,
            part,
            zbuffer,
            readback,
        })
    }

    /// Image size `(width, height)` this renderer draws at.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Renders `meshes` (world space) through `camera`, whose intrinsics must match the renderer's size.
    /// Textures are uploaded once per distinct image per call; a texture on a mesh without uvs is ignored. Meshes with out-of-range indices, or too big
    /// for one GPU buffer, are errors; non-finite vertices are ignored when fitting near/far.
    pub async fn render_view(
        &self,
        ctx: &GpuContext,
        meshes: &[PartMesh],
        camera: &Camera,
    ) -> GpuResult<RenderedView> {
        let k = camera.intrinsics;
        if (k.width, k.height) != (self.width, self.height) {
            return Err(invalid(format!(
                "camera is {}x{} but this renderer draws {}x{}",
                k.width, k.height, self.width, self.height
            )));
        }
        if !(k.fx.is_finite() && k.fy.is_finite() && k.cx.is_finite() && k.cy.is_finite())
            || k.fx <= 0.0
            || k.fy <= 0.0
        {
            return Err(invalid(format!(
                "camera intrinsics must be finite with positive focal lengths, got fx {} fy {} cx {} cy {}",
                k.fx, k.fy, k.cx, k.cy
            )));
        }
        let world_to_camera = camera.world_to_camera();
        let (near, far) = near_far(meshes, &world_to_camera);
        let (w, h) = (self.width as f32, self.height as f32);
        let frame = FrameParams {
            world_to_camera: world_to_camera.to_cols_array_2d(),
            proj: [
                2.0 * k.fx / w,
                2.0 * k.cx / w - 1.0,
                2.0 * k.fy / h,
                1.0 - 2.0 * k.cy / h,
            ],
            depth: [-near / (far - near), near * far / (far - near), near, far],
        };
        let device = &ctx.device;
        let frame_buffer = ctx.uniform_buffer("render_gt frame", &frame);
        let frame_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("render_gt frame"),
            layout: &self.frame_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: frame_buffer.as_entire_binding(),
            }],
        });

        // Upload geometry and materials; one draw per mesh.
        let mut textures: HashMap<*const RgbaImage, wgpu::TextureView> = HashMap::new();
        let mut draws = Vec::new();
        for (i, pm) in meshes.iter().enumerate() {
            let m = &pm.mesh;
            if m.indices.is_empty() {
                continue;
            }
            let vertices = vertices_of(i, m)?;
            let index_count = m.indices.len() as u64 * 3;
            let vbytes = vertices.len() as u64 * size_of::<Vertex>() as u64;
            let ibytes = index_count * 4;
            let max = ctx.limits.max_buffer_size;
            if vbytes > max || ibytes > max || index_count > u32::MAX as u64 {
                return Err(GpuError::TooManyElements {
                    what: format!("mesh {i}: vertex or index buffer (bytes)"),
                    count: vbytes.max(ibytes),
                    max,
                });
            }
            let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("render_gt vertices"),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            });
            let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("render_gt indices"),
                contents: bytemuck::cast_slice(&m.indices),
                usage: wgpu::BufferUsages::INDEX,
            });
            let textured = m.material.texture.is_some() && m.uvs.is_some();
            let view = match (&m.material.texture, textured) {
                (Some(tex), true) => match textures.entry(Arc::as_ptr(tex)) {
                    Entry::Occupied(e) => &*e.into_mut(),
                    Entry::Vacant(e) => &*e.insert(upload_texture(ctx, tex)?),
                },
                _ => &self.white,
            };
            let params = MeshParams {
                part: pm.part.into(),
                textured: textured as u32,
                _pad: [0; 2],
            };
            let params_buffer = ctx.uniform_buffer("render_gt mesh", &params);
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("render_gt mesh"),
                layout: &self.mesh_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: params_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::Sampler(&self.sampler),
                    },
                ],
            });
            draws.push((vertex_buffer, index_buffer, index_count as u32, group));
        }

        let views =
            [&self.color, &self.depth, &self.part].map(|t| t.create_view(&Default::default()));
        let zview = self.zbuffer.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let clear = |view, value| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(value),
                        store: wgpu::StoreOp::Store,
                    },
                })
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("render_gt"),
                color_attachments: &[
                    clear(&views[0], wgpu::Color::TRANSPARENT),
                    clear(&views[1], wgpu::Color::TRANSPARENT),
                    // Integer targets take the clear value's red channel as the integer: background −1.
                    clear(
                        &views[2],
                        wgpu::Color {
                            r: -1.0,
                            g: 0.0,
                            b: 0.0,
                            a: 0.0,
                        },
                    ),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &zview,
                    // Reversed z: clear to the far value 0.
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &frame_group, &[]);
            for (vb, ib, count, group) in &draws {
                pass.set_bind_group(1, group, &[]);
                pass.set_vertex_buffer(0, vb.slice(..));
                pass.set_index_buffer(ib.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..*count, 0, 0..1);
            }
        }
        let region = self.padded_row as u64 * self.height as u64;
        for (k, texture) in [&self.color, &self.depth, &self.part]
            .into_iter()
            .enumerate()
        {
            encoder.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &self.readback,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: k as u64 * region,
                        bytes_per_row: Some(self.padded_row),
                        rows_per_image: Some(self.height),
                    },
                },
                wgpu::Extent3d {
                    width: self.width,
                    height: self.height,
                    depth_or_array_layers: 1,
                },
            );
        }
        ctx.queue.submit([encoder.finish()]);
        let bytes: Vec<u8> = ctx.read_buffer(&self.readback, 3 * region as usize).await?;
        Ok(self.unpack(&bytes))
    }

    /// Strips the row padding of the three read-back targets and converts them to the output images.
    fn unpack(&self, bytes: &[u8]) -> RenderedView {
        let (w, h) = (self.width as usize, self.height as usize);
        let row = self.padded_row as usize;
        let region = row * h;
        let rows = |k: usize| {
            (0..h).flat_map(move |y| {
                let start = k * region + y * row;
                bytes[start..start + w * 4].chunks_exact(4)
            })
        };
        let pixels: Vec<u8> = rows(0).flatten().copied().collect();
        let parts: Vec<i32> = rows(2)
            .map(|c| i32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let depth_metres: Vec<f32> = rows(1)
            .zip(pixels.chunks_exact(4))
            .map(|(c, rgba)| {
                let z = f32::from_le_bytes([c[0], c[1], c[2], c[3]]);
                // Coverage comes from alpha (every drawn fragment writes 255), not from the depth value.
                if rgba[3] == 255 && z.is_finite() {
                    z
                } else {
                    0.0
                }
            })
            .collect();
        let millimetres = depth_metres
            .iter()
            .map(|&z| {
                if z > 0.0 {
                    (z as f64 * 1000.0).round().clamp(1.0, u16::MAX as f64) as u16
                } else {
                    0
                }
            })
            .collect();
        RenderedView {
            rgba: RgbaImage {
                width: self.width,
                height: self.height,
                pixels,
            },
            depth: DepthMap {
                width: self.width,
                height: self.height,
                millimetres,
            },
            parts: PartMap {
                width: self.width,
                height: self.height,
                ids: parts
                    .iter()
                    .map(|&p| p.clamp(i16::MIN.into(), i16::MAX.into()) as i16)
                    .collect(),
            },
            depth_metres,
        }
    }
}

/// Interleaved vertices of mesh `i`; errors on indices past the end. Missing or short normals/uvs become zero.
fn vertices_of(i: usize, m: &RenderMesh) -> GpuResult<Vec<Vertex>> {
    let n = m.positions.len();
    if let Some(bad) = m.indices.iter().flatten().find(|&&v| v as usize >= n) {
        return Err(invalid(format!(
            "mesh {i}: triangle index {bad} is out of range for {n} vertices"
        )));
    }
    let uvs = m.uvs.as_deref().unwrap_or(&[]);
    let colors = m.colors.as_deref().unwrap_or(&[]);
    let finite = |c: [f32; 3]| c.map(|v| if v.is_finite() { v } else { 0.0 });
    let [r, g, b, _] = m.material.base_color;
    let material = finite([r, g, b]);
    Ok(m.positions
        .iter()
        .enumerate()
        .map(|(v, p)| Vertex {
            position: p.to_array(),
            normal: m.normals.get(v).map_or([0.0; 3], |n| n.to_array()),
            uv: uvs.get(v).map_or([0.0; 2], |t| t.to_array()),
            color: colors.get(v).map_or(material, |&c| finite(c)),
        })
        .collect())
}

/// Near and far planes (positive view depths) enclosing every finite vertex in front of the camera, with a
/// margin. When some vertex lies at or behind the camera plane, triangles through it can be visible arbitrarily
/// close, so near drops to `far · 1e-6` (reversed z keeps that ratio well resolved); what is closer is clipped.
fn near_far(meshes: &[PartMesh], world_to_camera: &Mat4) -> (f32, f32) {
    let mut lo = f32::INFINITY;
    let mut hi = 0.0f32;
    let mut behind = false;
    for p in meshes.iter().flat_map(|m| m.mesh.positions.iter()) {
        let z = -world_to_camera.transform_point3(*p).z;
        if !z.is_finite() {
            continue;
        }
        if z > 0.0 {
            lo = lo.min(z);
            hi = hi.max(z);
        } else {
            behind = true;
        }
    }
    if hi <= 0.0 {
        return (0.01, 100.0);
    }
    // Capped so that far − near and near · far stay finite in f32.
    let far = (hi * 1.01 + 1e-3).min(1e12);
    let near = if behind { far * 1e-6 } else { lo * 0.99 };
    (near.clamp(far * 1e-6, far * 0.5), far)
}

/// Uploads an 8-bit RGBA image as an sRGB texture (sampling returns linear values), shrinking it by an integer
/// stride when it exceeds the adapter's texture size limit. Errors when the pixel buffer has the wrong length.
fn upload_texture(ctx: &GpuContext, image: &RgbaImage) -> GpuResult<wgpu::TextureView> {
    let (w, h) = (image.width as usize, image.height as usize);
    if w == 0 || h == 0 || image.pixels.len() != w * h * 4 {
        return Err(invalid(format!(
            "texture of {}x{} has {} bytes, expected {}",
            w,
            h,
            image.pixels.len(),
            w * h * 4
        )));
    }
    let max = ctx.limits.max_texture_dimension_2d.max(1) as usize;
    let stride = w.max(h).div_ceil(max);
    let (tw, th) = (w.div_ceil(stride), h.div_ceil(stride));
    let shrunk;
    let pixels: &[u8] = if stride == 1 {
        &image.pixels
    } else {
        shrunk = (0..th)
            .flat_map(|y| (0..tw).map(move |x| (y * stride * w + x * stride) * 4))
            .flat_map(|i| image.pixels[i..i + 4].iter().copied())
            .collect::<Vec<u8>>();
        &shrunk
    };
    let texture = ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some("render_gt material"),
            size: wgpu::Extent3d {
                width: tw as u32,
                height: th as u32,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        pixels,
    );
    Ok(texture.create_view(&Default::default()))
}

/// World-space meshes of `obj` at joint values `q` (see [`ArticulatedObject::forward_kinematics`]), each
/// tagged with its link's part from [`ArticulatedObject::parts`].
pub fn posed_part_meshes(obj: &ArticulatedObject, q: &[f32]) -> Vec<PartMesh> {
    let poses = obj.forward_kinematics(q);
    let parts = obj.parts();
    poses
        .iter()
        .enumerate()
        .flat_map(|(link, pose)| {
            let part = parts.link_part.get(link).copied().unwrap_or(0);
            let part = i16::try_from(part).unwrap_or(i16::MAX);
            obj.link_meshes(link).into_iter().map(move |m| PartMesh {
                mesh: m.transformed(pose),
                part,
            })
        })
        .collect()
}

/// `n` camera-to-world poses (OpenGL axes) on a sphere of `radius` around `centre`, each looking at `centre`
/// with world +z up in the image. Directions are uniform on the sphere, or on its upper half (`z ≥ centre.z`,
/// the z-up convention of the datasets) when `upper_hemisphere` is set. The same seed gives the same poses.
/// Directions within ~0.5° of the poles use +y as the up hint so the pose stays well defined.
pub fn sample_views(
    n: usize,
    centre: Vec3,
    radius: f32,
    seed: u64,
    upper_hemisphere: bool,
) -> Vec<Mat4> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            // Uniform on the sphere: z uniform in [−1, 1] (or [0, 1]), azimuth uniform.
            let u = rng.next_f32();
            let z = if upper_hemisphere { u } else { 2.0 * u - 1.0 };
            let phi = std::f32::consts::TAU * rng.next_f32();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let dir = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let up = if z.abs() > 0.99996 { Vec3::Y } else { Vec3::Z };
            look_at(centre + dir * radius, centre, up)
        })
        .collect()
}

/// Axis-aligned bounds of the finite vertices of `meshes`; `None` when there are none.
pub fn object_bounds(meshes: &[PartMesh]) -> Option<(Vec3, Vec3)> {
    crate::object::mesh_bounds(meshes.iter().map(|m| &m.mesh))
}

/// Joint values for one state: every part's joint at `lower + f · (upper − lower)` of its range with `f` drawn
/// uniformly from `fraction` (Articulate-100 draws the start state from [0.6, 0.8] and the end state from
/// [0.2, 0.4]); every other joint, merged chain joints included, at its rest value. One value per joint.
pub fn sample_state(obj: &ArticulatedObject, fraction: (f32, f32), rng: &mut Rng) -> Vec<f32> {
    let parts = obj.parts();
    let values: Vec<f32> = parts
        .parts
        .iter()
        .map(|part| {
            let f = fraction.0 + (fraction.1 - fraction.0) * rng.next_f32();
            part.joint
                .and_then(|j| obj.joints[j].range())
                .map_or(0.0, |(lo, hi)| lo + f * (hi - lo))
        })
        .collect();
    parts.configuration(obj, &values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Intrinsics;

    #[test]
    fn near_far_brackets_scene() {
        let cam = Camera {
            camera_to_world: crate::data::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y),
            intrinsics: Intrinsics::from_fov(8, 8, 1.0, None),
        };
        let mesh = crate::object::box_mesh(Vec3::ONE, Default::default());
        let pm = [PartMesh { mesh, part: 0 }];
        let (n, f) = near_far(&pm, &cam.world_to_camera());
        assert!(n > 0.0 && n < 2.5 && f > 3.5 && f < 4.0, "{n} {f}");
        assert_eq!(near_far(&[], &cam.world_to_camera()), (0.01, 100.0));
    }

    #[test]
    fn bad_indices_are_errors() {
        let mut mesh = crate::object::box_mesh(Vec3::ONE, Default::default());
        mesh.indices.push([0, 1, 99]);
        assert!(vertices_of(3, &mesh).is_err());
    }

    #[test]
    fn sampled_views_look_at_the_centre_from_the_sphere() {
        let centre = Vec3::new(0.2, -0.1, 0.4);
        for upper in [false, true] {
            let poses = sample_views(64, centre, 2.5, 9, upper);
            assert_eq!(poses, sample_views(64, centre, 2.5, 9, upper));
            assert_ne!(poses, sample_views(64, centre, 2.5, 10, upper));
            let mut below = 0;
            for pose in &poses {
                let cam = Camera {
                    camera_to_world: *pose,
                    intrinsics: Intrinsics::from_fov(16, 12, 1.0, None),
                };
                assert!(((cam.position() - centre).length() - 2.5).abs() < 1e-4);
                let (px, depth) = cam.project(centre).unwrap();
                assert!((px - glam::Vec2::new(8.0, 6.0)).length() < 1e-3, "{px}");
                assert!((depth - 2.5).abs() < 1e-4);
                below += usize::from(cam.position().z < centre.z);
            }
            assert_eq!(below == 0, upper, "{below} of 64 below the centre");
        }
    }
}
