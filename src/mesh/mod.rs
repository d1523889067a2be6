//! Mesh operations of the reconstruction phase, on the CPU copy of the mesh field: part-aware
//! restricted Delaunay remeshing ([`restricted_delaunay`], [`part_aware_remesh`]) and the topology
//! edits around it (densification splits, pruning, hardening, connectivity counts, closing short
//! holes, stitching thin parts' rims, decimation to a face budget for the exports), the
//! closest-point queries the articulation phase matches vertices with ([`closest`]), and the k-d
//! tree nearest-neighbour search over point sets ([`spatial`]).

pub mod closest;
mod decimate;
mod holes;
mod restricted_delaunay;
mod rims;
pub mod spatial;
pub mod topology;

pub use decimate::{Decimated, decimate};
pub use holes::{HoleStats, MAX_HOLE_EDGES, close_short_holes};
pub use restricted_delaunay::{RemeshOptions, part_aware_remesh, restricted_delaunay};
pub use rims::{RimStats, stitch_rims};
pub use topology::{
    EdgeCounts, PartSubmesh, edge_counts, face_components, harden_parts, part_meshes,
    part_submeshes,
};
