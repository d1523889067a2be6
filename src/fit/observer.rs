//! Who watches a fit. The driver (the CLI's progress bar, the page, a test) hears the fit's
//! progress events, may ask for a preview render of the state being reconstructed, and steers the
//! fit (run, pause, cancel) at checkpoints between GPU submissions. In the browser a checkpoint
//! is also where the fit hands the event loop a turn, so the page stays responsive.
//! The events themselves ([`Progress`], in [`Phase`]s) live here too: every stage of the fit
//! reports through this file, which depends on no other file of the fit.

use serde::Serialize;

use crate::data::{JointKind, State};
use crate::gpu::{GpuError, GpuResult, sleep_ms};

/// Stages of the reconstruction, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    Initialise,
    Optimise,
    Densify,
    Remesh,
    Recover,
    /// Articulation: the joints measured from the depth and part maps, a part at a time.
    Measure,
    /// Articulation: both joint-type candidates trained on alternating steps.
    Candidates,
    /// Articulation: the per-part joint-type decision.
    BakeOff,
    /// Articulation: the winners refined with both consistency terms.
    Refine,
    Done,
}

impl Phase {
    /// Whether this is a stage of the articulation phase (both states at once).
    pub fn is_articulation(self) -> bool {
        matches!(
            self,
            Phase::Measure | Phase::Candidates | Phase::BakeOff | Phase::Refine
        )
    }

    /// The step of the method this phase belongs to, in the paper's words.
    pub fn stage(self) -> &'static str {
        match self {
            Phase::Remesh => "remeshing",
            Phase::Measure => "joint measurement",
            Phase::Candidates | Phase::Refine => "articulation",
            Phase::BakeOff => "bake-off decision",
            _ => "reconstruction",
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Phase::Initialise => "initialise",
            Phase::Optimise => "optimise",
            Phase::Densify => "densify",
            Phase::Remesh => "remesh",
            Phase::Recover => "recover",
            Phase::Measure => "measure",
            Phase::Candidates => "candidates",
            Phase::BakeOff => "bake-off",
            Phase::Refine => "refine",
            Phase::Done => "done",
        }
    }
}

/// A progress event: where the reconstruction is and how it is doing.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Progress {
    pub state: State,
    pub phase: Phase,
    /// Iteration within the phase (optimise, recover) and the phase's length.
    pub iteration: u32,
    pub iterations: u32,
    /// Total loss of the last step, when read back.
    pub loss: Option<f32>,
    /// Mean training PSNR (dB), when measured.
    pub psnr: Option<f64>,
    pub vertices: usize,
    pub faces: usize,
    /// Seconds since this state's reconstruction began.
    pub elapsed_s: f64,
    /// In the candidates stage, whose step this was: the hinge and the slide candidates train
    /// on alternate steps, so their losses are two curves, not one.
    pub candidate: Option<JointKind>,
    /// In the joint measurement: the movable parts measured so far whose joints the depth maps
    /// left open (not measured, or not settled); the photometric stages will decide them.
    pub open: u32,
}

impl Progress {
    /// Whether the event comes from the articulation phase: one of its stages, or its closing
    /// [`Phase::Done`], the only `Done` that counts steps (a state's reconstruction ends with 0
    /// of 0).
    pub fn is_articulation(&self) -> bool {
        self.phase.is_articulation() || (self.phase == Phase::Done && self.iterations > 0)
    }
}

/// What the driver wants the fit to do next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    Run,
    /// Wait at the checkpoint, asking again every [`PAUSE_POLL_MS`].
    Pause,
    /// Stop: the fit returns [`GpuError::Cancelled`].
    Cancel,
}

/// How often a paused fit asks whether to go on.
pub(crate) const PAUSE_POLL_MS: u32 = 100;

/// A render of one training view beside its ground truth, both RGB8 row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Preview {
    pub state: State,
    /// Training view index and the iteration the render was taken at.
    pub view: usize,
    pub iteration: u32,
    /// The phase the render was taken in.
    pub phase: Phase,
    /// In the articulation: the motions the start state's mesh is moved by before it is
    /// rendered from the end state's view `view` ("joint seeds", "hinge candidates", "fitted
    /// joints", …); `None` for a state's own mesh.
    pub moved_by: Option<&'static str>,
    pub width: u32,
    pub height: u32,
    pub render: Vec<u8>,
    pub target: Vec<u8>,
    /// The render's parts and joint axes (the articulation's pictures; empty otherwise).
    pub marks: Marks,
}

/// What an articulation picture shows besides its colours: the part each pixel shows and the
/// moved parts' joint axes, in that picture's pixels, so a driver can colour and annotate it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Marks {
    /// Per pixel (row-major) the part it shows, 0 the base; [`Marks::EMPTY`] where nothing is.
    pub parts: Vec<u8>,
    pub axes: Vec<AxisMark>,
}

impl Marks {
    /// The label of a pixel the mesh does not cover.
    pub const EMPTY: u8 = u8::MAX;
}

/// One moved part's joint axis drawn over a picture: a hinge as a segment of its axis beside
/// the part, a slide as the path of the part's centre (at least half the part's size long).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisMark {
    pub part: usize,
    pub kind: JointKind,
    /// The segment's ends in pixels (x right, y down).
    pub from: [f32; 2],
    pub to: [f32; 2],
}

/// One part's bake-off as a picture: the start state's mesh with only this part moved by each
/// joint-type candidate, rendered from the end-state training view that sees the part most,
/// beside that view's photo (RGB8, row-major), with both models' evidence.
#[derive(Debug, Clone, PartialEq)]
pub struct BakeOffView {
    /// The part (1 ..= K) and the end-state training view.
    pub part: usize,
    pub view: usize,
    pub width: u32,
    pub height: u32,
    pub revolute: Vec<u8>,
    pub prismatic: Vec<u8>,
    pub target: Vec<u8>,
    /// Each candidate's picture's parts and axis.
    pub revolute_marks: Marks,
    pub prismatic_marks: Marks,
    /// Mean image loss per pixel of the part over the end-state views, with each candidate.
    pub revolute_loss: Option<f64>,
    pub prismatic_loss: Option<f64>,
    /// What the depth maps measured: each model's residual (m), when measured.
    pub revolute_residual: Option<f64>,
    pub prismatic_residual: Option<f64>,
    /// The type that won, and what decided it (`"bake-off"`, `"depth maps"`, …).
    pub kind: JointKind,
    pub decided_by: &'static str,
}

/// The audience of a fit. Any `FnMut(&Progress)` closure is one that only listens.
pub trait Observer {
    /// Hears every progress event.
    fn progress(&mut self, event: &Progress);
    /// Asked at reconstruction checkpoints; `true` makes the fit render a [`Preview`] there.
    fn wants_preview(&mut self) -> bool {
        false
    }
    /// Receives the preview asked for.
    fn preview(&mut self, _preview: Preview) {}
    /// Whether the driver shows the articulation as pictures: the start state's mesh moved by
    /// the joint seeds and by the fitted joints, and each part's bake-off ([`BakeOffView`]).
    /// They cost a few renders per part, so only a driver that shows them asks.
    fn wants_articulation_views(&self) -> bool {
        false
    }
    /// Receives one part's bake-off, when [`Self::wants_articulation_views`].
    fn bake_off(&mut self, _view: BakeOffView) {}
    /// Asked at every checkpoint.
    fn command(&mut self) -> Command {
        Command::Run
    }
}

impl<F: FnMut(&Progress)> Observer for F {
    fn progress(&mut self, event: &Progress) {
        self(event)
    }
}

/// An observer that ignores everything (benchmarks, tests that only want the result).
pub struct Unobserved;

impl Observer for Unobserved {
    fn progress(&mut self, _event: &Progress) {}
}

/// Seconds of work between two turns of the browser's event loop.
#[cfg(target_arch = "wasm32")]
const YIELD_EVERY_S: f64 = 0.03;

/// Reports `event`, then obeys the observer: returns on [`Command::Run`], waits while paused and
/// fails with [`GpuError::Cancelled`] on cancel. In the browser it also yields to the event loop
/// when the fit has held it for more than [`YIELD_EVERY_S`].
pub async fn checkpoint(observer: &mut dyn Observer, event: &Progress) -> GpuResult<()> {
    observer.progress(event);
    loop {
        match observer.command() {
            Command::Run => break,
            Command::Cancel => return Err(GpuError::Cancelled),
            Command::Pause => sleep_ms(PAUSE_POLL_MS).await,
        }
    }
    #[cfg(target_arch = "wasm32")]
    {
        use std::cell::Cell;
        thread_local!(static LAST_YIELD: Cell<f64> = const { Cell::new(0.0) });
        let now = crate::gpu::now_seconds();
        if now - LAST_YIELD.get() > YIELD_EVERY_S {
            sleep_ms(0).await;
            LAST_YIELD.set(crate::gpu::now_seconds());
        }
    }
    Ok(())
}
