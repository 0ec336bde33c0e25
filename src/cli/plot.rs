//! `varspec plot`: pictures of point sets.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::Subcommand;

use super::args;
use varspec::io::read_point_sets;
use varspec::report::png::{render_points, render_points_1d, save_png};

#[derive(Subcommand)]
pub enum PlotCommand {
    /// Draw one set of a point-set file, or a 2D projection of it, as PNG.
    Points(PointsArgs),
}

#[derive(clap::Args)]
pub struct PointsArgs {
    /// Point-set file (CSV, UTK text, .npy, or a table of `varspec tables`).
    file: PathBuf,
    /// The two dimensions to draw, horizontal then vertical (XU = 0,2; YV =
    /// 1,3); one dimension draws a strip of ticks (the default for 1D sets).
    #[arg(long)]
    dims: Option<String>,
    /// Which set of the file to draw (from 0).
    #[arg(value_parser = super::args::whole::<usize>, allow_negative_numbers = true, long, default_value_t = 0)]
    set: usize,
    /// Image side in pixels.
    #[arg(value_parser = super::args::whole::<u32>, allow_negative_numbers = true, long, default_value_t = 512)]
    size: u32,
    /// Output PNG.
    #[arg(short = 'o', long = "output", value_parser = super::args::png_path)]
    output: PathBuf,
}

pub fn run(c: PlotCommand) -> anyhow::Result<()> {
    match c {
        PlotCommand::Points(a) => points(a),
    }
}

fn points(a: PointsArgs) -> anyhow::Result<()> {
    args::check_outputs_beside([Some(a.output.as_path())], [Some(a.file.as_path())])?;
    if !(16..=8192).contains(&a.size) {
        bail!("--size {}: choose 16 to 8192 pixels", a.size);
    }
    // Checked before the file is read: a malformed --dims is refused at once.
    let asked = match &a.dims {
        Some(text) if !text.contains(',') => args::dims(text, 1)?,
        Some(text) => args::dims(text, 2)?,
        None => Vec::new(),
    };
    let sets = read_point_sets(&a.file)?;
    let Some(set) = sets.get(a.set) else {
        bail!(
            "{}: --set {} requested, the file holds sets 0..{}",
            a.file.display(),
            a.set,
            sets.len() - 1
        );
    };
    let dims = match asked.as_slice() {
        [] if set.dim() == 1 => vec![0],
        [] => vec![0, 1],
        _ => asked,
    };
    let img = match dims[..] {
        [d] => render_points_1d(set, d, a.size),
        _ => render_points(set, [dims[0], dims[1]], a.size),
    }
    .with_context(|| format!("{}", a.file.display()))?;
    save_png(&img, &a.output)?;
    let which = match dims[..] {
        [d] => format!("dimension {d}"),
        _ => format!("dimensions {} and {}", dims[0], dims[1]),
    };
    announce!(
        "wrote {}: set {} of {}, {which}",
        a.output.display(),
        a.set,
        a.file.display(),
    );
    Ok(())
}
