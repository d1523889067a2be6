//! The `artmesh` command line: drives the library headless and prints what it finds.
//! Native only; in the browser the same library is driven by `web/`.

#[cfg(target_arch = "wasm32")]
fn main() {}

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    cli::main()
}

#[cfg(not(target_arch = "wasm32"))]
mod cli {
    mod capture;
    mod progress;

    use std::path::{Path, PathBuf};
    use std::process::ExitCode;

    use artmesh::data::{self, Dataset, GroundTruth, State, fixture};
    use artmesh::eval;
    use artmesh::fit::reconstruct::Progress;
    use artmesh::gpu::{GpuContext, selftest};
    use artmesh::render::RenderSpec;
    use artmesh::synth::SuiteKind;
    use clap::{Parser, Subcommand};

    /// Articulated digital twins from multi-view RGB-D frames at two articulation states.
    #[derive(Parser)]
    #[command(name = "artmesh", version, about, long_about = None)]
    struct Cli {
        #[command(subcommand)]
        command: Command,
    }

    #[derive(Subcommand)]
    enum Command {
        /// Check a dataset folder and summarise it (views per state and split, resolution,
        /// parts, depth range, ground truth), or list every problem found.
        Info {
            /// Dataset folder in the ArtGS / MPArt-90 / PARIS layout (transforms_*_{start,end}.json, ...).
            dataset: PathBuf,
            /// Print the summary as JSON.
            #[arg(long)]
            json: bool,
        },
        /// Report the GPU adapter and check the GPU primitives (prefix sum, radix sort) against the CPU.
        Gpu {
            /// Largest input size for the self-test.
            #[arg(long, default_value_t = 1_000_003)]
            max_size: u32,
            /// Print the report as JSON.
            #[arg(long)]
            json: bool,
        },
        /// Write the built-in sample dataset (a small synthetic two-state object with depth,
        /// part maps and ground truth) to a new folder.
        Sample {
            /// Folder to create; existing files are never overwritten.
            #[arg(long)]
            out: PathBuf,
            /// Image width in pixels.
            #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(8..=4096))]
            width: u32,
            /// Image height in pixels.
            #[arg(long, default_value_t = 48, value_parser = clap::value_parser!(u32).range(8..=4096))]
            height: u32,
            /// Train views per state.
            #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u16).range(1..=1000))]
            views: u16,
            /// Movable parts (revolute and prismatic alternate).
            #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=15))]
            parts: u8,
        },
        /// Score predicted joints and part meshes against ground truth with the metrics of the
        /// paper's tables (Axis Ang, Axis Pos, Part Motion, CD-s, CD-m); prints JSON. Given a suite
        /// folder (with suite.json), scores every object (PRED/<id> against GT/<id>) and adds the
        /// tables by part-count bucket and by category.
        Eval {
            /// Prediction: a folder laid out like a dataset's gt/ folder (trans.json,
            /// {start,end}/{state}_static_rotate.ply, {state}_dynamic_{i}_rotate.ply), or one that contains gt/;
            /// for a suite, a folder with one such folder per object id.
            pred: PathBuf,
            /// Ground truth: a dataset folder (its gt/ is used) or a gt/ folder; or a suite folder.
            gt: PathBuf,
            /// For a suite: print the two tables as Markdown instead of JSON.
            #[arg(long)]
            markdown: bool,
            /// State whose part meshes are compared (the paper reports the start state).
            #[arg(long, default_value = "start", value_parser = ["start", "end"])]
            state: String,
            /// Object name written in the report (default: the ground-truth folder's name).
            #[arg(long)]
            id: Option<String>,
            /// Object category written in the report.
            #[arg(long, default_value = "unknown")]
            category: String,
            /// Area-weighted surface samples per mesh for the Chamfer distances.
            #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
            samples: u32,
        },
        /// Generate a procedural object of one benchmark category and capture it as a two-state
        /// dataset (ground truth included); the object itself goes to OUT/object/ as URDF + meshes.
        Synth {
            /// Category: a name of the paper's 16 (Box, Eyeglasses, Faucet, FoldingChair, Knife, Laptop,
            /// Oven, Pen, Pliers, Refrigerator, StorageFurniture, Suitcase, Table, Toilet, TrashCan,
            /// Window), any case, or an alias (storage, fridge, chair, bin, glasses, tap).
            #[arg(long)]
            category: String,
            /// Movable parts (default: drawn from the category's range with the seed).
            #[arg(long)]
            parts: Option<usize>,
            /// Seed of the shape, the states and the cameras.
            #[arg(long, default_value_t = 0)]
            seed: u64,
            /// New folder to write.
            #[arg(long)]
            out: PathBuf,
            /// Write only the object (URDF + meshes), no dataset.
            #[arg(long)]
            object_only: bool,
            #[command(flatten)]
            capture: CaptureArgs,
        },
        /// The rasterizer's learning driver: capture a procedural object at one state and fit a
        /// jittered, grey, half-transparent copy of its surface to those views with the
        /// differentiable rasterizer, the image loss and Adam. JSON (curve, PSNR) on stdout,
        /// progress on stderr.
        Learn {
            /// Category (as for `synth`).
            #[arg(long, default_value = "box")]
            category: String,
            /// Movable parts (default: 1).
            #[arg(long, default_value_t = 1)]
            parts: usize,
            /// Seed of the object and the cameras.
            #[arg(long, default_value_t = 3)]
            seed: u64,
            /// Square image size in pixels.
            #[arg(long, default_value_t = 128)]
            size: u32,
            /// Training views.
            #[arg(long, default_value_t = 16)]
            views: usize,
            /// Optimisation steps (one view each).
            #[arg(long, default_value_t = 400)]
            iterations: u32,
            /// Longest edge of the starting mesh, in pixels.
            #[arg(long, default_value_t = 1.5)]
            edge_pixels: f32,
            /// Also write a PNG (a new file): for three views, target | starting mesh | fitted mesh.
            #[arg(long)]
            preview: Option<PathBuf>,
        },
        /// The reconstruction phase: from each state's training frames (RGB-D + part maps), fit a
        /// part-aware mesh field, remesh it per part with restricted Delaunay and recover. Writes
        /// OUT/gt/{state}/{state}_static_rotate.ply and ..._dynamic_{i}_rotate.ply (one mesh per part
        /// and state, the layout `eval` reads) and OUT/report.json (mesh quality per part, Chamfer to
        /// the dataset's ground truth when it has one, time per phase); prints the report.
        Reconstruct {
            /// Dataset folder (ArtGS / MPArt-90 / PARIS layout, with depth and semantic maps).
            dataset: PathBuf,
            /// New folder to write.
            #[arg(long)]
            out: PathBuf,
            /// Budget: tiny (tests, seconds), fast (CPU demo, minutes), paper (20k iterations at full resolution).
            #[arg(long, default_value = "fast", value_parser = ["tiny", "fast", "paper"])]
            preset: String,
            /// part-aware (the paper) or global (ablation: one restricted Delaunay over all parts;
            /// the report counts the faces that cross parts).
            #[arg(long, default_value = "part-aware", value_parser = ["part-aware", "global"])]
            remesh: String,
            /// Override the preset's optimisation iterations per state.
            #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
            iterations: Option<u32>,
            /// Override the preset's largest image side (frames are downsampled by an integer factor; 0 = full size).
            #[arg(long)]
            max_size: Option<u32>,
            /// Override the preset's views per state (0 = all).
            #[arg(long)]
            max_views: Option<usize>,
        },
        /// The main job: reconstruct both states and fit every joint (revolute or prismatic: axis,
        /// pivot, motion). Writes OUT/joints.json (type, axis origin and direction, motion, limits per
        /// movable part), OUT/gt/ (trans.json and one PLY per part and state: the layout `eval` reads)
        /// and OUT/report.json (times, bake-off losses, warnings, mesh quality, and the paper's metrics
        /// when the dataset has ground truth), and the twin: OUT/urdf/twin.urdf (+ meshes), OUT/twin.glb
        /// and OUT/twin.zip (both for download); prints the joints and metrics.
        Fit {
            /// Dataset folder (ArtGS / MPArt-90 / PARIS layout, with depth and semantic maps).
            dataset: PathBuf,
            /// New folder to write.
            #[arg(long)]
            out: PathBuf,
            /// Budget: tiny (tests, seconds), fast (CPU demo, minutes), paper (the paper's 20k + 20k iterations).
            #[arg(long, default_value = "fast", value_parser = ["tiny", "fast", "paper"])]
            preset: String,
            /// Articulation ablation: full, no-vertex-color, no-vertex-opacity or no-backward.
            #[arg(long, default_value = "full", value_parser = ["full", "no-vertex-color", "no-vertex-opacity", "no-backward"])]
            ablation: String,
            /// part-aware (the paper) or global remeshing (ablation).
            #[arg(long, default_value = "part-aware", value_parser = ["part-aware", "global"])]
            remesh: String,
            /// Override the preset's articulation steps.
            #[arg(long)]
            articulation_iterations: Option<u32>,
            /// How the joints use the dataset's full-resolution depth and part maps: settle (joints
            /// the measurements settle skip the photometric stages), seed (they seed every part's
            /// photometric stages), off (the paper's method) [default: settle; off for paper].
            #[arg(long, value_parser = ["off", "seed", "settle"])]
            geometry: Option<String>,
        },
        /// Export a fit folder (what `fit` or `demo` wrote) again: the twin's GLB (a node per part, vertex
        /// colours, a start-to-end animation, joints in extras) and/or the zip of URDF + meshes +
        /// joints.json + GLB for simulators. Reads FIT_DIR/urdf/twin.urdf and FIT_DIR/joints.json.
        Export {
            /// Folder written by `fit` (or the `fit/` folder inside a `demo` folder).
            fit_dir: PathBuf,
            /// New GLB file to write.
            #[arg(long)]
            glb: Option<PathBuf>,
            /// New zip file to write (URDF + meshes + joints.json + GLB under one folder).
            #[arg(long)]
            urdf_zip: Option<PathBuf>,
        },
        /// Zero-set-up demo: generate the built-in object (a procedural cabinet with a drawer and a
        /// door), capture it at 64x64 with 12 views per state, fit it, score it against its ground
        /// truth and write everything (dataset, fit, metrics) to a new folder.
        Demo {
            /// New folder to write [default: a fresh ./artmesh-demo, -2, -3, ...].
            #[arg(long)]
            out: Option<PathBuf>,
            /// Budget (see `fit`).
            #[arg(long, default_value = "fast", value_parser = ["tiny", "fast", "paper"])]
            preset: String,
            /// Category of the generated object (see `synth`).
            #[arg(long, default_value = "storage")]
            category: String,
            /// Movable parts.
            #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=15))]
            parts: u8,
            /// Seed of the object, its states and cameras.
            #[arg(long, default_value_t = 4)]
            seed: u64,
        },
        /// Capture a URDF object (with its meshes) as a two-state dataset with ground truth.
        Render {
            /// The URDF; relative mesh paths resolve against its folder, package:// paths against the
            /// nearest enclosing folder with a package.xml.
            urdf: PathBuf,
            /// New folder to write.
            #[arg(long)]
            out: PathBuf,
            /// Seed of the states and the cameras.
            #[arg(long, default_value_t = 0)]
            seed: u64,
            #[command(flatten)]
            capture: CaptureArgs,
        },
        /// Generate the benchmark suite: 100 procedural objects (16 categories, part-count buckets
        /// 2 / 3 / 4-5 / 6+ in the paper's proportions 34 / 20 / 31 / 15), each captured as a
        /// dataset, plus suite.json and a contact sheet.
        Suite {
            /// New folder to write.
            #[arg(long)]
            out: PathBuf,
            /// The 16-object quick suite (one per category) at 64x64 with 6 train and 2 test views
            /// per state, for CI; capture options still override.
            #[arg(long)]
            quick: bool,
            /// The 16 held-out objects of the full suite (every sixth from index 3), captured as
            /// the full suite is: the sample the method was not tuned on.
            #[arg(long, conflicts_with = "quick")]
            holdout: bool,
            #[command(flatten)]
            capture: CaptureArgs,
        },
        /// Benchmarks that print machine-readable JSON.
        Bench {
            #[command(subcommand)]
            which: Bench,
        },
    }

    /// How objects are captured (defaults: the paper's Articulate-100 setting).
    /// Which suite objects a benchmark fits, and how they are captured.
    #[derive(clap::Args)]
    struct SuiteObjects {
        /// Preset: tiny, fast or paper.
        #[arg(long, default_value = "fast", value_parser = ["tiny", "fast", "paper"])]
        preset: String,
        /// Only objects whose id contains one of these (e.g. laptop,oven); default all.
        #[arg(long, value_delimiter = ',')]
        objects: Vec<String>,
        /// Square capture size (the quick suite's is 64).
        #[arg(long, default_value_t = 64)]
        size: u32,
        /// Training views per state (the quick suite's is 6).
        #[arg(long, default_value_t = 6)]
        views: usize,
    }

    #[derive(clap::Args)]
    struct CaptureArgs {
        /// Image width in pixels [default: 800; 64 with --quick].
        #[arg(long, value_parser = clap::value_parser!(u32).range(8..=8192))]
        width: Option<u32>,
        /// Image height in pixels [default: 800; 64 with --quick].
        #[arg(long, value_parser = clap::value_parser!(u32).range(8..=8192))]
        height: Option<u32>,
        /// Train views per state [default: 100; 6 with --quick].
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000))]
        train_views: Option<u32>,
        /// Test views per state [default: 20; 2 with --quick].
        #[arg(long, value_parser = clap::value_parser!(u32).range(0..=10_000))]
        test_views: Option<u32>,
        /// Horizontal field of view in degrees.
        #[arg(long, default_value_t = 39.6)]
        fov: f32,
        /// Start state: interval of each joint's normalised range to draw from.
        #[arg(long, value_delimiter = ',', num_args = 2, default_values_t = [0.6f32, 0.8])]
        start_range: Vec<f32>,
        /// End state: interval of each joint's normalised range to draw from.
        #[arg(long, value_delimiter = ',', num_args = 2, default_values_t = [0.2f32, 0.4])]
        end_range: Vec<f32>,
        /// Cameras on the whole sphere instead of the upper hemisphere.
        #[arg(long)]
        sphere: bool,
    }

    impl CaptureArgs {
        fn spec(&self, quick: bool, seed: u64) -> RenderSpec {
            let (size, train, test) = if quick { (64, 6, 2) } else { (800, 100, 20) };
            let pair = |v: &[f32]| {
                (
                    v.first().copied().unwrap_or(0.0),
                    v.get(1).copied().unwrap_or(0.0),
                )
            };
            RenderSpec {
                width: self.width.unwrap_or(size),
                height: self.height.unwrap_or(size),
                train_views: self.train_views.map_or(train, |v| v as usize),
                test_views: self.test_views.map_or(test, |v| v as usize),
                fov_x: self.fov.to_radians(),
                start_range: pair(&self.start_range),
                end_range: pair(&self.end_range),
                upper_hemisphere: !self.sphere,
                seed,
            }
        }
    }

    #[derive(Subcommand)]
    enum Bench {
        /// Dataset capture throughput (frames/s: render, readback, PNG encoding) of a 7-part
        /// procedural cabinet.
        Capture {
            /// Square image sizes to time.
            #[arg(long, value_delimiter = ',', default_values_t = [200u32, 800])]
            sizes: Vec<u32>,
            /// Train views per state (frames = 2 x views).
            #[arg(long, default_value_t = 10)]
            views: usize,
        },
        /// Rasterizer training iterations (forward + loss + backward + Adam) on a benchmark mesh:
        /// ms per iteration, pixel-face evaluations/s, model FLOP rate against an FMA peak probe.
        Raster {
            /// Cases as SIZExFACES (square image side, target face count).
            #[arg(long, value_delimiter = ',', default_values_t = ["128x20000".to_string(), "256x100000".to_string(), "800x300000".to_string()])]
            cases: Vec<String>,
            /// Timed iterations per case (after one warm-up iteration).
            #[arg(long, default_value_t = 3)]
            repeats: usize,
        },
        /// The reconstruction phase on the quick suite's objects (captured in memory): time per
        /// phase and state, mesh quality per part (pieces, boundary/non-manifold edges, cross-part
        /// faces, Chamfer to ground truth). Progress per object on stderr.
        Reconstruct {
            #[command(flatten)]
            suite: SuiteObjects,
            /// part-aware or global remeshing.
            #[arg(long, default_value = "part-aware", value_parser = ["part-aware", "global"])]
            remesh: String,
        },
        /// The whole fit (reconstruction + articulation) over a suite, scored against ground
        /// truth: per-object metrics and wall time, the paper-style tables by part count and by
        /// category (JSON on stdout; Markdown with --markdown), and with --ablations the paper's
        /// Table 4. The objects come from a suite folder (--suite-dir, as users hand datasets
        /// over) or, for CI-sized runs, are captured in memory at --size with --views.
        Fit {
            /// A folder written by `artmesh suite`: its datasets are fitted as they are.
            #[arg(long)]
            suite_dir: Option<PathBuf>,
            /// Without --suite-dir: quick (16 objects), full (100) or holdout (16 not in quick),
            /// captured in memory at the low --size and --views.
            #[arg(long = "suite", default_value = "quick", value_parser = ["quick", "full", "holdout"])]
            which: String,
            #[command(flatten)]
            suite: SuiteObjects,
            /// Override the preset's articulation steps.
            #[arg(long)]
            articulation_iterations: Option<u32>,
            /// How the joints use the dataset's full-resolution depth and part maps: settle (joints
            /// the measurements settle skip the photometric stages), seed (they seed every part's
            /// photometric stages), off (the paper's method) [default: settle; off for paper].
            #[arg(long, value_parser = ["off", "seed", "settle"])]
            geometry: Option<String>,
            /// Add Gaussian noise of this standard deviation (mm) to every depth pixel before fitting.
            #[arg(long, default_value_t = 0.0)]
            depth_noise: f32,
            /// Drop the depth map of every N-th training view before fitting (0: none).
            #[arg(long, default_value_t = 0)]
            drop_depth_every: usize,
            /// Also run the four ablations (w/o vertex colour, w/o vertex opacity, w/o backward pass,
            /// w/o part-aware remeshing) on every object.
            #[arg(long)]
            ablations: bool,
            /// Also write the tables as Markdown to this new file.
            #[arg(long)]
            markdown: Option<PathBuf>,
        },
        /// How far rounding-level changes move a fit's joints: the dataset fitted RUNS times, fit k
        /// with the reconstruction's SSIM weight scaled by 1 + k x STEP, each fit's joints against
        /// the unchanged fit's (axis angle, axis-line distance, motion). The yardstick for comparing
        /// fits on backends that round differently (native vs browser). Progress on stderr.
        Spread {
            /// Dataset folder.
            dataset: PathBuf,
            #[arg(long, default_value = "tiny", value_parser = ["tiny", "fast", "paper"])]
            preset: String,
            /// Fits, the unchanged one included.
            #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(2..=100))]
            runs: u32,
            /// What changes between fits: `ssim` scales the reconstruction's SSIM weight by
            /// 1 + k·step (reaches meshes and joints); `view-order` keeps one reconstruction
            /// and changes the articulation's view order (its own spread).
            #[arg(long, default_value = "ssim", value_parser = ["ssim", "view-order"])]
            vary: String,
            /// Relative change of the SSIM weight per fit.
            #[arg(long, default_value_t = 1e-6)]
            step: f64,
        },
        /// The joints the suite's full-resolution depth and part maps measure on their own (no
        /// reconstruction, no photometry), scored against ground truth (JSON; a line per object on
        /// stderr): what the fit's geometric stage starts from, in seconds per object.
        Joints {
            /// A folder written by `artmesh suite`.
            #[arg(long)]
            suite_dir: PathBuf,
            /// Only objects whose id contains one of these.
            #[arg(long, value_delimiter = ',')]
            objects: Vec<String>,
        },
        /// Radix-sort throughput (keys/s) on the current adapter.
        Sort {
            /// Key counts to time.
            #[arg(long, value_delimiter = ',', default_values_t = [1_000_000u32, 4_194_304])]
            sizes: Vec<u32>,
            /// Significant key bits (passes = ceil(bits / 8)).
            #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..=32))]
            key_bits: u32,
            /// Timed runs per size (after one warm-up run).
            #[arg(long, default_value_t = 5)]
            repeats: usize,
        },
    }

    /// `println!` that treats a closed stdout (`artmesh ... | head`) as done instead of panicking.
    macro_rules! out {
        ($($arg:tt)*) => {{
            use std::io::Write as _;
            let _ = writeln!(std::io::stdout().lock(), $($arg)*);
        }};
    }

    pub fn main() -> ExitCode {
        let cli = Cli::parse();
        match run(cli.command) {
            Ok(code) => code,
            Err(message) => {
                eprintln!("artmesh: {message}");
                ExitCode::FAILURE
            }
        }
    }

    fn run(command: Command) -> Result<ExitCode, String> {
        match command {
            Command::Info { dataset, json } => info(&dataset, json),
            Command::Gpu { max_size, json } => gpu(max_size, json),
            Command::Sample {
                out,
                width,
                height,
                views,
                parts,
            } => {
                let params = fixture::FixtureParams {
                    width,
                    height,
                    train_views: views.into(),
                    test_views: usize::from(views).div_ceil(4),
                    movable_parts: parts.into(),
                    ..Default::default()
                };
                let files = fixture::small_dataset(params)
                    .to_files()
                    .map_err(|e| e.to_string())?;
                data::write_dir(&files, &out).map_err(|e| e.to_string())?;
                out!("wrote {} files to {}", files.len(), out.display());
                Ok(ExitCode::SUCCESS)
            }
            Command::Eval {
                pred,
                gt,
                markdown,
                state,
                id,
                category,
                samples,
            } => {
                let state = if state == "end" {
                    State::End
                } else {
                    State::Start
                };
                if gt.join("suite.json").is_file() {
                    return evaluate_suite(&pred, &gt, state, samples, markdown);
                }
                let id = id.unwrap_or_else(|| folder_name(&gt));
                let report = evaluate(&pred, &gt, state, &id, &category, samples)?;
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
            Command::Learn {
                category,
                parts,
                seed,
                size,
                views,
                iterations,
                edge_pixels,
                preview,
            } => {
                use artmesh::fit::photometric::{self, PhotometricConfig};
                use artmesh::fixtures::photometric::{SceneSpec, synthetic_scene};
                if let Some(path) = &preview
                    && path.exists()
                {
                    return Err(format!(
                        "{}: already exists; nothing is overwritten",
                        path.display()
                    ));
                }
                let spec = SceneSpec {
                    category: artmesh::synth::Category::parse(&category)?,
                    movable_parts: Some(parts),
                    seed,
                    size,
                    views,
                    edge_pixels,
                    ..SceneSpec::default()
                };
                let config = PhotometricConfig {
                    iterations,
                    sh_degree_every: (iterations / 4).max(1),
                    ..PhotometricConfig::default()
                };
                let ctx = context()?;
                let start = std::time::Instant::now();
                let problem = pollster::block_on(synthetic_scene(&ctx, &spec))?;
                eprintln!(
                    "learn: {category} at {size}x{size}, {views} views; starting mesh {} vertices, {} faces",
                    problem.field.num_vertices(),
                    problem.field.faces.len()
                );
                let result = pollster::block_on(photometric::fit(&ctx, &problem, &config, &mut |p| {
                    let psnr = p.psnr.map(|v| format!(", PSNR {v:.2} dB")).unwrap_or_default();
                    eprintln!(
                        "learn: {:>5}/{iterations}  loss {:.4}{psnr}  gamma {:.3}  opacity floor {:.2}  [{:.0} s]",
                        p.iteration + 1,
                        p.loss.total,
                        p.gamma,
                        p.opacity_floor,
                        start.elapsed().as_secs_f64()
                    );
                }))
                .map_err(|e| e.to_string())?;
                if let Some(path) = &preview {
                    let views = [0, views / 3, 2 * views / 3];
                    let (w, h, rgb) = pollster::block_on(photometric::preview(
                        &ctx,
                        &problem,
                        &result.field,
                        &config,
                        &views,
                    ))
                    .map_err(|e| e.to_string())?;
                    let name = path.display().to_string();
                    let png = artmesh::data::encode_png(
                        &name,
                        w,
                        h,
                        artmesh::data::PngPixels::Rgb8(&rgb),
                    )
                    .map_err(|e| e.to_string())?;
                    std::fs::write(path, png).map_err(|e| format!("{name}: {e}"))?;
                    eprintln!("learn: preview (target | start | fitted) in {name}");
                }
                let report = serde_json::json!({
                    "category": spec.category.name(),
                    "size": size,
                    "views": views,
                    "vertices": problem.field.num_vertices(),
                    "faces": problem.field.faces.len(),
                    "config": config,
                    "psnr_start": result.psnr_start,
                    "psnr_end": result.psnr_end,
                    "seconds": start.elapsed().as_secs_f64(),
                    "curve": result.curve,
                });
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
            Command::Fit {
                dataset: root,
                out,
                preset,
                ablation,
                remesh,
                articulation_iterations,
                geometry,
            } => {
                let mut config = fit_config(&preset)?;
                config.reconstruction = reconstruction_config(&preset, &remesh)?;
                config.articulation.ablation =
                    artmesh::fit::articulate::Ablation::parse(&ablation)?;
                if let Some(n) = articulation_iterations {
                    config.articulation.iterations = n;
                }
                if let Some(g) = geometry {
                    config.articulation.geometry =
                        artmesh::fit::articulate::GeometryUse::parse(&g)?;
                }
                capture::fresh_folder(&out)?;
                let dataset = data::read_dataset(&root)?;
                let id = root
                    .file_name()
                    .map_or("object".into(), |n| n.to_string_lossy().into_owned());
                let report = fit_and_write(&dataset, &config, &out, &id, "unknown")?;
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
            Command::Export {
                fit_dir,
                glb,
                urdf_zip,
            } => {
                if glb.is_none() && urdf_zip.is_none() {
                    return Err(
                        "export: say what to write: --glb FILE and/or --urdf-zip FILE".into(),
                    );
                }
                for path in glb.iter().chain(&urdf_zip) {
                    capture::fresh_file(path)?;
                }
                let files = data::read_dir(&fit_dir).map_err(|e| e.to_string())?;
                let shown = |rel: &str| fit_dir.join(rel).display().to_string();
                let urdf = artmesh::export::URDF_FILE;
                if !files.contains_key(urdf) {
                    return Err(format!(
                        "{}: missing; expected a folder written by `artmesh fit` (or a demo's fit/ folder)",
                        shown(urdf)
                    ));
                }
                let object = artmesh::object::ArticulatedObject::from_urdf(urdf, &files)
                    .map_err(|e| format!("{}: {e}", fit_dir.display()))?;
                let joints_file = artmesh::export::JOINTS_FILE;
                let joints = files.get(joints_file).ok_or_else(|| {
                    format!(
                        "{}: missing (the joints' end-state motions)",
                        shown(joints_file)
                    )
                })?;
                let end = artmesh::export::end_configuration(&object, joints, &shown(joints_file))
                    .map_err(|e| e.to_string())?;
                let exports = artmesh::export::export_twin(&object, &end, joints)
                    .map_err(|e| e.to_string())?;
                for (path, bytes) in [(&glb, &exports.glb), (&urdf_zip, &exports.zip)] {
                    if let Some(path) = path {
                        std::fs::write(path, bytes)
                            .map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
                        eprintln!("export: wrote {} ({} bytes)", path.display(), bytes.len());
                    }
                }
                Ok(ExitCode::SUCCESS)
            }
            Command::Demo {
                out,
                preset,
                category,
                parts,
                seed,
            } => {
                let out = match out {
                    Some(out) => {
                        capture::fresh_folder(&out)?;
                        out
                    }
                    None => (1..)
                        .map(|i| {
                            PathBuf::from(if i == 1 {
                                "artmesh-demo".to_string()
                            } else {
                                format!("artmesh-demo-{i}")
                            })
                        })
                        .find(|p| !p.exists())
                        .expect("some folder name is free"),
                };
                let category = artmesh::synth::Category::parse(&category)?;
                let object = artmesh::synth::generate(&artmesh::synth::SynthParams {
                    category,
                    movable_parts: Some(usize::from(parts)),
                    seed,
                })?;
                let config = fit_config(&preset)?;
                // Captured as a user's dataset would be: the fit reads its working size, and
                // its joints come from the full-resolution depth and part maps (at 64² those
                // are too coarse: the demo cabinet's axes came out 20.9° off) and are judged
                // on the test views.
                let mut spec = config.demo_capture(seed);
                spec.width = (4 * spec.width).min(512);
                spec.height = spec.width;
                spec.test_views = 4;
                let (size, views) = (spec.width, spec.train_views);
                let ctx = context()?;
                eprintln!(
                    "demo: {} ({} movable parts) captured at {size}x{size}, {views} views per state",
                    object.name, parts
                );
                let dataset = pollster::block_on(artmesh::render::capture_dataset(
                    &ctx,
                    &object,
                    &spec,
                    &mut |_| {},
                ))
                .map_err(|e| format!("{}: {e}", object.name))?;
                let files = dataset.to_files().map_err(|e| e.to_string())?;
                data::write_dir(&files, &out.join("dataset")).map_err(|e| e.to_string())?;
                let report = fit_and_write(
                    &dataset,
                    &config,
                    &out.join("fit"),
                    &object.name,
                    category.name(),
                )?;
                out!("{}", to_json(&report)?);
                eprintln!(
                    "demo: dataset in {0}/dataset, fit in {0}/fit",
                    out.display()
                );
                Ok(ExitCode::SUCCESS)
            }
            Command::Reconstruct {
                dataset,
                out,
                preset,
                remesh,
                iterations,
                max_size,
                max_views,
            } => {
                let mut config = reconstruction_config(&preset, &remesh)?;
                if let Some(n) = iterations {
                    config.fit.iterations = n;
                }
                config.max_size = max_size.unwrap_or(config.max_size);
                config.max_views = max_views.unwrap_or(config.max_views);
                capture::fresh_folder(&out)?;
                let report = reconstruct(&dataset, &out, &config)?;
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
            Command::Synth {
                category,
                parts,
                seed,
                out,
                object_only,
                capture,
            } => {
                let category = artmesh::synth::Category::parse(&category)?;
                let params = artmesh::synth::SynthParams {
                    category,
                    movable_parts: parts,
                    seed,
                };
                let object = artmesh::synth::generate(&params)?;
                capture::fresh_folder(&out)?;
                capture::write_object(&object, &out.join("object"))?;
                if !object_only {
                    let ctx = context()?;
                    capture::dataset(&ctx, &object, &capture.spec(false, seed), &out)?;
                }
                out!("wrote {} to {}", object.name, out.display());
                Ok(ExitCode::SUCCESS)
            }
            Command::Render {
                urdf,
                out,
                seed,
                capture,
            } => {
                let object = capture::read_urdf(&urdf)?;
                capture::fresh_folder(&out)?;
                let ctx = context()?;
                capture::dataset(&ctx, &object, &capture.spec(false, seed), &out)?;
                out!("wrote {} to {}", object.name, out.display());
                Ok(ExitCode::SUCCESS)
            }
            Command::Suite {
                out,
                quick,
                holdout,
                capture,
            } => {
                let kind = match (quick, holdout) {
                    (true, _) => SuiteKind::Quick,
                    (_, true) => SuiteKind::Holdout,
                    _ => SuiteKind::Full,
                };
                let ctx = context()?;
                capture::suite(&ctx, &out, kind, &capture)?;
                Ok(ExitCode::SUCCESS)
            }
            Command::Bench {
                which: Bench::Joints { suite_dir, objects },
            } => {
                let ctx = context()?;
                let source = artmesh::bench::SuiteSource::Dir(suite_dir);
                let clouds = artmesh::articulation::observed::CloudOptions::default();
                let report = artmesh::bench::measured_joints(
                    &ctx,
                    &source,
                    &objects,
                    &clouds,
                    &mut |o| {
                        let m = &o.metrics;
                        let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
                        let per: Vec<String> = m
                            .joints
                            .iter()
                            .map(|j| format!("{:.2}", j.axis_ang))
                            .collect();
                        eprintln!(
                            "bench joints: {} {:.1} s  axis ang {} [{}]  axis pos {}  motion {}  types {}",
                            o.id,
                            o.seconds,
                            f(m.axis_ang),
                            per.join(" "),
                            f(m.axis_pos),
                            f(m.part_motion),
                            f(m.type_accuracy)
                        );
                    },
                )?;
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
            Command::Bench {
                which:
                    Bench::Fit {
                        suite_dir,
                        which,
                        suite:
                            SuiteObjects {
                                preset,
                                objects,
                                size,
                                views,
                            },
                        articulation_iterations,
                        geometry,
                        depth_noise,
                        drop_depth_every,
                        ablations,
                        markdown,
                    },
            } => {
                if !(0.0..=1000.0).contains(&depth_noise) {
                    return Err(format!(
                        "--depth-noise: expected a standard deviation from 0 to 1000 mm, found {depth_noise}"
                    ));
                }
                let mut config = fit_config(&preset)?;
                if let Some(n) = articulation_iterations {
                    config.articulation.iterations = n;
                }
                if let Some(g) = geometry {
                    config.articulation.geometry =
                        artmesh::fit::articulate::GeometryUse::parse(&g)?;
                }
                if let Some(path) = &markdown {
                    capture::fresh_file(path)?;
                }
                let ctx = context()?;
                let source = match suite_dir {
                    Some(dir) => artmesh::bench::SuiteSource::Dir(dir),
                    None => artmesh::bench::SuiteSource::Capture {
                        kind: SuiteKind::parse(&which).unwrap_or(SuiteKind::Quick),
                        size,
                        views,
                    },
                };
                let report = artmesh::bench::fit(
                    &ctx,
                    &config,
                    &source,
                    &objects,
                    &artmesh::bench::DepthDegradation {
                        noise_mm: depth_noise,
                        drop_every: drop_depth_every,
                    },
                    ablations,
                    &mut |o| {
                        let m = &o.metrics;
                        let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
                        eprintln!(
                            "bench fit: {} ({} parts) {:.0} s  axis ang {}  axis pos {}  motion {}  CD-s {}  CD-m {}  types {}",
                            o.id,
                            o.parts,
                            o.seconds,
                            f(m.axis_ang),
                            f(m.axis_pos),
                            f(m.part_motion),
                            f(m.cd_s.map(|c| c.cd_peer)),
                            f(m.cd_m.map(|c| c.cd_peer)),
                            f(m.type_accuracy)
                        );
                        for w in &o.warnings {
                            eprintln!("bench fit:   warning: {w}");
                        }
                    },
                )?;
                let md = report.to_markdown();
                eprintln!("{md}");
                if let Some(path) = &markdown {
                    std::fs::write(path, md).map_err(|e| format!("{}: {e}", path.display()))?;
                }
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
            Command::Bench {
                which:
                    Bench::Spread {
                        dataset: root,
                        preset,
                        runs,
                        vary,
                        step,
                    },
            } => {
                let config = fit_config(&preset)?;
                let change = artmesh::bench::SpreadChange::parse(&vary)?;
                let dataset = data::read_dataset(&root)?;
                let ctx = context()?;
                let report = artmesh::bench::spread(
                    &ctx,
                    &dataset,
                    &config,
                    change,
                    runs as usize,
                    step,
                    &mut |r| {
                        // Per joint against GT: axis angle (°) / Part Motion, fit then seed.
                        let errors = |e: &Option<Vec<artmesh::eval::joints::JointPairMetrics>>| {
                            e.as_ref().map_or("-".to_string(), |pairs| {
                                let each = pairs
                                    .iter()
                                    .map(|p| format!("{:.3}/{:.3}", p.axis_ang, p.part_motion));
                                each.collect::<Vec<_>>().join(" ")
                            })
                        };
                        eprintln!(
                            "bench spread: SSIM weight x {:.7}, articulation seed {}: {:.1} s, PSNR {:?}, remeshed faces {:?}, axes {:?}, GT error (axis/motion) {} (seeds {})",
                            r.ssim_factor,
                            r.articulation_seed,
                            r.seconds,
                            r.psnr_optimised,
                            r.remeshed_faces,
                            r.joints.iter().map(|j| j.direction).collect::<Vec<_>>(),
                            errors(&r.gt_errors),
                            errors(&r.seed_gt_errors),
                        );
                    },
                )?;
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
            Command::Bench {
                which: Bench::Capture { sizes, views },
            } => {
                let ctx = context()?;
                let report = artmesh::bench::capture(&ctx, &sizes, views)?;
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
            Command::Bench {
                which: Bench::Raster { cases, repeats },
            } => {
                let cases = cases
                    .iter()
                    .map(|c| {
                        let parsed = c.split_once('x').and_then(|(s, f)| {
                            Some((s.parse::<u32>().ok()?, f.parse::<usize>().ok()?))
                        });
                        match parsed {
                            Some((size, faces)) if size > 0 && faces > 0 => Ok((size, faces)),
                            _ => Err(format!(
                                "--cases: expected SIZExFACES such as 128x20000, found '{c}'"
                            )),
                        }
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                let ctx = context()?;
                let report = artmesh::bench::raster(&ctx, &cases, repeats.max(1))
                    .map_err(|e| e.to_string())?;
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
            Command::Bench {
                which:
                    Bench::Reconstruct {
                        suite:
                            SuiteObjects {
                                preset,
                                objects,
                                size,
                                views,
                            },
                        remesh,
                    },
            } => {
                let config = reconstruction_config(&preset, &remesh)?;
                let ctx = context()?;
                let report =
                    artmesh::bench::reconstruct(&ctx, &config, &objects, size, views, &mut |o| {
                        let parts: Vec<String> = o
                            .report
                            .states
                            .iter()
                            .map(|s| {
                                let pieces: Vec<String> = s
                                    .parts
                                    .iter()
                                    .map(|p| {
                                        format!(
                                            "{}:{}f/{}c/cd {:.1}mm",
                                            p.part,
                                            p.faces,
                                            p.components,
                                            p.chamfer.map_or(f64::NAN, |c| c.cd_mm)
                                        )
                                    })
                                    .collect();
                                format!(
                                    "{} {:.1} dB cross {} [{}]",
                                    s.state.name(),
                                    s.psnr_recovered,
                                    s.cross_part_faces,
                                    pieces.join(" ")
                                )
                            })
                            .collect();
                        eprintln!(
                            "bench reconstruct: {} ({} parts) {:.1} s  {}",
                            o.id,
                            o.parts,
                            o.seconds,
                            parts.join("  ")
                        );
                    })?;
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
            Command::Bench {
                which:
                    Bench::Sort {
                        sizes,
                        key_bits,
                        repeats,
                    },
            } => {
                let ctx = context()?;
                let report = artmesh::bench::sort(&ctx, &sizes, key_bits, repeats)
                    .map_err(|e| e.to_string())?;
                out!("{}", to_json(&report)?);
                Ok(ExitCode::SUCCESS)
            }
        }
    }

    /// Fits `dataset` with a progress bar on stderr, writes joints.json, gt/ and report.json
    /// under `out` (a fresh folder), prints the joints and metrics, and returns the report.
    fn fit_and_write(
        dataset: &Dataset,
        config: &artmesh::fit::object::FitConfig,
        out: &Path,
        id: &str,
        category: &str,
    ) -> Result<serde_json::Value, String> {
        let ctx = context()?;
        let start = std::time::Instant::now();
        let mut bar = progress::Bar::new("fit");
        let fit = pollster::block_on(artmesh::fit::object::fit_object(
            &ctx,
            dataset,
            config,
            &mut |p: &Progress| bar.show(p),
        ))
        .map_err(|e| format!("{id}: {e}"))?;
        bar.finish();
        let seconds = start.elapsed().as_secs_f64();
        let folder =
            artmesh::export::FitFolder::build(&fit, dataset, config, id, category, seconds)?;
        let (joints, metrics) = (&folder.joints, &folder.metrics);
        for w in &fit.articulation.warnings {
            eprintln!("fit: warning: {w}");
        }
        for j in joints {
            let unit = if j.kind == data::JointKind::Revolute {
                "°"
            } else {
                " m"
            };
            let registered = match j.axis_registration {
                Some(r) if r.applied => {
                    format!(", registered along the axis from {:.3}{unit}", r.fitted)
                }
                _ => String::new(),
            };
            eprintln!(
                "fit: part {}: {:?} joint, axis {:.3?} through {:.3?}, motion {:.3}{unit}{registered} (bake-off losses {:.4?})",
                j.part, j.kind, j.direction, j.origin, j.motion, j.bake_off
            );
        }
        if let Some(m) = metrics {
            let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
            eprintln!(
                "fit: against the ground truth: Axis Ang {} °, Axis Pos {} (0.1 m), Part Motion {}, CD-s {} ({} mm), CD-m {} ({} mm), joint types {}/{} right",
                f(m.axis_ang),
                f(m.axis_pos),
                f(m.part_motion),
                f(m.cd_s.map(|c| c.cd_peer)),
                f(m.cd_s.map(|c| c.cd_mm)),
                f(m.cd_m.map(|c| c.cd_peer)),
                f(m.cd_m.map(|c| c.cd_mm)),
                m.joints.len() - m.type_errors,
                m.joints.len() + m.unmatched_gt.len()
            );
        }
        let meshes = folder.files.keys().filter(|p| p.ends_with(".ply")).count();
        data::write_dir(&folder.files, out).map_err(|e| e.to_string())?;
        eprintln!(
            "fit: {seconds:.0} s; wrote joints.json, report.json, gt/ ({meshes} part meshes), the twin as {} \
             (+ meshes), {} and {} (all of it for download) to {}",
            artmesh::export::URDF_FILE,
            artmesh::export::GLB_FILE,
            artmesh::export::ZIP_FILE,
            out.display()
        );
        Ok(folder.report)
    }

    /// Both phases' settings of the named preset.
    fn fit_config(preset: &str) -> Result<artmesh::fit::object::FitConfig, String> {
        use artmesh::fit::reconstruct::Preset;
        Ok(artmesh::fit::object::FitConfig::preset(Preset::parse(
            preset,
        )?))
    }

    /// The named preset with the named remeshing mode (`part-aware` or `global`).
    fn reconstruction_config(
        preset: &str,
        remesh: &str,
    ) -> Result<artmesh::fit::reconstruct::ReconstructionConfig, String> {
        use artmesh::fit::reconstruct::{Preset, ReconstructionConfig, RemeshMode};
        let mut config = ReconstructionConfig::preset(Preset::parse(preset)?);
        if remesh == "global" {
            config.remesh = RemeshMode::Global;
        }
        Ok(config)
    }

    /// Loads `root`, reconstructs it with `config` (a progress bar on stderr), writes the part
    /// meshes and report.json under `out` and returns the report.
    fn reconstruct(
        root: &Path,
        out: &Path,
        config: &artmesh::fit::reconstruct::ReconstructionConfig,
    ) -> Result<eval::ReconstructionReport, String> {
        let dataset = data::read_dataset(root)?;
        let ctx = context()?;
        let mut bar = progress::Bar::new("reconstruct");
        let reconstruction = pollster::block_on(artmesh::fit::reconstruct::reconstruct(
            &ctx,
            &dataset,
            config,
            &mut |p: &Progress| bar.show(p),
        ))
        .map_err(|e| format!("{}: {e}", root.display()))?;
        bar.finish();
        let report = eval::reconstruction_report(
            &reconstruction,
            &dataset.gt_meshes,
            &eval::ChamferOptions::default(),
        );
        let mut files = reconstruction.as_ground_truth().to_files();
        files.insert("report.json".into(), to_json(&report)?.into_bytes());
        data::write_dir(&files, out).map_err(|e| e.to_string())?;
        for s in &report.states {
            eprintln!(
                "reconstruct: {} state: PSNR {:.2} dB (optimised {:.2}, remeshed {:.2}), {} cross-part faces, {:.0} s",
                s.state.name(),
                s.psnr_recovered,
                s.psnr_optimised,
                s.psnr_remeshed,
                s.cross_part_faces,
                s.times.total_s
            );
            for p in &s.parts {
                let gt = p
                    .gt_components
                    .map(|n| format!(" (ground truth {n})"))
                    .unwrap_or_default();
                let cd = p
                    .chamfer
                    .map(|c| format!(", Chamfer {:.1} mm / {:.3} peer", c.cd_mm, c.cd_peer))
                    .unwrap_or_default();
                eprintln!(
                    "reconstruct:   part {}: {} faces, {} piece(s){gt}, {} boundary / {} non-manifold edges{cd}",
                    p.part, p.faces, p.components, p.boundary_edges, p.non_manifold_edges
                );
            }
        }
        eprintln!(
            "reconstruct: wrote {} files to {}",
            files.len(),
            out.display()
        );
        Ok(report)
    }

    fn info(root: &std::path::Path, json: bool) -> Result<ExitCode, String> {
        let files = data::read_dir(root).map_err(|e| e.to_string())?;
        match Dataset::from_files(&files) {
            Ok(dataset) => {
                let summary = dataset.summary();
                if json {
                    out!("{}", to_json(&summary)?);
                } else {
                    out!("{}\n{summary}", root.display());
                }
                Ok(ExitCode::SUCCESS)
            }
            Err(problems) => {
                eprintln!("{}: {} problem(s) found:", root.display(), problems.0.len());
                eprintln!("{problems}");
                Ok(ExitCode::FAILURE)
            }
        }
    }

    /// Reads a gt/-style folder (or a folder containing gt/) as [`GroundTruth`].
    fn read_ground_truth(root: &Path) -> Result<GroundTruth, String> {
        let files = data::read_dir(root).map_err(|e| e.to_string())?;
        let files = if files.keys().any(|k| k.starts_with("gt/")) {
            files
        } else {
            files
                .into_iter()
                .map(|(k, v)| (format!("gt/{k}"), v))
                .collect()
        };
        GroundTruth::from_files(&files).map_err(|e| format!("{}:\n{e}", root.display()))
    }

    fn evaluate(
        pred: &Path,
        gt: &Path,
        state: State,
        id: &str,
        category: &str,
        samples: u32,
    ) -> Result<eval::ObjectMetrics, String> {
        let (pred, gt_data) = (read_ground_truth(pred)?, read_ground_truth(gt)?);
        let (Some(pred_joints), Some(gt_joints)) = (&pred.joints, &gt_data.joints) else {
            return Err("both the prediction and the ground truth need joints (trans.json)".into());
        };
        let meshes = match (&pred.meshes[state.index()], &gt_data.meshes[state.index()]) {
            (Some(p), Some(g)) => Some((p, g)),
            _ => {
                eprintln!("artmesh: no {state} part meshes on both sides: joint metrics only");
                None
            }
        };
        let options = eval::EvalOptions {
            chamfer: eval::ChamferOptions {
                samples: samples as usize,
                ..Default::default()
            },
        };
        eval::evaluate_object(id, category, pred_joints, gt_joints, meshes, &options)
            .map_err(|e| e.to_string())
    }

    /// Scores every object of a suite and prints the per-object reports and both benchmark tables.
    fn evaluate_suite(
        pred: &Path,
        gt: &Path,
        state: State,
        samples: u32,
        markdown: bool,
    ) -> Result<ExitCode, String> {
        let listing = artmesh::bench::read_suite_listing(gt)?;
        let mut reports = Vec::with_capacity(listing.objects.len());
        for (id, category) in &listing.objects {
            let report = evaluate(&pred.join(id), &gt.join(id), state, id, category, samples)
                .map_err(|e| format!("{id}: {e}"))?;
            reports.push(report);
        }
        let by_parts = eval::BenchmarkTable::by_part_count(&reports);
        let by_category = eval::BenchmarkTable::by_category(&reports);
        if markdown {
            out!(
                "By part count (the paper's Table 1)\n\n{}",
                by_parts.to_markdown()
            );
            out!(
                "By category (the paper's appendix table)\n\n{}",
                by_category.to_markdown()
            );
        } else {
            let json = serde_json::json!({
                "objects": reports,
                "by_part_count": by_parts,
                "by_category": by_category,
            });
            out!("{}", to_json(&json)?);
        }
        Ok(ExitCode::SUCCESS)
    }

    fn folder_name(path: &Path) -> String {
        path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    }

    fn gpu(max_size: u32, json: bool) -> Result<ExitCode, String> {
        let ctx = context()?;
        let sizes: Vec<u32> = selftest::DEFAULT_SIZES
            .iter()
            .copied()
            .filter(|&n| n <= max_size)
            .collect();
        let report = pollster::block_on(selftest::run(&ctx, &sizes)).map_err(|e| e.to_string())?;
        if json {
            out!("{}", to_json(&report)?);
        } else {
            let a = &report.adapter;
            out!(
                "adapter: {} ({}, {}, driver {})",
                a.name,
                a.backend,
                a.device_type,
                a.driver
            );
            out!(
                "limits: storage binding {} MiB, {} workgroups per dimension",
                a.max_storage_buffer_binding_size >> 20,
                a.max_compute_workgroups_per_dimension
            );
            for c in &report.checks {
                let verdict = if c.passed() { "ok" } else { "MISMATCH" };
                let bits = if c.key_bits > 0 {
                    format!("{}-bit keys", c.key_bits)
                } else {
                    String::new()
                };
                out!("{:>10}  n = {:<9} {bits:<12} {verdict}", c.kernel, c.n);
            }
        }
        Ok(if report.passed() {
            ExitCode::SUCCESS
        } else {
            ExitCode::FAILURE
        })
    }

    fn context() -> Result<GpuContext, String> {
        pollster::block_on(GpuContext::new()).map_err(|e| e.to_string())
    }

    fn to_json<T: serde::Serialize>(value: &T) -> Result<String, String> {
        serde_json::to_string_pretty(value).map_err(|e| e.to_string())
    }
}
