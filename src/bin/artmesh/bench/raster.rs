//! `artmesh bench raster`: training iterations of the rasterizer (forward, loss, backward, Adam)
//! on a benchmark mesh, with a model FLOP rate against an FMA peak probe
//! (`fit::photometric::timing`, which the browser benchmark runs too).

use artmesh::fit::photometric::timing::raster_bench;

use crate::args::{context, to_json};

/// `artmesh bench raster`'s arguments.
#[derive(clap::Args)]
pub struct RasterArgs {
    /// Cases as SIZExFACES (square image side, target face count).
    #[arg(long, value_delimiter = ',', default_values_t = ["128x20000".to_string(), "256x100000".to_string(), "800x300000".to_string()])]
    cases: Vec<String>,
    /// Timed iterations per case (after one warm-up iteration).
    #[arg(long, default_value_t = 3)]
    repeats: usize,
}

/// The benchmark's JSON.
pub fn run(args: &RasterArgs) -> Result<String, String> {
    let cases = args
        .cases
        .iter()
        .map(|c| parse_case(c))
        .collect::<Result<Vec<_>, _>>()?;
    let ctx = context()?;
    let report = pollster::block_on(raster_bench(&ctx, &cases, args.repeats.max(1)))
        .map_err(|e| e.to_string())?;
    to_json(&report)
}

/// One `--cases` entry, SIZExFACES.
fn parse_case(c: &str) -> Result<(u32, usize), String> {
    let parsed = c
        .split_once('x')
        .and_then(|(s, f)| Some((s.parse::<u32>().ok()?, f.parse::<usize>().ok()?)));
    match parsed {
        Some((size, faces)) if size > 0 && faces > 0 => Ok((size, faces)),
        _ => Err(format!(
            "--cases: expected SIZExFACES such as 128x20000, found '{c}'"
        )),
    }
}
