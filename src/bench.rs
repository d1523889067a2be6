//! Benchmarks (native only): machine-readable timings of GPU kernels on the current adapter.
//! They are not tests: nothing here asserts a speed; `artmesh bench ...` prints the JSON.

use std::time::Instant;

use serde::Serialize;

use crate::fit::observer::Unobserved;
use crate::gpu::{AdapterReport, GpuContext, GpuResult, RadixSort, key_mask};
use crate::rng::Rng;

/// Throughput of one sort size.
#[derive(Debug, Clone, Serialize)]
pub struct SortTiming {
    pub n: u32,
    pub key_bits: u32,
    pub repeats: usize,
    /// Median wall time of encode + submit + wait, excluding the upload of the keys.
    pub median_ms: f64,
    pub min_ms: f64,
    pub keys_per_second: f64,
}

/// `artmesh bench sort` output.
#[derive(Debug, Clone, Serialize)]
pub struct SortBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub results: Vec<SortTiming>,
}

/// Times the radix sort on random 32-bit keys for each size (one warm-up run each).
pub fn sort(
    ctx: &GpuContext,
    sizes: &[u32],
    key_bits: u32,
    repeats: usize,
) -> GpuResult<SortBench> {
    let mut results = Vec::new();
    for &n in sizes {
        let mut rng = Rng::new(u64::from(n));
        let mask = key_mask(key_bits);
        let keys: Vec<u32> = (0..n).map(|_| rng.next_u32() & mask).collect();
        let values: Vec<u32> = (0..n).collect();
        let sorter = RadixSort::new(ctx, n)?;
        let mut times = Vec::with_capacity(repeats);
        for run in 0..=repeats {
            ctx.queue
                .write_buffer(sorter.keys(), 0, bytemuck::cast_slice(&keys));
            ctx.queue
                .write_buffer(sorter.values(), 0, bytemuck::cast_slice(&values));
            ctx.queue.submit([]);
            ctx.poll_wait()?;
            let start = Instant::now();
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            sorter.encode(ctx, &mut encoder, n, key_bits)?;
            ctx.queue.submit([encoder.finish()]);
            ctx.poll_wait()?;
            ctx.check()?;
            if run > 0 {
                times.push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        times.sort_by(f64::total_cmp);
        let median_ms = times.get(times.len() / 2).copied().unwrap_or(f64::NAN);
        results.push(SortTiming {
            n,
            key_bits,
            repeats,
            median_ms,
            min_ms: times.first().copied().unwrap_or(f64::NAN),
            keys_per_second: f64::from(n) / (median_ms / 1e3),
        });
    }
    Ok(SortBench {
        bench: "radix_sort",
        adapter: ctx.adapter.clone(),
        results,
    })
}

/// Capture throughput of one image size.
#[derive(Debug, Clone, Serialize)]
pub struct CaptureTiming {
    pub width: u32,
    pub height: u32,
    pub object: String,
    pub triangles: usize,
    pub frames: usize,
    /// Wall time of the whole capture: render, readback and PNG encoding of every frame, ground truth.
    pub total_ms: f64,
    pub frames_per_second: f64,
    /// Bytes of the encoded dataset.
    pub bytes: usize,
}

/// `artmesh bench capture` output.
#[derive(Debug, Clone, Serialize)]
pub struct CaptureBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub results: Vec<CaptureTiming>,
}

/// Times `render_dataset` of one procedural object (StorageFurniture, 6 movable parts) at each size, with
/// `views` train views and no test views per state, the files kept in memory.
pub fn capture(ctx: &GpuContext, sizes: &[u32], views: usize) -> Result<CaptureBench, String> {
    use crate::render::{RenderSpec, render_dataset};
    use crate::synth::{Category, SynthParams, generate};
    let object = generate(&SynthParams {
        category: Category::StorageFurniture,
        movable_parts: Some(6),
        seed: 1,
    })?;
    let triangles = (0..object.links.len())
        .flat_map(|l| object.link_meshes(l))
        .map(|m| m.indices.len())
        .sum();
    let mut results = Vec::new();
    for &size in sizes {
        let spec = RenderSpec {
            width: size,
            height: size,
            train_views: views,
            test_views: 0,
            ..RenderSpec::default()
        };
        let mut bytes = 0;
        let start = Instant::now();
        let done = pollster::block_on(render_dataset(
            ctx,
            &object,
            &spec,
            &mut |files| {
                bytes += files.values().map(Vec::len).sum::<usize>();
                Ok(())
            },
            &mut |_| {},
        ))
        .map_err(|e| e.to_string())?;
        let total_ms = start.elapsed().as_secs_f64() * 1e3;
        results.push(CaptureTiming {
            width: size,
            height: size,
            object: object.name.clone(),
            triangles,
            frames: done.frames,
            total_ms,
            frames_per_second: done.frames as f64 / (total_ms / 1e3),
            bytes,
        });
    }
    Ok(CaptureBench {
        bench: "capture",
        adapter: ctx.adapter.clone(),
        results,
    })
}

/// Floating-point operations the rasterizer's compositing loops perform, counted by hand from the
/// WGSL (a transcendental counts as one): every per-pixel face evaluation pays the coverage test;
/// a hit pays the compositing (forward) or the replay and chain rule (backward), plus per part.
pub const FLOP_MODEL: &str = "per evaluation 19 (coverage test); per forward hit 41 + 8 P; \
    per backward hit 120 + 20 P; P = part logits";

fn model_flops(work: &crate::raster::WorkCounts, parts: u64) -> f64 {
    let coverage = 19.0 * (work.forward_evaluations + work.backward_evaluations) as f64;
    let hits = work.hits as f64;
    coverage + hits * (41.0 + 8.0 * parts as f64) + hits * (120.0 + 20.0 * parts as f64)
}

/// One `artmesh bench raster` case.
#[derive(Debug, Clone, Serialize)]
pub struct RasterTiming {
    pub width: u32,
    pub height: u32,
    pub faces: usize,
    pub parts: usize,
    /// (face, tile) pairs per view.
    pub pairs: u32,
    pub repeats: usize,
    /// Median wall time of one training iteration: forward (with its pair-count read-back), loss,
    /// backward and Adam on all four parameter groups, submitted and waited for.
    pub median_ms: f64,
    pub min_ms: f64,
    /// Per-stage times of one extra iteration with every stage submitted and waited for alone.
    pub stages_ms: Vec<(String, f64)>,
    pub work: crate::raster::WorkCounts,
    /// Pixel–face evaluations (forward + backward) per second of the median iteration.
    pub evaluations_per_second: f64,
    /// Model FLOPs of the compositing loops per iteration (see `flop_model`).
    pub model_flops: f64,
    /// Model FLOP rate over the whole iteration, and over the compositing kernels alone.
    pub gflops_iteration: f64,
    pub gflops_compositing: f64,
    /// `gflops_iteration` / FMA peak, and `gflops_compositing` / FMA peak.
    pub peak_fraction_iteration: f64,
    pub peak_fraction_compositing: f64,
}

/// `artmesh bench raster` output.
#[derive(Debug, Clone, Serialize)]
pub struct RasterBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub fma_peak: crate::gpu::FmaPeak,
    pub flop_model: &'static str,
    pub scene: &'static str,
    pub results: Vec<RasterTiming>,
}

/// Times training iterations of the rasterizer on the benchmark sphere (`raster::check::
/// sphere_scene`: γ = 0.5, mid-training opacity, 4 parts) for each (size, faces) case, against a
/// target rendered from the same mesh with its colours shuffled, after one warm-up iteration.
pub fn raster(ctx: &GpuContext, cases: &[(u32, usize)], repeats: usize) -> GpuResult<RasterBench> {
    use crate::data::{DepthMap, PartMap, RgbaImage};
    use crate::fit::photometric::{FieldAdam, FieldLearningRates};
    use crate::loss::{ImageLoss, LossWeights, TargetImages, TargetView};
    use crate::raster::{GpuField, RasterState, Rasterizer, SH_FLOATS, check};

    let peak = pollster::block_on(crate::gpu::fma_peak(ctx))?;
    let raster = Rasterizer::new(ctx);
    let mut results = Vec::new();
    for &(size, faces) in cases {
        let scene = check::sphere_scene(faces, size, size, 1);
        let parts = scene.field.num_parts as u32;
        // The target: the same mesh with shuffled colours, read back as dataset images.
        let mut target_field = scene.field.clone();
        target_field.sh.rotate_left(SH_FLOATS * 7);
        let target_gpu = GpuField::upload(ctx, &target_field)?;
        let mut state = RasterState::new(ctx, size, size, parts)?;
        pollster::block_on(raster.forward(
            ctx,
            &target_gpu,
            &mut state,
            &scene.camera,
            &scene.settings,
        ))?;
        let img = pollster::block_on(state.read_render(ctx))?;
        drop(target_gpu);
        let n = (size * size) as usize;
        let rgba = RgbaImage {
            width: size,
            height: size,
            pixels: (0..n)
                .flat_map(|i| {
                    let q = |c: usize| (img.plane(c)[i].clamp(0.0, 1.0) * 255.0).round() as u8;
                    [q(0), q(1), q(2), (img.plane(4)[i] > 0.5) as u8 * 255]
                })
                .collect(),
        };
        let depth = DepthMap {
            width: size,
            height: size,
            millimetres: img
                .plane(3)
                .iter()
                .map(|d| (d * 1000.0).round() as u16)
                .collect(),
        };
        let labels = PartMap {
            width: size,
            height: size,
            ids: (0..n)
                .map(|i| {
                    if img.plane(4)[i] < 0.5 {
                        return -1;
                    }
                    (0..parts as usize)
                        .max_by(|&a, &b| img.plane(5 + a)[i].total_cmp(&img.plane(5 + b)[i]))
                        .unwrap_or(0) as i16
                })
                .collect(),
        };
        let targets = TargetImages::upload(
            ctx,
            size,
            size,
            &[TargetView {
                rgba: &rgba,
                depth: Some(&depth),
                parts: Some(&labels),
            }],
        )?;
        let loss = ImageLoss::new(ctx, size, size, parts)?;
        let field = GpuField::upload(ctx, &scene.field)?;
        let mut optimizer = FieldAdam::new(
            ctx,
            &field,
            FieldLearningRates {
                position: 1e-5,
                sh: 1e-3,
                opacity: 1e-3,
                part: 1e-3,
            },
        )?;
        let mut iteration = |state: &mut RasterState| -> GpuResult<u32> {
            let stats = pollster::block_on(raster.forward(
                ctx,
                &field,
                state,
                &scene.camera,
                &scene.settings,
            ))?;
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            state.clock_lap(ctx, &mut encoder, "");
            loss.encode(
                ctx,
                &mut encoder,
                state.render(),
                &targets,
                0,
                &LossWeights::default(),
                scene.settings.background.to_array(),
                state.grad_render(),
            )?;
            state.clock_lap(ctx, &mut encoder, "loss");
            raster.encode_backward(ctx, &mut encoder, &field, state);
            state.clock_lap(ctx, &mut encoder, "");
            optimizer.encode_step(ctx, &mut encoder)?;
            state.clock_lap(ctx, &mut encoder, "adam");
            ctx.queue.submit([encoder.finish()]);
            ctx.poll_wait()?;
            ctx.check()?;
            Ok(stats.pairs)
        };
        let mut times = Vec::with_capacity(repeats);
        let mut pairs = 0;
        for run in 0..=repeats {
            let start = Instant::now();
            pairs = iteration(&mut state)?;
            if run > 0 {
                times.push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        // Work counts and a per-stage breakdown from one more (profiled) iteration.
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        state.clear_face_stats(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        state.set_profiling(true);
        iteration(&mut state)?;
        state.set_profiling(false);
        let stages: Vec<(String, f64)> = state
            .clock
            .take()
            .into_iter()
            .filter(|(s, _)| !s.is_empty())
            .map(|(s, t)| (s.to_string(), t))
            .collect();
        let work = pollster::block_on(state.read_work(ctx, field.num_faces))?;
        times.sort_by(f64::total_cmp);
        let median_ms = times.get(times.len() / 2).copied().unwrap_or(f64::NAN);
        let compositing_ms: f64 = stages
            .iter()
            .filter(|(s, _)| s.starts_with("composite"))
            .map(|(_, t)| t)
            .sum();
        let flops = model_flops(&work, u64::from(parts));
        let gflops_iteration = flops / (median_ms * 1e6);
        let gflops_compositing = flops / (compositing_ms * 1e6);
        results.push(RasterTiming {
            width: size,
            height: size,
            faces: scene.field.faces.len(),
            parts: parts as usize,
            pairs,
            repeats,
            median_ms,
            min_ms: times.first().copied().unwrap_or(f64::NAN),
            stages_ms: stages,
            work,
            evaluations_per_second: (work.forward_evaluations + work.backward_evaluations) as f64
                / (median_ms / 1e3),
            model_flops: flops,
            gflops_iteration,
            gflops_compositing,
            peak_fraction_iteration: gflops_iteration / peak.gflops,
            peak_fraction_compositing: gflops_compositing / peak.gflops,
        });
    }
    Ok(RasterBench {
        bench: "raster",
        adapter: ctx.adapter.clone(),
        fma_peak: peak,
        flop_model: FLOP_MODEL,
        scene: "bumpy UV sphere, random colours, opacity 0.62, gamma 0.5, 4 parts; target: shuffled colours",
        results,
    })
}

/// One object of `artmesh bench reconstruct`.
#[derive(Debug, Clone, Serialize)]
pub struct ReconstructObject {
    pub id: String,
    pub category: &'static str,
    pub parts: usize,
    pub seconds: f64,
    pub report: crate::eval::ReconstructionReport,
}

/// Time per phase summed over all objects and both states.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct PhaseTotals {
    pub seconds: crate::fit::reconstruct::PhaseTimes,
    /// The phase with the largest share, and that share.
    pub dominant: &'static str,
    pub dominant_share: f64,
}

/// `artmesh bench reconstruct` output.
#[derive(Debug, Clone, Serialize)]
pub struct ReconstructBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub preset: crate::fit::reconstruct::ReconstructionConfig,
    pub capture: CaptureSettings,
    pub phases: PhaseTotals,
    pub objects: Vec<ReconstructObject>,
}

/// How the quick-suite objects were captured for the benchmark.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct CaptureSettings {
    pub size: u32,
    pub train_views: usize,
}

/// A suite entry's object captured in memory at `size`² with `views` training views per state.
fn capture_entry(
    ctx: &GpuContext,
    entry: &crate::synth::SuiteEntry,
    size: u32,
    views: usize,
    test_views: usize,
) -> Result<crate::data::Dataset, String> {
    let id = entry.id();
    let object = crate::synth::generate(&entry.params()).map_err(|e| format!("{id}: {e}"))?;
    let spec = crate::render::RenderSpec {
        width: size,
        height: size,
        train_views: views,
        test_views,
        seed: entry.seed,
        ..crate::render::RenderSpec::default()
    };
    pollster::block_on(crate::render::capture_dataset(
        ctx,
        &object,
        &spec,
        &mut |_| {},
    ))
    .map_err(|e| format!("{id}: {e}"))
}

/// Reconstructs the quick-suite objects (all, or those whose id contains one of `only`), each
/// captured in memory at `size`² with `views` training views per state, and times every phase.
pub fn reconstruct(
    ctx: &GpuContext,
    config: &crate::fit::reconstruct::ReconstructionConfig,
    only: &[String],
    size: u32,
    views: usize,
    log: &mut dyn FnMut(&ReconstructObject),
) -> Result<ReconstructBench, String> {
    use crate::synth::suite_plan;
    let mut objects = Vec::new();
    let mut totals = PhaseTotals::default();
    for entry in suite_plan(true) {
        let id = entry.id();
        if !only.is_empty() && !only.iter().any(|o| id.contains(o.as_str())) {
            continue;
        }
        let dataset = capture_entry(ctx, &entry, size, views, 0)?;
        let start = Instant::now();
        let reconstruction = pollster::block_on(crate::fit::reconstruct::reconstruct(
            ctx,
            &dataset,
            config,
            &mut Unobserved,
        ))
        .map_err(|e| format!("{id}: {e}"))?;
        let seconds = start.elapsed().as_secs_f64();
        let report = crate::eval::reconstruction_report(
            &reconstruction,
            &dataset.gt_meshes,
            &crate::eval::ChamferOptions::default(),
        );
        for s in &report.states {
            totals.seconds.accumulate(&s.times);
        }
        let done = ReconstructObject {
            id,
            category: entry.category,
            parts: dataset.num_parts,
            seconds,
            report,
        };
        log(&done);
        objects.push(done);
    }
    (totals.dominant, totals.dominant_share) = totals.seconds.dominant();
    Ok(ReconstructBench {
        bench: "reconstruct",
        adapter: ctx.adapter.clone(),
        preset: *config,
        capture: CaptureSettings {
            size,
            train_views: views,
        },
        phases: totals,
        objects,
    })
}

/// One object of `artmesh bench fit`.
#[derive(Debug, Clone, Serialize)]
pub struct FitObject {
    pub id: String,
    pub category: String,
    pub parts: usize,
    /// Wall time of the whole fit, and of its two phases.
    pub seconds: f64,
    pub reconstruct_s: f64,
    pub articulate_s: f64,
    pub metrics: crate::eval::ObjectMetrics,
    pub joints: Vec<crate::export::JointRecord>,
    pub warnings: Vec<String>,
}

/// One variant of the ablation study (paper Table 4), over the same objects.
#[derive(Debug, Clone, Serialize)]
pub struct AblationRun {
    pub name: &'static str,
    pub objects: Vec<crate::eval::ObjectMetrics>,
}

/// `artmesh bench fit` output: per-object metrics and times, the paper-style tables and, when
/// asked, the ablation table.
#[derive(Debug, Clone, Serialize)]
pub struct FitBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub suite: SuiteSource,
    pub depth_degradation: DepthDegradation,
    pub config: crate::fit::object::FitConfig,
    pub capture: CaptureSettings,
    pub objects: Vec<FitObject>,
    pub by_part_count: crate::eval::BenchmarkTable,
    pub by_category: crate::eval::BenchmarkTable,
    /// Full model, w/o V-Color, w/o V-Opacity, w/o BackwardPass, w/o PartAware (All columns).
    pub ablation: Option<crate::eval::BenchmarkTable>,
    pub ablation_runs: Vec<AblationRun>,
    pub total_s: f64,
}

impl FitBench {
    /// The tables as Markdown (by part count, by category, ablations).
    pub fn to_markdown(&self) -> String {
        let mut out = format!(
            "### By part count\n\n{}\n### By category\n\n{}",
            self.by_part_count.to_markdown(),
            self.by_category.to_markdown()
        );
        if let Some(t) = &self.ablation {
            out.push_str(&format!("\n### Ablations\n\n{}", t.to_markdown()));
        }
        out
    }
}

/// The ablation variants of the articulation phase, by table label.
const ARTICULATION_ABLATIONS: [(&str, &str); 3] = [
    ("w/o V-Color", "no-vertex-color"),
    ("w/o V-Opacity", "no-vertex-opacity"),
    ("w/o BackwardPass", "no-backward"),
];

/// Where `artmesh bench fit` takes its objects from.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SuiteSource {
    /// A suite folder written by `artmesh suite` (suite.json and one dataset folder per id):
    /// the objects as a user would hand them over.
    Dir(std::path::PathBuf),
    /// The plan captured in memory at `size`² with `views` training and 2 test views per state:
    /// CI-sized runs only.
    Capture {
        kind: crate::synth::SuiteKind,
        size: u32,
        views: usize,
    },
}

/// What a suite folder's `suite.json` (written by `artmesh suite`) lists: each object's id (its
/// folder) and category, and how the suite was captured when it says.
pub struct SuiteListing {
    pub objects: Vec<(String, String)>,
    pub capture: Option<CaptureSettings>,
}

/// Reads `dir/suite.json`.
pub fn read_suite_listing(dir: &std::path::Path) -> Result<SuiteListing, String> {
    #[derive(serde::Deserialize)]
    struct Manifest {
        objects: Vec<Entry>,
        capture: Option<Capture>,
    }
    #[derive(serde::Deserialize)]
    struct Capture {
        width: u32,
        train_views: usize,
    }
    #[derive(serde::Deserialize)]
    struct Entry {
        id: String,
        category: String,
    }
    let path = dir.join("suite.json");
    let text = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let manifest: Manifest = serde_json::from_slice(&text).map_err(|e| {
        format!(
            "{}: expected a suite manifest ({{\"objects\": [{{\"id\", \"category\"}}]}}): {e}",
            path.display()
        )
    })?;
    Ok(SuiteListing {
        objects: manifest
            .objects
            .into_iter()
            .map(|o| (o.id, o.category))
            .collect(),
        capture: manifest.capture.map(|c| CaptureSettings {
            size: c.width,
            train_views: c.train_views,
        }),
    })
}

/// One object listed by a [`SuiteSource`].
struct SourceObject {
    id: String,
    category: String,
    entry: Option<crate::synth::SuiteEntry>,
}

impl SuiteSource {
    /// The objects, in suite order, and how they were captured.
    fn objects(&self) -> Result<(Vec<SourceObject>, CaptureSettings), String> {
        match self {
            SuiteSource::Capture { kind, size, views } => Ok((
                kind.plan()
                    .into_iter()
                    .map(|e| SourceObject {
                        id: e.id(),
                        category: e.category.to_string(),
                        entry: Some(e),
                    })
                    .collect(),
                CaptureSettings {
                    size: *size,
                    train_views: *views,
                },
            )),
            SuiteSource::Dir(dir) => {
                let listing = read_suite_listing(dir)?;
                let objects = listing
                    .objects
                    .into_iter()
                    .map(|(id, category)| {
                        // Ids name folders inside the suite: nothing that could leave it.
                        let plain = !id.is_empty()
                            && id
                                .chars()
                                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
                        if !plain {
                            return Err(format!(
                                "{}: object id {id:?} is not a plain folder name",
                                dir.join("suite.json").display()
                            ));
                        }
                        Ok(SourceObject {
                            id,
                            category,
                            entry: None,
                        })
                    })
                    .collect::<Result<_, _>>()?;
                let capture = listing.capture.ok_or_else(|| {
                    format!(
                        "{}: no \"capture\" settings (written by `artmesh suite`)",
                        dir.join("suite.json").display()
                    )
                })?;
                Ok((objects, capture))
            }
        }
    }

    /// One object's dataset.
    fn load(
        &self,
        ctx: &GpuContext,
        object: &SourceObject,
    ) -> Result<crate::data::Dataset, String> {
        match (self, &object.entry) {
            (SuiteSource::Capture { size, views, .. }, Some(entry)) => {
                capture_entry(ctx, entry, *size, *views, 2)
            }
            (SuiteSource::Dir(dir), _) => crate::data::read_dataset(&dir.join(&object.id)),
            _ => Err(format!("{}: no capture plan", object.id)),
        }
    }
}

/// Worse depth than the capture's, to measure how the fit copes: Gaussian noise on every depth
/// pixel and views without depth.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct DepthDegradation {
    /// Standard deviation of the noise added to every measured depth (mm; 0: none).
    pub noise_mm: f32,
    /// Every this many training views (from the second) lose their depth map (0: none).
    pub drop_every: usize,
}

impl DepthDegradation {
    /// Applies the degradation to `dataset`, reproducibly for `seed`.
    pub fn apply(&self, dataset: &mut crate::data::Dataset, seed: u64) {
        let mut rng = Rng::new(seed);
        for views in &mut dataset.views {
            let train = views.split == crate::data::Split::Train;
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

/// Fits the suite's objects (all, or those whose id contains one of `only`) and scores them.
/// With `ablations`, each object's reconstruction is also re-articulated without each
/// consistency component, and reconstructed and articulated once more with global remeshing.
pub fn fit(
    ctx: &GpuContext,
    config: &crate::fit::object::FitConfig,
    source: &SuiteSource,
    only: &[String],
    degrade: &DepthDegradation,
    ablations: bool,
    log: &mut dyn FnMut(&FitObject),
) -> Result<FitBench, String> {
    use crate::eval::{BenchmarkTable, ColumnSummary, EvalOptions};
    use crate::fit::articulate::{Ablation, articulate};
    use crate::fit::object::ObjectFit;
    use crate::fit::reconstruct::{RemeshMode, reconstruct};
    let started = Instant::now();
    let options = EvalOptions::default();
    let mut objects = Vec::new();
    let mut runs: Vec<AblationRun> = std::iter::once("Full model")
        .chain(ARTICULATION_ABLATIONS.iter().map(|a| a.0))
        .chain(["w/o PartAware"])
        .map(|name| AblationRun {
            name,
            objects: Vec::new(),
        })
        .collect();
    let (listed, capture) = source.objects()?;
    for object in listed {
        let id = object.id.clone();
        if !only.is_empty() && !only.iter().any(|o| id.contains(o.as_str())) {
            continue;
        }
        let named = |e: String| format!("{id}: {e}");
        let mut dataset = source.load(ctx, &object)?;
        degrade.apply(&mut dataset, 17);
        let category = object.category.clone();
        let score = |fit: &ObjectFit| -> Result<crate::eval::ObjectMetrics, String> {
            crate::eval::evaluate_fit(fit, &dataset, &id, &category, &options)
                .ok_or_else(|| named("the captured object has no ground-truth joints".into()))?
                .map_err(|e| named(e.to_string()))
        };
        let start = Instant::now();
        let reconstruction = pollster::block_on(reconstruct(
            ctx,
            &dataset,
            &config.reconstruction,
            &mut Unobserved,
        ))
        .map_err(|e| named(e.to_string()))?;
        let reconstruct_s = start.elapsed().as_secs_f64();
        let articulation = pollster::block_on(articulate(
            ctx,
            &dataset,
            &reconstruction,
            &config.articulation,
            &mut Unobserved,
        ))
        .map_err(|e| named(e.to_string()))?;
        let seconds = start.elapsed().as_secs_f64();
        let mut fit = ObjectFit {
            reconstruction,
            articulation,
        };
        let metrics = score(&fit)?;
        let done = FitObject {
            id: id.clone(),
            category: object.category.clone(),
            parts: dataset.num_parts,
            seconds,
            reconstruct_s,
            articulate_s: seconds - reconstruct_s,
            metrics: metrics.clone(),
            joints: crate::export::joint_records(&fit),
            warnings: fit.articulation.warnings.clone(),
        };
        log(&done);
        objects.push(done);
        if ablations {
            runs[0].objects.push(metrics);
            for (run, (_, name)) in runs[1..].iter_mut().zip(ARTICULATION_ABLATIONS) {
                let articulation = crate::fit::articulate::ArticulationConfig {
                    ablation: Ablation::parse(name)?,
                    ..config.articulation
                };
                fit.articulation = pollster::block_on(articulate(
                    ctx,
                    &dataset,
                    &fit.reconstruction,
                    &articulation,
                    &mut Unobserved,
                ))
                .map_err(|e| named(e.to_string()))?;
                run.objects.push(score(&fit)?);
            }
            let global = crate::fit::reconstruct::ReconstructionConfig {
                remesh: RemeshMode::Global,
                ..config.reconstruction
            };
            fit.reconstruction =
                pollster::block_on(reconstruct(ctx, &dataset, &global, &mut Unobserved))
                    .map_err(|e| named(e.to_string()))?;
            fit.articulation = pollster::block_on(articulate(
                ctx,
                &dataset,
                &fit.reconstruction,
                &config.articulation,
                &mut Unobserved,
            ))
            .map_err(|e| named(e.to_string()))?;
            runs[4].objects.push(score(&fit)?);
            eprintln!(
                "bench fit: {id} ablations (Axis Ang): {}",
                runs.iter()
                    .map(|r| format!(
                        "{} {:.2}",
                        r.name,
                        r.objects
                            .last()
                            .and_then(|m| m.axis_ang)
                            .unwrap_or(f64::NAN)
                    ))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    let metrics: Vec<crate::eval::ObjectMetrics> =
        objects.iter().map(|o| o.metrics.clone()).collect();
    let ablation = ablations.then(|| BenchmarkTable {
        columns: runs
            .iter()
            .map(|r| ColumnSummary::new(r.name, &r.objects.iter().collect::<Vec<_>>()))
            .collect(),
    });
    Ok(FitBench {
        bench: "fit",
        adapter: ctx.adapter.clone(),
        suite: source.clone(),
        depth_degradation: *degrade,
        config: *config,
        capture,
        by_part_count: BenchmarkTable::by_part_count(&metrics),
        by_category: BenchmarkTable::by_category(&metrics),
        ablation,
        ablation_runs: if ablations { runs } else { Vec::new() },
        objects,
        total_s: started.elapsed().as_secs_f64(),
    })
}

/// What `artmesh bench spread` changes from one fit to the next.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpreadChange {
    /// Fit k scales the reconstruction's SSIM weight by 1 + k·step: a change at the level of
    /// rounding that reaches everything downstream (densification, remeshing, articulation).
    Ssim,
    /// One reconstruction; articulation k draws its views in another order (seed + k). The
    /// meshes are identical, so the spread is the articulation phase's own.
    ViewOrder,
}

impl SpreadChange {
    /// The change named as on the command line (`ssim`, `view-order`).
    pub fn parse(name: &str) -> Result<SpreadChange, String> {
        match name {
            "ssim" => Ok(SpreadChange::Ssim),
            "view-order" => Ok(SpreadChange::ViewOrder),
            other => Err(format!(
                "unknown spread change {other:?}: expected ssim or view-order"
            )),
        }
    }
}

/// One fit of `artmesh bench spread`.
#[derive(Debug, Clone, Serialize)]
pub struct SpreadRun {
    /// The factor on the reconstruction's SSIM weight (1 for the unchanged fit).
    pub ssim_factor: f64,
    /// The articulation phase's seed (its view order).
    pub articulation_seed: u64,
    pub seconds: f64,
    /// Per state: mean training PSNR after the optimisation and the faces remeshing built, the
    /// first numbers where two fits part ways.
    pub psnr_optimised: Vec<f64>,
    pub remeshed_faces: Vec<usize>,
    pub joints: Vec<crate::export::JointRecord>,
    /// Against the dataset's ground truth (`None` without one): the fitted joints' errors, and
    /// those of the registration seeds the refinement started from (`None` when a part has no
    /// seed), matched as `artmesh eval` matches them. Shows whether the fits scatter around the
    /// truth or away from it, and what the refinement added to its seeds.
    pub gt_errors: Option<Vec<crate::eval::joints::JointPairMetrics>>,
    pub seed_gt_errors: Option<Vec<crate::eval::joints::JointPairMetrics>>,
}

/// How far one part's joint moved in a changed fit from the unchanged one.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct JointShift {
    pub part: usize,
    pub same_type: bool,
    pub axis_deg: f64,
    /// Distance between the axis lines (revolute joints), metres.
    pub axis_line_m: Option<f64>,
    /// Part Motion between the two (° or m, in the unchanged joint's type).
    pub motion: f64,
    /// How far the articulation's starting point (the registration seeds of the two states'
    /// meshes) moved: axis (°). Small against `axis_deg`: the articulation phase amplified the
    /// change; as large: it came in with the meshes.
    pub seed_axis_deg: Option<f64>,
}

/// `artmesh bench spread` output: the same dataset fitted `runs` times, each with a change
/// that should not matter ([`SpreadChange`]), and each changed fit's joints against the
/// unchanged one's. Two backends that round differently (lavapipe and SwiftShader, or two
/// GPUs) can be expected to disagree by as much as the `ssim` change moves the joints.
#[derive(Debug, Clone, Serialize)]
pub struct SpreadBench {
    pub bench: &'static str,
    pub adapter: AdapterReport,
    pub preset: crate::fit::reconstruct::Preset,
    pub change: SpreadChange,
    pub step: f64,
    pub fits: Vec<SpreadRun>,
    /// `shifts[k - 1]`: fit k's joints against fit 0's.
    pub shifts: Vec<Vec<JointShift>>,
    /// The largest shift over the changed fits: axis (°), axis line (m), motion.
    pub max_axis_deg: f64,
    pub max_axis_line_m: f64,
    pub max_motion: f64,
    pub total_s: f64,
}

/// Fits `dataset` with `config` `runs` times, changing `change` by `step` per fit (see
/// [`SpreadBench`]).
pub fn spread(
    ctx: &GpuContext,
    dataset: &crate::data::Dataset,
    config: &crate::fit::object::FitConfig,
    change: SpreadChange,
    runs: usize,
    step: f64,
    log: &mut dyn FnMut(&SpreadRun),
) -> Result<SpreadBench, String> {
    use crate::data::{GtJoint, JointKind};
    use crate::eval::joints::{axis_angle_deg, axis_line_distance, match_joints, motion_error};
    use crate::fit::articulate::articulate;
    use crate::fit::object::ObjectFit;
    use crate::fit::reconstruct::reconstruct;
    let started = Instant::now();
    let reconstruct_with = |ssim_factor: f64| {
        let mut changed = config.reconstruction;
        changed.fit.weights.ssim *= ssim_factor as f32;
        pollster::block_on(reconstruct(ctx, dataset, &changed, &mut Unobserved))
    };
    // The view-order change shares one reconstruction.
    let shared = match change {
        SpreadChange::ViewOrder => {
            Some(reconstruct_with(1.0).map_err(|e| format!("reconstruction: {e}"))?)
        }
        SpreadChange::Ssim => None,
    };
    let mut fits = Vec::new();
    let mut joints: Vec<(Vec<GtJoint>, Vec<Option<GtJoint>>)> = Vec::new();
    for k in 0..runs.max(2) {
        let start = Instant::now();
        let (ssim_factor, seed) = match change {
            SpreadChange::Ssim => (1.0 + k as f64 * step, config.articulation.seed),
            SpreadChange::ViewOrder => (1.0, config.articulation.seed + k as u64),
        };
        let reconstruction = match &shared {
            Some(r) => r.clone(),
            None => reconstruct_with(ssim_factor).map_err(|e| format!("fit {k}: {e}"))?,
        };
        let articulation_config = crate::fit::articulate::ArticulationConfig {
            seed,
            ..config.articulation
        };
        let articulation = pollster::block_on(articulate(
            ctx,
            dataset,
            &reconstruction,
            &articulation_config,
            &mut Unobserved,
        ))
        .map_err(|e| format!("fit {k}: {e}"))?;
        let fit = ObjectFit {
            reconstruction,
            articulation,
        };
        let states = &fit.reconstruction.states;
        let (fitted, seeds) = (fit.articulation.gt_joints(), fit.articulation.seed_joints());
        let against_gt = |joints: &[GtJoint]| {
            let gt = dataset.gt_joints.as_ref()?;
            match_joints(joints, gt).ok().map(|m| m.pairs)
        };
        let seeds_gt = seeds
            .iter()
            .copied()
            .collect::<Option<Vec<GtJoint>>>()
            .and_then(|s| against_gt(&s));
        let run = SpreadRun {
            ssim_factor,
            articulation_seed: seed,
            seconds: start.elapsed().as_secs_f64(),
            psnr_optimised: states.iter().map(|s| s.psnr_optimised).collect(),
            remeshed_faces: states.iter().map(|s| s.remesh.faces_built).collect(),
            joints: crate::export::joint_records(&fit),
            gt_errors: against_gt(&fitted),
            seed_gt_errors: seeds_gt,
        };
        log(&run);
        fits.push(run);
        joints.push((fitted, seeds));
    }
    let (first, first_seeds) = &joints[0];
    let shifts: Vec<Vec<JointShift>> = joints[1..]
        .iter()
        .map(|(fitted, seeds)| {
            first
                .iter()
                .zip(fitted)
                .zip(first_seeds.iter().zip(seeds))
                .enumerate()
                .map(|(i, ((a, b), seed))| JointShift {
                    part: i + 1,
                    same_type: a.kind == b.kind,
                    axis_deg: axis_angle_deg(a.direction, b.direction),
                    axis_line_m: (a.kind == JointKind::Revolute)
                        .then(|| axis_line_distance(a.origin, a.direction, b.origin, b.direction)),
                    motion: motion_error(b, a),
                    seed_axis_deg: match seed {
                        (Some(a), Some(b)) => Some(axis_angle_deg(a.direction, b.direction)),
                        _ => None,
                    },
                })
                .collect()
        })
        .collect();
    let max = |f: &dyn Fn(&JointShift) -> f64| shifts.iter().flatten().map(f).fold(0.0, f64::max);
    Ok(SpreadBench {
        bench: "spread",
        adapter: ctx.adapter.clone(),
        preset: config.reconstruction.preset,
        change,
        step,
        max_axis_deg: max(&|s| s.axis_deg),
        max_axis_line_m: max(&|s| s.axis_line_m.unwrap_or(0.0)),
        max_motion: max(&|s| s.motion),
        fits,
        shifts,
        total_s: started.elapsed().as_secs_f64(),
    })
}

/// One object of `artmesh bench joints`.
#[derive(Debug, Clone, Serialize)]
pub struct MeasuredObject {
    pub id: String,
    pub seconds: f64,
    pub metrics: crate::eval::ObjectMetrics,
    /// Per movable part, its measured joint (`None`: not in both states' clouds).
    pub joints: Vec<Option<crate::articulation::geometric::GeometricJoint>>,
}

/// `artmesh bench joints` output.
#[derive(Debug, Clone, Serialize)]
pub struct MeasuredBench {
    pub bench: &'static str,
    pub suite: SuiteSource,
    pub clouds: crate::articulation::observed::CloudOptions,
    pub objects: Vec<MeasuredObject>,
    pub by_part_count: crate::eval::BenchmarkTable,
    pub total_s: f64,
}

/// The joints the suite's depth and part maps measure on their own (no reconstruction, no
/// photometry), scored against ground truth: what the fit's geometric stage starts from.
pub fn measured_joints(
    ctx: &GpuContext,
    source: &SuiteSource,
    only: &[String],
    clouds: &crate::articulation::observed::CloudOptions,
    log: &mut dyn FnMut(&MeasuredObject),
) -> Result<MeasuredBench, String> {
    use crate::articulation::geometric::fit_joint;
    use crate::articulation::observed::observe_dataset;
    use crate::data::{JointKind, Split};
    let started = Instant::now();
    let (listed, _) = source.objects()?;
    let mut objects = Vec::new();
    for object in listed {
        let id = object.id.clone();
        if !only.is_empty() && !only.iter().any(|o| id.contains(o.as_str())) {
            continue;
        }
        let dataset = source.load(ctx, &object)?;
        let start = Instant::now();
        let [s, e] = observe_dataset(&dataset, Split::Train, clouds)
            .ok_or_else(|| format!("{id}: no training views of both states"))?;
        let joints: Vec<_> = (1..dataset.num_parts)
            .map(|p| {
                let anchor = crate::articulation::geometric::Anchor::new(
                    &s.others(p, 20_000),
                    &e.others(p, 20_000),
                );
                fit_joint(&s.parts[p], &e.parts[p], Some(&anchor))
            })
            .collect();
        let all: Vec<glam::Vec3> = s.parts.iter().flat_map(|c| c.points.clone()).collect();
        let center = crate::articulation::init::principal_frame(&all)
            .map_or(glam::DVec3::ZERO, |f| f.centroid);
        let predicted: Vec<crate::data::GtJoint> = joints
            .iter()
            .map(|g| match g {
                Some(g) => g.motion(g.kind).joint(g.kind, center),
                None => {
                    crate::articulation::PartMotion::IDENTITY.joint(JointKind::Revolute, center)
                }
            })
            .collect();
        let seconds = start.elapsed().as_secs_f64();
        let gt = dataset
            .gt_joints
            .as_ref()
            .ok_or_else(|| format!("{id}: no ground-truth joints"))?;
        let metrics = crate::eval::evaluate_object(
            &id,
            &object.category,
            &predicted,
            gt,
            None,
            &crate::eval::EvalOptions::default(),
        )
        .map_err(|e| format!("{id}: {e}"))?;
        let done = MeasuredObject {
            id,
            seconds,
            metrics,
            joints,
        };
        log(&done);
        objects.push(done);
    }
    let metrics: Vec<_> = objects.iter().map(|o| o.metrics.clone()).collect();
    Ok(MeasuredBench {
        bench: "joints",
        suite: source.clone(),
        clouds: *clouds,
        by_part_count: crate::eval::BenchmarkTable::by_part_count(&metrics),
        objects,
        total_s: started.elapsed().as_secs_f64(),
    })
}
