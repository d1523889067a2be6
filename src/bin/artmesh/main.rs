//! The `artmesh` command line: drives the library headless and prints what it finds.
//! Native only; in the browser the same library is driven by `web/`.
//!
//! One module per command (or family of commands) holds its clap arguments and what it runs;
//! this file only parses the command line and dispatches.

#[cfg(target_arch = "wasm32")]
fn main() {}

/// `println!` that treats a closed stdout (`artmesh ... | head`) as done instead of panicking.
#[cfg(not(target_arch = "wasm32"))]
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}

#[cfg(not(target_arch = "wasm32"))]
mod args;
#[cfg(not(target_arch = "wasm32"))]
mod bench;
#[cfg(not(target_arch = "wasm32"))]
mod capture;
#[cfg(not(target_arch = "wasm32"))]
mod demo;
#[cfg(not(target_arch = "wasm32"))]
mod eval;
#[cfg(not(target_arch = "wasm32"))]
mod export;
#[cfg(not(target_arch = "wasm32"))]
mod fit;
#[cfg(not(target_arch = "wasm32"))]
mod info;
#[cfg(not(target_arch = "wasm32"))]
mod learn;
#[cfg(not(target_arch = "wasm32"))]
mod output;
#[cfg(not(target_arch = "wasm32"))]
mod progress;
#[cfg(not(target_arch = "wasm32"))]
mod reconstruct;
#[cfg(not(target_arch = "wasm32"))]
mod suite;
#[cfg(not(target_arch = "wasm32"))]
mod synth;

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    let cli = <Cli as clap::Parser>::parse();
    match run(cli.command) {
        Ok(code) => code,
        Err(message) => {
            eprintln!("artmesh: {message}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// Articulated digital twins from multi-view RGB-D frames at two articulation states.
#[cfg(not(target_arch = "wasm32"))]
#[derive(clap::Parser)]
#[command(name = "artmesh", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// The variants' doc comments are the commands' help text; their arguments live with each command.
#[cfg(not(target_arch = "wasm32"))]
#[derive(clap::Subcommand)]
enum Command {
    /// Check a dataset folder and summarise it (views per state and split, resolution,
    /// parts, depth range, ground truth), or list every problem found.
    Info(info::InfoArgs),
    /// Report the GPU adapter and check the GPU primitives (prefix sum, radix sort) against the CPU.
    Gpu(info::GpuArgs),
    /// Write the built-in sample dataset (a small synthetic two-state object with depth,
    /// part maps and ground truth) to a new folder.
    Sample(info::SampleArgs),
    /// Score predicted joints and part meshes against ground truth with the metrics of the
    /// paper's tables (Axis Ang, Axis Pos, Part Motion, CD-s, CD-m); prints JSON. Given a suite
    /// folder (with suite.json), scores every object (PRED/<id> against GT/<id>) and adds the
    /// tables by part-count bucket and by category.
    Eval(eval::EvalArgs),
    /// Generate a procedural object of one benchmark category and capture it as a two-state
    /// dataset (ground truth included); the object itself goes to OUT/object/ as URDF + meshes.
    Synth(synth::SynthArgs),
    /// The rasterizer's learning driver: capture a procedural object at one state and fit a
    /// jittered, grey, half-transparent copy of its surface to those views with the
    /// differentiable rasterizer, the image loss and Adam. JSON (curve, PSNR) on stdout,
    /// progress on stderr.
    Learn(learn::LearnArgs),
    /// The reconstruction phase: from each state's training frames (RGB-D + part maps), fit a
    /// part-aware mesh field, remesh it per part with restricted Delaunay and recover. Writes
    /// OUT/gt/{state}/{state}_static_rotate.ply and ..._dynamic_{i}_rotate.ply (one mesh per part
    /// and state, the layout `eval` reads) and OUT/report.json (mesh quality per part, Chamfer to
    /// the dataset's ground truth when it has one, time per phase); prints the report.
    Reconstruct(reconstruct::ReconstructArgs),
    /// The main job: reconstruct both states and fit every joint (revolute or prismatic: axis,
    /// pivot, motion). Writes OUT/joints.json (type, axis origin and direction, motion, limits per
    /// movable part), OUT/gt/ (trans.json and one PLY per part and state: the layout `eval` reads)
    /// and OUT/report.json (times, bake-off losses, warnings, mesh quality, and the paper's metrics
    /// when the dataset has ground truth), and the twin: OUT/urdf/twin.urdf (+ meshes), OUT/twin.glb
    /// and OUT/twin.zip (both for download); prints the joints and metrics.
    Fit(fit::FitArgs),
    /// Export a fit folder (what `fit` or `demo` wrote) again: the twin's GLB (a node per part, vertex
    /// colours, a start-to-end animation, joints in extras) and/or the zip of URDF + meshes +
    /// joints.json + GLB for simulators. Reads FIT_DIR/urdf/twin.urdf and FIT_DIR/joints.json.
    Export(export::ExportArgs),
    /// Zero-set-up demo: generate the built-in object (a procedural cabinet with a drawer and a
    /// door), capture it at 256x256 (4x the working size, at least) with 12 views per state, fit it, score it against its ground
    /// truth and write everything (dataset, fit, metrics) to a new folder.
    Demo(demo::DemoArgs),
    /// Capture a URDF object (with its meshes) as a two-state dataset with ground truth.
    Render(synth::RenderArgs),
    /// Generate the benchmark suite: 100 procedural objects (16 categories, part-count buckets
    /// 2 / 3 / 4-5 / 6+ in the paper's proportions 34 / 20 / 31 / 15), each captured as a
    /// dataset, plus suite.json and a contact sheet.
    Suite(suite::SuiteArgs),
    /// Benchmarks that print machine-readable JSON.
    Bench {
        #[command(subcommand)]
        which: bench::Bench,
    },
}

/// Runs one command: `Ok` with its exit code, `Err` with the message `main` prints.
#[cfg(not(target_arch = "wasm32"))]
fn run(command: Command) -> Result<std::process::ExitCode, String> {
    match command {
        Command::Info(a) => info::info(&a),
        Command::Gpu(a) => info::gpu(&a),
        Command::Sample(a) => info::sample(&a),
        Command::Eval(a) => eval::run(a),
        Command::Synth(a) => synth::synth(a),
        Command::Learn(a) => learn::run(&a),
        Command::Reconstruct(a) => reconstruct::run(&a),
        Command::Fit(a) => fit::run(a),
        Command::Export(a) => export::run(&a),
        Command::Demo(a) => demo::run(a),
        Command::Render(a) => synth::render(a),
        Command::Suite(a) => suite::run(&a),
        Command::Bench { which } => bench::run(which),
    }
}
