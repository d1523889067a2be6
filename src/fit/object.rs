//! The product's main job on one object: the reconstruction phase on both states, then the
//! articulation phase on their frozen meshes, and the result in the dataset's own conventions
//! (part meshes as a `gt/` folder, joints as `gt/trans.json`) plus a richer `joints.json`.

use serde::Serialize;

use super::articulate::{Articulation, ArticulationConfig, articulate};
use super::observer::{Observer, Phase, Progress, Unobserved};
use super::preset::Preset;
use super::reconstruct::{Reconstruction, ReconstructionConfig, reconstruct};
use crate::data::{Dataset, GroundTruth, JointKind, State};
use crate::eval::{EvalError, EvalOptions, ObjectMetrics, evaluate_object};
use crate::gpu::{GpuContext, GpuResult};

/// Settings of both phases.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FitConfig {
    pub reconstruction: ReconstructionConfig,
    pub articulation: ArticulationConfig,
}

impl FitConfig {
    /// Both phases' settings of a preset.
    pub fn preset(preset: Preset) -> Self {
        Self {
            reconstruction: ReconstructionConfig::preset(preset),
            articulation: ArticulationConfig::preset(preset),
        }
    }

    /// How a demo captures its procedural object for this budget: square images at the
    /// reconstruction's working size (32 to 512 px) and as many training views per state as it
    /// uses (4 to 100), no test views. The CLI's and the page's demos share it.
    pub fn demo_capture(&self, seed: u64) -> crate::render::RenderSpec {
        let size = self.reconstruction.max_size.clamp(32, 512);
        crate::render::RenderSpec {
            width: size,
            height: size,
            train_views: self.reconstruction.max_views.clamp(4, 100),
            test_views: 0,
            seed,
            ..crate::render::RenderSpec::default()
        }
    }

    /// The fraction (0 to 1) of the whole fit done at `event`, counting renders: a reconstruction
    /// step as two (it also back-propagates into every face and steps Adam), a candidate step as
    /// one, a refinement step as [`ArticulationConfig::refine_renders`] for the preset's views
    /// per state (measured at fast: 75, 40 and 89 ms per step with one view per refinement step).
    pub fn fraction_done(&self, event: &Progress) -> f64 {
        let rec = &self.reconstruction;
        let (fit, recover) = (rec.fit.iterations, rec.recovery_iterations);
        let per_state = 2.0 * f64::from(fit + recover);
        let art = &self.articulation;
        let decide = art.decision_step();
        let refine_step = art.refine_renders(rec.max_views) as f64;
        let refine = f64::from(art.iterations - decide) * refine_step;
        let total = 2.0 * per_state + f64::from(decide) + refine;
        let done = if event.is_articulation() {
            2.0 * per_state
                + match event.phase {
                    Phase::Candidates => f64::from(event.iteration),
                    Phase::BakeOff => f64::from(decide),
                    Phase::Refine => f64::from(decide) + f64::from(event.iteration) * refine_step,
                    _ => f64::from(decide) + refine,
                }
        } else {
            let state = if event.state == State::End {
                per_state
            } else {
                0.0
            };
            state
                + 2.0
                    * f64::from(match event.phase {
                        Phase::Initialise => 0,
                        Phase::Optimise | Phase::Densify => event.iteration,
                        Phase::Remesh => fit,
                        Phase::Recover => fit + event.iteration,
                        _ => fit + recover,
                    })
        };
        (done / total.max(1.0)).clamp(0.0, 1.0)
    }
}

/// A fitted articulated object.
#[derive(Debug, Clone)]
pub struct ObjectFit {
    pub reconstruction: Reconstruction,
    pub articulation: Articulation,
}

/// One joint as `joints.json` lists it: the joint in the ground-truth conventions plus what a
/// simulator export needs (limits spanning both observed states).
#[derive(Debug, Clone, Serialize)]
pub struct JointRecord {
    /// The movable part this joint moves (1 ..= K; part 0 is the static base).
    pub part: usize,
    /// The joint's name in the exported URDF and GLB (its link is `part_{part}`).
    pub joint: String,
    #[serde(rename = "type")]
    pub kind: JointKind,
    /// A point on the axis (m); for revolute joints the one closest to the object's centre.
    pub origin: [f32; 3],
    /// Unit axis direction.
    pub direction: [f32; 3],
    /// Motion from the start to the end state: degrees (revolute) or metres (prismatic).
    pub motion: f32,
    /// Joint value at the start and end states (start 0).
    pub limits: [f32; 2],
    /// The bake-off's masked losses (revolute, prismatic).
    pub bake_off: [Option<f64>; 2],
    /// The magnitude before and after its registration along the axis (absent when off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_registration: Option<crate::articulation::axis_registration::AxisRegistration>,
    /// What decided the type and motion (`geometry`, `bake-off+refined`, …).
    pub decided_by: &'static str,
    /// The joint measured from the full-resolution depth and part maps: residuals (mm) of
    /// both models and of not moving, and the type call's margin (flagged under 0.5).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub geometry: Option<GeometryRecord>,
    /// Why the joint should be checked by hand; absent when nothing is known to be wrong.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flag: Option<String>,
    /// The fitted start → end motion g⁺ of the part as a 4 × 4 matrix, rows first (world frame).
    pub end_transform: [[f64; 4]; 4],
}

/// The measured evidence behind a joint, as `joints.json` lists it.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct GeometryRecord {
    #[serde(rename = "type")]
    pub kind: JointKind,
    pub margin: f64,
    pub revolute_residual_mm: f64,
    pub prismatic_residual_mm: f64,
    pub identity_residual_mm: f64,
    pub observable: bool,
    /// Points of the part in the start and end clouds.
    pub points: [usize; 2],
}

impl ObjectFit {
    /// Predicted meshes and joints as a `gt/` folder (what `artmesh eval` reads).
    pub fn as_ground_truth(&self) -> GroundTruth {
        GroundTruth {
            joints: Some(self.articulation.gt_joints()),
            ..self.reconstruction.as_ground_truth()
        }
    }

    /// The joints for `joints.json`.
    pub fn joint_records(&self) -> Vec<JointRecord> {
        self.articulation
            .joints
            .iter()
            .map(|j| {
                let motion = j.joint.motion();
                let (r, b) = j.motion.forward_affine();
                let row = |i: usize| [r.row(i).x, r.row(i).y, r.row(i).z, b[i]];
                JointRecord {
                    part: j.part,
                    joint: crate::export::twin::part_joint(j.part),
                    kind: j.kind,
                    origin: j.joint.origin.to_array(),
                    direction: j.joint.unit_direction().to_array(),
                    motion,
                    limits: [motion.min(0.0), motion.max(0.0)],
                    bake_off: [j.bake_off.revolute_loss, j.bake_off.prismatic_loss],
                    axis_registration: j.axis_registration,
                    decided_by: j.decided_by,
                    geometry: j.geometry.map(|g| GeometryRecord {
                        kind: g.kind,
                        margin: g.margin,
                        revolute_residual_mm: 1000.0 * g.revolute_residual,
                        prismatic_residual_mm: 1000.0 * g.prismatic_residual,
                        identity_residual_mm: 1000.0 * g.identity_residual,
                        observable: g.observable,
                        points: g.points,
                    }),
                    flag: j.flag.clone(),
                    end_transform: [row(0), row(1), row(2), [0.0, 0.0, 0.0, 1.0]],
                }
            })
            .collect()
    }

    /// Scores the fit against the dataset's ground truth (joints, and start-state meshes when
    /// both sides have them); `None` without GT joints.
    pub fn evaluate(
        &self,
        dataset: &Dataset,
        id: &str,
        category: &str,
        options: &EvalOptions,
    ) -> Option<Result<ObjectMetrics, EvalError>> {
        let gt_joints = dataset.gt_joints.as_ref()?;
        let predicted = self.as_ground_truth();
        let state = State::Start.index();
        let meshes = predicted.meshes[state]
            .as_ref()
            .zip(dataset.gt_meshes[state].as_ref());
        Some(evaluate_object(
            id,
            category,
            &self.articulation.gt_joints(),
            gt_joints,
            meshes,
            options,
        ))
    }
}

/// Fits `dataset`: reconstruction of both states, then articulation; `observer` hears both
/// and may pause or cancel them.
pub async fn fit_object(
    ctx: &GpuContext,
    dataset: &Dataset,
    config: &FitConfig,
    observer: &mut dyn Observer,
) -> GpuResult<ObjectFit> {
    let reconstruction = reconstruct(ctx, dataset, &config.reconstruction, observer).await?;
    let articulation = articulate(
        ctx,
        dataset,
        &reconstruction,
        &config.articulation,
        observer,
    )
    .await?;
    Ok(ObjectFit {
        reconstruction,
        articulation,
    })
}

/// A small procedural object (`category` with `movable_parts`, seed `seed`) captured at 32² with
/// 4 views per state and fitted with the `tiny` preset: the fit the native and browser tests
/// share. `edit` may change the dataset before the fit (to make odd data).
pub async fn tiny_fit(
    ctx: &GpuContext,
    category: crate::synth::Category,
    movable_parts: usize,
    seed: u64,
    spec_edit: &dyn Fn(&mut crate::render::RenderSpec),
    edit: &dyn Fn(&mut Dataset),
) -> Result<(Dataset, ObjectFit), String> {
    let config = FitConfig::preset(Preset::Tiny);
    tiny_fit_with(ctx, category, movable_parts, seed, spec_edit, edit, &config).await
}

/// [`tiny_fit`] with another fit configuration (the capture stays the tiny preset's).
pub async fn tiny_fit_with(
    ctx: &GpuContext,
    category: crate::synth::Category,
    movable_parts: usize,
    seed: u64,
    spec_edit: &dyn Fn(&mut crate::render::RenderSpec),
    edit: &dyn Fn(&mut Dataset),
    config: &FitConfig,
) -> Result<(Dataset, ObjectFit), String> {
    let object = crate::synth::generate(&crate::synth::SynthParams {
        category,
        movable_parts: Some(movable_parts),
        seed,
    })?;
    let mut spec = FitConfig::preset(Preset::Tiny).demo_capture(seed);
    spec_edit(&mut spec);
    let mut dataset = crate::render::capture_dataset(ctx, &object, &spec, &mut |_| {}).await?;
    edit(&mut dataset);
    let fit = fit_object(ctx, &dataset, config, &mut Unobserved)
        .await
        .map_err(|e| e.to_string())?;
    Ok((dataset, fit))
}
