//! Browser tests (wasm-bindgen-test in headless Chromium, WebGPU on SwiftShader): the same GPU
//! primitives and dataset checks as the native tests, on the browser's adapter and in wasm.
#![cfg(target_arch = "wasm32")]

use artmesh::gpu::{GpuContext, selftest};
use wasm_bindgen_test::*;

wasm_bindgen_test_configure!(run_in_browser);

async fn context() -> GpuContext {
    match GpuContext::new().await {
        Ok(ctx) => ctx,
        Err(e) => panic!("browser tests need WebGPU: {e}"),
    }
}

fn assert_all_pass(checks: &[selftest::PrimitiveCheck]) {
    let failed: Vec<_> = checks.iter().filter(|c| !c.passed()).collect();
    assert!(failed.is_empty(), "mismatches against the CPU: {failed:#?}");
}

#[wasm_bindgen_test]
async fn prefix_sum_and_radix_sort_match_cpu_up_to_4m() {
    let ctx = context().await;
    let mut checks = Vec::new();
    for (i, &n) in [1u32, 3, 256, 1025, 65_537, 1_000_003, 4_194_304]
        .iter()
        .enumerate()
    {
        checks.push(selftest::check_prefix_sum(&ctx, n, i as u64).await.unwrap());
        checks.push(
            selftest::check_radix_sort(&ctx, n, 32, i as u64)
                .await
                .unwrap(),
        );
    }
    checks.push(
        selftest::check_radix_sort(&ctx, 300_001, 20, 99)
            .await
            .unwrap(),
    );
    assert_all_pass(&checks);
}

#[wasm_bindgen_test]
async fn tiled_dispatch_matches_cpu() {
    let mut ctx = context().await;
    ctx.set_dispatch_dim_limit(7);
    let checks = [
        selftest::check_prefix_sum(&ctx, 100_000, 1).await.unwrap(),
        selftest::check_radix_sort(&ctx, 100_000, 32, 1)
            .await
            .unwrap(),
    ];
    assert_all_pass(&checks);
}

#[wasm_bindgen_test]
fn dataset_round_trip_in_wasm() {
    use artmesh::data::{Dataset, fixture};
    let dataset = fixture::small_dataset(fixture::FixtureParams::default());
    let files = dataset.to_files().unwrap();
    assert_eq!(Dataset::from_files(&files).unwrap(), dataset);
}

#[wasm_bindgen_test]
fn malformed_datasets_give_clear_errors_in_wasm() {
    use artmesh::data::{Dataset, fixture};
    let cases = fixture::malformed_catalogue();
    assert!(cases.len() >= 15);
    for case in cases {
        match Dataset::from_files(&case.files()) {
            Ok(_) => panic!("{}: accepted a malformed dataset", case.name),
            Err(errors) => assert!(
                errors.0.iter().any(|e| case.matches(e)),
                "{}: expected {} / {:?} / '{}', got:\n{errors}",
                case.name,
                case.file,
                case.field,
                case.message
            ),
        }
    }
}
