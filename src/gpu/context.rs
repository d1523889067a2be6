//! Device acquisition for both targets and the error type every GPU call returns.
//!
//! Natively the backend comes from the environment (`WGPU_BACKEND=vulkan` in CI, so a missing
//! Vulkan driver is an error instead of a silent fall-back to GL); in the browser it is WebGPU.
//! Validation errors are captured instead of panicking: a panic would kill the wasm app.

use std::sync::{Arc, Mutex};

use serde::Serialize;

use super::GpuResult;

/// Everything that can go wrong on the GPU side, phrased for the person who has to fix it.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter matched; `hint` says what to install or enable.
    #[error("no GPU adapter found ({detail}). {hint}")]
    NoAdapter { detail: String, hint: &'static str },
    /// The adapter exists but refused to create a device.
    #[error("the GPU adapter '{adapter}' refused to create a device: {detail}")]
    RequestDevice { adapter: String, detail: String },
    /// One storage binding would exceed the adapter's `max_storage_buffer_binding_size`.
    #[error(
        "{what} needs {bytes} bytes in one GPU storage binding, but this adapter allows at most {limit}; \
         use smaller images, fewer views or a smaller preset"
    )]
    BindingTooLarge {
        what: String,
        bytes: u64,
        limit: u64,
    },
    /// A count that has to fit the kernels' 32-bit indexing does not.
    #[error("{what}: {count} elements exceed the supported maximum of {max}")]
    TooManyElements { what: String, count: u64, max: u64 },
    /// wgpu reported a validation or out-of-memory error.
    #[error("GPU error: {0}")]
    Device(String),
    /// Mapping a buffer for readback failed.
    #[error("reading results back from the GPU failed: {0}")]
    Readback(String),
    /// A kernel's inputs do not fit together (sizes, indices, counts); the message says which and how.
    #[error("{0}")]
    InvalidInput(String),
    /// The driver cancelled the fit at a checkpoint ([`crate::fit::observer::Command::Cancel`]).
    #[error("cancelled: the fit was stopped before it finished")]
    Cancelled,
}

impl GpuError {
    /// `Err(TooManyElements)` when `n` exceeds the `capacity` a kernel's buffers were sized for.
    pub(crate) fn check_capacity(what: &str, n: u32, capacity: u32) -> GpuResult<()> {
        if n > capacity {
            return Err(GpuError::TooManyElements {
                what: what.to_string(),
                count: n.into(),
                max: capacity.into(),
            });
        }
        Ok(())
    }
}

/// The adapter in words, for `artmesh gpu`, the web page and benchmark output.
#[derive(Debug, Clone, Serialize)]
pub struct AdapterReport {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    pub max_storage_buffer_binding_size: u64,
    pub max_compute_workgroups_per_dimension: u32,
    pub max_compute_invocations_per_workgroup: u32,
    pub max_storage_buffers_per_shader_stage: u32,
}

/// A device and queue with the adapter's own limits, plus captured errors.
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter: AdapterReport,
    pub limits: wgpu::Limits,
    dispatch_dim_limit: u32,
    errors: Arc<Mutex<Vec<String>>>,
    /// The adapter the device came from (for [`GpuContext::another_device`]).
    source: wgpu::Adapter,
}

#[cfg(not(target_arch = "wasm32"))]
const NO_ADAPTER_HINT: &str = "Install a Vulkan driver (on Debian: `apt-get install mesa-vulkan-drivers` gives the \
    lavapipe software driver) and run with WGPU_BACKEND=vulkan, or select another backend with WGPU_BACKEND \
    (vulkan, metal, dx12, gl).";
#[cfg(target_arch = "wasm32")]
const NO_ADAPTER_HINT: &str = "This browser exposes no WebGPU adapter. Use Chrome or Edge 113+ (on Linux start \
    Chromium with --enable-unsafe-webgpu), Safari 26+, or Firefox 141+ on Windows; check that hardware \
    acceleration is enabled.";

impl GpuContext {
    /// Opens the best adapter available and a device with that adapter's own limits.
    pub async fn new() -> GpuResult<Self> {
        #[cfg(not(target_arch = "wasm32"))]
        let desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        #[cfg(target_arch = "wasm32")]
        let desc = wgpu::InstanceDescriptor {
            backends: wgpu::Backends::BROWSER_WEBGPU,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        };
        let instance = wgpu::Instance::new(desc);
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError::NoAdapter {
                detail: e.to_string(),
                hint: NO_ADAPTER_HINT,
            })?;
        Self::on_adapter(adapter).await
    }

    /// A second device on this context's adapter, with its own queue: work submitted to it
    /// runs beside this one's without sharing its locks (natively, a thread per device).
    pub async fn another_device(&self) -> GpuResult<Self> {
        Self::on_adapter(self.source.clone()).await
    }

    /// A device with the adapter's own limits, and its error log.
    async fn on_adapter(adapter: wgpu::Adapter) -> GpuResult<Self> {
        let info = adapter.get_info();
        let limits = adapter.limits();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("artmesh"),
                required_features: wgpu::Features::empty(),
                required_limits: limits.clone(),
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|e| GpuError::RequestDevice {
                adapter: info.name.clone(),
                detail: e.to_string(),
            })?;

        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut list) = sink.lock() {
                list.push(e.to_string());
            }
        }));

        // Browsers may hide the adapter's description (Chromium does): say so rather than print nothing.
        let name = match (info.name.trim(), info.device_type) {
            ("", wgpu::DeviceType::Cpu) => "unnamed software (fallback) adapter".to_string(),
            ("", _) => "unnamed adapter".to_string(),
            (name, _) => name.to_string(),
        };
        let report = AdapterReport {
            name,
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: format!("{} {}", info.driver, info.driver_info)
                .trim()
                .to_string(),
            max_storage_buffer_binding_size: limits.max_storage_buffer_binding_size,
            max_compute_workgroups_per_dimension: limits.max_compute_workgroups_per_dimension,
            max_compute_invocations_per_workgroup: limits.max_compute_invocations_per_workgroup,
            max_storage_buffers_per_shader_stage: limits.max_storage_buffers_per_shader_stage,
        };
        Ok(Self {
            device,
            queue,
            dispatch_dim_limit: limits.max_compute_workgroups_per_dimension.max(1),
            adapter: report,
            limits,
            errors,
            source: adapter,
        })
    }

    /// Returns (and clears) any error the device reported since the last check.
    pub fn check(&self) -> GpuResult<()> {
        let mut list = self
            .errors
            .lock()
            .map_err(|_| GpuError::Device("error log poisoned".into()))?;
        if list.is_empty() {
            Ok(())
        } else {
            let joined = list.join("; ");
            list.clear();
            Err(GpuError::Device(joined))
        }
    }

    /// Lowers the per-dimension workgroup limit used for tiling, so tests can exercise the 2-D
    /// tiling path at small sizes. Values above the adapter's limit are clamped to it.
    pub fn set_dispatch_dim_limit(&mut self, limit: u32) {
        self.dispatch_dim_limit =
            limit.clamp(1, self.limits.max_compute_workgroups_per_dimension.max(1));
    }

    /// The (x, y) grid that covers `workgroups` linear workgroups without exceeding the
    /// per-dimension limit. Kernels rebuild the linear index as `id.x + id.y * num_workgroups.x`
    /// and skip indices past the end (the grid may overshoot by less than one row).
    pub fn workgroup_grid(&self, workgroups: u32) -> (u32, u32) {
        let x = workgroups.clamp(1, self.dispatch_dim_limit);
        (x, workgroups.div_ceil(x).max(1))
    }

    /// Records `workgroups` linear workgroups of `pipeline`, tiled in 2-D when needed.
    pub fn dispatch(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        pipeline: &wgpu::ComputePipeline,
        bind_group: &wgpu::BindGroup,
        workgroups: u32,
    ) {
        if workgroups == 0 {
            return;
        }
        let (x, y) = self.workgroup_grid(workgroups);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups(x, y, 1);
    }

    /// Waits for submitted work natively; a no-op in the browser, where the event loop drives it.
    pub fn poll_wait(&self) -> GpuResult<()> {
        #[cfg(not(target_arch = "wasm32"))]
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Device(e.to_string()))?;
        Ok(())
    }
}
