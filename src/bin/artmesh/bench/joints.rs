//! `artmesh bench joints`: the joints a suite's depth and part maps measure on their own (no
//! reconstruction, no photometry), scored against ground truth.

use std::path::PathBuf;
use std::time::Instant;

use artmesh::articulation::PartMotion;
use artmesh::articulation::geometric::{GeometricJoint, measure_joints};
use artmesh::articulation::init::principal_frame;
use artmesh::articulation::observed::{CloudOptions, DepthNoise, observe_dataset};
use artmesh::data::{GtJoint, JointKind, Split};
use artmesh::eval::{BenchmarkTable, EvalOptions, ObjectMetrics, evaluate_object};
use artmesh::gpu::GpuContext;
use serde::Serialize;

use super::source::SuiteSource;
use crate::args::{context, to_json};

/// `artmesh bench joints`'s arguments.
#[derive(clap::Args)]
pub struct JointsArgs {
    /// A folder written by `artmesh suite`.
    #[arg(long)]
    suite_dir: PathBuf,
    /// Only objects whose id contains one of these.
    #[arg(long, value_delimiter = ',')]
    objects: Vec<String>,
}

/// The benchmark's JSON; a line per object on stderr.
pub fn run(args: &JointsArgs) -> Result<String, String> {
    let ctx = context()?;
    let source = SuiteSource::Dir(args.suite_dir.clone());
    let clouds = CloudOptions::default();
    let report = measured_joints(&ctx, &source, &args.objects, &clouds, &mut log_object)?;
    to_json(&report)
}

/// One object's metrics, on stderr.
fn log_object(o: &MeasuredObject) {
    let m = &o.metrics;
    let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
    // Per joint: axis error, then the measured evidence (type z, margin, residual over the
    // expected, settled or not).
    let per: Vec<String> = m
        .joints
        .iter()
        .zip(&o.joints)
        .map(|(j, g)| match g {
            Some(g) => format!(
                "{:.2}° ({} z {:.1} m {:.2} r/n {:.2}{})",
                j.axis_ang,
                if g.kind == JointKind::Revolute {
                    "R"
                } else {
                    "P"
                },
                g.type_evidence,
                g.margin,
                g.quartile_residual / g.noise.unwrap_or(f64::NAN),
                if g.settled() { " settled" } else { "" }
            ),
            None => format!("{:.2}°", j.axis_ang),
        })
        .collect();
    let noise = o.noise.map_or("-".into(), |n| {
        format!(
            "{:.2} mm at {:.2} m, reach {}",
            1000.0 * n.sigma,
            n.depth,
            n.reach
        )
    });
    eprintln!(
        "bench joints: {} {:.1} s  depth noise {}  axis ang {} [{}]  axis pos {}  motion {}  types {}",
        o.id,
        o.seconds,
        noise,
        f(m.axis_ang),
        per.join(" "),
        f(m.axis_pos),
        f(m.part_motion),
        f(m.type_accuracy)
    );
}

/// One object of `artmesh bench joints`.
#[derive(Debug, Clone, Serialize)]
pub struct MeasuredObject {
    pub id: String,
    pub seconds: f64,
    pub metrics: ObjectMetrics,
    /// Per movable part, its measured joint (`None`: not in both states' clouds).
    pub joints: Vec<Option<GeometricJoint>>,
    /// The training views' depth noise, estimated from the start state's maps.
    pub noise: Option<DepthNoise>,
}

/// `artmesh bench joints` output.
#[derive(Debug, Clone, Serialize)]
pub struct MeasuredBench {
    pub bench: &'static str,
    pub suite: SuiteSource,
    pub clouds: CloudOptions,
    pub objects: Vec<MeasuredObject>,
    pub by_part_count: BenchmarkTable,
    pub total_s: f64,
}

/// The joints the suite's depth and part maps measure on their own (no reconstruction, no
/// photometry), scored against ground truth: what the fit's geometric stage starts from.
pub fn measured_joints(
    ctx: &GpuContext,
    source: &SuiteSource,
    only: &[String],
    clouds: &CloudOptions,
    log: &mut dyn FnMut(&MeasuredObject),
) -> Result<MeasuredBench, String> {
    let started = Instant::now();
    let (listed, _) = source.objects()?;
    let mut objects = Vec::new();
    for object in listed {
        let id = object.id.clone();
        if !super::selected(only, &id) {
            continue;
        }
        let dataset = source.load(ctx, &object)?;
        let start = Instant::now();
        let observed = observe_dataset(&dataset, Split::Train, clouds)
            .ok_or_else(|| format!("{id}: no training views of both states"))?;
        let joints: Vec<_> = measure_joints(&observed).into_iter().skip(1).collect();
        let all: Vec<glam::Vec3> = observed[0]
            .parts
            .iter()
            .flat_map(|c| c.points.clone())
            .collect();
        let center = principal_frame(&all).map_or(glam::DVec3::ZERO, |f| f.centroid);
        let predicted: Vec<GtJoint> = joints
            .iter()
            .map(|g| match g {
                Some(g) => g.motion(g.kind).joint(g.kind, center),
                None => PartMotion::IDENTITY.joint(JointKind::Revolute, center),
            })
            .collect();
        let seconds = start.elapsed().as_secs_f64();
        let gt = dataset
            .gt_joints
            .as_ref()
            .ok_or_else(|| format!("{id}: no ground-truth joints"))?;
        let metrics = evaluate_object(
            &id,
            &object.category,
            &predicted,
            gt,
            None,
            &EvalOptions::default(),
        )
        .map_err(|e| format!("{id}: {e}"))?;
        let done = MeasuredObject {
            id,
            seconds,
            metrics,
            joints,
            noise: observed[0].noise,
        };
        log(&done);
        objects.push(done);
    }
    let metrics: Vec<_> = objects.iter().map(|o| o.metrics.clone()).collect();
    Ok(MeasuredBench {
        bench: "joints",
        suite: source.clone(),
        clouds: *clouds,
        by_part_count: BenchmarkTable::by_part_count(&metrics),
        objects,
        total_s: started.elapsed().as_secs_f64(),
    })
}
