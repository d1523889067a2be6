//! Progress of long fits on stderr: a bar redrawn in place on a terminal; on a pipe or in CI one
//! line per phase change and every tenth of a phase, so logs stay short and readable.

use std::io::{IsTerminal, Write};

use artmesh::fit::observer::{Phase, Progress};

/// Draws [`Progress`] events.
pub struct Bar {
    label: &'static str,
    terminal: bool,
    last: Option<(Phase, u32)>,
    /// When the current phase began (for its ETA).
    phase_start: Option<(Phase, std::time::Instant)>,
}

impl Bar {
    pub fn new(label: &'static str) -> Self {
        Self {
            label,
            terminal: std::io::stderr().is_terminal(),
            last: None,
            phase_start: None,
        }
    }

    pub fn show(&mut self, p: &Progress) {
        let fraction = if p.iterations > 0 {
            p.iteration as f32 / p.iterations as f32
        } else {
            1.0
        };
        let tenth = (fraction * 10.0) as u32;
        if self.phase_start.is_none_or(|(phase, _)| phase != p.phase) {
            self.phase_start = Some((p.phase, std::time::Instant::now()));
        }
        // The phase's remaining time at its pace so far.
        let eta = self
            .phase_start
            .map(|(_, t)| t.elapsed().as_secs_f32())
            .filter(|_| fraction > 0.02 && fraction < 1.0)
            .map(|spent| format!("  ETA {:.0} s", spent * (1.0 - fraction) / fraction))
            .unwrap_or_default();
        let changed = self
            .last
            .is_none_or(|(phase, t)| phase != p.phase || t != tenth);
        if !self.terminal && !changed {
            return;
        }
        self.last = Some((p.phase, tenth));
        const WIDTH: usize = 24;
        let filled = (fraction.clamp(0.0, 1.0) * WIDTH as f32).round() as usize;
        let bar = format!("{}{}", "#".repeat(filled), ".".repeat(WIDTH - filled));
        let steps = if p.iterations > 0 {
            format!(" {:>5}/{}", p.iteration, p.iterations)
        } else {
            String::new()
        };
        let loss = p.loss.map(|l| format!("  loss {l:.4}")).unwrap_or_default();
        let psnr = p.psnr.map(|v| format!("  {v:.2} dB")).unwrap_or_default();
        let line = format!(
            "{}: {:<6} {:<10} [{bar}]{steps}{loss}{psnr}  {} faces  {:.0} s{eta}",
            self.label,
            // The articulation phase works on both states at once.
            if p.is_articulation() {
                "joints"
            } else {
                p.state.name()
            },
            p.phase.name(),
            p.faces,
            p.elapsed_s
        );
        let mut err = std::io::stderr().lock();
        let _ = if self.terminal {
            write!(err, "\r\x1b[2K{line}")
        } else {
            writeln!(err, "{line}")
        };
        if self.terminal && p.phase == Phase::Done {
            let _ = writeln!(err);
        }
    }

    pub fn finish(&mut self) {
        if self.terminal {
            let _ = writeln!(std::io::stderr());
        }
    }
}
