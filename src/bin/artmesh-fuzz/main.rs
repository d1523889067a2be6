//! `artmesh-fuzz`: the long fuzz run over every input reader (issue 26). It supervises one worker
//! process per job (this program again, with a hidden `--worker` flag); each worker runs a range
//! of one reader's mutated inputs under a 2 GB live-heap cap, catching panics, while the
//! supervisor counts a dead worker as an abort and kills one stuck on an input for 20 s as a
//! timeout. Prints one JSON line per reader and a total line; `--out` keeps failing inputs.
//!
//! ```text
//! artmesh-fuzz [--readers png,urdf] [--inputs N] [--seed S] [--jobs J] [--out DIR]
//! artmesh-fuzz --replay READER:INDEX [--seed S] [--input FILE]
//! ```
//! Native only.

#[cfg(target_arch = "wasm32")]
fn main() {}

#[cfg(not(target_arch = "wasm32"))]
mod alloc;
#[cfg(not(target_arch = "wasm32"))]
mod stats;
#[cfg(not(target_arch = "wasm32"))]
mod supervise;
#[cfg(not(target_arch = "wasm32"))]
mod worker;

/// Every allocation of the supervisor and its workers is counted; workers cap it.
#[cfg(not(target_arch = "wasm32"))]
#[global_allocator]
static ALLOCATOR: alloc::Counting = alloc::Counting;

#[cfg(not(target_arch = "wasm32"))]
#[derive(clap::Parser, Debug)]
#[command(
    name = "artmesh-fuzz",
    about = "Fuzz every input reader with mutated seeds, supervised, under a per-input memory and time budget"
)]
struct Args {
    /// Readers to fuzz, comma-separated (default: all; `--list` names them).
    #[arg(long, value_delimiter = ',')]
    readers: Vec<String>,
    /// Inputs per reader.
    #[arg(long, default_value_t = 100_000)]
    inputs: u64,
    /// Run seed: input i of a reader is a function of (reader, seed, i).
    #[arg(long, default_value_t = 26)]
    seed: u64,
    /// Worker processes (default: one per core).
    #[arg(long)]
    jobs: Option<usize>,
    /// Inputs per worker process before it is replaced.
    #[arg(long, default_value_t = 25_000)]
    chunk: u64,
    /// Folder for failing inputs (created; existing files are never overwritten).
    #[arg(long)]
    out: Option<std::path::PathBuf>,
    /// Lists the readers and their seeds (and how many the reader accepts), then exits.
    #[arg(long)]
    list: bool,
    /// Runs one input READER:INDEX here, without catching a panic (for a backtrace).
    #[arg(long)]
    replay: Option<String>,
    /// With --replay, the input's bytes from this file instead of regenerated from the index.
    #[arg(long, requires = "replay")]
    input: Option<std::path::PathBuf>,
    #[arg(long, hide = true)]
    worker: Option<String>,
    #[arg(long, hide = true, default_value_t = 0)]
    first: u64,
    #[arg(long, hide = true, default_value_t = 0)]
    count: u64,
}

#[cfg(not(target_arch = "wasm32"))]
fn main() {
    use clap::Parser as _;
    let args = Args::parse();
    if let Some(name) = &args.worker {
        std::process::exit(worker::work(name, args.seed, args.first, args.count));
    }
    std::process::exit(match run(&args) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("artmesh-fuzz: {e}");
            2
        }
    });
}

/// Everything but the worker: list, replay or the supervised run.
#[cfg(not(target_arch = "wasm32"))]
fn run(args: &Args) -> Result<i32, String> {
    use artmesh::fixtures::fuzz;
    let readers = fuzz::readers()?;
    if args.list {
        for r in &readers {
            let bytes: usize = r.seeds.iter().map(Vec::len).sum();
            let accepted = r.seeds.iter().filter(|s| r.read(s).is_ok()).count();
            println!(
                "{:<11} {:?}, {} seeds ({accepted} accepted), {bytes} bytes",
                r.name,
                r.format,
                r.seeds.len()
            );
        }
        return Ok(0);
    }
    let find = |name: &str| {
        readers.iter().position(|r| r.name == name).ok_or_else(|| {
            let names: Vec<&str> = readers.iter().map(|r| r.name).collect();
            format!("no reader named '{name}' (readers: {})", names.join(", "))
        })
    };
    if let Some(spec) = &args.replay {
        let (name, index) = spec.split_once(':').unwrap_or((spec, "0"));
        let reader = &readers[find(name)?];
        let input = match &args.input {
            Some(path) => std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?,
            None => {
                let index = index
                    .parse()
                    .map_err(|_| format!("bad index in '{spec}'"))?;
                reader.input(args.seed, index)
            }
        };
        println!("{}: {} input bytes", reader.name, input.len());
        let start = std::time::Instant::now();
        let result = reader.read(&input);
        println!(
            "{:?} after {:.1} ms",
            result,
            start.elapsed().as_secs_f64() * 1e3
        );
        return Ok(0);
    }
    let chosen = if args.readers.is_empty() {
        (0..readers.len()).collect()
    } else {
        args.readers
            .iter()
            .map(|n| find(n))
            .collect::<Result<Vec<_>, _>>()?
    };
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let plan = supervise::Plan {
        readers: chosen,
        inputs: args.inputs,
        seed: args.seed,
        jobs,
        chunk: args.chunk,
        out: args.out.clone(),
    };
    Ok(supervise::supervise(&plan, &readers))
}
