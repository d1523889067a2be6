//! The articulation phase's rigid-motion maths (paper §3.2): per-part motions with their analytic
//! inverse, the per-part gradient sums both consistency terms reduce to, and the vertex-wise
//! motion consistency on the CPU.

pub mod init;
pub mod kernels;
pub mod motion;
pub mod sums;

pub use motion::{MotionAdam, MotionGradient, MotionMask, MotionRates, PartMotion};
pub use sums::PartSums;
