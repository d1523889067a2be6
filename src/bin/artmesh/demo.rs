//! `artmesh demo`: the zero-set-up demo, a generated object captured, fitted and scored.

use std::path::PathBuf;
use std::process::ExitCode;

use artmesh::data::SensorModel;
use artmesh::pipeline::{self, demo};
use artmesh::synth::Category;

use crate::args::{BudgetArgs, context, to_json};
use crate::fit::fit_and_write;
use crate::output::NewFolder;

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
    /// Sensor model of the capture (see `render`): ideal, consumer or consumer-tracked.
    #[arg(long, default_value = "ideal")]
    sensor: SensorModel,
    #[command(flatten)]
    budget: BudgetArgs,
}

/// `artmesh demo`: OUT/dataset (the capture) and OUT/fit (what `fit` writes); prints the report.
pub fn run(args: DemoArgs) -> Result<ExitCode, String> {
    let out = match args.out {
        Some(out) => out,
        None => (1..)
            .map(|i| {
                PathBuf::from(if i == 1 {
                    "artmesh-demo".to_string()
                } else {
                    format!("artmesh-demo-{i}")
                })
            })
            .find(|p| std::fs::symlink_metadata(p).is_err())
            .expect("some folder name is free"),
    };
    let (parts, seed) = (args.parts, args.seed);
    let category = Category::parse(&args.category).map_err(|e| e.to_string())?;
    let object =
        demo::demo_object(category, usize::from(parts), seed).map_err(|e| e.to_string())?;
    let config = args.budget.fit_config(&args.preset)?;
    let mut spec = config.full_demo_capture(seed);
    spec.sensor = args.sensor;
    let (size, views) = (spec.width, spec.train_views);
    let folder = NewFolder::create(&out)?;
    let ctx = context()?;
    eprintln!(
        "demo: {} ({} movable parts) captured at {size}x{size}, {views} views per state, sensor: {}",
        object.name,
        parts,
        spec.sensor.label()
    );
    let input = pollster::block_on(demo::capture_demo(
        &ctx,
        &object,
        category,
        &spec,
        &mut |_| {},
    ))
    .map_err(|e| e.to_string())?;
    let dataset = folder.path().join("dataset");
    pipeline::write_dataset(&input.dataset, &dataset).map_err(|e| e.to_string())?;
    let report = fit_and_write(
        &input,
        &config,
        &folder.path().join("fit"),
        &out.join("fit"),
    )?;
    folder.finish()?;
    out!("{}", to_json(&report)?);
    eprintln!(
        "demo: dataset in {0}/dataset, fit in {0}/fit",
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}
