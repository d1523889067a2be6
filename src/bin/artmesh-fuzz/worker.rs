//! The worker process: runs one reader on one range of inputs and reports each input on stdout,
//! its index before the reader sees it (so a crash or a hang is pinned on the right input) and its
//! outcome, time and peak heap after. The line protocol, one line per event:
//!
//! ```text
//! s INDEX                      the input is about to run
//! e INDEX a|r|p MICROS BYTES   accepted / rejected / panicked, time in the reader, peak heap above the base
//! p INDEX MESSAGE              the panic's message and `(at FILE:LINE:COL)` (newlines replaced)
//! done                         the range is finished
//! ```

use std::cell::{Cell, RefCell};
use std::io::Write;

use artmesh::fixtures::fuzz::{self, INPUT_MEMORY_BUDGET, Outcome};

use crate::alloc;

/// Runs inputs `first .. first + count` of `reader_name` with run seed `seed`. Returns the exit code.
pub fn work(reader_name: &str, seed: u64, first: u64, count: u64) -> i32 {
    let readers = match fuzz::readers() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("artmesh-fuzz worker: cannot build the seeds: {e}");
            return 2;
        }
    };
    let Some(reader) = readers.iter().find(|r| r.name == reader_name) else {
        eprintln!("artmesh-fuzz worker: no reader named {reader_name}");
        return 2;
    };
    alloc::set_limit(INPUT_MEMORY_BUDGET);
    let out = RefCell::new(std::io::BufWriter::new(std::io::stdout().lock()));
    let base = Cell::new(0usize);
    // A write error means the supervisor is gone: stop rather than fuzz for no one.
    let broken = Cell::new(false);
    let mut before = |index: u64, _: &[u8]| {
        let mut out = out.borrow_mut();
        if writeln!(out, "s {index}")
            .and_then(|()| out.flush())
            .is_err()
        {
            broken.set(true);
        }
        base.set(alloc::reset_peak());
    };
    let mut after = |index: u64, outcome: &Outcome, elapsed: std::time::Duration| {
        let peak = alloc::peak().saturating_sub(base.get());
        let code = match outcome {
            Outcome::Accepted => 'a',
            Outcome::Rejected => 'r',
            Outcome::Panicked(message) => {
                let message = message.replace('\n', " | ");
                let _ = writeln!(out.borrow_mut(), "p {index} {message}");
                'p'
            }
        };
        let micros = elapsed.as_micros();
        let _ = writeln!(out.borrow_mut(), "e {index} {code} {micros} {peak}");
    };
    // One input at a time so a broken pipe stops the worker promptly.
    for index in first..first.saturating_add(count) {
        if broken.get() {
            return 3;
        }
        fuzz::run(reader, seed, index, 1, &mut before, &mut after);
    }
    let mut out = out.borrow_mut();
    if writeln!(out, "done").and_then(|()| out.flush()).is_err() {
        return 3;
    }
    0
}
