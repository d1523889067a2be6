//! The reconstruction phase's settings: the budgets of a [`Preset`] (via [`Budget`]) plus the
//! per-preset schedules of initialisation, optimisation, densification, remeshing and recovery.

use serde::Serialize;

use crate::fit::init::InitOptions;
use crate::fit::photometric::PhotometricConfig;
use crate::fit::preset::{Budget, Preset};
use crate::mesh::{MAX_HOLE_EDGES, RemeshOptions};

/// The longest hole loop closed where no view can check the fill: a movable part's (its fills
/// meet only its own state's views, and its motion is not known yet, so a drawer's open top,
/// hidden in the start state, would close unchecked) and a base's over optimised surfaces.
/// Quick suite: 96 on every part closed drawers' tops, CD-m 3.47 -> 3.64 mm (docs/results.md).
pub const UNCHECKED_HOLE_EDGES: usize = 48;

/// How faces are rebuilt after hardening.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RemeshMode {
    /// Restricted Delaunay per hardened part: no face can span two parts (the paper's method).
    PartAware,
    /// One restricted Delaunay over all vertices, cross-part faces kept (the ablation).
    Global,
}

/// Where the remeshed surface's vertices come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SurfaceSource {
    /// The optimised mesh's vertices, thinned (the paper's method).
    Optimised,
    /// Each part's surface as the dataset measured it: points back-projected from every training
    /// view's full-resolution depth and part map, voxel-averaged
    /// ([`crate::articulation::observed`]); a part with too few measured points keeps its
    /// optimised vertices.
    Measured,
}

/// Densification and pruning, every `every` iterations between the fractions `from` and `until`
/// of the optimisation. Pixel sizes are at the object's median distance from the cameras.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DensifyConfig {
    pub from: f32,
    pub until: f32,
    /// At least the number of views, so every view has been rendered once in each window.
    pub every: u32,
    /// Faces whose maximum blending weight reached this are visible enough to split...
    pub split_weight: f32,
    /// ...when their longest edge is at least this many pixels.
    pub split_pixels: f32,
    /// No split beyond this many faces.
    pub max_faces: usize,
    /// Faces whose maximum blending weight stayed below this in a window are pruned.
    pub prune_weight: f32,
    /// Faces whose mean vertex opacity fell below this are pruned.
    pub prune_opacity: f32,
    /// Faces with an edge longer than this many pixels are pruned.
    pub oversize_pixels: f32,
}

/// Everything the reconstruction of one state needs to know.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReconstructionConfig {
    pub preset: Preset,
    /// Frames larger than this (longer side, pixels) are downsampled by an integer factor; 0 = never.
    pub max_size: u32,
    /// At most this many training views per state, evenly spaced; 0 = all.
    pub max_views: usize,
    pub init: InitOptions,
    /// Iterations, learning rates, γ / opacity-floor / SH schedules of the optimisation.
    pub fit: PhotometricConfig,
    pub densify: DensifyConfig,
    pub remesh: RemeshMode,
    /// Where the remeshed vertices come from.
    pub surface: SurfaceSource,
    pub remesh_options: RemeshOptions,
    /// Before remeshing, vertices are thinned to one per voxel of this many median edge lengths
    /// (0 = keep all).
    pub remesh_spacing: f32,
    /// After remeshing, a part's connected pieces with fewer faces than this fraction of its
    /// largest piece are dropped as floaters.
    pub min_component_fraction: f32,
    /// After that, the static base's holes bounded by at most this many boundary edges (at most
    /// [`MAX_HOLE_EDGES`]) are closed where its fills are checked against both states' views
    /// (measured surfaces), every other part's (and an unchecked base's) up to
    /// [`UNCHECKED_HOLE_EDGES`] (0 = none).
    pub close_holes: usize,
    /// Then boundary runs that stay within this many median edge lengths of another loop's
    /// boundary (a thin part's two sides at its rim) are zipped together (0 = none).
    pub rim_gap: f32,
    /// Iterations of the fixed-topology recovery stage.
    pub recovery_iterations: u32,
    /// Position learning rate of the recovery stage (decayed ×0.1 over it).
    pub recovery_position_lr: f32,
}

impl ReconstructionConfig {
    /// The settings of a preset (see [`Preset`]), at its own budget.
    pub fn preset(preset: Preset) -> Self {
        Self::budgeted(preset, &preset.budget())
    }

    /// The settings of a preset spending `budget` (the preset's own, or one with overrides):
    /// the working size, views, iterations and face cap come from `budget`, the schedules from
    /// the preset.
    pub fn budgeted(preset: Preset, budget: &Budget) -> Self {
        let base = PhotometricConfig::default();
        let b = budget;
        match preset {
            Preset::Tiny => Self {
                preset,
                init: InitOptions {
                    spacing_pixels: 1.5,
                    max_triangles: 2_000,
                    ..InitOptions::default()
                },
                fit: PhotometricConfig {
                    iterations: b.reconstruction_iterations,
                    report_every: 10,
                    sh_degree_every: 30,
                    max_sh_degree: 1,
                    ..base
                },
                densify: DensifyConfig {
                    from: 0.15,
                    until: 0.5,
                    every: 12,
                    split_pixels: 2.5,
                    max_faces: b.max_faces,
                    ..DensifyConfig::default()
                },
                ..Self::common(preset, b)
            },
            Preset::Fast => Self {
                preset,
                init: InitOptions {
                    spacing_pixels: 1.5,
                    max_triangles: 8_000,
                    ..InitOptions::default()
                },
                // The schedule scales with the budget: the SH degree rises over the first
                // 90 % of the steps, and the densification window holds about four rounds.
                fit: PhotometricConfig {
                    iterations: b.reconstruction_iterations,
                    report_every: 20,
                    sh_degree_every: (b.reconstruction_iterations * 3 / 10).max(1),
                    ..base
                },
                densify: DensifyConfig {
                    from: 0.1,
                    until: 0.5,
                    every: (b.reconstruction_iterations / 10).max(24),
                    max_faces: b.max_faces,
                    ..DensifyConfig::default()
                },
                ..Self::common(preset, b)
            },
            Preset::Paper => Self {
                preset,
                init: InitOptions {
                    spacing_pixels: 1.0,
                    max_triangles: 400_000,
                    ..InitOptions::default()
                },
                // The paper's learning rates (and its 20k iterations, in the budget).
                fit: PhotometricConfig {
                    iterations: b.reconstruction_iterations,
                    sh_lr: 1.6e-3,
                    report_every: 100,
                    sh_degree_every: 1_000,
                    ..base
                },
                densify: DensifyConfig {
                    from: 0.05,
                    until: 0.5,
                    every: 500,
                    split_pixels: 1.5,
                    max_faces: b.max_faces,
                    ..DensifyConfig::default()
                },
                ..Self::common(preset, b)
            },
        }
    }

    /// What every preset shares, with `budget`'s working size, views and recovery steps.
    fn common(preset: Preset, budget: &Budget) -> Self {
        Self {
            preset,
            max_size: budget.max_size,
            max_views: budget.max_views,
            init: InitOptions::default(),
            fit: PhotometricConfig::default(),
            densify: DensifyConfig::default(),
            remesh: RemeshMode::PartAware,
            // fast takes the measured surfaces (quick suite: CD-s 14.2 -> 10.4 mm, CD-m 8.7 ->
            // 3.6 mm; docs/results.md, "Measured surfaces"); tiny keeps the optimised ones (its
            // fits are the tests', and a measured part is ~10x the faces), paper the paper's.
            surface: if preset == Preset::Fast {
                SurfaceSource::Measured
            } else {
                SurfaceSource::Optimised
            },
            // Measured on the quick suite's laptop (fast preset): thinning to 1.5 median edges and
            // edges up to 2.5 local spacings leave a third fewer boundary edges than 1.0 / 2.0 at
            // the same PSNR and Chamfer.
            remesh_options: RemeshOptions {
                max_edge_factor: 2.5,
                ..RemeshOptions::default()
            },
            remesh_spacing: 1.5,
            min_component_fraction: 0.05,
            // Quick suite (fast), fills checked against the views: 96 on the base against 48,
            // CD-s 9.83 -> 9.51 mm; every loop the fill takes (256) against 96, 9.18 -> 8.92 mm
            // (holdout 12.22 -> 11.80 mm): open undersides close. docs/results.md.
            close_holes: MAX_HOLE_EDGES,
            rim_gap: 3.0,
            recovery_iterations: budget.recovery_iterations,
            recovery_position_lr: 2e-5,
        }
    }

    /// The fixed-topology recovery stage's schedule: γ and the opacity floor at their final
    /// values, the full SH degree, part logits frozen.
    pub fn recovery(&self) -> PhotometricConfig {
        let gamma = self.fit.gamma.1;
        PhotometricConfig {
            iterations: self.recovery_iterations,
            position_lr: (self.recovery_position_lr, 0.1 * self.recovery_position_lr),
            part_lr: 0.0,
            gamma: (gamma, gamma),
            opacity_ramp: (-1.0, 0.0),
            sh_degree_start: self.fit.max_sh_degree,
            report_every: (self.recovery_iterations / 5).max(1),
            ..self.fit
        }
    }
}

impl Default for DensifyConfig {
    fn default() -> Self {
        Self {
            from: 0.1,
            until: 0.5,
            every: 50,
            split_weight: 0.2,
            split_pixels: 2.0,
            max_faces: 100_000,
            prune_weight: 0.02,
            prune_opacity: 0.02,
            oversize_pixels: 24.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_scale() {
        let it = |p| ReconstructionConfig::preset(p).fit.iterations;
        assert!(it(Preset::Tiny) < it(Preset::Fast) && it(Preset::Fast) < it(Preset::Paper));
        assert_eq!(it(Preset::Paper), 20_000);
        let r = ReconstructionConfig::preset(Preset::Fast).recovery();
        assert_eq!(r.settings_at(0).opacity_floor, 1.0);
        assert_eq!(r.settings_at(0).sh_degree, 3);
    }
}
