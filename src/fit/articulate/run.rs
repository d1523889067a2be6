//! What the photometric stages of the articulation (candidates, bake-off, refinement) share:
//! the two moved views and their renderer, the schedule's step counts, the random stream of
//! view picks, the curve, and how a stage's progress event reads.

use super::config::ArticulationConfig;
use super::moved_view::{MotionRenderer, MovedView};
use super::results::ArticulationPoint;
use crate::articulation::PartMotion;
use crate::data::State;
use crate::fit::observer::{Observer, Phase, Preview, Progress};
use crate::gpu::{GpuContext, GpuResult, now_seconds};
use crate::rng::Rng;

/// The steps of the photometric stages.
#[derive(Debug, Clone, Copy)]
pub(super) struct Schedule {
    /// Steps in all (0 when no part is left for photometry).
    pub(super) n: u32,
    /// The bake-off's step: candidates before it, refinement after.
    pub(super) decide: u32,
    /// The first step with the backward pixel-wise term.
    pub(super) backward_from: u32,
}

impl Schedule {
    /// The schedule of `config`, or no steps at all when `photometric` is false.
    pub(super) fn new(config: &ArticulationConfig, photometric: bool) -> Self {
        let n = if photometric { config.iterations } else { 0 };
        Self {
            n,
            decide: config.decision_step().min(n),
            backward_from: (n as f32 * config.backward_from) as u32,
        }
    }

    /// Refinement steps.
    pub(super) fn refine(&self) -> u32 {
        self.n - self.decide
    }
}

/// The photometric stages' shared state.
pub(super) struct Run<'a> {
    pub(super) ctx: &'a GpuContext,
    pub(super) config: &'a ArticulationConfig,
    /// Movable parts plus the base.
    pub(super) k: usize,
    pub(super) schedule: Schedule,
    pub(super) renderer: MotionRenderer,
    /// State t₁'s mesh, moved by g⁺, against state t₂'s views.
    pub(super) forward: MovedView<'a>,
    /// State t₂'s mesh, moved by g⁻, against state t₁'s views.
    pub(super) backward: MovedView<'a>,
    pub(super) rng: Rng,
    pub(super) curve: Vec<ArticulationPoint>,
    /// When the phase began, and both meshes' (vertices, faces) for the events.
    pub(super) t0: f64,
    pub(super) sizes: (usize, usize),
}

impl Run<'_> {
    /// A progress event of the articulation (reported as the end state's).
    pub(super) fn event(
        &self,
        phase: Phase,
        iteration: u32,
        iterations: u32,
        loss: Option<f32>,
    ) -> Progress {
        Progress {
            state: State::End,
            phase,
            iteration,
            iterations,
            loss,
            psnr: None,
            vertices: self.sizes.0,
            faces: self.sizes.1,
            elapsed_s: now_seconds() - self.t0,
            candidate: None,
            open: 0,
        }
    }
}

impl Run<'_> {
    /// Renders the start state's mesh moved by `motions` from the end-state view that sees the
    /// first movable part most, and hands it to `observer` as a [`Preview`] (with its marks).
    pub(super) async fn show_moved(
        &mut self,
        observer: &mut dyn Observer,
        motions: &[PartMotion],
        (phase, iteration): (Phase, u32),
        moved_by: &'static str,
    ) -> GpuResult<()> {
        let view = self.forward.view_showing(1);
        let shot = self
            .forward
            .snapshot(self.ctx, &self.renderer, motions, view)
            .await?;
        observer.preview(Preview {
            state: State::End,
            view,
            iteration,
            phase,
            moved_by: Some(moved_by),
            width: shot.width,
            height: shot.height,
            render: shot.render,
            target: shot.target,
            marks: shot.marks,
        });
        Ok(())
    }
}
