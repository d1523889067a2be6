//! Why a state surface or a vertex-wise motion loss cannot be built: the inputs that do not fit
//! together, phrased for the caller who passed them.

use glam::Vec3;

use crate::raster::FieldError;

/// Why [`super::StateSurface`] rejects its arrays.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SurfaceError {
    /// The mesh field itself is inconsistent.
    #[error(transparent)]
    Field(#[from] FieldError),
    /// No part at all.
    #[error("num_parts is 0, expected at least 1 (the static base)")]
    NoParts,
    /// More vertices than `u32` face indices can address.
    #[error("{0} vertices do not fit u32 face indices")]
    TooManyVertices(usize),
    /// A per-vertex array whose length is not the vertex count.
    #[error("{what} has {len} values, expected one per vertex ({vertices})")]
    Length {
        /// The array's name.
        what: &'static str,
        /// Its length.
        len: usize,
        /// The vertex count.
        vertices: usize,
    },
    /// A vertex position with a NaN or infinite coordinate.
    #[error("vertex {vertex} has a non-finite position {position}")]
    NonFinitePosition {
        /// Index of the vertex.
        vertex: usize,
        /// Its position.
        position: Vec3,
    },
    /// A vertex colour with a NaN or infinite channel.
    #[error("vertex {vertex} has a non-finite colour {color}")]
    NonFiniteColor {
        /// Index of the vertex.
        vertex: usize,
        /// Its colour.
        color: Vec3,
    },
    /// An opacity outside [0, 1].
    #[error("vertex {vertex} has opacity {opacity}, expected a value in [0, 1]")]
    Opacity {
        /// Index of the vertex.
        vertex: usize,
        /// Its opacity.
        opacity: f32,
    },
    /// A part label at or above the part count.
    #[error("vertex {vertex} has part {part}, expected 0 to {}", .num_parts - 1)]
    Part {
        /// Index of the vertex.
        vertex: usize,
        /// Its label.
        part: u32,
        /// The part count.
        num_parts: usize,
    },
    /// A face with a vertex index out of range.
    #[error("face {face} is {indices:?}, but there are only {vertices} vertices")]
    FaceIndex {
        /// Index of the face.
        face: usize,
        /// Its vertex indices.
        indices: [u32; 3],
        /// The vertex count.
        vertices: usize,
    },
}

/// Why [`super::vertex_motion_loss`] cannot compare two surfaces.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotionLossError {
    /// The surfaces disagree on the number of parts.
    #[error("the source has {source_parts} parts but the target {target_parts}")]
    PartCounts {
        /// Parts of the source surface.
        source_parts: usize,
        /// Parts of the target surface.
        target_parts: usize,
    },
    /// Fewer motions than parts.
    #[error("{motions} motions for {parts} parts (one per part, the static base included)")]
    TooFewMotions {
        /// Motions given.
        motions: usize,
        /// Parts of the surfaces.
        parts: usize,
    },
    /// A movable part's motion has a NaN or infinite entry.
    #[error("the motion of part {0} is not finite")]
    NonFiniteMotion(usize),
    /// A weight that is negative or not finite.
    #[error("weight {what} is {value}, expected a finite value ≥ 0")]
    Weight {
        /// The weight's name.
        what: &'static str,
        /// Its value.
        value: f32,
    },
}
