//! The `artmesh` command line: drives the library headless and prints what it finds.
//! Native only; in the browser the same library is driven by `web/`.

#[cfg(target_arch = "wasm32")]
fn main() {}

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    cli::main()
}

#[cfg(not(target_arch = "wasm32"))]
mod cli {
    use std::path::PathBuf;
    use std::process::ExitCode;

    use artmesh::data::{self, Dataset, fixture};
    use artmesh::gpu::{GpuContext, selftest};
    use clap::{Parser, Subcommand};

    /// Articulated digital twins from multi-view RGB-D frames at two articulation states.
    #[derive(Parser)]
    #[command(name = "artmesh", version, about, long_about = None)]
    struct Cli {
        #[command(subcommand)]
        command: Command,
    }

    #[derive(Subcommand)]
    enum Command {
        /// Check a dataset folder and summarise it (views per state and split, resolution,
        /// parts, depth range, ground truth), or list every problem found.
        Info {
            /// Dataset folder in the ArtGS / MPArt-90 / PARIS layout (transforms_*_{start,end}.json, ...).
            dataset: PathBuf,
            /// Print the summary as JSON.
            #[arg(long)]
            json: bool,
        },
        /// Report the GPU adapter and check the GPU primitives (prefix sum, radix sort) against the CPU.
        Gpu {
            /// Largest input size for the self-test.
            #[arg(long, default_value_t = 1_000_003)]
            max_size: u32,
            /// Print the report as JSON.
            #[arg(long)]
            json: bool,
        },
        /// Write the built-in sample dataset (a small synthetic two-state object with depth,
        /// part maps and ground truth) to a new folder.
        Sample {
            /// Folder to create; existing files are never overwritten.
            #[arg(long)]
            out: PathBuf,
            /// Image width in pixels.
            #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(8..=4096))]
            width: u32,
            /// Image height in pixels.
            #[arg(long, default_value_t = 48, value_parser = clap::value_parser!(u32).range(8..=4096))]
            height: u32,
            /// Train views per state.
            #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u16).range(1..=1000))]
            views: u16,
            /// Movable parts (revolute and prismatic alternate).
            #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=15))]
            parts: u8,
        },
        /// Benchmarks that print machine-readable JSON.
        Bench {
            #[command(subcommand)]
            which: Bench,
        },
    }

    #[derive(Subcommand)]
    enum Bench {
        /// Radix-sort throughput (keys/s) on the current adapter.
        Sort {
            /// Key counts to time.
            #[arg(long, value_delimiter = ',', default_values_t = [1_000_000u32, 4_194_304])]
            sizes: Vec<u32>,
            /// Significant key bits (passes = ceil(bits / 8)).
            #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..=32))]
            key_bits: u32,
            /// Timed runs per size (after one warm-up run).
            #[arg(long, default_value_t = 5)]
            repeats: usize,
        },
    }

    pub fn main() -> ExitCode {
        let cli = Cli::parse();
        match run(cli.command) {
            Ok(code) => code,
            Err(message) => {
                eprintln!("artmesh: {message}");
                ExitCode::FAILURE
            }
        }
    }

    fn run(command: Command) -> Result<ExitCode, String> {
        match command {
            Command::Info { dataset, json } => info(&dataset, json),
            Command::Gpu { max_size, json } => gpu(max_size, json),
            Command::Sample {
                out,
                width,
                height,
                views,
                parts,
            } => {
                let params = fixture::FixtureParams {
                    width,
                    height,
                    train_views: views.into(),
                    test_views: usize::from(views).div_ceil(4),
                    movable_parts: parts.into(),
                    ..Default::default()
                };
                let files = fixture::small_dataset(params)
                    .to_files()
                    .map_err(|e| e.to_string())?;
                data::write_dir(&files, &out).map_err(|e| e.to_string())?;
                println!("wrote {} files to {}", files.len(), out.display());
                Ok(ExitCode::SUCCESS)
            }
            Command::Bench {
                which:
                    Bench::Sort {
                        sizes,
                        key_bits,
                        repeats,
                    },
            } => {
                let ctx = context()?;
                let report = artmesh::bench::sort(&ctx, &sizes, key_bits, repeats)
                    .map_err(|e| e.to_string())?;
                println!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
        }
    }

    fn info(root: &std::path::Path, json: bool) -> Result<ExitCode, String> {
        let files = data::read_dir(root).map_err(|e| e.to_string())?;
        match Dataset::from_files(&files) {
            Ok(dataset) => {
                let summary = dataset.summary();
                if json {
                    println!("{}", to_json(&summary)?);
                } else {
                    println!("{}\n{summary}", root.display());
                }
                Ok(ExitCode::SUCCESS)
            }
            Err(problems) => {
                eprintln!("{}: {} problem(s) found:", root.display(), problems.0.len());
                eprintln!("{problems}");
                Ok(ExitCode::FAILURE)
            }
        }
    }

    fn gpu(max_size: u32, json: bool) -> Result<ExitCode, String> {
        let ctx = context()?;
        let sizes: Vec<u32> = selftest::DEFAULT_SIZES
            .iter()
            .copied()
            .filter(|&n| n <= max_size)
            .collect();
        let report = pollster::block_on(selftest::run(&ctx, &sizes)).map_err(|e| e.to_string())?;
        if json {
            println!("{}", to_json(&report)?);
        } else {
            let a = &report.adapter;
            println!(
                "adapter: {} ({}, {}, driver {})",
                a.name, a.backend, a.device_type, a.driver
            );
            println!(
                "limits: storage binding {} MiB, {} workgroups per dimension",
                a.max_storage_buffer_binding_size >> 20,
                a.max_compute_workgroups_per_dimension
            );
            for c in &report.checks {
                let verdict = if c.passed() { "ok" } else { "MISMATCH" };
                let bits = if c.key_bits > 0 {
                    format!("{}-bit keys", c.key_bits)
                } else {
                    String::new()
                };
                println!("{:>10}  n = {:<9} {bits:<12} {verdict}", c.kernel, c.n);
            }
        }
        Ok(if report.passed() {
            ExitCode::SUCCESS
        } else {
            ExitCode::FAILURE
        })
    }

    fn context() -> Result<GpuContext, String> {
        pollster::block_on(GpuContext::new()).map_err(|e| e.to_string())
    }

    fn to_json<T: serde::Serialize>(value: &T) -> Result<String, String> {
        serde_json::to_string_pretty(value).map_err(|e| e.to_string())
    }
}
