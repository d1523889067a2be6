//! The hostile-input catalogue (`fixtures::hostile`) in wasm: the same small inputs end in the same
//! clear errors or correct results in the browser, each within 20 s (the native twin is
//! tests/native/object_budgets.rs).

use artmesh::fixtures::hostile;
use wasm_bindgen_test::*;

#[wasm_bindgen_test]
fn every_hostile_input_ends_in_a_clear_error_or_a_correct_result() {
    let now = || js_sys::Date::now() / 1e3;
    let failures = hostile::run_catalogue(now, |line| console_log!("{line}"));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
