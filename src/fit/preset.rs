//! The named budgets of a fit (`tiny` for tests, `fast` for the CPU demo, `paper` for the
//! paper's setting) and what each one spends: the working image size, the training views per
//! state, the reconstruction's and the articulation's iterations, the face cap. Each phase's
//! configuration is built from a [`Budget`]; a driver (the CLI, the page) may override any of
//! its numbers with [`BudgetOverrides`] before building them.

use serde::Serialize;

/// A preset name [`Preset::parse`] does not know; the message lists the valid ones.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown preset '{0}', expected one of tiny, fast, paper")]
pub struct UnknownPreset(pub String);

/// Named budgets: `tiny` for tests, `fast` for the CPU demo, `paper` for the paper's setting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Preset {
    Tiny,
    Fast,
    Paper,
}

impl Preset {
    pub const ALL: [Preset; 3] = [Preset::Tiny, Preset::Fast, Preset::Paper];

    /// The preset's name, as the command line and the page spell it.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Tiny => "tiny",
            Preset::Fast => "fast",
            Preset::Paper => "paper",
        }
    }

    /// Parses a preset name; the error lists the valid ones.
    pub fn parse(name: &str) -> Result<Preset, UnknownPreset> {
        Preset::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name))
            .ok_or_else(|| UnknownPreset(name.to_string()))
    }

    /// What this preset spends (see [`Budget`]).
    pub fn budget(self) -> Budget {
        match self {
            Preset::Tiny => Budget {
                max_size: 32,
                max_views: 4,
                reconstruction_iterations: 60,
                recovery_iterations: 16,
                max_faces: 6_000,
                articulation_iterations: 40,
            },
            // The depth maps place the surface from the start: at 150 + 40 steps the quick
            // suite's Chamfer distances and PSNR are those of 400 + 100 (docs/results.md).
            Preset::Fast => Budget {
                max_size: 64,
                max_views: 12,
                reconstruction_iterations: 150,
                recovery_iterations: 40,
                max_faces: 30_000,
                articulation_iterations: 300,
            },
            // The paper's 20k reconstruction and articulation iterations on full-size views.
            Preset::Paper => Budget {
                max_size: 0,
                max_views: 0,
                reconstruction_iterations: 20_000,
                recovery_iterations: 2_000,
                max_faces: 3_000_000,
                articulation_iterations: 20_000,
            },
        }
    }
}

/// The numbers a preset spends: what makes a fit slower or faster, larger or smaller. The rest
/// of a preset's settings (schedules, report cadence, learning rates) follow the preset itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Budget {
    /// Working image size: frames larger than this (longer side, pixels) are downsampled by an
    /// integer factor; 0 = never.
    pub max_size: u32,
    /// Training views per state, evenly spaced; 0 = all.
    pub max_views: usize,
    /// Optimisation steps of each state's reconstruction.
    pub reconstruction_iterations: u32,
    /// Steps of each state's fixed-topology recovery.
    pub recovery_iterations: u32,
    /// No densification beyond this many faces.
    pub max_faces: usize,
    /// Steps of the articulation phase (candidates and refinement together).
    pub articulation_iterations: u32,
}

/// Changes to a preset's [`Budget`]; `None` keeps the preset's number.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct BudgetOverrides {
    pub max_size: Option<u32>,
    pub max_views: Option<usize>,
    pub reconstruction_iterations: Option<u32>,
    pub recovery_iterations: Option<u32>,
    pub max_faces: Option<usize>,
    pub articulation_iterations: Option<u32>,
}

impl Budget {
    /// This budget with `overrides` applied on top.
    pub fn with(self, overrides: &BudgetOverrides) -> Budget {
        Budget {
            max_size: overrides.max_size.unwrap_or(self.max_size),
            max_views: overrides.max_views.unwrap_or(self.max_views),
            reconstruction_iterations: overrides
                .reconstruction_iterations
                .unwrap_or(self.reconstruction_iterations),
            recovery_iterations: overrides
                .recovery_iterations
                .unwrap_or(self.recovery_iterations),
            max_faces: overrides.max_faces.unwrap_or(self.max_faces),
            articulation_iterations: overrides
                .articulation_iterations
                .unwrap_or(self.articulation_iterations),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_parse_and_scale() {
        assert_eq!(Preset::parse("FAST").unwrap(), Preset::Fast);
        assert!(
            Preset::parse("huge")
                .unwrap_err()
                .to_string()
                .contains("tiny, fast, paper")
        );
        let it = |p: Preset| p.budget().reconstruction_iterations;
        assert!(it(Preset::Tiny) < it(Preset::Fast) && it(Preset::Fast) < it(Preset::Paper));
    }

    #[test]
    fn overrides_replace_only_what_they_name() {
        let base = Preset::Fast.budget();
        assert_eq!(base.with(&BudgetOverrides::default()), base);
        let over = base.with(&BudgetOverrides {
            max_size: Some(128),
            articulation_iterations: Some(10),
            ..BudgetOverrides::default()
        });
        assert_eq!((over.max_size, over.articulation_iterations), (128, 10));
        assert_eq!(over.max_views, base.max_views);
    }
}
