//! The differentiable soft mesh rasterizer (MeshSplatting-style, docs/design.md §4; paper §3.1
//! "Differentiable mesh rendering"): the mesh field's faces are projected, binned into 8×8
//! tiles with the GPU radix sort, and alpha-composited front to back with the triangle window
//! φ = ReLU(L(p)/L(s))^γ; colour, depth and part logits use perspective-correct barycentrics.
//! The backward pass reaches positions, SH coefficients, opacities and part logits without float
//! atomics. [`reference`] is a plain CPU renderer of the same model; [`check`] holds the
//! finite-difference and reference checks run natively and in the browser.

pub mod check;
mod field;
mod kernels;
mod rasterizer;
pub mod reference;
mod settings;
mod state;

pub use field::{
    FieldError, FieldGradients, GpuField, MeshField, SH_C0, SH_FLOATS, vertex_corners,
};
pub use kernels::{MAX_PARTS, TILE};
pub use rasterizer::{ForwardStats, Rasterizer};
pub use settings::{BASE_CHANNELS, RasterSettings, sort_key_bits};
pub use state::{RasterState, RenderImages, StageClock, WorkCounts};
