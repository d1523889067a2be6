//! Rendering one view: camera checks and projection uniforms, geometry and material upload, the render pass,
//! and reading the three targets back into a [`RenderedView`].

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::sync::Arc;

use glam::Mat4;
use wgpu::util::DeviceExt;

use crate::data::{Camera, DepthMap, PartMap, RgbaImage};
use crate::gpu::{GpuContext, GpuError, GpuResult};
use crate::object::RenderMesh;

use super::pipeline::{FrameParams, GtRenderer, MeshParams, Vertex, invalid, upload_texture};
use super::{PartMesh, RenderedView};

/// One mesh's draw: vertex and index buffers, index count and its bind group.
struct MeshDraw {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    group: wgpu::BindGroup,
}

impl GtRenderer {
    /// Renders `meshes` (world space) through `camera`, whose intrinsics must match the renderer's size.
    /// Textures are uploaded once per distinct image per call; a texture on a mesh without uvs is ignored. Meshes with out-of-range indices, or too big
    /// for one GPU buffer, are errors; non-finite vertices are ignored when fitting near/far.
    pub async fn render_view(
        &self,
        ctx: &GpuContext,
        meshes: &[PartMesh],
        camera: &Camera,
    ) -> GpuResult<RenderedView> {
        let frame = self.frame_params(meshes, camera)?;
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
        let draws = self.upload_meshes(ctx, meshes)?;
        let mut encoder = device.create_command_encoder(&Default::default());
        self.draw_pass(&mut encoder, &frame_group, &draws);
        let region = self.copy_to_readback(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        let bytes: Vec<u8> = ctx.read_buffer(&self.readback, 3 * region as usize).await?;
        Ok(self.unpack(&bytes))
    }

    /// Checks the camera against the renderer and builds the view's projection and depth-range uniform.
    fn frame_params(&self, meshes: &[PartMesh], camera: &Camera) -> GpuResult<FrameParams> {
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
        Ok(FrameParams {
            world_to_camera: world_to_camera.to_cols_array_2d(),
            proj: [
                2.0 * k.fx / w,
                2.0 * k.cx / w - 1.0,
                2.0 * k.fy / h,
                1.0 - 2.0 * k.cy / h,
            ],
            depth: [-near / (far - near), near * far / (far - near), near, far],
        })
    }

    /// Uploads geometry and materials: one draw per part and texture, however many meshes share
    /// them (a glTF scene can instance one small mesh 100 000 times, and a draw each would take
    /// minutes a view). Each distinct texture image is uploaded once.
    fn upload_meshes(&self, ctx: &GpuContext, meshes: &[PartMesh]) -> GpuResult<Vec<MeshDraw>> {
        let device = &ctx.device;
        let mut textures: HashMap<*const RgbaImage, wgpu::TextureView> = HashMap::new();
        let mut draws = Vec::new();
        for batch in batches(meshes)? {
            let index_count = batch.indices.len() as u64;
            let vbytes = batch.vertices.len() as u64 * size_of::<Vertex>() as u64;
            let ibytes = index_count * 4;
            let max = ctx.limits.max_buffer_size;
            if vbytes > max || ibytes > max || index_count > u32::MAX as u64 {
                return Err(GpuError::TooManyElements {
                    what: format!("part {}: vertex or index buffer (bytes)", batch.part),
                    count: vbytes.max(ibytes),
                    max,
                });
            }
            let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("render_gt vertices"),
                contents: bytemuck::cast_slice(&batch.vertices),
                usage: wgpu::BufferUsages::VERTEX,
            });
            let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("render_gt indices"),
                contents: bytemuck::cast_slice(&batch.indices),
                usage: wgpu::BufferUsages::INDEX,
            });
            let view = match batch.texture {
                Some(tex) => match textures.entry(Arc::as_ptr(tex)) {
                    Entry::Occupied(e) => &*e.into_mut(),
                    Entry::Vacant(e) => &*e.insert(upload_texture(ctx, tex)?),
                },
                None => &self.white,
            };
            let params = MeshParams {
                part: batch.part.into(),
                textured: batch.texture.is_some() as u32,
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
            draws.push(MeshDraw {
                vertices: vertex_buffer,
                indices: index_buffer,
                index_count: index_count as u32,
                group,
            });
        }
        Ok(draws)
    }

    /// Records the render pass: clear (transparent black, part −1, far depth), then every draw.
    fn draw_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        frame_group: &wgpu::BindGroup,
        draws: &[MeshDraw],
    ) {
        let views =
            [&self.color, &self.depth, &self.part].map(|t| t.create_view(&Default::default()));
        let zview = self.zbuffer.create_view(&Default::default());
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
        pass.set_bind_group(0, frame_group, &[]);
        for d in draws {
            pass.set_bind_group(1, &d.group, &[]);
            pass.set_vertex_buffer(0, d.vertices.slice(..));
            pass.set_index_buffer(d.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..d.index_count, 0, 0..1);
        }
    }

    /// Copies the three targets into the readback buffer, one padded region each; returns the region size.
    fn copy_to_readback(&self, encoder: &mut wgpu::CommandEncoder) -> u64 {
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
        region
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
/// The meshes of one part that share a texture (or have none), as one vertex and index list.
struct Batch<'a> {
    part: i16,
    texture: Option<&'a Arc<RgbaImage>>,
    vertices: Vec<Vertex>,
    indices: Vec<u32>,
}

/// The non-empty meshes merged into one [`Batch`] per part and texture, in order of first use.
/// A texture on a mesh without uvs is ignored.
fn batches(meshes: &[PartMesh]) -> GpuResult<Vec<Batch<'_>>> {
    let mut out: Vec<Batch> = Vec::new();
    let mut slot: HashMap<(i16, Option<*const RgbaImage>), usize> = HashMap::new();
    for (i, pm) in meshes.iter().enumerate() {
        let m = &pm.mesh;
        if m.indices.is_empty() {
            continue;
        }
        let texture = m.material.texture.as_ref().filter(|_| m.uvs.is_some());
        let key = (pm.part, texture.map(Arc::as_ptr));
        let k = *slot.entry(key).or_insert_with(|| {
            out.push(Batch {
                part: pm.part,
                texture,
                vertices: Vec::new(),
                indices: Vec::new(),
            });
            out.len() - 1
        });
        let batch = &mut out[k];
        let base = u32::try_from(batch.vertices.len())
            .ok()
            .filter(|b| b.checked_add(m.positions.len() as u32).is_some())
            .ok_or_else(|| invalid(format!("part {}: more than 2³² vertices", pm.part)))?;
        batch.vertices.extend(vertices_of(i, m)?);
        batch
            .indices
            .extend(m.indices.iter().flatten().map(|&v| base + v));
    }
    Ok(out)
}

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

#[cfg(test)]
mod tests {
    use glam::Vec3;

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
}
