//! `artmesh bench joints`: the joints a suite's depth and part maps measure on their own (no
//! reconstruction, no photometry), scored against ground truth.

use std::path::PathBuf;
use std::time::Instant;

use artmesh::articulation::PartMotion;
use artmesh::articulation::geometric::{Anchor, GeometricJoint, fit_joint};
use artmesh::articulation::init::principal_frame;
use artmesh::articulation::observed::{CloudOptions, observe_dataset};
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
    let per: Vec<String> = m
        .joints
        .iter()
        .map(|j| format!("{:.2}", j.axis_ang))
        .collect();
    eprintln!(
        "bench joints: {} {:.1} s  axis ang {} [{}]  axis pos {}  motion {}  types {}",
        o.id,
        o.seconds,
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
        let [s, e] = observe_dataset(&dataset, Split::Train, clouds)
            .ok_or_else(|| format!("{id}: no training views of both states"))?;
        let joints: Vec<_> = (1..dataset.num_parts)
            .map(|p| {
                let anchor = Anchor::new(&s.others(p, 20_000), &e.others(p, 20_000));
                fit_joint(&s.parts[p], &e.parts[p], Some(&anchor))
            })
            .collect();
        let all: Vec<glam::Vec3> = s.parts.iter().flat_map(|c| c.points.clone()).collect();
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
