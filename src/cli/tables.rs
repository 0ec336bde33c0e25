//! `varspec tables`: pattern tables for renderers, with metadata.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::ValueEnum;

use super::args::DrawArgs;
use super::progress;
use varspec::io::read_point_sets;
use varspec::io::tables::{TableFormat, write_table};
use varspec::io::write_atomic;
use varspec::registry;
use varspec::samplers;
use varspec::tables::{
    PredictedVariances, Provenance, REFERENCE_INTEGRANDS, metadata, optimized_for,
};

#[derive(Clone, Copy, ValueEnum)]
enum FormatArg {
    Csv,
    Json,
    F32,
    F64,
    CHeader,
}

#[derive(clap::Args)]
pub struct Args {
    /// Sampler to draw the table from.
    #[arg(long, conflicts_with = "from", required_unless_present = "from")]
    sampler: Option<String>,
    /// Point-set file to convert instead.
    #[arg(long)]
    from: Option<PathBuf>,
    /// Points per set (with --sampler).
    #[arg(short = 'n', long = "n", value_parser = super::args::count, allow_negative_numbers = true)]
    n: Option<usize>,
    /// Dimension (with --sampler).
    #[arg(value_parser = super::args::whole::<usize>, allow_negative_numbers = true, short = 'd', long = "dim")]
    dim: Option<usize>,
    #[command(flatten)]
    draw: DrawArgs,
    /// Output format.
    #[arg(long, value_enum)]
    format: FormatArg,
    /// Output file (csv, f32 and f64 also get PATH.json with the metadata).
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
    /// Compute the metadata's predicted variances whatever the cost (the
    /// exact spatial form is O(N²) per set; by default they are skipped,
    /// with a note, beyond 2^28 pair evaluations).
    #[arg(long)]
    variance: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    super::args::check_outputs([Some(a.output.as_path())])?;
    let (sets, source) = match (&a.sampler, &a.from) {
        (Some(name), _) => {
            let n = a.n.context("--sampler needs -n")?;
            if a.draw.sets() == 0 {
                bail!("--sets must be at least 1");
            }
            let s = registry::build(name, n, a.dim, &a.draw.params)?;
            let bar = progress::bar(a.draw.sets() as u64, "sampling");
            let sets =
                samplers::generate_sets(s.as_ref(), a.draw.seed(), a.draw.sets(), &|| bar.inc(1))?;
            bar.finish_and_clear();
            (sets, name.clone())
        }
        (None, Some(path)) => {
            a.draw.refuse_with_file(path, false)?;
            if a.n.is_some() || a.dim.is_some() {
                bail!(
                    "-n and --dim apply to --sampler; {} fixes N and d itself",
                    path.display()
                );
            }
            (read_point_sets(path)?, path.display().to_string())
        }
        (None, None) => bail!("give --sampler or --from"),
    };
    let format = match a.format {
        FormatArg::Csv => TableFormat::Csv,
        FormatArg::Json => TableFormat::Json,
        FormatArg::F32 => TableFormat::F32,
        FormatArg::F64 => TableFormat::F64,
        FormatArg::CHeader => TableFormat::CHeader,
    };
    let provenance = Provenance {
        optimized_for: optimized_for(a.sampler.as_deref(), &a.draw.params)?,
        source,
        params: a.draw.params.clone(),
        seed: a.draw.seed(),
    };
    let (meta, predicted) = metadata(&sets, provenance, format, a.variance)?;
    if let PredictedVariances::OverBudget { pairs } = predicted {
        eprintln!(
            "predicted variances left out of the metadata: {pairs:.3e} pair evaluations \
             ({} integrands x N^2 x {} sets) exceed 2^28; pass --variance to compute them",
            REFERENCE_INTEGRANDS.len(),
            sets.len()
        );
    }
    let name = a
        .output
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "table".into());
    write_atomic(&a.output, |w| write_table(w, &sets, &meta, format, &name))?;
    if format.needs_sidecar() {
        let mut sidecar = a.output.clone().into_os_string();
        sidecar.push(".json");
        write_atomic(std::path::Path::new(&sidecar), |w| {
            w.write_all(
                serde_json::to_string_pretty(&meta)
                    .map_err(std::io::Error::other)?
                    .as_bytes(),
            )
        })?;
    }
    println!(
        "wrote {} ({} sets of {} points in {}D)",
        a.output.display(),
        sets.len(),
        meta.n,
        meta.dim
    );
    Ok(())
}
