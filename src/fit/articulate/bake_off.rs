//! Stage 2 of the articulation, the bake-off: per part, the loss masked to the part's pixels
//! in state t₂ with only that part moved by each candidate, summed over all state-t₂ views; the
//! lower wins (ties to revolute, as in the paper). Where the part was measured, both models'
//! evidence decides together ([`combined_kind`]).

use glam::{DMat3, DVec3};

use super::candidates::Candidates;
use super::measured::Measured;
use super::results::BakeOff;
use super::run::Run;
use crate::articulation::PartMotion;
use crate::articulation::geometric::GeometricJoint;
use crate::data::JointKind;
use crate::fit::observer::{Observer, Phase, checkpoint};
use crate::gpu::{GpuResult, now_seconds};

/// What the bake-off decided, per part.
pub(super) struct Decision {
    pub(super) kinds: Vec<JointKind>,
    pub(super) bake_offs: Vec<BakeOff>,
    /// The winners (the measured or seeded joint of a settled part; still for a part without
    /// candidates).
    pub(super) motions: Vec<PartMotion>,
}

/// Weight of the bake-off's evidence against the measured one. Its losses (summed over a
/// part's pixels at the working size) differ by a fraction of a percent where the measured
/// residuals differ by tens of percent; at this weight a bake-off 5 % apart outvotes a measured
/// call on the threshold, and a tie leaves the measurements to decide.
const BAKE_OFF_WEIGHT: f64 = 10.0;

/// The joint type from both models' evidence: ln(prismatic / (slack × revolute)) of the measured
/// residuals (none when the motion is not observable there) plus [`BAKE_OFF_WEIGHT`] times
/// ln(prismatic / revolute) of the bake-off's losses; positive (or zero) is revolute, as the
/// paper breaks ties.
fn combined_kind(g: &GeometricJoint, revolute_loss: f64, prismatic_loss: f64) -> JointKind {
    use crate::articulation::geometric::PRISMATIC_SLACK;
    let measured = if g.observable {
        (g.prismatic_residual / (PRISMATIC_SLACK * g.revolute_residual.max(1e-9))).ln()
    } else {
        0.0
    };
    let photometric = (prismatic_loss.max(1e-12) / revolute_loss.max(1e-12)).ln();
    if measured + BAKE_OFF_WEIGHT * photometric >= 0.0 {
        JointKind::Revolute
    } else {
        JointKind::Prismatic
    }
}

/// Decides every part's joint type: the measured type where the photometry does not run, the
/// bake-off (with the measured evidence) where it does. Returns the decision and the stage's
/// seconds.
pub(super) async fn bake_off(
    run: &mut Run<'_>,
    candidates: &Candidates,
    measured: &Measured,
    observer: &mut dyn Observer,
    warnings: &mut Vec<String>,
) -> GpuResult<(Decision, f64)> {
    let (ctx, k) = (run.ctx, run.k);
    let t_bake = now_seconds();
    checkpoint(
        observer,
        &run.event(Phase::BakeOff, 0, (k - 1) as u32, None),
    )
    .await?;
    let mut kinds: Vec<JointKind> = (0..k)
        .map(|p| measured.joints[p].map_or(JointKind::Revolute, |g| g.kind))
        .collect();
    let mut bake_offs: Vec<BakeOff> = kinds
        .iter()
        .map(|&kind| BakeOff {
            revolute_loss: None,
            prismatic_loss: None,
            pixels: 0,
            kind,
        })
        .collect();
    let trainable = &candidates.trainable;
    for part in (1..k).filter(|&p| trainable[p]) {
        let only = |m: PartMotion| -> Vec<(DMat3, DVec3)> {
            (0..k)
                .map(|p| if p == part { m } else { PartMotion::IDENTITY }.forward_affine())
                .collect()
        };
        let (rot, pixels) = run
            .forward
            .masked_loss(ctx, &run.renderer, &only(candidates.revolute[part]), part)
            .await?;
        let (trans, _) = run
            .forward
            .masked_loss(ctx, &run.renderer, &only(candidates.prismatic[part]), part)
            .await?;
        let c = candidates.seeds[part]
            .as_ref()
            .expect("trainable parts have candidates");
        let kind = if pixels > 0 {
            if rot <= trans {
                JointKind::Revolute
            } else {
                JointKind::Prismatic
            }
        } else {
            warnings.push(format!(
                "part {part} owns no pixel in any end-state view: its joint type is decided by the registration residuals instead"
            ));
            if c.registration.residual <= c.prismatic_residual {
                JointKind::Revolute
            } else {
                JointKind::Prismatic
            }
        };
        // Both models' evidence: the measured residuals' and the bake-off's log ratios.
        let kind = match &measured.joints[part] {
            Some(g) if pixels > 0 => combined_kind(g, rot, trans),
            Some(g) if g.observable => g.kind,
            _ => kind,
        };
        kinds[part] = kind;
        bake_offs[part] = BakeOff {
            revolute_loss: (pixels > 0).then(|| rot / pixels as f64),
            prismatic_loss: (pixels > 0).then(|| trans / pixels as f64),
            pixels,
            kind,
        };
        let at = run.event(Phase::BakeOff, part as u32, (k - 1) as u32, None);
        checkpoint(observer, &at).await?;
    }
    let motions: Vec<PartMotion> = (0..k)
        .map(|p| match kinds[p] {
            _ if !trainable[p] && !measured.settled[p] => PartMotion::IDENTITY,
            JointKind::Revolute => candidates.revolute[p],
            JointKind::Prismatic => candidates.prismatic[p],
        })
        .collect();
    let decision = Decision {
        kinds,
        bake_offs,
        motions,
    };
    Ok((decision, now_seconds() - t_bake))
}
