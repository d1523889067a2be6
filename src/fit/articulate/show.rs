//! What the articulation shows a watching driver (the page) besides the moved previews
//! (`Run::show_moved`): the joint seeds it starts from and each part's bake-off, both
//! candidates side by side with their evidence. Nothing here changes the fit; a driver that
//! does not ask costs nothing.

use super::candidates::Candidates;
use super::measured::Measured;
use super::run::Run;
use crate::articulation::PartMotion;
use crate::data::JointKind;
use crate::fit::observer::{BakeOffView, Observer};
use crate::gpu::GpuResult;

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
    let rot = run.forward.snapshot(ctx, renderer, &revolute, view).await?;
    let trans = run
        .forward
        .snapshot(ctx, renderer, &prismatic, view)
        .await?;
    let g = measured.joints[part].as_ref();
    observer.bake_off(BakeOffView {
        part,
        view,
        width: rot.width,
        height: rot.height,
        revolute: rot.render,
        prismatic: trans.render,
        target: rot.target,
        revolute_marks: rot.marks,
        prismatic_marks: trans.marks,
        revolute_loss: verdict.losses.0,
        prismatic_loss: verdict.losses.1,
        revolute_residual: g.map(|g| g.revolute_residual),
        prismatic_residual: g.map(|g| g.prismatic_residual),
        kind: verdict.kind,
        decided_by: verdict.decided_by,
    });
    Ok(())
}
