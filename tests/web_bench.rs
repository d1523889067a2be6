//! The browser twin of `artmesh bench raster`: the same training iterations on the same benchmark
//! scenes (`fit::photometric::timing`), on the browser's adapter (SwiftShader in headless
//! Chromium). A benchmark, not a test: `scripts/test.sh` does not run it. Run it with
//!
//! ```sh
//! CHROMEDRIVER=/usr/bin/chromedriver WASM_BINDGEN_TEST_TIMEOUT=1800 \
//!   cargo test --release --target wasm32-unknown-unknown --test web_bench -- --nocapture
//! ```
//!
//! It prints the benchmark's JSON (`ARTMESH_BENCH_RASTER {...}`) to the runner's output;
//! per-stage times are native only (a browser cannot wait for one stage alone).
#![cfg(target_arch = "wasm32")]

use artmesh::fit::photometric::timing::{DEFAULT_CASES, raster_bench};
use artmesh::gpu::GpuContext;
use wasm_bindgen_test::*;

wasm_bindgen_test_configure!(run_in_browser);

#[wasm_bindgen_test]
async fn bench_raster_in_the_browser() {
    let ctx = GpuContext::new()
        .await
        .unwrap_or_else(|e| panic!("the browser benchmark needs WebGPU: {e}"));
    let report = raster_bench(&ctx, &DEFAULT_CASES, 3)
        .await
        .unwrap_or_else(|e| panic!("bench raster failed in the browser: {e}"));
    let json = serde_json::to_string(&report).expect("the report serialises");
    console_log!("ARTMESH_BENCH_RASTER {json}");
}
