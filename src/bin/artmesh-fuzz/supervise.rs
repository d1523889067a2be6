//! The supervisor: splits each reader's inputs into chunks, keeps one worker process per job busy
//! with them, and reads the workers' line protocol ([`crate::worker`]). A worker that dies
//! mid-input is an abort of that input, one silent for longer than the time budget is killed as a
//! timeout; either way the rest of its chunk goes to a fresh worker. Each reader's figures are
//! printed as one JSON line when its last input is in.

use std::collections::{HashMap, VecDeque};
use std::fs::OpenOptions;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use artmesh::fixtures::fuzz::{INPUT_MEMORY_BUDGET, INPUT_TIME_BUDGET, Reader};
use serde_json::json;

use crate::stats::{Kind, Stats};

/// What to run: readers (indices into the reader table), inputs per reader, seed and jobs.
pub struct Plan {
    pub readers: Vec<usize>,
    pub inputs: u64,
    pub seed: u64,
    pub jobs: usize,
    pub chunk: u64,
    pub out: Option<PathBuf>,
}

/// A range of one reader's inputs, handed to one worker.
#[derive(Debug, Clone, Copy)]
struct Task {
    reader: usize,
    first: u64,
    end: u64,
}

enum Event {
    Line(String),
    Closed,
}

/// A running worker and what it last said.
struct Worker {
    child: Child,
    task: Task,
    /// The input it is running, if it announced one and has not finished it.
    current: Option<u64>,
    /// When `current` started.
    since: Instant,
    /// The first input of its task it has not finished.
    next: u64,
    done: bool,
    stderr: (Arc<Mutex<String>>, JoinHandle<()>),
}

/// Last characters of a worker's stderr kept for an abort's report.
const STDERR_TAIL: usize = 2000;

fn spawn(
    id: usize,
    task: Task,
    plan: &Plan,
    name: &str,
    tx: &Sender<(usize, Event)>,
) -> Result<Worker, String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot find this program: {e}"))?;
    let mut child = Command::new(exe)
        .args(["--worker", name, "--seed", &plan.seed.to_string()])
        .args([
            "--first",
            &task.first.to_string(),
            "--count",
            &(task.end - task.first).to_string(),
        ])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start a worker: {e}"))?;
    let (Some(stdout), Some(mut stderr)) = (child.stdout.take(), child.stderr.take()) else {
        return Err("a worker has no pipes".into());
    };
    let tx = tx.clone();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            if tx.send((id, Event::Line(line))).is_err() {
                return;
            }
        }
        let _ = tx.send((id, Event::Closed));
    });
    let tail = Arc::new(Mutex::new(String::new()));
    let keep = Arc::clone(&tail);
    let stderr_thread = std::thread::spawn(move || {
        let mut buf = [0u8; 4096];
        while let Ok(n @ 1..) = stderr.read(&mut buf) {
            if let Ok(mut t) = keep.lock() {
                t.push_str(&String::from_utf8_lossy(&buf[..n]));
                if t.len() > 2 * STDERR_TAIL {
                    let cut = t.len() - STDERR_TAIL;
                    let cut = (cut..t.len()).find(|&i| t.is_char_boundary(i)).unwrap_or(0);
                    t.drain(..cut);
                }
            }
        }
    });
    Ok(Worker {
        child,
        task,
        current: None,
        since: Instant::now(),
        next: task.first,
        done: false,
        stderr: (tail, stderr_thread),
    })
}

/// The whole run: per-reader JSON lines as readers finish, then a total line. Returns the exit code
/// (0: nothing found, 1: failures found, 2: the run could not go on).
pub fn supervise(plan: &Plan, readers: &[Reader]) -> i32 {
    let mut queue: VecDeque<Task> = VecDeque::new();
    for &reader in &plan.readers {
        let mut first = 0;
        while first < plan.inputs {
            let end = (first + plan.chunk.max(1)).min(plan.inputs);
            queue.push_back(Task { reader, first, end });
            first = end;
        }
    }
    let mut stats: Vec<Stats> = readers.iter().map(|_| Stats::new(plan.inputs)).collect();
    let (tx, rx) = mpsc::channel();
    let mut workers: HashMap<usize, Worker> = HashMap::new();
    let start = Instant::now();
    let mut next_id = 0;
    let mut last_progress = Instant::now();
    let mut printed = vec![false; readers.len()];
    loop {
        while workers.len() < plan.jobs.max(1) {
            let Some(task) = queue.pop_front() else { break };
            stats[task.reader].started.get_or_insert_with(Instant::now);
            match spawn(next_id, task, plan, readers[task.reader].name, &tx) {
                Ok(w) => {
                    workers.insert(next_id, w);
                    next_id += 1;
                }
                Err(e) => {
                    eprintln!("artmesh-fuzz: {e}");
                    return 2;
                }
            }
        }
        if workers.is_empty() {
            break;
        }
        let code = step(&rx, &mut workers, &mut stats, &mut queue, plan, readers);
        if code != 0 {
            return code;
        }
        kill_timeouts(&mut workers, &mut stats, &mut queue, plan, readers);
        for (i, s) in stats.iter().enumerate() {
            if s.remaining == 0 && plan.readers.contains(&i) && !printed[i] {
                printed[i] = true;
                println!("{}", s.json(readers[i].name, plan));
            }
        }
        if last_progress.elapsed() > Duration::from_secs(30) {
            last_progress = Instant::now();
            let done: u64 = stats.iter().map(|s| s.inputs).sum();
            eprintln!(
                "[artmesh-fuzz] {done} / {} inputs in {:.0} s",
                plan.inputs * plan.readers.len() as u64,
                start.elapsed().as_secs_f64()
            );
        }
    }
    finish(&stats, plan, start.elapsed())
}

/// The total line; the exit code from the failures found.
fn finish(stats: &[Stats], plan: &Plan, wall: Duration) -> i32 {
    let inputs: u64 = stats.iter().map(|s| s.inputs).sum();
    let failures: u64 = stats.iter().map(Stats::failures).sum();
    println!(
        "{}",
        json!({
            "total": {
                "readers": plan.readers.len(),
                "inputs": inputs,
                "failures": failures,
                "wall_s": (wall.as_secs_f64() * 10.0).round() / 10.0,
                "jobs": plan.jobs,
                "seed": plan.seed,
                "time_budget_s": INPUT_TIME_BUDGET.as_secs(),
                "memory_budget_bytes": INPUT_MEMORY_BUDGET,
            }
        })
    );
    i32::from(failures > 0)
}

/// Handles the next worker event (or none within a moment).
fn step(
    rx: &Receiver<(usize, Event)>,
    workers: &mut HashMap<usize, Worker>,
    stats: &mut [Stats],
    queue: &mut VecDeque<Task>,
    plan: &Plan,
    readers: &[Reader],
) -> i32 {
    let (id, event) = match rx.recv_timeout(Duration::from_millis(200)) {
        Ok(e) => e,
        Err(RecvTimeoutError::Timeout) => return 0,
        Err(RecvTimeoutError::Disconnected) => return 2,
    };
    // Events of a worker already killed as a timeout are stale.
    let Some(w) = workers.get_mut(&id) else {
        return 0;
    };
    let s = &mut stats[w.task.reader];
    match event {
        Event::Line(line) => {
            let mut words = line.splitn(3, ' ');
            let (tag, index) = (
                words.next(),
                words.next().and_then(|i| i.parse::<u64>().ok()),
            );
            match (tag, index) {
                (Some("s"), Some(i)) => {
                    w.current = Some(i);
                    w.since = Instant::now();
                }
                (Some("e"), Some(i)) => {
                    s.record(i, words.next().unwrap_or_default());
                    w.current = None;
                    w.next = i + 1;
                }
                (Some("p"), Some(i)) => {
                    let message = words.next().unwrap_or_default().to_string();
                    let reader = &readers[w.task.reader];
                    s.fail(Kind::Panic, i, message, || save(plan, reader, i, "panic"));
                }
                (Some("done"), _) => w.done = true,
                _ => eprintln!("artmesh-fuzz: unexpected worker line {line:?}"),
            }
            0
        }
        Event::Closed => {
            let Some(mut w) = workers.remove(&id) else {
                return 0;
            };
            let status = w.child.wait();
            let _ = w.stderr.1.join();
            let clean = w.done && status.as_ref().is_ok_and(|s| s.success());
            if clean || w.next >= w.task.end {
                return 0;
            }
            let tail = w
                .stderr
                .0
                .lock()
                .map(|t| t.trim().to_string())
                .unwrap_or_default();
            let Some(index) = w.current else {
                // It died between inputs: the harness, not a reader, failed.
                eprintln!("artmesh-fuzz: a worker exited outside any input ({status:?}): {tail}");
                return 2;
            };
            let status = status.map_or_else(|e| e.to_string(), |s| s.to_string());
            let reader = &readers[w.task.reader];
            let message = format!("worker {status}; stderr: {}", tail.replace('\n', " | "));
            stats[w.task.reader].fail(Kind::Abort, index, message, || {
                save(plan, reader, index, "abort")
            });
            requeue(queue, w.task, index + 1);
            0
        }
    }
}

/// Kills workers stuck on one input past the time budget; their inputs count as timeouts.
fn kill_timeouts(
    workers: &mut HashMap<usize, Worker>,
    stats: &mut [Stats],
    queue: &mut VecDeque<Task>,
    plan: &Plan,
    readers: &[Reader],
) {
    let stuck: Vec<usize> = workers
        .iter()
        .filter(|(_, w)| w.current.is_some() && w.since.elapsed() > INPUT_TIME_BUDGET)
        .map(|(&id, _)| id)
        .collect();
    for id in stuck {
        let Some(mut w) = workers.remove(&id) else {
            continue;
        };
        let _ = w.child.kill();
        let _ = w.child.wait();
        let index = w.current.unwrap_or(w.next);
        let reader = &readers[w.task.reader];
        let message = format!("no answer within {} s; killed", INPUT_TIME_BUDGET.as_secs());
        stats[w.task.reader].fail(Kind::Timeout, index, message, || {
            save(plan, reader, index, "timeout")
        });
        requeue(queue, w.task, index + 1);
    }
}

/// Puts the rest of `task` from `from` at the front of the queue.
fn requeue(queue: &mut VecDeque<Task>, task: Task, from: u64) {
    if from < task.end {
        queue.push_front(Task {
            first: from,
            ..task
        });
    }
}

/// Writes the failing input to `--out` (never over an existing file); its path, if written.
fn save(plan: &Plan, reader: &Reader, index: u64, kind: &str) -> Option<String> {
    let dir = plan.out.as_deref()?;
    let path = dir.join(format!(
        "{}-seed{}-{index}-{kind}.bin",
        reader.name, plan.seed
    ));
    match write_new(&path, &reader.input(plan.seed, index)) {
        Ok(()) => Some(path.display().to_string()),
        Err(e) => {
            eprintln!("artmesh-fuzz: cannot write {}: {e}", path.display());
            None
        }
    }
}

fn write_new(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)?
        .write_all(bytes)
}
