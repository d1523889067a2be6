//! Worse depth than a capture's: Gaussian noise on every depth pixel and training views without
//! depth, to measure how the fit copes with real sensors (used by `artmesh bench fit` and tests).

use super::{Dataset, Split};
use crate::rng::Rng;

/// Worse depth than the capture's, to measure how the fit copes: Gaussian noise on every depth
/// pixel and views without depth.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct DepthDegradation {
    /// Standard deviation of the noise added to every measured depth (mm; 0: none).
    pub noise_mm: f32,
    /// Every this many training views (from the second) lose their depth map (0: none).
    pub drop_every: usize,
}

impl DepthDegradation {
    /// Applies the degradation to `dataset`, reproducibly for `seed`.
    pub fn apply(&self, dataset: &mut Dataset, seed: u64) {
        let mut rng = Rng::new(seed);
        for views in &mut dataset.views {
            let train = views.split == Split::Train;
            for (i, frame) in views.frames.iter_mut().enumerate() {
                if train && self.drop_every > 0 && i % self.drop_every == 1 % self.drop_every {
                    frame.depth = None;
                    continue;
                }
                let Some(depth) = frame.depth.as_mut().filter(|_| self.noise_mm > 0.0) else {
                    continue;
                };
                for mm in depth.millimetres.iter_mut().filter(|mm| **mm > 0) {
                    // Box–Muller: a standard normal from two uniforms.
                    let (u, w) = (rng.uniform(1e-7, 1.0), rng.uniform(0.0, 1.0));
                    let n = (-2.0 * u.ln()).sqrt() * (std::f32::consts::TAU * w).cos();
                    *mm = (f32::from(*mm) + self.noise_mm * n)
                        .round()
                        .clamp(1.0, 65535.0) as u16;
                }
            }
        }
    }
}
