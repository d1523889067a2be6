//! The hostile-input catalogue (`fixtures::hostile`) in wasm: the same small inputs end in the same
//! clear errors or correct results in the browser, each within 20 s (the native twin is
//! tests/native/object_budgets.rs).

use artmesh::fixtures::hostile;
use wasm_bindgen_test::*;

#[wasm_bindgen_test]
fn every_hostile_input_ends_in_a_clear_error_or_a_correct_result() {
    let mut failures = Vec::new();
    for case in hostile::catalogue() {
        let start = js_sys::Date::now();
        let outcome = (case.check)();
        let secs = (js_sys::Date::now() - start) / 1e3;
        console_log!("{secs:6.2} s  {}", case.name);
        match outcome {
            Err(why) => failures.push(format!("{}: {why}", case.name)),
            Ok(()) if secs > 20.0 => failures.push(format!("{}: took {secs:.1} s", case.name)),
            Ok(()) => {}
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
