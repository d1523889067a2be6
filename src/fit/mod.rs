//! Fitting: the optimisation loops that drive the rasterizer, the losses and Adam. Today this
//! holds the photometric inner loop on its own ([`photometric`]), which proves the differentiable
//! renderer learns; the two-phase schedule of the paper (reconstruction, remeshing, articulation)
//! builds on it.

pub mod photometric;
mod subdivide;

pub use subdivide::{subdivide_to_edge, weld};
