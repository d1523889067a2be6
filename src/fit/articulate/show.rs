//! What the articulation shows a watching driver (the page): the start state's mesh moved by
//! the current joints and rendered from an end-state view beside its photo — the forward
//! pixel-wise motion consistency as a picture — and each part's bake-off, both candidates side
//! by side. Nothing here changes the fit; a driver that does not ask costs nothing.

use super::candidates::Candidates;
use super::measured::Measured;
use super::moved_view::forward_maps;
use super::run::Run;
use crate::articulation::PartMotion;
use crate::data::{JointKind, State};
use crate::fit::observer::{BakeOffView, Observer, Phase, Preview};
use crate::gpu::GpuResult;

/// Renders the start state's mesh moved by `motions` from the end-state view that sees the
/// first movable part most, and hands it to `observer` as a [`Preview`].
pub(super) async fn show_moved(
    run: &mut Run<'_>,
    observer: &mut dyn Observer,
    motions: &[PartMotion],
    (phase, iteration): (Phase, u32),
    moved_by: &'static str,
) -> GpuResult<()> {
    let view = run.forward.view_showing(1);
    let (width, height, render, target) = run
        .forward
        .snapshot(run.ctx, &run.renderer, &forward_maps(motions), view)
        .await?;
    observer.preview(Preview {
        state: State::End,
        view,
        iteration,
        phase,
        moved_by: Some(moved_by),
        width,
        height,
        render,
        target,
    });
    Ok(())
}

/// The joint seeds per part: the reconstructions' seed of the type whose registration fits
/// better (identity for the base and for a part without one). What the articulation starts
/// from before the measurements or the photometry have a say.
pub(super) fn seed_motions(candidates: &Candidates) -> Vec<PartMotion> {
    candidates
        .seeds
        .iter()
        .map(|c| match c {
            Some(c) if c.registration.residual <= c.prismatic_residual => c.revolute,
            Some(c) => c.prismatic,
            None => PartMotion::IDENTITY,
        })
        .collect()
}

/// The evidence a bake-off picture carries besides the renders.
pub(super) struct Verdict {
    /// Mean masked image loss per pixel with each candidate, when measured.
    pub(super) losses: (Option<f64>, Option<f64>),
    pub(super) kind: JointKind,
    pub(super) decided_by: &'static str,
}

/// Renders part `part` moved by each candidate alone (every other part still) from the
/// end-state view that sees it most, and hands the pair to `observer` with the evidence.
pub(super) async fn show_bake_off(
    run: &mut Run<'_>,
    observer: &mut dyn Observer,
    candidates: &Candidates,
    measured: &Measured,
    part: usize,
    verdict: Verdict,
) -> GpuResult<()> {
    let k = run.k;
    let only = |m: PartMotion| -> Vec<PartMotion> {
        (0..k)
            .map(|p| if p == part { m } else { PartMotion::IDENTITY })
            .collect()
    };
    let view = run.forward.view_showing(part);
    let (ctx, renderer) = (run.ctx, &run.renderer);
    let revolute = only(candidates.revolute[part]);
    let prismatic = only(candidates.prismatic[part]);
    let (width, height, rot, target) = run
        .forward
        .snapshot(ctx, renderer, &forward_maps(&revolute), view)
        .await?;
    let (_, _, trans, _) = run
        .forward
        .snapshot(ctx, renderer, &forward_maps(&prismatic), view)
        .await?;
    let g = measured.joints[part].as_ref();
    observer.bake_off(BakeOffView {
        part,
        view,
        width,
        height,
        revolute: rot,
        prismatic: trans,
        target,
        revolute_loss: verdict.losses.0,
        prismatic_loss: verdict.losses.1,
        revolute_residual: g.map(|g| g.revolute_residual),
        prismatic_residual: g.map(|g| g.prismatic_residual),
        kind: verdict.kind,
        decided_by: verdict.decided_by,
    });
    Ok(())
}
