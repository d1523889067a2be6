//! The wasm-bindgen surface for `web/`: the page calls these to report the adapter, run the GPU
//! self-test and check dropped dataset files. Results cross the boundary as JSON strings.

use wasm_bindgen::prelude::*;

use crate::data::{Dataset, FileSet};
use crate::gpu::{GpuContext, selftest};

/// Installs the panic hook so a Rust panic shows in the console instead of a silent dead app.
#[wasm_bindgen(start)]
pub fn start() {
    console_error_panic_hook::set_once();
}

fn js_error(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// The WebGPU adapter and its limits, as JSON.
#[wasm_bindgen]
pub async fn adapter_report() -> Result<String, JsError> {
    let ctx = GpuContext::new().await.map_err(js_error)?;
    serde_json::to_string(&ctx.adapter).map_err(js_error)
}

/// Runs the prefix-sum and radix-sort self-test for the default sizes up to `max_size`, as JSON
/// (`passed` tells the verdict).
#[wasm_bindgen]
pub async fn gpu_self_test(max_size: u32) -> Result<String, JsError> {
    let ctx = GpuContext::new().await.map_err(js_error)?;
    let sizes: Vec<u32> = selftest::DEFAULT_SIZES
        .iter()
        .copied()
        .filter(|&n| n <= max_size)
        .collect();
    let report = selftest::run(&ctx, &sizes).await.map_err(js_error)?;
    let value = serde_json::json!({ "passed": report.passed(), "report": report });
    serde_json::to_string(&value).map_err(js_error)
}

/// Checks a dropped dataset: `paths[i]` (relative, '/'-separated) holds `contents[i]`.
/// Returns `{"ok": true, "summary": ...}` or `{"ok": false, "problems": [...]}` as JSON.
#[wasm_bindgen]
pub fn inspect_dataset(
    paths: Vec<String>,
    contents: Vec<js_sys::Uint8Array>,
) -> Result<String, JsError> {
    if paths.len() != contents.len() {
        return Err(JsError::new(
            "inspect_dataset: paths and contents differ in length",
        ));
    }
    let files: FileSet = paths
        .into_iter()
        .zip(contents.iter().map(|c| c.to_vec()))
        .collect();
    let value = match Dataset::from_files(&files) {
        Ok(dataset) => {
            let summary = dataset.summary();
            serde_json::json!({ "ok": true, "text": summary.to_string(), "summary": summary })
        }
        Err(problems) => serde_json::json!({
            "ok": false,
            "problems": problems.0.iter().map(ToString::to_string).collect::<Vec<_>>(),
        }),
    };
    serde_json::to_string(&value).map_err(js_error)
}
