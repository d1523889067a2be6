//! The reconstruction phase (paper §3.1, DESIGN.md §5), run independently per articulation
//! state:
//!
//! 1. **initialise** a triangle soup from the depth maps ([`super::init`]);
//! 2. **optimise** positions, SH colour, opacity and part logits with the image loss, while
//!    **densifying** (1 → 4 splits of visible faces larger than a few pixels) and **pruning**
//!    (faces that never blend above a small weight, transparent ones, oversized ones) in a
//!    window, and annealing γ and the opacity floor towards hard, opaque triangles;
//! 3. **harden** part labels (argmax), drop the old faces (and with them every cross-part one),
//!    and rebuild connectivity with **part-aware restricted Delaunay** per part
//!    ([`crate::mesh::part_aware_remesh`]; [`RemeshMode::Global`] is the ablation), keeping the
//!    pieces that are not tiny floaters;
//! 4. **recover**: a short fit with the topology fixed, γ and the floor at their final values.
//!
//! Progress is reported as [`Progress`] events; the CLI draws them as a bar, the browser plots them.

use glam::Vec3;
use serde::Serialize;

use super::init::{InitOptions, initial_field};
use super::observer::{Observer, checkpoint};
use super::photometric::{CurvePoint, PhotometricConfig, Trainer};
use super::views::downsample_frame;
use crate::data::{Camera, Dataset, Frame, GroundTruth, GtMeshes, Split, State, TriMesh};
use crate::gpu::{GpuContext, GpuError, GpuResult, now_seconds};
use crate::mesh::topology::{
    compact, cross_part_faces, drop_small_components, face_part, longest_edge, median_edge,
    retain_faces, split_faces, thin_vertices, vertex_normals,
};
use crate::mesh::{
    RemeshOptions, harden_parts, part_aware_remesh, part_meshes, restricted_delaunay,
};
use crate::raster::{MeshField, RasterSettings};

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

    pub fn name(self) -> &'static str {
        match self {
            Preset::Tiny => "tiny",
            Preset::Fast => "fast",
            Preset::Paper => "paper",
        }
    }

    /// Parses a preset name; the error lists the valid ones.
    pub fn parse(name: &str) -> Result<Preset, String> {
        Preset::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name))
            .ok_or_else(|| format!("unknown preset '{name}', expected one of tiny, fast, paper"))
    }
}

/// How faces are rebuilt after hardening.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RemeshMode {
    /// Restricted Delaunay per hardened part: no face can span two parts (the paper's method).
    PartAware,
    /// One restricted Delaunay over all vertices, cross-part faces kept (the ablation).
    Global,
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
    pub remesh_options: RemeshOptions,
    /// Before remeshing, vertices are thinned to one per voxel of this many median edge lengths
    /// (0 = keep all).
    pub remesh_spacing: f32,
    /// After remeshing, a part's connected pieces with fewer faces than this fraction of its
    /// largest piece are dropped as floaters.
    pub min_component_fraction: f32,
    /// Iterations of the fixed-topology recovery stage.
    pub recovery_iterations: u32,
    /// Position learning rate of the recovery stage (decayed ×0.1 over it).
    pub recovery_position_lr: f32,
}

impl ReconstructionConfig {
    /// The settings of a preset (see [`Preset`]).
    pub fn preset(preset: Preset) -> Self {
        let base = PhotometricConfig::default();
        match preset {
            Preset::Tiny => Self {
                preset,
                max_size: 32,
                max_views: 4,
                init: InitOptions {
                    spacing_pixels: 1.5,
                    max_triangles: 2_000,
                    ..InitOptions::default()
                },
                fit: PhotometricConfig {
                    iterations: 60,
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
                    max_faces: 6_000,
                    ..DensifyConfig::default()
                },
                recovery_iterations: 16,
                ..Self::common(preset)
            },
            Preset::Fast => Self {
                preset,
                max_size: 64,
                max_views: 12,
                init: InitOptions {
                    spacing_pixels: 1.5,
                    max_triangles: 8_000,
                    ..InitOptions::default()
                },
                fit: PhotometricConfig {
                    iterations: 400,
                    report_every: 20,
                    sh_degree_every: 120,
                    ..base
                },
                densify: DensifyConfig {
                    from: 0.1,
                    until: 0.5,
                    every: 40,
                    max_faces: 30_000,
                    ..DensifyConfig::default()
                },
                recovery_iterations: 100,
                ..Self::common(preset)
            },
            Preset::Paper => Self {
                preset,
                max_size: 0,
                max_views: 0,
                init: InitOptions {
                    spacing_pixels: 1.0,
                    max_triangles: 400_000,
                    ..InitOptions::default()
                },
                // The paper's 20k reconstruction iterations and its learning rates.
                fit: PhotometricConfig {
                    iterations: 20_000,
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
                    max_faces: 3_000_000,
                    ..DensifyConfig::default()
                },
                recovery_iterations: 2_000,
                ..Self::common(preset)
            },
        }
    }

    fn common(preset: Preset) -> Self {
        Self {
            preset,
            max_size: 0,
            max_views: 0,
            init: InitOptions::default(),
            fit: PhotometricConfig::default(),
            densify: DensifyConfig::default(),
            remesh: RemeshMode::PartAware,
            // Measured on the quick suite's laptop (fast preset): thinning to 1.5 median edges and
            // edges up to 2.5 local spacings leave a third fewer boundary edges than 1.0 / 2.0 at
            // the same PSNR and Chamfer.
            remesh_options: RemeshOptions {
                max_edge_factor: 2.5,
                ..RemeshOptions::default()
            },
            remesh_spacing: 1.5,
            min_component_fraction: 0.05,
            recovery_iterations: 100,
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

/// Stages of the reconstruction, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    Initialise,
    Optimise,
    Densify,
    Remesh,
    Recover,
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
        matches!(self, Phase::Candidates | Phase::BakeOff | Phase::Refine)
    }

    /// The step of the method this phase belongs to, in the paper's words.
    pub fn stage(self) -> &'static str {
        match self {
            Phase::Remesh => "remeshing",
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
}

impl Progress {
    /// Whether the event comes from the articulation phase: one of its stages, or its closing
    /// [`Phase::Done`], the only `Done` that counts steps (a state's reconstruction ends with 0
    /// of 0).
    pub fn is_articulation(&self) -> bool {
        self.phase.is_articulation() || (self.phase == Phase::Done && self.iterations > 0)
    }
}

/// Wall-clock seconds spent in each phase of one state.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct PhaseTimes {
    pub initialise_s: f64,
    /// The optimisation steps (GPU), without the densify/prune edits.
    pub optimise_s: f64,
    /// Densify/prune: face statistics read back, CPU edits, re-upload, Adam remap.
    pub densify_s: f64,
    pub remesh_s: f64,
    pub recover_s: f64,
    /// PSNR measurements over all views between stages.
    pub measure_s: f64,
    pub total_s: f64,
}

impl PhaseTimes {
    /// Adds `other`'s seconds to these.
    pub fn accumulate(&mut self, other: &PhaseTimes) {
        for (mine, theirs) in self.phases_mut().into_iter().zip(other.phases()) {
            *mine += theirs.1;
        }
        self.total_s += other.total_s;
    }

    /// (phase, seconds) without the total.
    pub fn phases(&self) -> [(&'static str, f64); 6] {
        [
            ("initialise", self.initialise_s),
            ("optimise", self.optimise_s),
            ("densify", self.densify_s),
            ("remesh", self.remesh_s),
            ("recover", self.recover_s),
            ("measure", self.measure_s),
        ]
    }

    /// The same fields as [`PhaseTimes::phases`], in the same order, to add to.
    fn phases_mut(&mut self) -> [&mut f64; 6] {
        [
            &mut self.initialise_s,
            &mut self.optimise_s,
            &mut self.densify_s,
            &mut self.remesh_s,
            &mut self.recover_s,
            &mut self.measure_s,
        ]
    }

    /// The phase with the largest share of the total, and that share.
    pub fn dominant(&self) -> (&'static str, f64) {
        let (name, t) = self
            .phases()
            .into_iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or(("none", 0.0));
        (name, t / self.total_s.max(1e-9))
    }
}

/// What the remeshing step did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct RemeshStats {
    pub mode: Option<RemeshMode>,
    /// Faces before remeshing and how many of them spanned two hardened parts (all are dropped).
    pub faces_before: usize,
    pub cross_part_faces_before: usize,
    /// Faces the restricted Delaunay step built.
    pub faces_built: usize,
    /// Of those, spanning two parts: 0 for part-aware remeshing by construction; for the
    /// global ablation, the faces that would tear or stretch under the parts' rigid motions.
    pub cross_part_faces: usize,
    /// Faces in small floating pieces that were dropped.
    pub floater_faces: usize,
    /// Vertices dropped: thinned out before remeshing, or used by no rebuilt face.
    pub unused_vertices: usize,
}

/// One state's reconstruction.
#[derive(Debug, Clone)]
pub struct StateReconstruction {
    pub state: State,
    /// The final field: remeshed, recovered, part logits hardened.
    pub field: MeshField,
    /// Hardened part per vertex.
    pub parts: Vec<u32>,
    /// One mesh per part (static base first).
    pub part_meshes: Vec<TriMesh>,
    pub remesh: RemeshStats,
    /// Faces split and pruned over all densification steps.
    pub faces_split: usize,
    pub faces_pruned: usize,
    pub initial_faces: usize,
    /// Mean training PSNR after the optimisation, after remeshing, after recovery.
    pub psnr_optimised: f64,
    pub psnr_remeshed: f64,
    pub psnr_recovered: f64,
    pub curve: Vec<CurvePoint>,
    pub times: PhaseTimes,
    /// Size and number of the training views used.
    pub width: u32,
    pub height: u32,
    pub views: usize,
}

/// Both states' reconstructions.
#[derive(Debug, Clone)]
pub struct Reconstruction {
    pub config: ReconstructionConfig,
    pub num_parts: usize,
    pub states: Vec<StateReconstruction>,
}

impl Reconstruction {
    /// The part meshes in the layout of a dataset's `gt/` folder (`gt/{state}/{state}_static_rotate.ply`,
    /// `..._dynamic_{i}_rotate.ply`), so `artmesh eval` and the peers' scripts read them as predictions.
    pub fn as_ground_truth(&self) -> GroundTruth {
        let mut meshes: [Option<GtMeshes>; 2] = [None, None];
        for s in &self.states {
            let mut parts = s.part_meshes.iter().cloned();
            meshes[s.state.index()] = Some(GtMeshes {
                static_part: parts.next().unwrap_or_default(),
                movable: parts.collect(),
            });
        }
        GroundTruth {
            joints: None,
            meshes,
        }
    }
}

/// The training views of `state` under `config`: evenly spaced, downsampled.
pub fn training_views(
    dataset: &Dataset,
    state: State,
    config: &ReconstructionConfig,
) -> Result<Vec<Frame>, String> {
    let frames = dataset
        .views(state, Split::Train)
        .map(|v| &v.frames)
        .filter(|f| !f.is_empty())
        .ok_or_else(|| format!("the dataset has no {} training views", state.name()))?;
    let n = frames.len();
    let take = if config.max_views == 0 {
        n
    } else {
        config.max_views.min(n)
    };
    let longest = frames[0].rgba.width.max(frames[0].rgba.height);
    let factor = if config.max_size == 0 {
        1
    } else {
        longest.div_ceil(config.max_size).max(1)
    };
    Ok((0..take)
        .map(|i| downsample_frame(&frames[i * n / take], factor))
        .collect())
}

/// Reconstructs both states of `dataset`.
pub async fn reconstruct(
    ctx: &GpuContext,
    dataset: &Dataset,
    config: &ReconstructionConfig,
    observer: &mut dyn Observer,
) -> GpuResult<Reconstruction> {
    let mut states = Vec::new();
    for state in [State::Start, State::End] {
        let frames = training_views(dataset, state, config).map_err(GpuError::InvalidInput)?;
        states.push(
            reconstruct_state(ctx, state, &frames, dataset.num_parts, config, observer).await?,
        );
    }
    Ok(Reconstruction {
        config: *config,
        num_parts: dataset.num_parts,
        states,
    })
}

/// Pixels per metre at the field's median distance from the cameras.
fn pixels_per_metre(field: &MeshField, cameras: &[Camera]) -> f32 {
    let Some(camera) = cameras.first() else {
        return 1.0;
    };
    let mut d: Vec<f32> = field
        .positions
        .iter()
        .step_by((field.positions.len() / 512).max(1))
        .map(|p| p.distance(camera.position()))
        .collect();
    if d.is_empty() {
        return 1.0;
    }
    d.sort_by(f32::total_cmp);
    camera.intrinsics.fx / d[d.len() / 2].max(1e-6)
}

fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x).exp())
}

/// One densify-and-prune edit of `field` from the window's face statistics. Returns the new
/// field, its new → old vertex map, and (split, pruned) face counts.
fn densify_and_prune(
    field: &MeshField,
    stats: &[(f32, u32)],
    config: &DensifyConfig,
    px_per_m: f32,
) -> (MeshField, Vec<u32>, usize, usize) {
    let n = field.faces.len();
    let mut keep = vec![true; n];
    let mut candidates = Vec::new();
    for (f, face) in field.faces.iter().enumerate() {
        let (weight, _) = stats.get(f).copied().unwrap_or((0.0, 0));
        let edge_px = longest_edge(&field.positions, face) * px_per_m;
        let opacity = face
            .iter()
            .map(|&v| sigmoid(field.opacity[v as usize]))
            .sum::<f32>()
            / 3.0;
        if weight < config.prune_weight
            || opacity < config.prune_opacity
            || edge_px > config.oversize_pixels
        {
            keep[f] = false;
        } else if weight >= config.split_weight && edge_px >= config.split_pixels {
            candidates.push((weight * edge_px * edge_px, f));
        }
    }
    let pruned = keep.iter().filter(|k| !**k).count();
    let budget = config.max_faces.saturating_sub(n - pruned) / 3;
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut selected = vec![false; n];
    for &(_, f) in candidates.iter().take(budget) {
        selected[f] = true;
    }
    let split = candidates.len().min(budget);
    let (split_field, split_map) = split_faces(field, &selected);
    // split_faces keeps face order, replacing each selected face by its four children.
    let keep_after: Vec<bool> = (0..n)
        .flat_map(|f| std::iter::repeat_n(keep[f], if selected[f] { 4 } else { 1 }))
        .collect();
    let (out, map) = retain_faces(&split_field, &keep_after);
    let map = map.iter().map(|&v| split_map[v as usize]).collect();
    (out, map, split, pruned)
}

/// Hardened labels, new faces and what happened, for `field` remeshed with `config`'s mode.
fn remesh(field: &MeshField, config: &ReconstructionConfig) -> (MeshField, RemeshStats) {
    let parts = harden_parts(field);
    let normals = vertex_normals(&field.positions, &field.faces);
    let mut stats = RemeshStats {
        mode: Some(config.remesh),
        faces_before: field.faces.len(),
        cross_part_faces_before: cross_part_faces(&field.faces, &parts),
        ..RemeshStats::default()
    };
    // Only vertices the optimised faces still use take part, thinned to an even spacing of
    // about one median edge: the soup's vertices come in tight clusters, which would leave the
    // restricted Delaunay step holes and slivers. Thinning never mixes parts.
    let (used, used_map) = compact(field, field.faces.clone());
    let used_parts: Vec<u32> = used_map.iter().map(|&v| parts[v as usize]).collect();
    let used_normals: Vec<Vec3> = used_map.iter().map(|&v| normals[v as usize]).collect();
    let cell = config.remesh_spacing * median_edge(&used.positions, &used.faces);
    let (used, used_normals) = if cell > 0.0 {
        thin_vertices(&used, &used_normals, &used_parts, cell)
    } else {
        (used, used_normals)
    };
    let used_parts = harden_parts(&used);
    let faces = match config.remesh {
        RemeshMode::PartAware => part_aware_remesh(
            &used.positions,
            Some(&used_normals),
            &used_parts,
            &config.remesh_options,
        ),
        RemeshMode::Global => {
            restricted_delaunay(&used.positions, Some(&used_normals), &config.remesh_options)
        }
    };
    stats.faces_built = faces.len();
    stats.cross_part_faces = cross_part_faces(&faces, &used_parts);
    // Floaters are judged per part, among that part's faces.
    let mut keep = vec![false; faces.len()];
    for k in 0..field.num_parts as u32 {
        let ids: Vec<usize> = (0..faces.len())
            .filter(|&f| face_part(&faces[f], &used_parts) == k)
            .collect();
        let own: Vec<[u32; 3]> = ids.iter().map(|&f| faces[f]).collect();
        for (&f, kept) in ids
            .iter()
            .zip(drop_small_components(&own, config.min_component_fraction))
        {
            keep[f] = kept;
        }
    }
    stats.floater_faces = keep.iter().filter(|k| !**k).count();
    let faces: Vec<[u32; 3]> = faces
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(f, _)| *f)
        .collect();
    let (mut out, _) = compact(&used, faces);
    stats.unused_vertices = field.num_vertices() - out.num_vertices();
    // Hardened logits: the label strongly, so renders of part logits show the labels.
    let labels = harden_parts(&out);
    let p = out.num_parts;
    for (v, &k) in labels.iter().enumerate() {
        let logits = &mut out.part_logits[v * p..(v + 1) * p];
        logits.fill(0.0);
        logits[k as usize] = 10.0;
    }
    (out, stats)
}

/// A training checkpoint: reports `event`, then renders training view 0 for the observer when it
/// asks for a preview.
async fn watch(
    ctx: &GpuContext,
    observer: &mut dyn Observer,
    trainer: &mut Trainer<'_>,
    event: &Progress,
    settings: &RasterSettings,
) -> GpuResult<()> {
    checkpoint(observer, event).await?;
    if observer.wants_preview() {
        let at = (event.state, event.iteration);
        observer.preview(trainer.preview(ctx, 0, settings, at).await?);
    }
    Ok(())
}

/// Reconstructs one state from its training `frames` (see the module docs).
pub async fn reconstruct_state(
    ctx: &GpuContext,
    state: State,
    frames: &[Frame],
    num_parts: usize,
    config: &ReconstructionConfig,
    observer: &mut dyn Observer,
) -> GpuResult<StateReconstruction> {
    let t0 = now_seconds();
    let mut times = PhaseTimes::default();
    let mut lap = {
        let mut last = t0;
        move || {
            let now = now_seconds();
            let dt = now - last;
            last = now;
            dt
        }
    };
    let event = |phase, iteration, iterations, loss, psnr, field: (usize, usize)| Progress {
        state,
        phase,
        iteration,
        iterations,
        loss,
        psnr,
        vertices: field.0,
        faces: field.1,
        elapsed_s: now_seconds() - t0,
    };
    let cameras: Vec<Camera> = frames.iter().map(|f| f.camera).collect();
    let Some(first) = frames.first() else {
        return Err(GpuError::InvalidInput(format!(
            "the {} state has no training views",
            state.name()
        )));
    };
    let (width, height) = (first.rgba.width, first.rgba.height);

    let field = initial_field(frames, num_parts, &config.init)
        .map_err(|e| GpuError::InvalidInput(format!("{} state: {e}", state.name())))?;
    let initial_faces = field.faces.len();
    let px_per_m = pixels_per_metre(&field, &cameras);
    times.initialise_s = lap();
    checkpoint(
        observer,
        &event(
            Phase::Initialise,
            0,
            0,
            None,
            None,
            (field.num_vertices(), field.faces.len()),
        ),
    )
    .await?;

    // Optimisation with densification and pruning.
    let fit = &config.fit;
    let mut trainer = Trainer::new(
        ctx,
        &cameras,
        frames,
        &field,
        fit.rates(fit.position_decay().lr(0)),
        fit.seed,
    )?;
    let mut sizes = (field.num_vertices(), field.faces.len());
    let every = config.densify.every.max(frames.len() as u32).max(1);
    let window = (
        (config.densify.from * fit.iterations as f32) as u32,
        (config.densify.until * fit.iterations as f32) as u32,
    );
    let (mut faces_split, mut faces_pruned) = (0, 0);
    let mut curve = Vec::new();
    trainer.clear_face_stats(ctx);
    for i in 0..fit.iterations {
        if let (settings, Some(point)) = trainer.scheduled_step(ctx, fit, i).await? {
            times.optimise_s += lap();
            let at = event(
                Phase::Optimise,
                i + 1,
                fit.iterations,
                Some(point.loss.total),
                point.psnr,
                sizes,
            );
            watch(ctx, observer, &mut trainer, &at, &settings).await?;
            curve.push(point);
        }
        if i > 0 && i % every == 0 {
            times.optimise_s += lap();
            if (window.0..=window.1).contains(&i) {
                let current = trainer.download(ctx).await?;
                let stats = trainer.read_face_stats(ctx).await?;
                let (edited, map, split, pruned) =
                    densify_and_prune(&current, &stats, &config.densify, px_per_m);
                if edited.faces.is_empty() {
                    return Err(GpuError::InvalidInput(format!(
                        "{} state: pruning removed every face at iteration {i} (is the object in view?)",
                        state.name()
                    )));
                }
                trainer.replace_field(ctx, &edited, &map)?;
                faces_split += split;
                faces_pruned += pruned;
                sizes = (edited.num_vertices(), edited.faces.len());
                times.densify_s += lap();
                let at = event(Phase::Densify, i + 1, fit.iterations, None, None, sizes);
                checkpoint(observer, &at).await?;
            }
            trainer.clear_face_stats(ctx);
        }
    }
    times.optimise_s += lap();
    let final_settings = fit.settings_at(fit.iterations);
    let psnr_optimised = trainer.mean_psnr(ctx, &final_settings).await?;
    let optimised = trainer.download(ctx).await?;
    times.measure_s += lap();

    // Hardening and part-aware remeshing.
    let (remeshed, remesh_stats) = remesh(&optimised, config);
    if remeshed.faces.is_empty() {
        return Err(GpuError::InvalidInput(format!(
            "{} state: remeshing built no faces from {} vertices",
            state.name(),
            optimised.num_vertices()
        )));
    }
    sizes = (remeshed.num_vertices(), remeshed.faces.len());
    times.remesh_s = lap();
    checkpoint(observer, &event(Phase::Remesh, 0, 0, None, None, sizes)).await?;

    // Recovery with fixed topology.
    let recovery = config.recovery();
    trainer.restart(
        ctx,
        &remeshed,
        recovery.rates(recovery.position_lr.0),
        fit.seed ^ 1,
    )?;
    let psnr_remeshed = trainer.mean_psnr(ctx, &recovery.settings_at(0)).await?;
    times.measure_s += lap();
    for i in 0..recovery.iterations {
        if let (settings, Some(point)) = trainer.scheduled_step(ctx, &recovery, i).await? {
            let at = event(
                Phase::Recover,
                i + 1,
                recovery.iterations,
                Some(point.loss.total),
                point.psnr,
                sizes,
            );
            watch(ctx, observer, &mut trainer, &at, &settings).await?;
        }
    }
    times.recover_s = lap();
    let psnr_recovered = trainer
        .mean_psnr(ctx, &recovery.settings_at(recovery.iterations))
        .await?;
    let field = trainer.download(ctx).await?;
    times.measure_s += lap();

    let parts = harden_parts(&field);
    let meshes = part_meshes(&field.positions, &field.faces, &parts, num_parts);
    times.total_s = now_seconds() - t0;
    checkpoint(
        observer,
        &event(Phase::Done, 0, 0, None, Some(psnr_recovered), sizes),
    )
    .await?;
    Ok(StateReconstruction {
        state,
        field,
        parts,
        part_meshes: meshes,
        remesh: remesh_stats,
        faces_split,
        faces_pruned,
        initial_faces,
        psnr_optimised,
        psnr_remeshed,
        psnr_recovered,
        curve,
        times,
        width,
        height,
        views: frames.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optim::FRESH;

    #[test]
    fn densify_splits_visible_large_faces_and_prunes_invisible_ones() {
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        let field = MeshField::new(positions, vec![[0, 1, 2], [3, 4, 5]], 1, 0.0);
        let config = DensifyConfig {
            split_pixels: 2.0,
            ..DensifyConfig::default()
        };
        // 10 px per metre: both faces are ~14 px; face 0 seen, face 1 never.
        let (out, map, split, pruned) =
            densify_and_prune(&field, &[(0.9, 40), (0.0, 0)], &config, 10.0);
        assert_eq!((split, pruned), (1, 1));
        assert_eq!(out.faces.len(), 4);
        assert_eq!(out.num_vertices(), 6);
        // The split face's corners keep their moments; its three midpoints start fresh.
        let mut old: Vec<u32> = map.iter().copied().filter(|&m| m != FRESH).collect();
        old.sort();
        assert_eq!(old, vec![0, 1, 2]);
        for (new, &m) in map.iter().enumerate() {
            if m != FRESH {
                assert_eq!(out.positions[new], field.positions[m as usize]);
            }
        }
        out.validate().unwrap();
    }

    #[test]
    fn presets_parse_and_scale() {
        assert_eq!(Preset::parse("FAST").unwrap(), Preset::Fast);
        assert!(
            Preset::parse("huge")
                .unwrap_err()
                .contains("tiny, fast, paper")
        );
        let it = |p| ReconstructionConfig::preset(p).fit.iterations;
        assert!(it(Preset::Tiny) < it(Preset::Fast) && it(Preset::Fast) < it(Preset::Paper));
        assert_eq!(it(Preset::Paper), 20_000);
        let r = ReconstructionConfig::preset(Preset::Fast).recovery();
        assert_eq!(r.settings_at(0).opacity_floor, 1.0);
        assert_eq!(r.settings_at(0).sh_degree, 3);
    }
}
