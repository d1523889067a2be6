//! Fitting: the optimisation loops that drive the rasterizer, the losses and Adam.
//! [`photometric`] is the inner loop on its own (a field against posed views);
//! [`init`] seeds a state's field from its depth maps; [`reconstruct`] is the paper's
//! reconstruction phase per state (densify, prune, anneal, harden, part-aware remeshing,
//! recovery). The articulation phase builds on its result.

pub mod articulate;
pub mod init;
pub mod object;
pub mod photometric;
pub mod reconstruct;
mod subdivide;
mod views;

pub use subdivide::{subdivide_to_edge, weld};
pub use views::{ViewCycle, downsample_frame};
