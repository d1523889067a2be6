//! GPU foundation shared by every stage: one way to get a device natively and in the browser
//! ([`GpuContext`]), buffer and readback helpers, the kernel-family wrapper that owns a shader's
//! pipelines and bind-group layout, and the two data-parallel primitives later stages build on:
//! an exclusive [`PrefixSum`] and a key–value [`RadixSort`] (the rasterizer's tile binning).
//! [`fma_peak`] measures the adapter's achievable f32 FMA rate, the denominator of benchmark
//! efficiency figures.
//!
//! Every kernel obeys the portability rules of docs/design.md §3 so the same WGSL runs on lavapipe,
//! on SwiftShader inside Chromium, and on real GPUs: ≤ 256 invocations per workgroup, ≤ 8 storage
//! buffers per stage, no float atomics, dispatches tiled in 2-D past the per-dimension limit.

mod buffers;
mod clock;
mod context;
mod fma;
mod kernel;
mod radix_sort;
mod scan;
pub mod selftest;

pub use buffers::binding_chunks;
pub use clock::{now_seconds, sleep_ms};
pub use context::{AdapterReport, GpuContext, GpuError};
pub use fma::{FmaPeak, fma_peak, fma_peak_with_clock};
pub(crate) use kernel::compute_pass;
pub use kernel::{Binding, KernelFamily};
pub use radix_sort::{RadixSort, key_mask};
pub use scan::PrefixSum;

/// Result type of everything that touches the GPU.
pub type GpuResult<T> = Result<T, GpuError>;
