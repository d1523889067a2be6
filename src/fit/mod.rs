//! Fitting: the optimisation loops that drive the rasterizer, the losses and Adam.
//! [`photometric`] is the inner loop on its own (a field against posed views);
//! [`init`] seeds a state's field from its depth maps; [`reconstruct`] is the paper's
//! reconstruction phase per state (densify, prune, anneal, harden, part-aware remeshing,
//! recovery). [`articulate`] is the articulation phase on its frozen meshes, [`object`] both
//! phases on one object; [`observer`] is how a driver hears, previews, pauses and cancels them
//! (and the progress events they report); [`preset`] names the budgets all of them spend, and
//! [`work`] counts what a fit of a capture will do, for its time estimates.

pub mod articulate;
pub mod init;
pub mod object;
pub mod observer;
pub mod photometric;
pub mod preset;
pub mod reconstruct;
mod subdivide;
mod views;
pub mod work;

pub use subdivide::{subdivide_to_edge, weld};
pub use views::{ViewCycle, downsample_frame};
