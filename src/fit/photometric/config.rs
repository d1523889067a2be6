//! A photometric fit's schedule: iterations, learning rates (the position rate decaying
//! log-linearly), the annealing of the window sharpness γ and of the opacity floor, the SH
//! degree's rise, and the reporting cadence; and the learning curve's points.

use glam::Vec3;
use serde::Serialize;

use super::adam::FieldLearningRates;
use crate::loss::{LossTerms, LossWeights};
use crate::optim::ExponentialDecay;
use crate::raster::RasterSettings;

/// Schedules and learning rates of a photometric fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PhotometricConfig {
    pub iterations: u32,
    /// Position learning rate, decayed log-linearly over the run (paper: 2e-4 → 2e-6).
    pub position_lr: (f32, f32),
    /// SH coefficients (paper: 1.6e-3 for 20k iterations; short fits need more).
    pub sh_lr: f32,
    /// Opacity logits (paper: 3e-2).
    pub opacity_lr: f32,
    /// Part logits (paper: 5e-3).
    pub part_lr: f32,
    /// Window sharpness γ, annealed geometrically from the first to the second value.
    pub gamma: (f32, f32),
    /// The opacity floor ramps from 0 to 1 between these fractions of the run, so faces end opaque.
    pub opacity_ramp: (f32, f32),
    /// The active SH degree rises by one every this many iterations, up to `max_sh_degree`.
    pub sh_degree_every: u32,
    /// Active SH degree at iteration 0 (a recovery stage starts where the fit ended).
    pub sh_degree_start: u32,
    pub max_sh_degree: u32,
    pub weights: LossWeights,
    pub background: Vec3,
    pub seed: u64,
    /// Loss terms are read back (and reported) every this many iterations.
    pub report_every: u32,
}

impl Default for PhotometricConfig {
    fn default() -> Self {
        Self {
            iterations: 300,
            position_lr: (2e-4, 2e-6),
            sh_lr: 1e-2,
            opacity_lr: 3e-2,
            part_lr: 5e-3,
            gamma: (1.0, 0.02),
            opacity_ramp: (0.4, 0.7),
            sh_degree_every: 100,
            sh_degree_start: 0,
            max_sh_degree: 3,
            weights: LossWeights::default(),
            background: Vec3::ZERO,
            seed: 1,
            report_every: 25,
        }
    }
}

impl PhotometricConfig {
    /// Raster settings at iteration `i`.
    pub(crate) fn settings_at(&self, i: u32) -> RasterSettings {
        let t = i as f32 / self.iterations.max(1) as f32;
        let (g0, g1) = self.gamma;
        let (r0, r1) = self.opacity_ramp;
        RasterSettings {
            gamma: g0 * (g1 / g0).powf(t),
            opacity_floor: ((t - r0) / (r1 - r0).max(1e-6)).clamp(0.0, 1.0),
            background: self.background,
            sh_degree: (self.sh_degree_start + i / self.sh_degree_every.max(1))
                .min(self.max_sh_degree),
            ..RasterSettings::default()
        }
    }
}

/// One point of the learning curve.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct CurvePoint {
    pub iteration: u32,
    /// Loss of the view trained at this iteration.
    pub loss: LossTerms,
    /// Mean PSNR (dB) over all training views, when it was measured at this point.
    pub psnr: Option<f64>,
    pub gamma: f32,
    pub opacity_floor: f32,
}

impl PhotometricConfig {
    /// The position learning rate's log-linear decay over the run.
    pub(crate) fn position_decay(&self) -> ExponentialDecay {
        ExponentialDecay {
            start: self.position_lr.0,
            end: self.position_lr.1,
            steps: self.iterations,
        }
    }

    /// The learning rates at the start, with `position` for the scheduled group.
    pub(crate) fn rates(&self, position: f32) -> FieldLearningRates {
        FieldLearningRates {
            position,
            sh: self.sh_lr,
            opacity: self.opacity_lr,
            part: self.part_lr,
        }
    }
}
