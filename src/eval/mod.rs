//! Evaluation: the metrics of docs/design.md §7, computed exactly as the peers (PARIS, ArtGS, the ArtMesh paper)
//! compute them, plus Chamfer in true units.
//!
//! - [`joints`]: Axis Ang (°), Axis Pos (0.1 m, revolute only, a real line-to-line distance that handles
//!   parallel axes), Part Motion (° geodesic for revolute, m for prismatic), and the optimal type-consistent
//!   matching of predicted to GT joints.
//! - [`chamfer`]: area-weighted surface sampling, k-d tree nearest neighbours, `cd_peer` and `cd_mm`.
//! - [`mesh_quality`]: per-part components, boundary / non-manifold / cross-part counts and Chamfer of a
//!   reconstruction ([`reconstruction_report`]).
//! - [`seen`]: what the training views' depth sees of the static part, and the CD-s a fit of only that
//!   can reach ([`StaticBound`]), beside the metric's sampling floor.
//! - [`report`]: [`ObjectMetrics`] per object ([`evaluate_object`], or [`evaluate_fit`] for a fit
//!   against its dataset's ground truth), serialisable to JSON.
//! - [`tables`]: part-count buckets (2 / 3 / 4-5 / 6+ / All, the paper's Table 1) and per-category columns (the
//!   appendix table), as structs and Markdown.
//!
//! Joint type errors: the matching prefers type-consistent pairs; a pair whose types cannot agree is matched
//! anyway, flagged `type_correct = false`, counted, and scored in the GT joint's units (the prediction read as
//! the rigid motion it describes), so it enters the averages with the cost of its error rather than vanishing.
//! GT joints left without any prediction are listed and lower the type accuracy, but have no error to average.
//! Every input problem (non-finite joints, empty or degenerate meshes, mismatched counts) is an [`EvalError`];
//! reports never hold NaN.

pub mod chamfer;
pub mod joints;
pub mod mesh_quality;
pub mod report;
pub mod seen;
pub mod tables;

pub use crate::synth::PartBucket;
pub use chamfer::{
    ChamferDistance, ChamferOptions, PointSetFault, chamfer_meshes, chamfer_points, sample_surface,
};
pub use joints::{
    JointFault, JointMatching, JointPairMetrics, Solver, axis_angle_deg, axis_line_distance,
    axis_pos, match_joints, match_joints_using, motion_error,
};
pub use mesh_quality::{
    MeshSummary, PartQuality, ReconstructionReport, StateQuality, mesh_summary,
    reconstruction_report,
};
pub use report::{EvalOptions, ObjectMetrics, PartChamfer, evaluate_fit, evaluate_object};
pub use seen::{StaticBound, seen_by, static_bound};
pub use tables::{BenchmarkTable, ColumnSummary};

/// Why an object could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// A joint with non-finite values or a zero axis direction.
    #[error("{side} joint {index}: {reason}")]
    InvalidJoint {
        /// `"predicted"` or `"ground-truth"`.
        side: &'static str,
        /// Index of the joint in its list.
        index: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A mesh that cannot be sampled (no triangles, zero area, bad indices, non-finite vertices).
    #[error("{mesh}: {reason}")]
    InvalidMesh {
        /// Which mesh, e.g. `predicted movable part 2`.
        mesh: String,
        /// What is wrong with it.
        reason: String,
    },
    /// Inputs that do not fit together (e.g. a movable mesh count different from the joint count).
    #[error("{0}")]
    Inconsistent(String),
}
