//! Both states' reconstructions at once, natively: the end state on a second thread and a second
//! device of the same adapter, while the start state runs on the caller's. At working sizes a
//! training step is a few dozen small dispatches whose fixed costs keep about one core busy, so
//! the second state fills the core the first leaves idle (on lavapipe at 64², the fast preset's
//! box: 4.8 + 3.3 s in turn, 5.0 and 4.2 s at once). One device would serialise the two on its
//! locks (6.4 and 6.2 s at once).
//!
//! The states share nothing but the adapter, so each comes out exactly as it would alone. The
//! driver's observer still hears one state after the other, in the sequential order: the end
//! state's events wait in a channel until the start state is done, then play in order (live
//! from there). Its commands reach the end state too: a pause or a cancel at any checkpoint
//! pauses or stops both. In the browser (one thread) the states run in turn ([`super::reconstruct`]).

use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::sync::mpsc;

use super::{ReconstructionConfig, StateReconstruction, StateViews, reconstruct_state};
use crate::data::State;
use crate::fit::observer::{Command, Observer, PAUSE_POLL_MS, Preview, Progress};
use crate::gpu::{GpuContext, GpuError, GpuResult};

/// What the end state's thread tells the driver.
enum Heard {
    Progress(Progress),
    Preview(Preview),
}

/// The driver's last command and wishes, as both threads see them.
#[derive(Default)]
struct Shared {
    /// [`Command`] as 0 run, 1 pause, 2 cancel.
    command: AtomicU8,
    previews: AtomicBool,
}

impl Shared {
    fn set(&self, command: Command) {
        let code = match command {
            Command::Run => 0,
            Command::Pause => 1,
            Command::Cancel => 2,
        };
        self.command.store(code, Ordering::Relaxed);
    }

    fn get(&self) -> Command {
        match self.command.load(Ordering::Relaxed) {
            0 => Command::Run,
            1 => Command::Pause,
            _ => Command::Cancel,
        }
    }
}

/// The end state's observer: its events go down the channel, the driver's commands come from
/// [`Shared`].
struct Relay<'a> {
    sender: mpsc::Sender<Heard>,
    shared: &'a Shared,
}

impl Observer for Relay<'_> {
    fn progress(&mut self, event: &Progress) {
        // The receiver only hangs up once the fit is over: nothing left to tell.
        let _ = self.sender.send(Heard::Progress(*event));
    }
    fn wants_preview(&mut self) -> bool {
        self.shared.previews.load(Ordering::Relaxed)
    }
    fn preview(&mut self, preview: Preview) {
        let _ = self.sender.send(Heard::Preview(preview));
    }
    fn command(&mut self) -> Command {
        self.shared.get()
    }
}

/// The driver's observer as the start state sees it: every call passes through, and what the
/// driver answers is shared with the end state.
struct Steering<'a> {
    driver: &'a mut dyn Observer,
    shared: &'a Shared,
}

impl Observer for Steering<'_> {
    fn progress(&mut self, event: &Progress) {
        self.driver.progress(event);
    }
    fn wants_preview(&mut self) -> bool {
        let wanted = self.driver.wants_preview();
        self.shared.previews.store(wanted, Ordering::Relaxed);
        wanted
    }
    fn preview(&mut self, preview: Preview) {
        self.driver.preview(preview);
    }
    fn command(&mut self) -> Command {
        let command = self.driver.command();
        self.shared.set(command);
        command
    }
}

/// Plays the end state's events to the driver as they come (after the start state's), obeying
/// its commands as a checkpoint would; `Err(Cancelled)` when it cancels.
fn play(heard: &mpsc::Receiver<Heard>, steering: &mut Steering) -> GpuResult<()> {
    for message in heard {
        match message {
            Heard::Preview(preview) => steering.preview(preview),
            Heard::Progress(event) => {
                steering.progress(&event);
                loop {
                    match steering.command() {
                        Command::Run => break,
                        Command::Cancel => return Err(GpuError::Cancelled),
                        Command::Pause => {
                            std::thread::sleep(std::time::Duration::from_millis(
                                PAUSE_POLL_MS.into(),
                            ));
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

/// Reconstructs the start state from `views[0]` and the end state from `views[1]` at once
/// (see the module docs).
pub(super) fn reconstruct_both(
    ctx: &GpuContext,
    views: &[StateViews; 2],
    num_parts: usize,
    config: &ReconstructionConfig,
    observer: &mut dyn Observer,
) -> GpuResult<[StateReconstruction; 2]> {
    // A device of its own for the end state: one device's locks would serialise the two.
    let second = pollster::block_on(ctx.another_device())?;
    let shared = Shared::default();
    let (sender, heard) = mpsc::channel();
    std::thread::scope(|scope| {
        let end = scope.spawn(|| {
            let mut relay = Relay {
                sender,
                shared: &shared,
            };
            let ctx = &second;
            let state =
                reconstruct_state(ctx, State::End, &views[1], num_parts, config, &mut relay);
            pollster::block_on(state)
        });
        let mut steering = Steering {
            driver: observer,
            shared: &shared,
        };
        let state = reconstruct_state(
            ctx,
            State::Start,
            &views[0],
            num_parts,
            config,
            &mut steering,
        );
        let start = pollster::block_on(state);
        let played = match &start {
            Ok(_) => play(&heard, &mut steering),
            Err(_) => Ok(()),
        };
        if start.is_err() || played.is_err() {
            // The end state stops at its next checkpoint; its result is not wanted.
            shared.set(Command::Cancel);
        }
        let end = end.join().unwrap_or_else(|p| std::panic::resume_unwind(p));
        played?;
        Ok([start?, end?])
    })
}
