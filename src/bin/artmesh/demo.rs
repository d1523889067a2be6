//! `artmesh demo`: the zero-set-up demo, a generated object captured, fitted and scored.

use std::path::PathBuf;
use std::process::ExitCode;

use artmesh::data;
use artmesh::synth::{Category, SynthParams, generate};

use crate::args::{BudgetArgs, context, to_json};
use crate::capture;
use crate::fit::fit_and_write;

/// `artmesh demo`'s arguments.
#[derive(clap::Args)]
pub struct DemoArgs {
    /// New folder to write [default: a fresh ./artmesh-demo, -2, -3, ...].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Budget (see `fit`).
    #[arg(long, default_value = "fast", value_parser = ["tiny", "fast", "paper"])]
    preset: String,
    /// Category of the generated object (see `synth`).
    #[arg(long, default_value = "storage")]
    category: String,
    /// Movable parts.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=15))]
    parts: u8,
    /// Seed of the object, its states and cameras.
    #[arg(long, default_value_t = 4)]
    seed: u64,
    #[command(flatten)]
    budget: BudgetArgs,
}

/// `artmesh demo`: OUT/dataset (the capture) and OUT/fit (what `fit` writes); prints the report.
pub fn run(args: DemoArgs) -> Result<ExitCode, String> {
    let out = match args.out {
        Some(out) => {
            capture::fresh_folder(&out)?;
            out
        }
        None => (1..)
            .map(|i| {
                PathBuf::from(if i == 1 {
                    "artmesh-demo".to_string()
                } else {
                    format!("artmesh-demo-{i}")
                })
            })
            .find(|p| !p.exists())
            .expect("some folder name is free"),
    };
    let (parts, seed) = (args.parts, args.seed);
    let category = Category::parse(&args.category).map_err(|e| e.to_string())?;
    let object = generate(&SynthParams {
        category,
        movable_parts: Some(usize::from(parts)),
        seed,
    })
    .map_err(|e| e.to_string())?;
    let config = args.budget.fit_config(&args.preset)?;
    // Captured as a user's dataset would be: the fit reads its working size, and
    // its joints come from the full-resolution depth and part maps (at 64² those
    // are too coarse: the demo cabinet's axes came out 20.9° off) and are judged
    // on the test views.
    let mut spec = config.demo_capture(seed);
    spec.width = (4 * spec.width).min(512);
    spec.height = spec.width;
    spec.test_views = 4;
    let (size, views) = (spec.width, spec.train_views);
    let ctx = context()?;
    eprintln!(
        "demo: {} ({} movable parts) captured at {size}x{size}, {views} views per state",
        object.name, parts
    );
    let dataset = pollster::block_on(artmesh::render::capture_dataset(
        &ctx,
        &object,
        &spec,
        &mut |_| {},
    ))
    .map_err(|e| format!("{}: {e}", object.name))?;
    let files = dataset.to_files().map_err(|e| e.to_string())?;
    data::write_dir(&files, &out.join("dataset")).map_err(|e| e.to_string())?;
    let report = fit_and_write(
        &dataset,
        &config,
        &out.join("fit"),
        &object.name,
        category.name(),
    )?;
    out!("{}", to_json(&report)?);
    eprintln!(
        "demo: dataset in {0}/dataset, fit in {0}/fit",
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}
