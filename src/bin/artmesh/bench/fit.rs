//! `artmesh bench fit`: the whole fit over a suite, scored against ground truth, with the
//! paper-style tables and, when asked, the ablation table (paper Table 4).

use std::path::PathBuf;
use std::time::Instant;

use artmesh::data::degrade::DepthDegradation;
use artmesh::data::{Dataset, State};
use artmesh::eval::{
    BenchmarkTable, ColumnSummary, EvalOptions, MeshSummary, ObjectMetrics, StaticBound,
    mesh_summary, static_bound,
};
use artmesh::export::JointRecord;
use artmesh::fit::articulate::{Ablation, ArticulationConfig, GeometryUse, articulate};
use artmesh::fit::object::{FitConfig, ObjectFit};
use artmesh::fit::observer::Unobserved;
use artmesh::fit::reconstruct::{ReconstructionConfig, RemeshMode, reconstruct};
use artmesh::gpu::{AdapterReport, GpuContext};
use artmesh::synth::SuiteKind;
use serde::Serialize;

use super::source::{SourceObject, SuiteSource};
use crate::args::{BudgetArgs, SuiteObjects, context, to_json};
use crate::output::{check_new_file, write_new_file};
use crate::suite::CaptureSettings;

/// `artmesh bench fit`'s arguments.
#[derive(clap::Args)]
pub struct FitBenchArgs {
    /// A folder written by `artmesh suite`: its datasets are fitted as they are.
    #[arg(long)]
    suite_dir: Option<PathBuf>,
    /// Without --suite-dir: quick (16 objects), full (100) or holdout (16 not in quick),
    /// captured in memory at the low --size and --views.
    #[arg(long = "suite", default_value = "quick", value_parser = ["quick", "full", "holdout"])]
    which: String,
    #[command(flatten)]
    suite: SuiteObjects,
    /// Overrides of the preset's budget (working size, views, iterations, face cap).
    #[command(flatten)]
    budget: BudgetArgs,
    /// How the joints use the dataset's full-resolution depth and part maps: settle (joints
    /// the measurements settle skip the photometric stages), seed (they seed every part's
    /// photometric stages), off (the paper's method) [default: settle; off for paper].
    #[arg(long, value_parser = ["off", "seed", "settle"])]
    geometry: Option<String>,
    /// Add Gaussian noise of this standard deviation (mm) to every depth pixel before fitting.
    #[arg(long, default_value_t = 0.0)]
    depth_noise: f32,
    /// Drop the depth map of every N-th training view before fitting (0: none).
    #[arg(long, default_value_t = 0)]
    drop_depth_every: usize,
    /// Also run the four ablations (w/o vertex colour, w/o vertex opacity, w/o backward pass,
    /// w/o part-aware remeshing) on every object.
    #[arg(long)]
    ablations: bool,
    /// Also write the tables as Markdown to this new file.
    #[arg(long)]
    markdown: Option<PathBuf>,
}

/// The benchmark's JSON; a line per object and the tables (Markdown) on stderr.
pub fn run(args: &FitBenchArgs) -> Result<String, String> {
    let depth_noise = args.depth_noise;
    if !(0.0..=1000.0).contains(&depth_noise) {
        return Err(format!(
            "--depth-noise: expected a standard deviation from 0 to 1000 mm, found {depth_noise}"
        ));
    }
    let s = &args.suite;
    let mut config = args.budget.fit_config(&s.preset)?;
    if let Some(g) = &args.geometry {
        config.articulation.geometry = GeometryUse::parse(g).map_err(|e| e.to_string())?;
    }
    if let Some(path) = &args.markdown {
        check_new_file(path)?;
    }
    let ctx = context()?;
    let source = match &args.suite_dir {
        Some(dir) => SuiteSource::Dir(dir.clone()),
        None => SuiteSource::Capture {
            kind: SuiteKind::parse(&args.which).unwrap_or(SuiteKind::Quick),
            size: s.size,
            views: s.views,
        },
    };
    let degrade = DepthDegradation {
        noise_mm: depth_noise,
        drop_every: args.drop_depth_every,
    };
    let report = fit_suite(
        &ctx,
        &config,
        &source,
        &s.objects,
        &degrade,
        args.ablations,
        &mut log_object,
    )?;
    let md = report.to_markdown();
    eprintln!("{md}");
    if let Some(path) = &args.markdown {
        write_new_file(path, md.as_bytes())?;
    }
    to_json(&report)
}

/// One object's metrics and warnings, on stderr.
fn log_object(o: &FitObject) {
    let m = &o.metrics;
    let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
    let f1 = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.1}"));
    eprintln!(
        "bench fit: {} ({} parts) {:.0} s (+{:.0} s reading)  PSNR {:.1}/{:.1} dB (test {}/{})  axis ang {}  axis pos {}  motion {}  CD-s {}  CD-m {}  types {}",
        o.id,
        o.parts,
        o.seconds,
        o.load_s,
        o.psnr[0],
        o.psnr[1],
        f1(o.psnr_test[0]),
        f1(o.psnr_test[1]),
        f(m.axis_ang),
        f(m.axis_pos),
        f(m.part_motion),
        f(m.cd_s.map(|c| c.cd_peer)),
        f(m.cd_m.map(|c| c.cd_peer)),
        f(m.type_accuracy)
    );
    eprintln!(
        "bench fit:   meshes: {:.1} % boundary edges on closed parts, {} non-manifold edges, {} cross-part faces, {} split parts, {} holes closed, {} fill faces left out (seen through)",
        100.0 * o.mesh.closed_boundary_fraction(),
        o.mesh.non_manifold_edges,
        o.mesh.cross_part_faces,
        o.mesh.split_parts,
        o.mesh.holes_closed,
        o.mesh.fill_faces_refused
    );
    if let (Some(cd), Some(b)) = (m.cd_s, o.cd_s_bound) {
        eprintln!(
            "bench fit:   CD-s {:.2} mm; a fit of the seen surface alone scores {:.2} mm (views see {:.0} % of the true base; sampling floor {:.2} mm)",
            cd.cd_mm,
            b.seen_only_mm,
            100.0 * b.seen_share,
            b.floor_mm
        );
    }
    for w in &o.warnings {
        eprintln!("bench fit:   warning: {w}");
    }
}

/// One object of `artmesh bench fit`.
#[derive(Debug, Clone, Serialize)]
pub struct FitObject {
    pub id: String,
    pub category: String,
    pub parts: usize,
    /// Wall time of the whole fit, and of its two phases.
    pub seconds: f64,
    pub reconstruct_s: f64,
    pub articulate_s: f64,
    /// Seconds reading the dataset (decoding its images) before the fit.
    pub load_s: f64,
    /// Mean training-view PSNR (dB) of each state's reconstruction after its recovery.
    pub psnr: [f64; 2],
    /// The same over each state's held-out (test) views.
    pub psnr_test: [Option<f64>; 2],
    pub metrics: ObjectMetrics,
    /// Both states' part meshes: boundary, non-manifold and cross-part counts, split parts.
    pub mesh: MeshSummary,
    /// What the training views measure of the true static part, and the CD-s bounds that sets.
    pub cd_s_bound: Option<StaticBound>,
    pub joints: Vec<JointRecord>,
    pub warnings: Vec<String>,
}

/// One variant of the ablation study (paper Table 4), over the same objects.
#[derive(Debug, Clone, Serialize)]
pub struct AblationRun {
    pub name: &'static str,
    pub objects: Vec<ObjectMetrics>,
}

/// `artmesh bench fit` output: per-object metrics and times, the paper-style tables and, when
/// asked, the ablation table.
#[derive(Debug, Clone, Serialize)]
pub struct FitBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub suite: SuiteSource,
    pub depth_degradation: DepthDegradation,
    pub config: FitConfig,
    pub capture: CaptureSettings,
    pub objects: Vec<FitObject>,
    pub by_part_count: BenchmarkTable,
    pub by_category: BenchmarkTable,
    /// Full model, w/o V-Color, w/o V-Opacity, w/o BackwardPass, w/o PartAware (All columns).
    pub ablation: Option<BenchmarkTable>,
    pub ablation_runs: Vec<AblationRun>,
    pub total_s: f64,
}

impl FitBench {
    /// The tables as Markdown (by part count, by category, ablations).
    pub fn to_markdown(&self) -> String {
        let mut out = format!(
            "### By part count\n\n{}\n### By category\n\n{}",
            self.by_part_count.to_markdown(),
            self.by_category.to_markdown()
        );
        out.push_str(&meshes_markdown(&self.objects));
        out.push_str(&bounds_markdown(&self.objects));
        if let Some(t) = &self.ablation {
            out.push_str(&format!("\n### Ablations\n\n{}", t.to_markdown()));
        }
        out
    }
}

/// The mesh facts summed over `objects`, as a Markdown table.
fn meshes_markdown(objects: &[FitObject]) -> String {
    let m = objects
        .iter()
        .fold(MeshSummary::default(), |sum, o| sum.plus(&o.mesh));
    format!(
        "\n### Meshes (both states, all objects)\n\n\
         | Part meshes | Boundary edges | On closed parts | Non-manifold edges | Cross-part faces | Split parts | Holes closed | Fill faces seen through |\n\
         |---|---|---|---|---|---|---|---|\n\
         | {} | {:.1} % | {:.1} % ({} parts) | {} | {} | {} | {} | {} |\n",
        m.parts,
        100.0 * m.boundary_edges as f64 / m.edges.max(1) as f64,
        100.0 * m.closed_boundary_fraction(),
        m.closed_parts,
        m.non_manifold_edges,
        m.cross_part_faces,
        m.split_parts,
        m.holes_closed,
        m.fill_faces_refused
    )
}

/// The fitted CD-s beside what the measurements allow (`eval::seen`), averaged over the objects
/// that have both, as a Markdown table.
fn bounds_markdown(objects: &[FitObject]) -> String {
    let rows: Vec<(f64, StaticBound)> = objects
        .iter()
        .filter_map(|o| Some((o.metrics.cd_s.as_ref()?.cd_mm, o.cd_s_bound?)))
        .collect();
    let mean = |f: &dyn Fn(&(f64, StaticBound)) -> f64| {
        rows.iter().map(f).sum::<f64>() / rows.len().max(1) as f64
    };
    format!(
        "\n### CD-s and what the views measure ({} objects)\n\n\
         | Fitted CD-s mm | Seen-surface bound mm | Sampling floor mm | True static surface seen |\n\
         |---|---|---|---|\n\
         | {:.2} | {:.2} | {:.2} | {:.1} % |\n",
        rows.len(),
        mean(&|r| r.0),
        mean(&|r| r.1.seen_only_mm),
        mean(&|r| r.1.floor_mm),
        100.0 * mean(&|r| r.1.seen_share),
    )
}

/// The ablation variants of the articulation phase, by table label.
const ARTICULATION_ABLATIONS: [(&str, &str); 3] = [
    ("w/o V-Color", "no-vertex-color"),
    ("w/o V-Opacity", "no-vertex-opacity"),
    ("w/o BackwardPass", "no-backward"),
];

/// Fits the suite's objects (all, or those whose id contains one of `only`) and scores them.
/// With `ablations`, each object's reconstruction is also re-articulated without each
/// consistency component, and reconstructed and articulated once more with global remeshing.
pub fn fit_suite(
    ctx: &GpuContext,
    config: &FitConfig,
    source: &SuiteSource,
    only: &[String],
    degrade: &DepthDegradation,
    ablations: bool,
    log: &mut dyn FnMut(&FitObject),
) -> Result<FitBench, String> {
    let started = Instant::now();
    let mut objects = Vec::new();
    let mut runs: Vec<AblationRun> = std::iter::once("Full model")
        .chain(ARTICULATION_ABLATIONS.iter().map(|a| a.0))
        .chain(["w/o PartAware"])
        .map(|name| AblationRun {
            name,
            objects: Vec::new(),
        })
        .collect();
    let (listed, capture) = source.objects()?;
    eprintln!(
        "bench fit: {} objects captured at {}², {} views per state, sensor: {}",
        listed.len(),
        capture.size,
        capture.train_views,
        capture.sensor.label()
    );
    for object in listed {
        if !super::selected(only, &object.id) {
            continue;
        }
        let loading = Instant::now();
        let mut dataset = source.load(ctx, &object)?;
        let load_s = loading.elapsed().as_secs_f64();
        degrade.apply(&mut dataset, 17);
        let (mut done, mut fit) = fit_one(ctx, config, &dataset, &object)?;
        done.load_s = load_s;
        let metrics = done.metrics.clone();
        log(&done);
        objects.push(done);
        if ablations {
            runs[0].objects.push(metrics);
            ablate(ctx, config, &dataset, &object, &mut fit, &mut runs)?;
        }
    }
    let metrics: Vec<ObjectMetrics> = objects.iter().map(|o| o.metrics.clone()).collect();
    let ablation = ablations.then(|| BenchmarkTable {
        columns: runs
            .iter()
            .map(|r| ColumnSummary::new(r.name, &r.objects.iter().collect::<Vec<_>>()))
            .collect(),
    });
    Ok(FitBench {
        bench: "fit",
        adapter: ctx.adapter.clone(),
        suite: source.clone(),
        depth_degradation: *degrade,
        config: *config,
        capture,
        by_part_count: BenchmarkTable::by_part_count(&metrics),
        by_category: BenchmarkTable::by_category(&metrics),
        ablation,
        ablation_runs: if ablations { runs } else { Vec::new() },
        objects,
        total_s: started.elapsed().as_secs_f64(),
    })
}

/// `fit` of `object` scored against its ground truth (errors named by the object's id).
fn score(
    fit: &ObjectFit,
    dataset: &Dataset,
    object: &SourceObject,
) -> Result<ObjectMetrics, String> {
    let id = &object.id;
    artmesh::eval::evaluate_fit(fit, dataset, id, &object.category, &EvalOptions::default())
        .ok_or_else(|| format!("{id}: the captured object has no ground-truth joints"))?
        .map_err(|e| format!("{id}: {e}"))
}

/// Reconstructs and articulates one object with `config`, timing both phases.
fn fit_one(
    ctx: &GpuContext,
    config: &FitConfig,
    dataset: &Dataset,
    object: &SourceObject,
) -> Result<(FitObject, ObjectFit), String> {
    let named = |e: String| format!("{}: {e}", object.id);
    let start = Instant::now();
    let reconstruction = pollster::block_on(reconstruct(
        ctx,
        dataset,
        &config.reconstruction,
        &mut Unobserved,
    ))
    .map_err(|e| named(e.to_string()))?;
    let reconstruct_s = start.elapsed().as_secs_f64();
    let articulation = pollster::block_on(articulate(
        ctx,
        dataset,
        &reconstruction,
        &config.articulation,
        &mut Unobserved,
    ))
    .map_err(|e| named(e.to_string()))?;
    let seconds = start.elapsed().as_secs_f64();
    let fit = ObjectFit {
        reconstruction,
        articulation,
    };
    let done = FitObject {
        id: object.id.clone(),
        category: object.category.clone(),
        parts: dataset.num_parts,
        seconds,
        reconstruct_s,
        articulate_s: seconds - reconstruct_s,
        load_s: 0.0,
        psnr: [0, 1].map(|i| {
            let states = &fit.reconstruction.states;
            states.get(i).map_or(f64::NAN, |s| s.psnr_recovered)
        }),
        psnr_test: [0, 1].map(|i| fit.reconstruction.states.get(i).and_then(|s| s.psnr_test)),
        metrics: score(&fit, dataset, object)?,
        mesh: mesh_summary(&fit.reconstruction, &dataset.gt_meshes),
        cd_s_bound: static_bound(dataset, State::Start, &EvalOptions::default().chamfer),
        joints: artmesh::export::joint_records(&fit),
        warnings: fit.articulation.warnings.clone(),
    };
    Ok((done, fit))
}

/// The ablations of one object: its reconstruction re-articulated without each consistency
/// component, then reconstructed with global remeshing and articulated; each scored into
/// `runs[1..]` (`runs[0]`, the full model, is the caller's).
fn ablate(
    ctx: &GpuContext,
    config: &FitConfig,
    dataset: &Dataset,
    object: &SourceObject,
    fit: &mut ObjectFit,
    runs: &mut [AblationRun],
) -> Result<(), String> {
    let named = |e: String| format!("{}: {e}", object.id);
    for (run, (_, name)) in runs[1..].iter_mut().zip(ARTICULATION_ABLATIONS) {
        let articulation = ArticulationConfig {
            ablation: Ablation::parse(name).map_err(|e| e.to_string())?,
            ..config.articulation
        };
        fit.articulation = pollster::block_on(articulate(
            ctx,
            dataset,
            &fit.reconstruction,
            &articulation,
            &mut Unobserved,
        ))
        .map_err(|e| named(e.to_string()))?;
        run.objects.push(score(fit, dataset, object)?);
    }
    let global = ReconstructionConfig {
        remesh: RemeshMode::Global,
        ..config.reconstruction
    };
    fit.reconstruction = pollster::block_on(reconstruct(ctx, dataset, &global, &mut Unobserved))
        .map_err(|e| named(e.to_string()))?;
    fit.articulation = pollster::block_on(articulate(
        ctx,
        dataset,
        &fit.reconstruction,
        &config.articulation,
        &mut Unobserved,
    ))
    .map_err(|e| named(e.to_string()))?;
    runs[4].objects.push(score(fit, dataset, object)?);
    eprintln!(
        "bench fit: {} ablations (Axis Ang): {}",
        object.id,
        runs.iter()
            .map(|r| format!(
                "{} {:.2}",
                r.name,
                r.objects
                    .last()
                    .and_then(|m| m.axis_ang)
                    .unwrap_or(f64::NAN)
            ))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}
