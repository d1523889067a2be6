//! One wrapper for a family of compute kernels that share a WGSL file and one bind-group layout.
//!
//! Every entry point of a family sees the same bindings, so one bind group serves all of them
//! and a stage's wrapper holds only its buffers, its pipelines and its uniform structs.

use super::GpuContext;

/// Shared WGSL helpers prepended to every kernel family (2-D dispatch tiling, workgroup scan).
const PRELUDE: &str = include_str!("../../shaders/prelude.wgsl");

/// The kind of one binding, in binding-index order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binding {
    Uniform,
    StorageRead,
    StorageReadWrite,
}

/// A compiled WGSL kernel family: its bind-group layout, shared by all its entry points.
pub struct KernelFamily {
    layout: wgpu::BindGroupLayout,
    label: &'static str,
}

impl KernelFamily {
    /// Compiles `source` (with the prelude prepended) and builds one pipeline per entry point,
    /// returned in the order given.
    pub fn new<const N: usize>(
        ctx: &GpuContext,
        label: &'static str,
        source: &str,
        bindings: &[Binding],
        entry_points: [&str; N],
    ) -> (Self, [wgpu::ComputePipeline; N]) {
        let module = ctx
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(format!("{PRELUDE}\n{source}").into()),
            });
        let entries: Vec<_> = bindings
            .iter()
            .enumerate()
            .map(|(i, kind)| wgpu::BindGroupLayoutEntry {
                binding: i as u32,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: match kind {
                    Binding::Uniform => wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    Binding::StorageRead | Binding::StorageReadWrite => wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage {
                            read_only: *kind == Binding::StorageRead,
                        },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                },
                count: None,
            })
            .collect();
        let layout = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries: &entries,
            });
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let pipelines = entry_points.map(|entry| {
            ctx.device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&pipeline_layout),
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                })
        });
        (Self { layout, label }, pipelines)
    }

    /// A bind group with `buffers[i]` (whole) at binding `i`.
    pub(crate) fn bind(&self, ctx: &GpuContext, buffers: &[&wgpu::Buffer]) -> wgpu::BindGroup {
        let entries: Vec<_> = buffers
            .iter()
            .enumerate()
            .map(|(i, buffer)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.label),
            layout: &self.layout,
            entries: &entries,
        })
    }
}

/// Begins a labelled compute pass (no timestamps).
pub(crate) fn compute_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &'static str,
) -> wgpu::ComputePass<'e> {
    encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes: None,
    })
}
