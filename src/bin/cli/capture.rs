//! `artmesh synth`, `render` and `suite`: objects in, two-state datasets out, written as they are rendered.

use std::io::{IsTerminal, Write as _};
use std::path::{Path, PathBuf};

use artmesh::data::{self, FileSet, PngPixels, encode_png};
use artmesh::export::write_urdf;
use artmesh::gpu::GpuContext;
use artmesh::object::ArticulatedObject;
use artmesh::render::{
    RenderProgress, RenderSpec, RenderedDataset, SheetEntry, contact_sheet, render_dataset,
};
use artmesh::synth::{SuiteEntry, SuiteKind, generate};

use super::CaptureArgs;

/// Refuses an existing non-empty folder: generated files never mix with (or overwrite) the user's.
pub fn fresh_folder(out: &Path) -> Result<(), String> {
    match std::fs::read_dir(out).map(|mut entries| entries.next().is_some()) {
        Ok(true) => Err(format!(
            "{} already exists and is not empty; choose a new folder",
            out.display()
        )),
        Ok(false) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(format!("{}: {e}", out.display())),
    }
}

/// Refuses an existing file: outputs never overwrite the user's files.
pub fn fresh_file(path: &Path) -> Result<(), String> {
    if path.exists() {
        return Err(format!(
            "{} already exists; choose a new file",
            path.display()
        ));
    }
    Ok(())
}

/// Writes `object` as `<name>.urdf` + `meshes/` below `folder`.
pub fn write_object(object: &ArticulatedObject, folder: &Path) -> Result<(), String> {
    let files = write_urdf(object, &format!("{}.urdf", object.name)).map_err(|e| e.to_string())?;
    data::write_dir(&files, folder).map_err(|e| format!("{}: {e}", folder.display()))
}

/// Imports a URDF, reading the nearest enclosing folder with a `package.xml` (for `package://` paths), or the
/// URDF's own folder.
pub fn read_urdf(urdf: &Path) -> Result<ArticulatedObject, String> {
    if !urdf.is_file() {
        return Err(format!("{}: no such file", urdf.display()));
    }
    let folder = urdf
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let root: PathBuf = folder
        .ancestors()
        .take(4)
        .find(|a| a.join("package.xml").is_file())
        .unwrap_or(folder)
        .to_path_buf();
    let files = data::read_dir(&root).map_err(|e| format!("{}: {e}", root.display()))?;
    let key = urdf
        .strip_prefix(&root)
        .map_err(|_| format!("{} is not inside {}", urdf.display(), root.display()))?
        .to_string_lossy()
        .replace('\\', "/");
    let object = ArticulatedObject::from_urdf(&key, &files)
        .map_err(|e| format!("{}: {e}", root.display()))?;
    for w in &object.warnings {
        eprintln!("artmesh: warning: {w}");
    }
    Ok(object)
}

/// Renders `object`'s dataset into `out`, file by file, reporting progress on stderr.
pub fn dataset(
    ctx: &GpuContext,
    object: &ArticulatedObject,
    spec: &RenderSpec,
    out: &Path,
) -> Result<RenderedDataset, String> {
    let mut sink = |files: FileSet| data::write_dir(&files, out);
    let mut progress = progress_printer(&object.name);
    let result = pollster::block_on(render_dataset(ctx, object, spec, &mut sink, &mut progress))
        .map_err(|e| format!("{}: {e}", object.name))?;
    Ok(result)
}

/// A progress callback: an updating line on a terminal, a line per 25 % otherwise (logs stay short).
fn progress_printer(name: &str) -> impl FnMut(RenderProgress) + '_ {
    let terminal = std::io::stderr().is_terminal();
    let mut last_quarter = 0;
    move |p: RenderProgress| {
        let mut err = std::io::stderr().lock();
        if terminal {
            let _ = write!(err, "\r{name}: rendered {}/{} frames", p.done, p.total);
            if p.done == p.total {
                let _ = writeln!(err);
            }
        } else {
            let quarter = 4 * p.done / p.total.max(1);
            if quarter > last_quarter {
                last_quarter = quarter;
                let _ = writeln!(err, "{name}: rendered {}/{} frames", p.done, p.total);
            }
        }
    }
}

/// The suite manifest: what was generated and how it was captured.
#[derive(serde::Serialize)]
struct SuiteManifest<'a> {
    suite: &'static str,
    generator: String,
    capture: CaptureJson,
    objects: Vec<ManifestEntry<'a>>,
}

#[derive(serde::Serialize)]
struct CaptureJson {
    width: u32,
    height: u32,
    train_views: usize,
    test_views: usize,
    fov_x: f32,
    start_range: (f32, f32),
    end_range: (f32, f32),
    upper_hemisphere: bool,
}

#[derive(serde::Serialize)]
struct ManifestEntry<'a> {
    id: String,
    #[serde(flatten)]
    entry: &'a SuiteEntry,
    name: String,
    parts: usize,
}

/// `artmesh suite`: every planned object into `out/<id>/` (dataset + `object/`), then `suite.json` and
/// `contact-sheet.png`.
pub fn suite(
    ctx: &GpuContext,
    out: &Path,
    kind: SuiteKind,
    capture: &CaptureArgs,
) -> Result<(), String> {
    fresh_folder(out)?;
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
