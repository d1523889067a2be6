//! What `artmesh synth`, `render` and `suite` share: objects in, two-state datasets out, written as
//! they are rendered (into folders `output::NewFolder` makes).

use std::io::{IsTerminal, Write as _};
use std::path::{Path, PathBuf};

use artmesh::data::{self, FileSet};
use artmesh::export::write_urdf;
use artmesh::gpu::GpuContext;
use artmesh::object::ArticulatedObject;
use artmesh::render::{RenderProgress, RenderSpec, RenderedDataset, render_dataset};

/// Writes `object` as `<name>.urdf` + `meshes/` below `folder`.
pub fn write_object(object: &ArticulatedObject, folder: &Path) -> Result<(), String> {
    let files = write_urdf(object, &format!("{}.urdf", object.name)).map_err(|e| e.to_string())?;
    data::write_dir(&files, folder).map_err(|e| format!("{}: {e}", folder.display()))
}

/// Imports a URDF from the nearest enclosing folder with a `package.xml` (for `package://` paths),
/// or the URDF's own folder, reading only the files the URDF and its meshes refer to.
pub fn read_urdf(urdf: &Path) -> Result<ArticulatedObject, String> {
    if !urdf.is_file() {
        return Err(format!("{}: no such file", urdf.display()));
    }
    // Absolute, so that a bare `robot.urdf` has a folder and every ancestor is a real one.
    let urdf = urdf
        .canonicalize()
        .map_err(|e| format!("{}: {e}", urdf.display()))?;
    let folder = urdf.parent().unwrap_or(Path::new("/"));
    let root: PathBuf = folder
        .ancestors()
        .take(4)
        .find(|a| a.join("package.xml").is_file())
        .unwrap_or(folder)
        .to_path_buf();
    let files = data::LazyFolder::list(&root).map_err(|e| format!("{}: {e}", root.display()))?;
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
