//! What several commands share: capture options, the suite objects a benchmark fits, the
//! preset budgets, and the GPU context and JSON output every command uses.

use artmesh::data::SensorModel;
use artmesh::fit::object::FitConfig;
use artmesh::fit::preset::{BudgetOverrides, Preset};
use artmesh::fit::reconstruct::{ReconstructionConfig, RemeshMode, SurfaceSource};
use artmesh::gpu::GpuContext;
use artmesh::mesh::MAX_HOLE_EDGES;
use artmesh::render::RenderSpec;

/// Which suite objects a benchmark fits, and how they are captured.
#[derive(clap::Args)]
pub struct SuiteObjects {
    /// Preset: tiny, fast or paper.
    #[arg(long, default_value = "fast", value_parser = ["tiny", "fast", "paper"])]
    pub preset: String,
    /// Only objects whose id contains one of these (e.g. laptop,oven); default all.
    #[arg(long, value_delimiter = ',')]
    pub objects: Vec<String>,
    /// Square capture size (the quick suite's is 64).
    #[arg(long, default_value_t = 64)]
    pub size: u32,
    /// Training views per state (the quick suite's is 6).
    #[arg(long, default_value_t = 6)]
    pub views: usize,
}

/// How objects are captured (defaults: the paper's Articulate-100 setting).
#[derive(clap::Args)]
pub struct CaptureArgs {
    /// Image width in pixels [default: 800; 64 for `suite --quick`].
    #[arg(long, value_parser = clap::value_parser!(u32).range(8..=8192))]
    width: Option<u32>,
    /// Image height in pixels [default: 800; 64 for `suite --quick`].
    #[arg(long, value_parser = clap::value_parser!(u32).range(8..=8192))]
    height: Option<u32>,
    /// Train views per state [default: 100; 6 for `suite --quick`].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    train_views: Option<u32>,
    /// Test views per state [default: 20; 2 for `suite --quick`].
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=10_000))]
    test_views: Option<u32>,
    /// Horizontal field of view in degrees.
    #[arg(long, default_value_t = 39.6)]
    fov: f32,
    /// Start state: interval of each joint's normalised range to draw from, as `LOW,HIGH`.
    #[arg(long, value_parser = interval, default_value = "0.6,0.8")]
    start_range: (f32, f32),
    /// End state: interval of each joint's normalised range to draw from, as `LOW,HIGH`.
    #[arg(long, value_parser = interval, default_value = "0.2,0.4")]
    end_range: (f32, f32),
    /// Cameras on the whole sphere instead of the upper hemisphere.
    #[arg(long)]
    sphere: bool,
    /// Sensor model of the written frames: ideal (exact renders), consumer (an RGB-D camera's
    /// depth noise, edge errors and dropouts, a segmenter's ragged part maps) or
    /// consumer-tracked (consumer, with SLAM-sized camera-pose error).
    #[arg(long, default_value = "ideal")]
    sensor: SensorModel,
}

/// Parses `LOW,HIGH` (two numbers, comma-separated); whether it lies in [0, 1] is the capture's check.
fn interval(text: &str) -> Result<(f32, f32), String> {
    let parse = |v: &str| v.trim().parse::<f32>().map_err(|e| format!("'{v}': {e}"));
    match text.split(',').collect::<Vec<_>>()[..] {
        [lo, hi] => Ok((parse(lo)?, parse(hi)?)),
        _ => Err(format!(
            "expected two numbers as LOW,HIGH (e.g. 0.6,0.8), found '{text}'"
        )),
    }
}

impl CaptureArgs {
    /// The capture these options ask for (quick: the quick suite's defaults), drawn with `seed`.
    pub fn spec(&self, quick: bool, seed: u64) -> RenderSpec {
        let (size, train, test) = if quick { (64, 6, 2) } else { (800, 100, 20) };
        RenderSpec {
            width: self.width.unwrap_or(size),
            height: self.height.unwrap_or(size),
            train_views: self.train_views.map_or(train, |v| v as usize),
            test_views: self.test_views.map_or(test, |v| v as usize),
            fov_x: self.fov.to_radians(),
            start_range: self.start_range,
            end_range: self.end_range,
            upper_hemisphere: !self.sphere,
            seed,
            sensor: self.sensor,
        }
    }
}

/// Overrides of a preset's budget shared by `fit` and `demo` (flattened into both), so a user
/// with a real GPU can ask for more than `fast` without going to `paper`.
#[derive(clap::Args)]
pub struct BudgetArgs {
    /// Override the preset's working image size: frames with a longer side above this many
    /// pixels are downsampled by an integer factor (0: full resolution).
    #[arg(long)]
    max_size: Option<u32>,
    /// Override the preset's training views per state, evenly spaced (0: all).
    #[arg(long)]
    max_views: Option<usize>,
    /// Override the preset's reconstruction steps per state.
    #[arg(long)]
    reconstruction_iterations: Option<u32>,
    /// Override the preset's fixed-topology recovery steps per state.
    #[arg(long)]
    recovery_iterations: Option<u32>,
    /// Override the preset's face cap for densification.
    #[arg(long)]
    max_faces: Option<usize>,
    /// Override the preset's articulation steps.
    #[arg(long)]
    articulation_iterations: Option<u32>,
    /// Where the part surfaces come from: measured (every training view's full-resolution depth
    /// and part maps, remeshed) or optimised (the photometric fit's vertices, the paper's way)
    /// [default: measured for fast, optimised for tiny and paper].
    #[arg(long, value_parser = ["measured", "optimised"])]
    surface: Option<String>,
    /// After remeshing, close the static base's holes bounded by at most this many edges where the
    /// depth maps check its fills (measured surfaces), every other part's by at most 48; fill
    /// faces the views saw through are left out (0: none, at most 256) [default: 256].
    #[arg(long)]
    close_holes: Option<usize>,
    /// Then zip a thin part's two sides together where their rims stay within this many median
    /// edge lengths of each other (0: none) [default: 3].
    #[arg(long)]
    rim_gap: Option<f32>,
    /// Decimate the exported twin's visual meshes towards this many faces over all parts, each part
    /// its share (0: no limit) [default: 100000]. A target, not a cap: an edge collapse that would
    /// break a surface or flip a face is not made, so a part may keep more faces than its share.
    #[arg(long)]
    max_visual_faces: Option<usize>,
}

impl BudgetArgs {
    /// Both phases' settings of the named preset, with these overrides applied.
    pub fn fit_config(&self, preset: &str) -> Result<FitConfig, String> {
        let overrides = BudgetOverrides {
            max_size: self.max_size,
            max_views: self.max_views,
            reconstruction_iterations: self.reconstruction_iterations,
            recovery_iterations: self.recovery_iterations,
            max_faces: self.max_faces,
            articulation_iterations: self.articulation_iterations,
        };
        let mut config = FitConfig::budgeted(
            Preset::parse(preset).map_err(|e| e.to_string())?,
            &overrides,
        );
        match self.surface.as_deref() {
            Some("measured") => config.reconstruction.surface = SurfaceSource::Measured,
            Some(_) => config.reconstruction.surface = SurfaceSource::Optimised,
            None => {}
        }
        if let Some(n) = self.close_holes {
            if n > MAX_HOLE_EDGES {
                return Err(format!(
                    "--close-holes: expected at most {MAX_HOLE_EDGES} edges (0: none), found {n}"
                ));
            }
            config.reconstruction.close_holes = n;
        }
        if let Some(g) = self.rim_gap {
            if !(g.is_finite() && g >= 0.0) {
                return Err(format!(
                    "--rim-gap: expected a non-negative number of edge lengths, found {g}"
                ));
            }
            config.reconstruction.rim_gap = g;
        }
        if let Some(n) = self.max_visual_faces {
            config.max_visual_faces = n;
        }
        Ok(config)
    }
}

/// Both phases' settings of the named preset.
pub fn fit_config(preset: &str) -> Result<FitConfig, String> {
    Ok(FitConfig::preset(
        Preset::parse(preset).map_err(|e| e.to_string())?,
    ))
}

/// The named preset with the named remeshing mode (`part-aware` or `global`).
pub fn reconstruction_config(preset: &str, remesh: &str) -> Result<ReconstructionConfig, String> {
    let mut config =
        ReconstructionConfig::preset(Preset::parse(preset).map_err(|e| e.to_string())?);
    if remesh == "global" {
        config.remesh = RemeshMode::Global;
    }
    Ok(config)
}

/// The GPU every command runs on.
pub fn context() -> Result<GpuContext, String> {
    pollster::block_on(GpuContext::new()).map_err(|e| e.to_string())
}

/// `value` as pretty JSON (what commands print on stdout).
pub fn to_json<T: serde::Serialize>(value: &T) -> Result<String, String> {
    serde_json::to_string_pretty(value).map_err(|e| e.to_string())
}

/// How much a dataset may take when read (flattened into `info` and `fit`).
#[derive(clap::Args)]
pub struct ReadArgs {
    /// Budget for a whole dataset's decoded images, in MB [default: 8 GiB]: a dataset over it
    /// is refused before decoding, naming its size.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    max_decoded_mb: Option<u64>,
}

impl ReadArgs {
    /// The reader's limits these options ask for.
    pub fn limits(&self) -> artmesh::data::ReadLimits {
        let mut limits = artmesh::data::ReadLimits::default();
        if let Some(mb) = self.max_decoded_mb {
            limits.max_decoded_bytes = mb.saturating_mul(1_000_000);
        }
        limits
    }
}
