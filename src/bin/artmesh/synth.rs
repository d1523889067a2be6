//! `artmesh synth` and `render`: one object (procedural, or a user's URDF) captured as a
//! two-state dataset.

use std::path::PathBuf;
use std::process::ExitCode;

use artmesh::synth::{Category, SynthParams, generate};

use crate::args::{CaptureArgs, context};
use crate::capture;
use crate::output::NewFolder;

/// `artmesh synth`'s arguments.
#[derive(clap::Args)]
pub struct SynthArgs {
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
}

/// `artmesh render`'s arguments.
#[derive(clap::Args)]
pub struct RenderArgs {
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
}

/// `artmesh synth`: the generated object under OUT/object/ and, unless `--object-only`, its dataset.
pub fn synth(args: SynthArgs) -> Result<ExitCode, String> {
    let category = Category::parse(&args.category).map_err(|e| e.to_string())?;
    let params = SynthParams {
        category,
        movable_parts: args.parts,
        seed: args.seed,
    };
    let object = generate(&params).map_err(|e| e.to_string())?;
    let folder = NewFolder::create(&args.out)?;
    capture::write_object(&object, &folder.path().join("object"))?;
    if !args.object_only {
        let ctx = context()?;
        let spec = args.capture.spec(false, args.seed);
        capture::dataset(&ctx, &object, &spec, folder.path())?;
    }
    let out = folder.finish()?;
    out!("wrote {} to {}", object.name, out.display());
    Ok(ExitCode::SUCCESS)
}

/// `artmesh render`: a URDF object's dataset.
pub fn render(args: RenderArgs) -> Result<ExitCode, String> {
    let object = capture::read_urdf(&args.urdf)?;
    let folder = NewFolder::create(&args.out)?;
    let ctx = context()?;
    let spec = args.capture.spec(false, args.seed);
    capture::dataset(&ctx, &object, &spec, folder.path())?;
    let out = folder.finish()?;
    out!("wrote {} to {}", object.name, out.display());
    Ok(ExitCode::SUCCESS)
}
