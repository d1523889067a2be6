//! `artmesh suite`: the benchmark suite written as a folder (one dataset per object, suite.json,
//! a contact sheet), and the reader of its suite.json that `eval` and the benchmarks share.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use artmesh::data::{self, FileSet, PngPixels, SensorModel, encode_png};
use artmesh::gpu::GpuContext;
use artmesh::render::{SheetEntry, contact_sheet};
use artmesh::synth::{SuiteEntry, SuiteKind, generate};
use serde::Serialize;

use crate::args::{CaptureArgs, context};
use crate::capture::{dataset, write_object};
use crate::output::NewFolder;

/// `artmesh suite`'s arguments.
#[derive(clap::Args)]
pub struct SuiteArgs {
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
}

/// `artmesh suite`: the full, quick or held-out suite.
pub fn run(args: &SuiteArgs) -> Result<ExitCode, String> {
    let kind = match (args.quick, args.holdout) {
        (true, _) => SuiteKind::Quick,
        (_, true) => SuiteKind::Holdout,
        _ => SuiteKind::Full,
    };
    let folder = NewFolder::create(&args.out)?;
    let ctx = context()?;
    suite(&ctx, folder.path(), kind, &args.capture)?;
    let out = folder.finish()?;
    eprintln!("suite: in {}", out.display());
    Ok(ExitCode::SUCCESS)
}

/// The suite manifest: what was generated and how it was captured.
#[derive(Serialize)]
struct SuiteManifest<'a> {
    suite: &'static str,
    generator: String,
    capture: CaptureJson,
    objects: Vec<ManifestEntry<'a>>,
}

#[derive(Serialize)]
struct CaptureJson {
    width: u32,
    height: u32,
    train_views: usize,
    test_views: usize,
    fov_x: f32,
    start_range: (f32, f32),
    end_range: (f32, f32),
    upper_hemisphere: bool,
    sensor: SensorModel,
}

#[derive(Serialize)]
struct ManifestEntry<'a> {
    id: String,
    #[serde(flatten)]
    entry: &'a SuiteEntry,
    name: String,
    parts: usize,
}

/// Every planned object into `out/<id>/` (dataset + `object/`), then `suite.json` and
/// `contact-sheet.png`; `out` is a new folder.
fn suite(
    ctx: &GpuContext,
    out: &Path,
    kind: SuiteKind,
    capture: &CaptureArgs,
) -> Result<(), String> {
    let quick = kind == SuiteKind::Quick;
    let plan = kind.plan();
    let mut objects = Vec::with_capacity(plan.len());
    let mut manifest = Vec::with_capacity(plan.len());
    let spec0 = capture.spec(quick, 0);
    for entry in &plan {
        let object = generate(&entry.params()).map_err(|e| format!("{}: {e}", entry.id()))?;
        let folder = out.join(entry.id());
        write_object(&object, &folder.join("object"))?;
        let rendered = dataset(ctx, &object, &capture.spec(quick, entry.seed), &folder)?;
        eprintln!(
            "[{}/{}] {} ({} parts, {} frames)",
            manifest.len() + 1,
            plan.len(),
            entry.id(),
            rendered.num_parts,
            rendered.frames
        );
        manifest.push(ManifestEntry {
            id: entry.id(),
            entry,
            name: object.name.clone(),
            parts: rendered.num_parts,
        });
        objects.push((object, rendered.truth.states));
    }
    let json = SuiteManifest {
        suite: kind.name(),
        generator: format!("artmesh {}", env!("CARGO_PKG_VERSION")),
        capture: CaptureJson {
            width: spec0.width,
            height: spec0.height,
            train_views: spec0.train_views,
            test_views: spec0.test_views,
            fov_x: spec0.fov_x,
            start_range: spec0.start_range,
            end_range: spec0.end_range,
            upper_hemisphere: spec0.upper_hemisphere,
            sensor: spec0.sensor,
        },
        objects: manifest,
    };
    let mut files = FileSet::new();
    let text = serde_json::to_vec_pretty(&json).map_err(|e| e.to_string())?;
    files.insert("suite.json".into(), text);
    let entries: Vec<SheetEntry> = objects
        .iter()
        .map(|(object, states)| SheetEntry {
            object,
            states: states.clone(),
        })
        .collect();
    let sheet =
        pollster::block_on(contact_sheet(ctx, &entries, 128, 8)).map_err(|e| e.to_string())?;
    let png = encode_png(
        "contact-sheet.png",
        sheet.width,
        sheet.height,
        PngPixels::Rgba8(&sheet.pixels),
    )
    .map_err(|e| e.to_string())?;
    files.insert("contact-sheet.png".into(), png);
    data::write_dir(&files, out).map_err(|e| e.to_string())?;
    eprintln!(
        "wrote {} objects, suite.json and contact-sheet.png to {}",
        plan.len(),
        out.display()
    );
    Ok(())
}

/// How suite objects were captured (the size and training views a benchmark reports).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct CaptureSettings {
    pub size: u32,
    pub train_views: usize,
    /// The sensor model the frames were degraded with (suites written before it: ideal).
    pub sensor: SensorModel,
}

/// What a suite folder's `suite.json` (written by `artmesh suite`) lists: each object's id (its
/// folder) and category, and how the suite was captured when it says.
pub struct SuiteListing {
    pub objects: Vec<(String, String)>,
    pub capture: Option<CaptureSettings>,
}

/// Reads `dir/suite.json`.
pub fn read_suite_listing(dir: &Path) -> Result<SuiteListing, String> {
    #[derive(serde::Deserialize)]
    struct Manifest {
        objects: Vec<Entry>,
        capture: Option<Capture>,
    }
    #[derive(serde::Deserialize)]
    struct Capture {
        width: u32,
        train_views: usize,
        #[serde(default)]
        sensor: SensorModel,
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
    // An id names a folder inside the suite: never an absolute path, `..` or a nested path.
    for (i, o) in manifest.objects.iter().enumerate() {
        let mut parts = Path::new(&o.id).components();
        let plain = matches!(
            (parts.next(), parts.next()),
            (Some(std::path::Component::Normal(_)), None)
        );
        if !plain || o.id.contains('\\') {
            return Err(format!(
                "{}: objects[{i}].id {:?} is not a folder name inside the suite (no '/', '\\' or '..')",
                path.display(),
                o.id.chars().take(80).collect::<String>()
            ));
        }
    }
    Ok(SuiteListing {
        objects: manifest
            .objects
            .into_iter()
            .map(|o| (o.id, o.category))
            .collect(),
        capture: manifest.capture.map(|c| CaptureSettings {
            size: c.width,
            train_views: c.train_views,
            sensor: c.sensor,
        }),
    })
}
