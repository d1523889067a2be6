//! Mesh operations of the reconstruction phase. So far: part-aware restricted Delaunay
//! remeshing ([`restricted_delaunay`], [`part_aware_remesh`]); densification, pruning and mesh
//! quality reports follow with the reconstruction phase.

mod restricted_delaunay;

pub use restricted_delaunay::{RemeshOptions, part_aware_remesh, restricted_delaunay};
