//! The hostile-input catalogue (`fixtures::hostile`, issue 26): each small input that a naive
//! reader would let exhaust memory or time, or that would make an output hold numbers other tools
//! cannot read, ends in a clear error or a correct result, within 20 s. The browser tests run
//! the same catalogue (tests/web/readers.rs).

use std::time::Instant;

use artmesh::fixtures::hostile;

#[test]
fn every_hostile_input_ends_in_a_clear_error_or_a_correct_result() {
    let clock = Instant::now();
    let failures =
        hostile::run_catalogue(|| clock.elapsed().as_secs_f64(), |line| eprintln!("{line}"));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
