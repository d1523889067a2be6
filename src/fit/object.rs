//! The product's main job on one object: the reconstruction phase on both states, then the
//! articulation phase on their frozen meshes, and the result in the dataset's own conventions
//! (part meshes as a `gt/` folder, joints as `gt/trans.json`). Scoring and the output files
//! (`joints.json`, the exports) are the evaluation's and the export's, on top of this.

use serde::Serialize;

use super::articulate::{Articulation, ArticulationConfig, articulate};
use super::observer::{Observer, Phase, Progress};
use super::preset::{BudgetOverrides, Preset};
use super::reconstruct::{Reconstruction, ReconstructionConfig, SurfaceSource, reconstruct};
use crate::data::{Dataset, GroundTruth, State};
use crate::gpu::{GpuContext, GpuResult};

/// Settings of both phases and of the twin the exports write.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FitConfig {
    pub reconstruction: ReconstructionConfig,
    pub articulation: ArticulationConfig,
    /// Most faces of the exported twin's visual meshes, over all parts (decimated beyond; 0: no
    /// limit). The default keeps MuJoCo's and PyBullet's loading well under a second.
    pub max_visual_faces: usize,
}

/// The default of [`FitConfig::max_visual_faces`]: MuJoCo loads a fitted twin of 30k faces with
/// its visuals in under 0.1 s, and refuses a mesh over 200k.
pub const DEFAULT_VISUAL_FACES: usize = 100_000;

impl FitConfig {
    /// Both phases' settings of a preset.
    pub fn preset(preset: Preset) -> Self {
        Self::budgeted(preset, &BudgetOverrides::default())
    }

    /// Both phases' settings of a preset with some of its budgets (working size, views per
    /// state, iteration counts) overridden: what the CLI's and the page's budget options set.
    pub fn budgeted(preset: Preset, overrides: &BudgetOverrides) -> Self {
        let budget = preset.budget().with(overrides);
        Self {
            reconstruction: ReconstructionConfig::budgeted(preset, &budget),
            articulation: ArticulationConfig::budgeted(preset, &budget),
            max_visual_faces: DEFAULT_VISUAL_FACES,
        }
    }

    /// The fraction (0 to 1) of the whole fit done at `event`, counting renders: a reconstruction
    /// step as two (it also back-propagates into every face and steps Adam), a candidate step as
    /// one, a refinement step as [`ArticulationConfig::refine_renders`] for the preset's views
    /// per state (measured at fast: 75, 40 and 89 ms per step with one view per refinement step).
    pub fn fraction_done(&self, event: &Progress) -> f64 {
        let rec = &self.reconstruction;
        // Measured surfaces skip the optimisation (where every part was measured, as usual).
        let fit = match rec.surface {
            SurfaceSource::Measured => 0,
            SurfaceSource::Optimised => rec.fit.iterations,
        };
        let recover = rec.recovery_iterations;
        let per_state = 2.0 * f64::from(fit + recover);
        let art = &self.articulation;
        let decide = art.decision_step();
        let refine_step = art.refine_renders(rec.max_views) as f64;
        let refine = f64::from(art.iterations - decide) * refine_step;
        let total = 2.0 * per_state + f64::from(decide) + refine;
        let done = if event.is_articulation() {
            2.0 * per_state
                + match event.phase {
                    Phase::Measure => 0.0,
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
                        // (Bounded: a measured fit that had to optimise stands still meanwhile.)
                        Phase::Optimise | Phase::Densify => event.iteration.min(fit),
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

impl ObjectFit {
    /// Predicted meshes and joints as a `gt/` folder (what `artmesh eval` reads).
    pub fn as_ground_truth(&self) -> GroundTruth {
        GroundTruth {
            joints: Some(self.articulation.gt_joints()),
            ..self.reconstruction.as_ground_truth()
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budget_overrides_reach_both_phases_and_none_keeps_the_preset() {
        for preset in Preset::ALL {
            assert_eq!(
                FitConfig::budgeted(preset, &BudgetOverrides::default()),
                FitConfig::preset(preset)
            );
        }
        let overrides = BudgetOverrides {
            max_size: Some(96),
            max_views: Some(40),
            articulation_iterations: Some(7),
            ..BudgetOverrides::default()
        };
        let config = FitConfig::budgeted(Preset::Fast, &overrides);
        assert_eq!(
            (
                config.reconstruction.max_size,
                config.reconstruction.max_views
            ),
            (96, 40)
        );
        assert_eq!(config.articulation.iterations, 7);
        let fast = FitConfig::preset(Preset::Fast);
        assert_eq!(
            config.reconstruction.fit.iterations,
            fast.reconstruction.fit.iterations
        );
    }
}
