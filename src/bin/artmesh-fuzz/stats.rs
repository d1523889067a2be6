//! One reader's figures in a long run, and their JSON line.

use std::collections::BTreeMap;
use std::time::Instant;

use serde_json::{Value, json};

use crate::supervise::Plan;

/// How an input failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// The reader panicked (caught in the worker).
    Panic,
    /// The worker process died in the input (abort, signal, refused allocation).
    Abort,
    /// The input ran past the time budget and its worker was killed.
    Timeout,
}

/// Failing inputs that share a kind and a site (the panic's location, or an abort's last line).
#[derive(Debug, Clone)]
struct Group {
    count: u64,
    first_index: u64,
    message: String,
    /// Inputs written to `--out`, at most [`SAVED_PER_GROUP`].
    files: Vec<String>,
}

/// Inputs kept per group: a few reproduce a bug; thousands would only fill the disk.
const SAVED_PER_GROUP: usize = 5;

/// Where a failure happened: a panic's `(at FILE:LINE:COL)`, else the message's last line (an
/// abort's stderr ends with its cause).
fn site(message: &str) -> String {
    let site = match message.rsplit_once(" (at ") {
        Some((_, at)) => at.trim_end_matches(')'),
        None => message.rsplit(" | ").next().unwrap_or_default(),
    };
    site.chars().take(200).collect()
}

/// Counts for one reader.
#[derive(Debug)]
pub struct Stats {
    pub inputs: u64,
    accepted: u64,
    rejected: u64,
    /// Time in the reader over all inputs (µs).
    busy_micros: u64,
    /// The slowest input: (µs, index).
    slowest: (u64, u64),
    /// The highest peak heap of one input above the worker's base (bytes).
    peak_bytes: u64,
    /// Failures grouped by (kind, site).
    groups: BTreeMap<(Kind, String), Group>,
    /// Failures of each kind: panics, aborts, timeouts.
    counts: [u64; 3],
    /// Inputs not yet accounted for.
    pub remaining: u64,
    pub started: Option<Instant>,
    finished: Option<Instant>,
}

impl Stats {
    pub fn new(inputs: u64) -> Stats {
        Stats {
            inputs: 0,
            accepted: 0,
            rejected: 0,
            busy_micros: 0,
            slowest: (0, 0),
            peak_bytes: 0,
            groups: BTreeMap::new(),
            counts: [0; 3],
            remaining: inputs,
            started: None,
            finished: None,
        }
    }

    fn count(&mut self) {
        self.inputs += 1;
        self.remaining = self.remaining.saturating_sub(1);
        if self.remaining == 0 {
            self.finished = Some(Instant::now());
        }
    }

    /// Counts a finished input from its worker line's rest: `a|r|p MICROS BYTES`.
    pub fn record(&mut self, index: u64, rest: &str) {
        let mut words = rest.split(' ');
        match words.next() {
            Some("a") => self.accepted += 1,
            Some("r") => self.rejected += 1,
            _ => {} // a panic, already counted from its own line
        }
        let mut number = || {
            words
                .next()
                .and_then(|w| w.parse::<u64>().ok())
                .unwrap_or(0)
        };
        let (micros, peak) = (number(), number());
        self.busy_micros += micros;
        if micros >= self.slowest.0 {
            self.slowest = (micros, index);
        }
        self.peak_bytes = self.peak_bytes.max(peak);
        self.count();
    }

    /// Records a failing input. `save` writes it to `--out` (its path), called only while its
    /// group has fewer than [`SAVED_PER_GROUP`] inputs kept. Aborts and timeouts end their worker,
    /// so they count as inputs here; a panic is counted by its `e` line.
    pub fn fail(
        &mut self,
        kind: Kind,
        index: u64,
        message: String,
        save: impl FnOnce() -> Option<String>,
    ) {
        self.counts[kind as usize] += 1;
        let group = self
            .groups
            .entry((kind, site(&message)))
            .or_insert_with(|| Group {
                count: 0,
                first_index: index,
                message,
                files: Vec::new(),
            });
        group.count += 1;
        if group.files.len() < SAVED_PER_GROUP {
            group.files.extend(save());
        }
        if kind != Kind::Panic {
            self.count();
        }
    }

    /// Failures of any kind.
    pub fn failures(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// The reader's JSON line: counts, rates, the slowest input, peak heap and the failures by site.
    pub fn json(&self, name: &str, plan: &Plan) -> Value {
        let wall = match (self.started, self.finished) {
            (Some(a), Some(b)) => b.duration_since(a).as_secs_f64(),
            _ => 0.0,
        };
        let busy = self.busy_micros as f64 / 1e6;
        let round = |x: f64| (x * 10.0).round() / 10.0;
        let failures: Vec<Value> = self
            .groups
            .iter()
            .map(|((kind, site), g)| {
                json!({
                    "kind": format!("{kind:?}").to_lowercase(),
                    "site": site,
                    "count": g.count,
                    "first_index": g.first_index,
                    "message": g.message,
                    "files": g.files,
                })
            })
            .collect();
        json!({
            "reader": name,
            "seed": plan.seed,
            "inputs": self.inputs,
            "accepted": self.accepted,
            "rejected": self.rejected,
            "panics": self.counts[Kind::Panic as usize],
            "aborts": self.counts[Kind::Abort as usize],
            "timeouts": self.counts[Kind::Timeout as usize],
            "wall_s": round(wall),
            "inputs_per_s": round(self.inputs as f64 / wall.max(1e-9)),
            "inputs_per_core_s": round(self.inputs as f64 / busy.max(1e-9)),
            "max_input_ms": round(self.slowest.0 as f64 / 1e3),
            "slowest_index": self.slowest.1,
            "peak_bytes": self.peak_bytes,
            "failures": failures,
        })
    }
}
