//! artmesh: articulated digital twins from multi-view RGB-D frames at two articulation states.
//!
//! The module tree follows the pipeline of the ArtMesh paper: [`data`] (cameras, frames, the dataset layout)
//! feeds the fitting stages, which run as WGSL compute kernels through [`gpu`]. The crate is async and
//! I/O-free at its core so the same code runs natively (CLI, tests, lavapipe in CI) and in the browser (WebGPU);
//! file-system access lives only in the CLI and in native-only helpers.

pub mod articulation;
pub mod data;
pub mod eval;
pub mod export;
pub mod fit;
pub mod fixtures;
pub mod gpu;
pub mod loss;
pub mod mesh;
pub mod object;
pub mod optim;
pub mod raster;
pub mod render;
pub mod rng;
pub mod synth;

#[cfg(not(target_arch = "wasm32"))]
pub mod bench;

#[cfg(target_arch = "wasm32")]
pub mod web;
