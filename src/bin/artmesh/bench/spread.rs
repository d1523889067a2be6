//! `artmesh bench spread`: how far changes that should not matter (rounding-level, or the view
//! order) move a fit's joints; the yardstick for comparing backends that round differently.

use std::path::PathBuf;
use std::time::Instant;

use artmesh::data::{Dataset, GtJoint, JointKind, read_dataset};
use artmesh::eval::joints::{
    JointPairMetrics, axis_angle_deg, axis_line_distance, match_joints, motion_error,
};
use artmesh::export::JointRecord;
use artmesh::fit::articulate::{ArticulationConfig, articulate};
use artmesh::fit::object::{FitConfig, ObjectFit};
use artmesh::fit::observer::Unobserved;
use artmesh::fit::preset::Preset;
use artmesh::fit::reconstruct::reconstruct;
use artmesh::gpu::{AdapterReport, GpuContext};
use serde::Serialize;

use crate::args::{context, fit_config, to_json};

/// `artmesh bench spread`'s arguments.
#[derive(clap::Args)]
pub struct SpreadArgs {
    /// Dataset folder.
    dataset: PathBuf,
    #[arg(long, default_value = "tiny", value_parser = ["tiny", "fast", "paper"])]
    preset: String,
    /// Fits, the unchanged one included.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(2..=100))]
    runs: u32,
    /// What changes between fits: `ssim` scales the reconstruction's SSIM weight by
    /// 1 + k·step (reaches meshes and joints); `view-order` keeps one reconstruction
    /// and changes the articulation's view order (its own spread).
    #[arg(long, default_value = "ssim", value_parser = ["ssim", "view-order"])]
    vary: String,
    /// Relative change of the SSIM weight per fit.
    #[arg(long, default_value_t = 1e-6)]
    step: f64,
}

/// The benchmark's JSON; a line per fit on stderr.
pub fn run(args: &SpreadArgs) -> Result<String, String> {
    let config = fit_config(&args.preset)?;
    let change = SpreadChange::parse(&args.vary)?;
    let dataset = read_dataset(&args.dataset).map_err(|e| e.to_string())?;
    let ctx = context()?;
    let runs = args.runs as usize;
    let report = spread(
        &ctx,
        &dataset,
        &config,
        change,
        runs,
        args.step,
        &mut log_run,
    )?;
    to_json(&report)
}

/// One fit's numbers, on stderr.
fn log_run(r: &SpreadRun) {
    // Per joint against GT: axis angle (°) / Part Motion, fit then seed.
    let errors = |e: &Option<Vec<JointPairMetrics>>| {
        e.as_ref().map_or("-".to_string(), |pairs| {
            let each = pairs
                .iter()
                .map(|p| format!("{:.3}/{:.3}", p.axis_ang, p.part_motion));
            each.collect::<Vec<_>>().join(" ")
        })
    };
    eprintln!(
        "bench spread: SSIM weight x {:.7}, articulation seed {}: {:.1} s, PSNR {:?}, remeshed faces {:?}, axes {:?}, GT error (axis/motion) {} (seeds {})",
        r.ssim_factor,
        r.articulation_seed,
        r.seconds,
        r.psnr_optimised,
        r.remeshed_faces,
        r.joints.iter().map(|j| j.direction).collect::<Vec<_>>(),
        errors(&r.gt_errors),
        errors(&r.seed_gt_errors),
    );
}

/// What `artmesh bench spread` changes from one fit to the next.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpreadChange {
    /// Fit k scales the reconstruction's SSIM weight by 1 + k·step: a change at the level of
    /// rounding that reaches everything downstream (densification, remeshing, articulation).
    Ssim,
    /// One reconstruction; articulation k draws its views in another order (seed + k). The
    /// meshes are identical, so the spread is the articulation phase's own.
    ViewOrder,
}

impl SpreadChange {
    /// The change named as on the command line (`ssim`, `view-order`).
    pub fn parse(name: &str) -> Result<SpreadChange, String> {
        match name {
            "ssim" => Ok(SpreadChange::Ssim),
            "view-order" => Ok(SpreadChange::ViewOrder),
            other => Err(format!(
                "unknown spread change {other:?}: expected ssim or view-order"
            )),
        }
    }
}

/// One fit of `artmesh bench spread`.
#[derive(Debug, Clone, Serialize)]
pub struct SpreadRun {
    /// The factor on the reconstruction's SSIM weight (1 for the unchanged fit).
    pub ssim_factor: f64,
    /// The articulation phase's seed (its view order).
    pub articulation_seed: u64,
    pub seconds: f64,
    /// Per state: mean training PSNR after the optimisation and the faces remeshing built, the
    /// first numbers where two fits part ways.
    pub psnr_optimised: Vec<f64>,
    pub remeshed_faces: Vec<usize>,
    pub joints: Vec<JointRecord>,
    /// Against the dataset's ground truth (`None` without one): the fitted joints' errors, and
    /// those of the registration seeds the refinement started from (`None` when a part has no
    /// seed), matched as `artmesh eval` matches them. Shows whether the fits scatter around the
    /// truth or away from it, and what the refinement added to its seeds.
    pub gt_errors: Option<Vec<JointPairMetrics>>,
    pub seed_gt_errors: Option<Vec<JointPairMetrics>>,
}

/// How far one part's joint moved in a changed fit from the unchanged one.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct JointShift {
    pub part: usize,
    pub same_type: bool,
    pub axis_deg: f64,
    /// Distance between the axis lines (revolute joints), metres.
    pub axis_line_m: Option<f64>,
    /// Part Motion between the two (° or m, in the unchanged joint's type).
    pub motion: f64,
    /// How far the articulation's starting point (the registration seeds of the two states'
    /// meshes) moved: axis (°). Small against `axis_deg`: the articulation phase amplified the
    /// change; as large: it came in with the meshes.
    pub seed_axis_deg: Option<f64>,
}

/// `artmesh bench spread` output: the same dataset fitted `runs` times, each with a change
/// that should not matter ([`SpreadChange`]), and each changed fit's joints against the
/// unchanged one's. Two backends that round differently (lavapipe and SwiftShader, or two
/// GPUs) can be expected to disagree by as much as the `ssim` change moves the joints.
#[derive(Debug, Clone, Serialize)]
pub struct SpreadBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub preset: Preset,
    pub change: SpreadChange,
    pub step: f64,
    pub fits: Vec<SpreadRun>,
    /// `shifts[k - 1]`: fit k's joints against fit 0's.
    pub shifts: Vec<Vec<JointShift>>,
    /// The largest shift over the changed fits: axis (°), axis line (m), motion.
    pub max_axis_deg: f64,
    pub max_axis_line_m: f64,
    pub max_motion: f64,
    pub total_s: f64,
}

/// A fit's joints and the registration seeds they started from (`None`: a part without one).
type FitJoints = (Vec<GtJoint>, Vec<Option<GtJoint>>);

/// Fits `dataset` with `config` `runs` times, changing `change` by `step` per fit (see
/// [`SpreadBench`]).
pub fn spread(
    ctx: &GpuContext,
    dataset: &Dataset,
    config: &FitConfig,
    change: SpreadChange,
    runs: usize,
    step: f64,
    log: &mut dyn FnMut(&SpreadRun),
) -> Result<SpreadBench, String> {
    let started = Instant::now();
    let reconstruct_with = |ssim_factor: f64| {
        let mut changed = config.reconstruction;
        changed.fit.weights.ssim *= ssim_factor as f32;
        pollster::block_on(reconstruct(ctx, dataset, &changed, &mut Unobserved))
    };
    // The view-order change shares one reconstruction.
    let shared = match change {
        SpreadChange::ViewOrder => {
            Some(reconstruct_with(1.0).map_err(|e| format!("reconstruction: {e}"))?)
        }
        SpreadChange::Ssim => None,
    };
    let mut fits = Vec::new();
    let mut joints: Vec<FitJoints> = Vec::new();
    for k in 0..runs.max(2) {
        let start = Instant::now();
        let (ssim_factor, seed) = match change {
            SpreadChange::Ssim => (1.0 + k as f64 * step, config.articulation.seed),
            SpreadChange::ViewOrder => (1.0, config.articulation.seed + k as u64),
        };
        let reconstruction = match &shared {
            Some(r) => r.clone(),
            None => reconstruct_with(ssim_factor).map_err(|e| format!("fit {k}: {e}"))?,
        };
        let articulation_config = ArticulationConfig {
            seed,
            ..config.articulation
        };
        let articulation = pollster::block_on(articulate(
            ctx,
            dataset,
            &reconstruction,
            &articulation_config,
            &mut Unobserved,
        ))
        .map_err(|e| format!("fit {k}: {e}"))?;
        let fit = ObjectFit {
            reconstruction,
            articulation,
        };
        let (run, fit_joints) = spread_run(&fit, dataset, ssim_factor, seed, start);
        log(&run);
        fits.push(run);
        joints.push(fit_joints);
    }
    let shifts = joint_shifts(&joints);
    let max = |f: &dyn Fn(&JointShift) -> f64| shifts.iter().flatten().map(f).fold(0.0, f64::max);
    Ok(SpreadBench {
        bench: "spread",
        adapter: ctx.adapter.clone(),
        preset: config.reconstruction.preset,
        change,
        step,
        max_axis_deg: max(&|s| s.axis_deg),
        max_axis_line_m: max(&|s| s.axis_line_m.unwrap_or(0.0)),
        max_motion: max(&|s| s.motion),
        fits,
        shifts,
        total_s: started.elapsed().as_secs_f64(),
    })
}

/// One fit's record, and its joints and seeds for the shifts.
fn spread_run(
    fit: &ObjectFit,
    dataset: &Dataset,
    ssim_factor: f64,
    seed: u64,
    start: Instant,
) -> (SpreadRun, FitJoints) {
    let states = &fit.reconstruction.states;
    let (fitted, seeds) = (fit.articulation.gt_joints(), fit.articulation.seed_joints());
    let against_gt = |joints: &[GtJoint]| {
        let gt = dataset.gt_joints.as_ref()?;
        match_joints(joints, gt).ok().map(|m| m.pairs)
    };
    let seeds_gt = seeds
        .iter()
        .copied()
        .collect::<Option<Vec<GtJoint>>>()
        .and_then(|s| against_gt(&s));
    let run = SpreadRun {
        ssim_factor,
        articulation_seed: seed,
        seconds: start.elapsed().as_secs_f64(),
        psnr_optimised: states.iter().map(|s| s.psnr_optimised).collect(),
        remeshed_faces: states.iter().map(|s| s.remesh.faces_built).collect(),
        joints: artmesh::export::joint_records(fit),
        gt_errors: against_gt(&fitted),
        seed_gt_errors: seeds_gt,
    };
    (run, (fitted, seeds))
}

/// Each changed fit's joints (and seeds) against the unchanged fit's, `joints[0]`.
fn joint_shifts(joints: &[FitJoints]) -> Vec<Vec<JointShift>> {
    let (first, first_seeds) = &joints[0];
    joints[1..]
        .iter()
        .map(|(fitted, seeds)| {
            first
                .iter()
                .zip(fitted)
                .zip(first_seeds.iter().zip(seeds))
                .enumerate()
                .map(|(i, ((a, b), seed))| JointShift {
                    part: i + 1,
                    same_type: a.kind == b.kind,
                    axis_deg: axis_angle_deg(a.direction, b.direction),
                    axis_line_m: (a.kind == JointKind::Revolute)
                        .then(|| axis_line_distance(a.origin, a.direction, b.origin, b.direction)),
                    motion: motion_error(b, a),
                    seed_axis_deg: match seed {
                        (Some(a), Some(b)) => Some(axis_angle_deg(a.direction, b.direction)),
                        _ => None,
                    },
                })
                .collect()
        })
        .collect()
}
