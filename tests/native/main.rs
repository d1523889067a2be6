//! The native integration tests, one module per concern, in one test binary: one link instead of
//! nineteen, and one harness whose threads stay busy across modules (`cargo test --test native
//! raster::` runs one module). The browser's tests are `tests/web.rs`.
#![cfg(not(target_arch = "wasm32"))]

mod common;
mod eval_metrics_common;

mod app;
mod articulation;
mod capture;
mod cli;
mod data_malformed;
mod data_roundtrip;
mod dataset_folder;
mod eval_metrics;
mod eval_metrics_objects;
mod export;
mod fit_photometric;
mod fuzz;
mod gpu_primitives;
mod layering;
mod loss_optim;
mod measured_space;
mod object_budgets;
mod object_import;
mod object_import_errors;
mod outputs;
mod outputs_valid;
mod raster;
mod reconstruct;
mod render_gt;
mod synth_objects;
mod urdf_folder;
mod urdf_zip;
mod viewer_opening;
