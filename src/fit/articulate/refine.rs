//! Stage 3 of the articulation, refinement: the bake-off's winners with fresh Adam moments and
//! type-masked gradients, trained by both consistency terms: the pixel-wise one (PMC) forward
//! and, from `backward_from`, backward (state t₂'s mesh moved by the analytic inverse g⁻,
//! rendered from state-t₁ cameras), and the vertex-wise one (VMC) in both directions. Each
//! step's pixel-wise gradients come from one view per direction (the paper) or from all of
//! them ([`RefineViews`](super::config::RefineViews)).

use glam::{DMat3, DVec3};

use super::bake_off::Decision;
use super::config::ArticulationConfig;
use super::moved_view::{backward_maps, forward_maps};
use super::results::ArticulationPoint;
use super::run::Run;
use crate::articulation::vertex_motion::{StateSurface, VertexMotionWeights, vertex_motion_loss};
use crate::articulation::{MotionAdam, MotionMask, PartSums};
use crate::fit::observer::{Observer, Phase, checkpoint};
use crate::gpu::{GpuError, GpuResult, now_seconds};

/// The vertex-wise term's weights with the ablated terms off.
fn vertex_weights(config: &ArticulationConfig) -> VertexMotionWeights {
    VertexMotionWeights {
        color: if config.ablation.vertex_color {
            config.vertex.color
        } else {
            0.0
        },
        opacity: if config.ablation.vertex_opacity {
            config.vertex.opacity
        } else {
            0.0
        },
        ..config.vertex
    }
}

/// The vertex-wise term of one step: per-part sums forward and backward, and the loss (both
/// directions); zeros and `None` when the term is off.
type VertexTerm = (Vec<PartSums>, Vec<PartSums>, Option<f64>);

/// The vertex-wise motion consistency under this step's maps `g_fwd` and `g_bwd`.
fn vertex_term(
    config: &ArticulationConfig,
    k: usize,
    surfaces: &[StateSurface; 2],
    weights: &VertexMotionWeights,
    g_fwd: &[(DMat3, DVec3)],
    g_bwd: &[(DMat3, DVec3)],
) -> GpuResult<VertexTerm> {
    let (mut vf, mut vb) = (vec![PartSums::default(); k], vec![PartSums::default(); k]);
    if !(weights.color > 0.0 || weights.opacity > 0.0) {
        return Ok((vf, vb, None));
    }
    let [surface1, surface2] = surfaces;
    let f = vertex_motion_loss(surface1, surface2, g_fwd, weights)
        .map_err(|e| GpuError::InvalidInput(e.to_string()))?;
    let mut total = f.loss;
    vf = f.per_part;
    if config.ablation.backward {
        let b = vertex_motion_loss(surface2, surface1, g_bwd, weights)
            .map_err(|e| GpuError::InvalidInput(e.to_string()))?;
        total += b.loss;
        vb = b.per_part;
    }
    Ok((vf, vb, Some(total)))
}

/// Refines the decided motions of the trainable parts until the schedule ends or the reported
/// objective is flat. Returns the refinement step it stopped at early (if it did) and the
/// stage's seconds.
pub(super) async fn refine(
    run: &mut Run<'_>,
    decision: &mut Decision,
    trainable: &[bool],
    surfaces: &[StateSurface; 2],
    observer: &mut dyn Observer,
) -> GpuResult<(Option<u32>, f64)> {
    let (ctx, config, k) = (run.ctx, run.config, run.k);
    let (n, decide) = (run.schedule.n, run.schedule.decide);
    let t_refine = now_seconds();
    let mut adam = MotionAdam::new(k, config.rates);
    let vertex = vertex_weights(config);
    let refine = run.schedule.refine();
    checkpoint(observer, &run.event(Phase::Refine, 0, refine, None)).await?;
    let (mut last_objective, mut refine_stopped_at) = (None::<f64>, None);
    let motions = &mut decision.motions;
    for i in decide..n {
        adam.set_scale(
            config
                .final_rate
                .powf(f64::from(i - decide) / f64::from(refine.max(1))),
        );
        // This step's affine maps, both directions, shared by the pixel- and vertex-wise terms.
        let (g_fwd, g_bwd) = (forward_maps(motions), backward_maps(motions));
        let step = i - decide;
        let report = (step + 1).is_multiple_of(config.report_every.max(1)) || i + 1 == n;
        let views = config.refine_views;
        let (sums_f, forward_loss) = run
            .forward
            .refine_step(ctx, &run.renderer, &g_fwd, views, &mut run.rng, report)
            .await?;
        let with_backward = config.ablation.backward && i >= run.schedule.backward_from;
        let (sums_b, backward_loss) = if with_backward {
            run.backward
                .refine_step(ctx, &run.renderer, &g_bwd, views, &mut run.rng, report)
                .await?
        } else {
            (vec![PartSums::default(); k], None)
        };
        let (vf, vb, vertex_loss) = vertex_term(config, k, surfaces, &vertex, &g_fwd, &g_bwd)?;
        for part in (1..k).filter(|&p| trainable[p]) {
            let fw = sums_f[part]
                .scaled(config.pixel_weight)
                .merged(vf[part].scaled(config.vertex_weight));
            let bw = sums_b[part]
                .scaled(config.pixel_weight)
                .merged(vb[part].scaled(config.vertex_weight));
            let g = motions[part].gradient(&fw, &bw);
            let mask = MotionMask::of(decision.kinds[part]);
            adam.step(part, &mut motions[part], &g, mask);
        }
        // Read back only on report steps.
        if let Some(forward_loss) = forward_loss {
            run.curve.push(ArticulationPoint {
                iteration: i,
                phase: Phase::Refine,
                forward_loss,
                backward_loss,
                vertex_loss,
            });
            let at = run.event(Phase::Refine, step + 1, refine, Some(forward_loss));
            checkpoint(observer, &at).await?;
            if observer.wants_preview() {
                let at = (Phase::Refine, step + 1);
                run.show_moved(observer, motions, at, "refined joints")
                    .await?;
            }
            // Flat: the reported objective moved by less than the tolerance since the last report.
            let objective = f64::from(forward_loss)
                + f64::from(backward_loss.unwrap_or(0.0))
                + vertex_loss.unwrap_or(0.0);
            if let Some(before) = last_objective {
                let change: f64 = (objective - before) / f64::max(f64::abs(before), 1e-12);
                if change.abs() < config.flat_tolerance && i + 1 < n {
                    refine_stopped_at = Some(step + 1);
                    break;
                }
            }
            last_objective = Some(objective);
        } else {
            // Every step is a checkpoint: a step takes seconds on a software adapter.
            checkpoint(observer, &run.event(Phase::Refine, step + 1, refine, None)).await?;
        }
    }
    Ok((refine_stopped_at, now_seconds() - t_refine))
}
