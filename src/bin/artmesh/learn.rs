//! `artmesh learn`: the rasterizer's learning driver on one captured state of a procedural object.

use std::path::PathBuf;
use std::process::ExitCode;

use artmesh::fit::photometric::{self, PhotometricConfig};
use artmesh::fixtures::photometric::{SceneSpec, synthetic_scene};

use crate::args::{context, to_json};
use crate::output::{check_new_file, write_new_file};

/// `artmesh learn`'s arguments.
#[derive(clap::Args)]
pub struct LearnArgs {
    /// Category (as for `synth`).
    #[arg(long, default_value = "box")]
    category: String,
    /// Movable parts (default: 1).
    #[arg(long, default_value_t = 1)]
    parts: usize,
    /// Seed of the object and the cameras.
    #[arg(long, default_value_t = 3)]
    seed: u64,
    /// Square image size in pixels.
    #[arg(long, default_value_t = 128)]
    size: u32,
    /// Training views.
    #[arg(long, default_value_t = 16)]
    views: usize,
    /// Optimisation steps (one view each).
    #[arg(long, default_value_t = 400)]
    iterations: u32,
    /// Longest edge of the starting mesh, in pixels.
    #[arg(long, default_value_t = 1.5)]
    edge_pixels: f32,
    /// Also write a PNG (a new file): for three views, target | starting mesh | fitted mesh.
    #[arg(long)]
    preview: Option<PathBuf>,
}

/// `artmesh learn`: fits the jittered copy, prints the curve and PSNR as JSON.
pub fn run(args: &LearnArgs) -> Result<ExitCode, String> {
    let LearnArgs {
        category,
        parts,
        seed,
        size,
        views,
        iterations,
        edge_pixels,
        preview,
    } = args;
    let (size, views, iterations) = (*size, *views, *iterations);
    if let Some(path) = preview {
        check_new_file(path)?;
    }
    let spec = SceneSpec {
        category: artmesh::synth::Category::parse(category).map_err(|e| e.to_string())?,
        movable_parts: Some(*parts),
        seed: *seed,
        size,
        views,
        edge_pixels: *edge_pixels,
        ..SceneSpec::default()
    };
    let config = PhotometricConfig {
        iterations,
        sh_degree_every: (iterations / 4).max(1),
        ..PhotometricConfig::default()
    };
    let ctx = context()?;
    let start = std::time::Instant::now();
    let problem = pollster::block_on(synthetic_scene(&ctx, &spec)).map_err(|e| e.to_string())?;
    eprintln!(
        "learn: {category} at {size}x{size}, {views} views; starting mesh {} vertices, {} faces",
        problem.field.num_vertices(),
        problem.field.faces.len()
    );
    let result = pollster::block_on(photometric::fit(&ctx, &problem, &config, &mut |p| {
        let psnr = p.psnr.map(|v| format!(", PSNR {v:.2} dB")).unwrap_or_default();
        eprintln!(
            "learn: {:>5}/{iterations}  loss {:.4}{psnr}  gamma {:.3}  opacity floor {:.2}  [{:.0} s]",
            p.iteration + 1,
            p.loss.total,
            p.gamma,
            p.opacity_floor,
            start.elapsed().as_secs_f64()
        );
    }))
    .map_err(|e| e.to_string())?;
    if let Some(path) = preview {
        let views = [0, views / 3, 2 * views / 3];
        let (w, h, rgb) = pollster::block_on(photometric::preview(
            &ctx,
            &problem,
            &result.field,
            &config,
            &views,
        ))
        .map_err(|e| e.to_string())?;
        let name = path.display().to_string();
        let png = artmesh::data::encode_png(&name, w, h, artmesh::data::PngPixels::Rgb8(&rgb))
            .map_err(|e| e.to_string())?;
        write_new_file(path, &png)?;
        eprintln!("learn: preview (target | start | fitted) in {name}");
    }
    let report = serde_json::json!({
        "category": spec.category.name(),
        "size": size,
        "views": views,
        "vertices": problem.field.num_vertices(),
        "faces": problem.field.faces.len(),
        "config": config,
        "psnr_start": result.psnr_start,
        "psnr_end": result.psnr_end,
        "seconds": start.elapsed().as_secs_f64(),
        "curve": result.curve,
    });
    out!("{}", to_json(&report)?);
    Ok(ExitCode::SUCCESS)
}
