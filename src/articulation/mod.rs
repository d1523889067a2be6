//! The articulation phase's rigid-motion maths (paper §3.2): per-part motions with their analytic
//! inverse, the per-part gradient sums both consistency terms reduce to, and the vertex-wise
//! motion consistency on the CPU, the joint magnitude's registration along the fitted axis, and the
//! joints measured directly from the depth and part maps ([`observed`], [`geometric`]).

pub mod axis_registration;
pub mod geometric;
pub mod init;
pub mod kernels;
pub mod motion;
pub mod observed;
pub mod sums;
pub mod vertex_motion;

pub use motion::{MotionAdam, MotionGradient, MotionMask, MotionRates, PartMotion};
pub use sums::PartSums;
pub use vertex_motion::{StateSurface, VertexMotionLoss, VertexMotionWeights, vertex_motion_loss};
