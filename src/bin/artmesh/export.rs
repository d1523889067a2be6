//! `artmesh export`: a fit folder's twin written again as GLB and/or the simulator zip.

use std::path::PathBuf;
use std::process::ExitCode;

use artmesh::data;
use artmesh::export::{JOINTS_FILE, URDF_FILE, end_configuration, export_twin};
use artmesh::object::ArticulatedObject;

use crate::output::{check_distinct, check_new_file, write_new_file};

/// `artmesh export`'s arguments.
#[derive(clap::Args)]
pub struct ExportArgs {
    /// Folder written by `fit` (or the `fit/` folder inside a `demo` folder).
    fit_dir: PathBuf,
    /// New GLB file to write.
    #[arg(long)]
    glb: Option<PathBuf>,
    /// New zip file to write (URDF + meshes + joints.json + GLB under one folder).
    #[arg(long)]
    urdf_zip: Option<PathBuf>,
}

/// `artmesh export`: reads FIT_DIR's URDF and joints and writes the files asked for (new files only).
pub fn run(args: &ExportArgs) -> Result<ExitCode, String> {
    let ExportArgs {
        fit_dir,
        glb,
        urdf_zip,
    } = args;
    if glb.is_none() && urdf_zip.is_none() {
        return Err("export: say what to write: --glb FILE and/or --urdf-zip FILE".into());
    }
    let outputs: Vec<&std::path::Path> = glb.iter().chain(urdf_zip).map(|p| p.as_path()).collect();
    check_distinct(&outputs)?;
    for path in &outputs {
        check_new_file(path)?;
    }
    let files = data::read_dir(fit_dir).map_err(|e| e.to_string())?;
    let shown = |rel: &str| fit_dir.join(rel).display().to_string();
    if !files.contains_key(URDF_FILE) {
        return Err(format!(
            "{}: missing; expected a folder written by `artmesh fit` (or a demo's fit/ folder)",
            shown(URDF_FILE)
        ));
    }
    let object = ArticulatedObject::from_urdf(URDF_FILE, &files)
        .map_err(|e| format!("{}: {e}", fit_dir.display()))?;
    let joints = files.get(JOINTS_FILE).ok_or_else(|| {
        format!(
            "{}: missing (the joints' end-state motions)",
            shown(JOINTS_FILE)
        )
    })?;
    let end = end_configuration(&object, joints, &shown(JOINTS_FILE)).map_err(|e| e.to_string())?;
    let exports = export_twin(&object, &end, joints).map_err(|e| e.to_string())?;
    for (path, bytes) in [(glb, &exports.glb), (urdf_zip, &exports.zip)] {
        if let Some(path) = path {
            write_new_file(path, bytes)?;
            eprintln!("export: wrote {} ({} bytes)", path.display(), bytes.len());
        }
    }
    Ok(ExitCode::SUCCESS)
}
