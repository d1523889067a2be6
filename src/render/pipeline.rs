//! The ground-truth renderer's GPU side: the shader interface (uniforms, vertex layout), the render pipeline,
//! its three read-back targets and z-buffer, and material texture upload.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::data::RgbaImage;
use crate::gpu::{GpuContext, GpuError, GpuResult};

const SHADER: &str = include_str!("../../shaders/render_gt.wgsl");

pub(super) const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub(super) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
pub(super) const PART_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Sint;
pub(super) const ZBUFFER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Bytes per texel of each of the three read-back targets (all 32-bit).
pub(super) const TEXEL_BYTES: u32 = 4;

/// Per-view uniform shared with `render_gt.wgsl` (`Frame`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct FrameParams {
    pub(super) world_to_camera: [[f32; 4]; 4],
    pub(super) proj: [f32; 4],
    pub(super) depth: [f32; 4],
}

/// Per-mesh uniform shared with `render_gt.wgsl` (`MeshParams`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct MeshParams {
    pub(super) part: i32,
    pub(super) textured: u32,
    pub(super) _pad: [u32; 2],
}
const _: () = assert!(size_of::<MeshParams>() == 16);

/// Interleaved vertex: position, normal, uv, linear base colour (the mesh's vertex colours, or
/// its material's colour on every vertex).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct Vertex {
    pub(super) position: [f32; 3],
    pub(super) normal: [f32; 3],
    pub(super) uv: [f32; 2],
    pub(super) color: [f32; 3],
}
const _: () = assert!(size_of::<Vertex>() == 44);

/// Renders colour, z-depth and part ids at a fixed image size; reusable across views and scenes.
pub struct GtRenderer {
    pub(super) width: u32,
    pub(super) height: u32,
    /// Bytes per row of one target in the readback buffer (padded to `COPY_BYTES_PER_ROW_ALIGNMENT`).
    pub(super) padded_row: u32,
    pub(super) pipeline: wgpu::RenderPipeline,
    pub(super) frame_layout: wgpu::BindGroupLayout,
    pub(super) mesh_layout: wgpu::BindGroupLayout,
    pub(super) sampler: wgpu::Sampler,
    /// 1×1 white texture bound for untextured meshes.
    pub(super) white: wgpu::TextureView,
    pub(super) color: wgpu::Texture,
    pub(super) depth: wgpu::Texture,
    pub(super) part: wgpu::Texture,
    pub(super) zbuffer: wgpu::Texture,
    pub(super) readback: wgpu::Buffer,
}

/// A renderer error about its inputs (sizes, intrinsics, indices, texture bytes).
pub(super) fn invalid(msg: String) -> GpuError {
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
        let (frame_layout, mesh_layout) = bind_group_layouts(device);
        let pipeline = render_pipeline(device, &module, &frame_layout, &mesh_layout);
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
        let target =
            |label, format, copy| render_target(device, label, format, copy, width, height);
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
}

/// Bind group layouts of the shader: per view (the frame uniform) and per mesh (uniform, texture, sampler).
fn bind_group_layouts(device: &wgpu::Device) -> (wgpu::BindGroupLayout, wgpu::BindGroupLayout) {
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
    (frame_layout, mesh_layout)
}

/// The render pipeline: no culling (imported meshes do not always wind consistently), reversed-z depth test,
/// three colour targets (colour, z-depth, part id).
fn render_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    frame_layout: &wgpu::BindGroupLayout,
    mesh_layout: &wgpu::BindGroupLayout,
) -> wgpu::RenderPipeline {
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("render_gt"),
        bind_group_layouts: &[Some(frame_layout), Some(mesh_layout)],
        immediate_size: 0,
    });
    let attributes =
        wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x3];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("render_gt"),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module,
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
            module,
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
    })
}

/// One `width`×`height` render target; `copy` targets can be read back.
fn render_target(
    device: &wgpu::Device,
    label: &str,
    format: wgpu::TextureFormat,
    copy: bool,
    width: u32,
    height: u32,
) -> wgpu::Texture {
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
}

/// Uploads an 8-bit RGBA image as an sRGB texture (sampling returns linear values), shrinking it by an integer
/// stride when it exceeds the adapter's texture size limit. Errors when the pixel buffer has the wrong length.
pub(super) fn upload_texture(ctx: &GpuContext, image: &RgbaImage) -> GpuResult<wgpu::TextureView> {
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
