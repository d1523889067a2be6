//! The articulation phase's rigid-motion maths (paper §3.2): per-part motions with their analytic
//! inverse, the per-part gradient sums both consistency terms reduce to, and the vertex-wise
//! motion consistency on the CPU.

pub mod sums;

pub use sums::PartSums;
