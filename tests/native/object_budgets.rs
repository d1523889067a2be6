//! The hostile-input catalogue (`fixtures::hostile`, issue 26): each small input that a naive
//! reader would let exhaust memory or time, or that would make an output hold numbers other tools
//! cannot read, ends in a clear error or a correct result, within 20 s. The browser tests run
//! the same catalogue (tests/web/readers.rs).

use std::time::Instant;

use artmesh::fixtures::hostile;

#[test]
fn every_hostile_input_ends_in_a_clear_error_or_a_correct_result() {
    let mut failures = Vec::new();
    for case in hostile::catalogue() {
        let start = Instant::now();
        let outcome = (case.check)();
        let secs = start.elapsed().as_secs_f64();
        eprintln!("{secs:6.2} s  {}", case.name);
        match outcome {
            Err(why) => failures.push(format!("{}: {why}", case.name)),
            Ok(()) if secs > 20.0 => failures.push(format!("{}: took {secs:.1} s", case.name)),
            Ok(()) => {}
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
