//! The articulation phase's settings: its schedule, loss weights and learning rates per
//! [`Preset`] (iterations from the preset's [`Budget`]), the Table 4 ablations, and how the
//! measured part surfaces are used.

use serde::Serialize;

use crate::articulation::MotionRates;
use crate::articulation::observed::CloudOptions;
use crate::articulation::vertex_motion::VertexMotionWeights;
use crate::fit::preset::{Budget, Preset};
use crate::loss::LossWeights;

/// A command-line option value that names no known setting: what it should name, the value given
/// (quoted), and the valid values.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} {name:?}: expected {expected}")]
pub struct UnknownOption {
    /// What the value names, e.g. `ablation`.
    pub what: &'static str,
    /// The value given.
    pub name: String,
    /// The valid values, as a phrase.
    pub expected: &'static str,
}

/// Which parts of the motion-consistency objective are on (the paper's Table 4 ablations; the
/// fourth, part-aware remeshing, is the reconstruction's `RemeshMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Ablation {
    /// The vertex-wise colour term.
    pub vertex_color: bool,
    /// The vertex-wise opacity term.
    pub vertex_opacity: bool,
    /// The backward direction (backward pixel-wise and vertex-wise terms).
    pub backward: bool,
}

impl Ablation {
    /// The full model.
    pub(crate) const FULL: Ablation = Ablation {
        vertex_color: true,
        vertex_opacity: true,
        backward: true,
    };

    /// The ablation named as on the command line (`full`, `no-vertex-color`, `no-vertex-opacity`,
    /// `no-backward`).
    pub fn parse(name: &str) -> Result<Ablation, UnknownOption> {
        let full = Ablation::FULL;
        Ok(match name {
            "full" => full,
            "no-vertex-color" => Ablation {
                vertex_color: false,
                ..full
            },
            "no-vertex-opacity" => Ablation {
                vertex_opacity: false,
                ..full
            },
            "no-backward" => Ablation {
                backward: false,
                ..full
            },
            other => {
                return Err(UnknownOption {
                    what: "ablation",
                    name: other.to_string(),
                    expected: "full, no-vertex-color, no-vertex-opacity or no-backward",
                });
            }
        })
    }
}

/// How many views one refinement step's pixel-wise gradients average, per direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RefineViews {
    /// The next view of a shuffled cycle: the paper's stochastic steps.
    One,
    /// Every view: the full-batch gradient, as many renders per step as the state has views.
    All,
}

/// How the articulation uses the part surfaces measured by the dataset's full-resolution depth
/// and part maps ([`crate::articulation::geometric`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GeometryUse {
    /// Not at all: the paper's method (seeds from the reconstructed meshes, photometric stages).
    Off,
    /// Measured joints seed the photometric stages of every part, the measured type evidence
    /// overrules a bake-off it contradicts by a clear margin, and the result is kept only where it
    /// fits the measured surfaces at least as well as its seed.
    Seed,
    /// As `Seed`, but a joint the measurements settle (motion visible, type by a clear margin)
    /// is taken as measured: the photometric stages run only for the parts they cannot settle
    /// (no depth, unobservable motion, a close type call), and not at all when none is left.
    Settle,
}

impl GeometryUse {
    /// The mode named as on the command line (`off`, `seed`, `settle`).
    pub fn parse(name: &str) -> Result<GeometryUse, UnknownOption> {
        match name {
            "off" => Ok(GeometryUse::Off),
            "seed" => Ok(GeometryUse::Seed),
            "settle" => Ok(GeometryUse::Settle),
            other => Err(UnknownOption {
                what: "geometry mode",
                name: other.to_string(),
                expected: "off, seed or settle",
            }),
        }
    }
}

/// Schedule, weights and learning rates of the articulation phase.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ArticulationConfig {
    pub iterations: u32,
    /// Fraction of the phase at which the joint type is decided and the vertex-wise term starts.
    pub decide_at: f32,
    /// Fraction at which the backward pixel-wise term starts (the paper delays it).
    pub backward_from: f32,
    /// λ_PMC and λ_VMC (paper: 0.05 each).
    pub pixel_weight: f64,
    pub vertex_weight: f64,
    /// The pixel-wise term's image loss.
    pub weights: LossWeights,
    /// Window sharpness γ and opacity floor of the articulation renders. Softer than the
    /// reconstruction's final opaque, hard triangles: through those, moving a part changes which
    /// pixels it covers only in jumps the gradient cannot see (φ = u^γ saturates the opacity
    /// clamp), and the remaining colour-interpolation gradient drifts the motion away.
    pub gamma: f32,
    pub opacity_floor: f32,
    pub vertex: VertexMotionWeights,
    pub rates: MotionRates,
    /// Views per refinement step. At 32–64 px the objective has local minima a degree or more
    /// apart, and with single-view steps their noise picks which one a fit ends in.
    pub refine_views: RefineViews,
    /// Each stage (candidates, refine) decays the rates log-linearly to this fraction of
    /// themselves (1 = the paper's constant rates). Ours: with a few hundred single-view steps
    /// instead of 20 000, constant rates leave Adam's per-step jitter (≈ one rate per step) in
    /// the result; measured on the quick suite's laptop and cabinet (fast preset), 0.05 took the
    /// cabinet's Axis Ang from 18.1° (seeds) to 6.2° where constant rates drifted away.
    pub final_rate: f64,
    /// Whether the refined joints' magnitudes are registered along their axes
    /// ([`register_along_axis`](crate::articulation::axis_registration::register_along_axis)).
    /// On the fast laptop it took the motion 0.51° → 0.15° from the truth and the
    /// browser-vs-native gap 0.84° → 0.28° (docs/results.md, "Browser vs native").
    pub register_magnitude: bool,
    /// How the measured part surfaces are used.
    pub geometry: GeometryUse,
    /// How those surfaces are sampled.
    pub clouds: CloudOptions,
    /// The refinement stops early once its reported objective changes by less than this fraction
    /// between two reports (0: never).
    pub flat_tolerance: f64,
    pub ablation: Ablation,
    /// Loss terms are read back (and reported) every this many steps.
    pub report_every: u32,
    pub seed: u64,
}

impl ArticulationConfig {
    /// Renders per refinement step, both directions, for states of `views` training views.
    pub(crate) fn refine_renders(&self, views: usize) -> usize {
        match self.refine_views {
            RefineViews::One => 2,
            RefineViews::All => 2 * views.max(1),
        }
    }

    /// The step at which the joint types are decided: candidates before it, refinement after.
    pub(crate) fn decision_step(&self) -> u32 {
        ((self.iterations as f32 * self.decide_at) as u32).min(self.iterations)
    }

    /// The articulation settings of a preset (tiny 40, fast 300, paper 20 000 steps).
    ///
    /// `tiny` and `fast` train at a quarter of the paper's rates and refine on every view: with
    /// one view per step and the paper's rates, changes that should not matter (the SSIM weight
    /// × (1 + 1e-6), SwiftShader's rounding instead of lavapipe's) moved the fast laptop's axis
    /// by up to 1.4° and its motion by 2.3°; now by 0.13° and 0.26° (`bench spread`, docs/results.md,
    /// "Browser vs native"), at about three times the fit's time. Keeping the paper's rates for the
    /// candidates brought that back to 2.1°. `paper` keeps the paper's 20 000 single-view steps
    /// at full rates (every one of 100 views per step would cost 100×).
    pub fn preset(preset: Preset) -> Self {
        Self::budgeted(preset, &preset.budget())
    }

    /// The articulation settings of a preset spending `budget` (its articulation iterations;
    /// the rest follows the preset, see [`Self::preset`]).
    pub fn budgeted(preset: Preset, budget: &Budget) -> Self {
        let iterations = budget.articulation_iterations;
        let report_every = match preset {
            Preset::Tiny => 5,
            Preset::Fast => 20,
            Preset::Paper => 200,
        };
        // The axis registration is measured at tiny and fast only (docs/results.md, "Browser vs native"):
        // `paper` stays the paper's method.
        let (refine_views, rate_factor, register_magnitude) = match preset {
            Preset::Tiny | Preset::Fast => (RefineViews::All, 0.25, true),
            Preset::Paper => (RefineViews::One, 1.0, false),
        };
        Self {
            iterations,
            decide_at: 0.5,
            backward_from: 0.5,
            pixel_weight: 0.05,
            vertex_weight: 0.05,
            // The reconstruction's image loss: besides the paper's L1 + SSIM, depth and the part
            // labels say directly where a moved part belongs.
            weights: LossWeights::default(),
            gamma: 1.0,
            opacity_floor: 0.0,
            vertex: VertexMotionWeights::default(),
            rates: MotionRates::default().scaled(rate_factor),
            refine_views,
            final_rate: 0.05,
            register_magnitude,
            geometry: match preset {
                Preset::Tiny | Preset::Fast => GeometryUse::Settle,
                Preset::Paper => GeometryUse::Off,
            },
            clouds: CloudOptions::default(),
            flat_tolerance: 1e-3,
            ablation: Ablation::FULL,
            report_every,
            seed: 7,
        }
    }
}
