//! `varspec tables`: pattern tables for renderers, with metadata.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::ValueEnum;

use super::args::DrawArgs;
use super::progress;
use varspec::experiment::Shard;
use varspec::io::read_point_sets_with_metadata;
use varspec::io::shards::{read_shard_files, shard_file_name};
use varspec::io::tables::{TableFormat, write_table};
use varspec::io::write_atomic;
use varspec::registry;
use varspec::samplers;
use varspec::tables::shard::{TableRun, TableShard, draw_shard, merge_table_shards};
use varspec::tables::{PredictedVariances, Provenance, dimensions, metadata, optimized_for};

#[derive(Clone, Copy, ValueEnum)]
enum FormatArg {
    Csv,
    Json,
    F32,
    F64,
    CHeader,
}

#[derive(clap::Args)]
#[command(group = clap::ArgGroup::new("table_source").required(true).args(["sampler", "from", "merge"]))]
#[command(mut_arg("sets_given", |a| a.help("Sets in the table (with --sampler; default 16)")))]
pub struct Args {
    /// Sampler to draw the table from.
    #[arg(long)]
    sampler: Option<String>,
    /// Point-set file to convert instead (--points, as in the analysis
    /// commands, is the same).
    #[arg(long, visible_alias = "points", value_name = "FILE")]
    from: Option<PathBuf>,
    /// Points per set (with --sampler).
    #[arg(short = 'n', long = "n", value_parser = super::args::count, allow_negative_numbers = true)]
    n: Option<usize>,
    /// Dimension (with --sampler).
    #[arg(value_parser = super::args::whole::<usize>, allow_negative_numbers = true, short = 'd', long = "dim")]
    dim: Option<usize>,
    #[command(flatten)]
    draw: DrawArgs,
    /// Output format [default: from the output's name: .csv, .json, .h or
    /// .hpp; f32 and f64 are named with --format].
    #[arg(long, value_enum)]
    format: Option<FormatArg>,
    /// Output file (csv, f32 and f64 also get PATH.json with the metadata).
    #[arg(short = 'o', long = "output")]
    output: PathBuf,
    /// Draw only shard i of n of the sets (set r when r mod n = i) into
    /// OUTPUT.shard-i-of-n.json; `--merge` then writes the table, byte for
    /// byte the one a single run writes (with --sampler; Slurm's array
    /// index as i).
    #[arg(long, requires = "sampler", value_parser = varspec::experiment::Shard::parse)]
    shard: Option<varspec::experiment::Shard>,
    /// Write the table from every OUTPUT.shard-i-of-n.json beside OUTPUT.
    #[arg(long, conflicts_with_all = ["sampler", "from", "n", "dim", "sets_given", "params", "seed_given"])]
    merge: bool,
    /// Compute the metadata's predicted variances whatever the cost (the
    /// exact spatial form is O(N²) per set; by default they are skipped,
    /// with a note, beyond 2^28 pair evaluations).
    #[arg(long)]
    variance: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    super::args::check_outputs_beside([Some(a.output.as_path())], [a.from.as_deref()])?;
    if let Some(shard) = a.shard {
        return draw_table_shard(&a, shard);
    }
    // The format before any drawing: a name that says none fails at once.
    let named = match a
        .output
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .as_deref()
    {
        Some("csv") => Some(FormatArg::Csv),
        Some("json") => Some(FormatArg::Json),
        Some("h" | "hpp") => Some(FormatArg::CHeader),
        _ => None,
    };
    let format = a.format.or(named).with_context(|| {
        format!(
            "--format is needed: {} does not name one (.csv, .json, .h, .hpp); f32 and f64 are \
             raw floats, named with --format",
            a.output.display()
        )
    })?;
    // `--format f32 -o t.csv` wrote raw floats under a table's name.
    let (own, what): (&[&str], _) = match format {
        FormatArg::Csv => (&["csv"], "a CSV table"),
        FormatArg::Json => (&["json"], "a JSON table"),
        FormatArg::CHeader => (&["h", "hpp"], "a C header"),
        FormatArg::F32 | FormatArg::F64 => (&[], "a table of raw binary floats"),
    };
    super::args::check_extension(&a.output, own, what)?;
    let format = match format {
        FormatArg::Csv => TableFormat::Csv,
        FormatArg::Json => TableFormat::Json,
        FormatArg::F32 => TableFormat::F32,
        FormatArg::F64 => TableFormat::F64,
        FormatArg::CHeader => TableFormat::CHeader,
    };
    // The metadata sidecar is an output too: `--from t.csv.json -o t.csv`
    // overwrote its own input.
    let sidecar = format
        .needs_sidecar()
        .then(|| varspec::io::tables::sidecar_path(&a.output));
    // So is the input's sidecar: `--from t.csv -o t.csv.json` replaced
    // the provenance of the file it read.
    let from_sidecar = a.from.as_deref().map(varspec::io::tables::sidecar_path);
    super::args::check_outputs_beside(
        [Some(a.output.as_path()), sidecar.as_deref()],
        [a.from.as_deref(), from_sidecar.as_deref()],
    )?;
    let mut run_params = a.draw.params.clone();
    let mut run_seed = Some(a.draw.seed());
    let mut run_sampler = a.sampler.clone();
    // A varspec table given to --from keeps the provenance its metadata
    // records.
    let mut carried = None;
    let (sets, source) = match (&a.sampler, &a.from) {
        _ if a.merge => {
            let shards = read_table_shards(&a.output)?;
            let (run, sets) = merge_table_shards(&shards)
                .map_err(|e| anyhow::anyhow!("{}: {e}", a.output.display()))?;
            run_params = run.params;
            run_seed = Some(run.seed);
            run_sampler = Some(run.sampler.clone());
            (sets, run.sampler)
        }
        (Some(name), _) => {
            let n = a.n.context("--sampler needs -n")?;
            let s = registry::build(name, n, a.dim, &a.draw.params)?;
            super::args::note_caveat(s.as_ref());
            // The metadata records the parameters the sampler was built
            // with, in one place: the shorthand's and --param's (which win).
            let (base, resolved) = registry::resolved_params(name, &a.draw.params)?;
            run_params = resolved;
            run_sampler = Some(base.to_string());
            let bar = progress::bar(a.draw.sets() as u64, "sampling");
            let sets =
                samplers::generate_sets(s.as_ref(), a.draw.seed(), a.draw.sets(), &|_| bar.inc(1))?;
            bar.finish_and_clear();
            (sets, base.to_string())
        }
        (None, Some(path)) => {
            a.draw.refuse_with_file(path, false)?;
            if a.n.is_some() || a.dim.is_some() {
                bail!(
                    "-n and --dim apply to --sampler; {} fixes N and d itself",
                    path.display()
                );
            }
            run_seed = None;
            let (sets, found) = read_point_sets_with_metadata(path)?;
            if let Some(stale) = &found.stale {
                eprintln!(
                    "note: {stale} of {} does not describe its values (unreadable, or they were \
                     edited or written over since): its provenance is not carried; the table \
                     records the file's path as its source and no seed",
                    path.display()
                );
            }
            carried = found.describing;
            (sets, path.display().to_string())
        }
        (None, None) => bail!("give --sampler or --from"),
    };
    let provenance = match carried {
        Some(m) => Provenance {
            source: m.source,
            params: m.params,
            seed: m.seed,
            optimized_for: m.optimized_for,
            dimensions: m.dimensions,
        },
        None => Provenance {
            optimized_for: optimized_for(run_sampler.as_deref(), &run_params)?,
            dimensions: dimensions(run_sampler.as_deref(), &run_params)?,
            source,
            params: run_params,
            seed: run_seed,
        },
    };
    let (meta, predicted) = metadata(&sets, provenance, format, a.variance)?;
    // The metadata says why they are missing; a skipped cost is also said here.
    if let PredictedVariances::OverBudget { .. } = predicted
        && let Some(why) = &meta.predicted_variance_skipped
    {
        eprintln!("predicted variances left out of the metadata: {why}");
    }
    // The file's name up to its last `.` (docs/formats.md; `.h` gives an
    // empty name, which c_identifier prefixes to `table_`).
    let name = a
        .output
        .file_name()
        .map(|s| {
            let s = s.to_string_lossy();
            s.rsplit_once('.')
                .map_or(s.to_string(), |(stem, _)| stem.to_string())
        })
        .unwrap_or_else(|| "table".into());
    write_atomic(&a.output, |w| write_table(w, &sets, &meta, format, &name))?;
    if let Some(sidecar) = &sidecar {
        write_atomic(sidecar, |w| {
            w.write_all(
                serde_json::to_string_pretty(&meta)
                    .map_err(std::io::Error::other)?
                    .as_bytes(),
            )
        })?;
    }
    announce!(
        "wrote {} ({} of {} points in {}D)",
        a.output.display(),
        super::stdout::counted(sets.len(), "set"),
        meta.n,
        meta.dim
    );
    Ok(())
}

/// The shard file of `output` for shard i of n: `OUTPUT.shard-i-of-n.json`
/// beside it.
fn shard_path(output: &std::path::Path, shard: Shard) -> PathBuf {
    let mut name = output.as_os_str().to_owned();
    name.push(shard_file_name(".shard-", shard.index, shard.count));
    PathBuf::from(name)
}

/// `tables --shard i/n`: draws the shard's sets and writes them with the run.
fn draw_table_shard(a: &Args, shard: Shard) -> anyhow::Result<()> {
    let name = a.sampler.as_deref().context("--shard needs --sampler")?;
    let n = a.n.context("--sampler needs -n")?;
    let sampler = registry::build(name, n, a.dim, &a.draw.params)?;
    let run = TableRun {
        sampler: name.to_string(),
        n,
        dim: a.dim,
        params: a.draw.params.clone(),
        seed: a.draw.seed(),
        sets: a.draw.sets(),
    };
    let mine = (shard.index..run.sets).step_by(shard.count).count();
    let bar = progress::bar(mine as u64, "sampling");
    let part = draw_shard(sampler.as_ref(), run, shard, &|| bar.inc(1))?;
    bar.finish_and_clear();
    let path = shard_path(&a.output, shard);
    let json = serde_json::to_string(&part)?;
    write_atomic(&path, |w| w.write_all(json.as_bytes()))?;
    announce!(
        "wrote {} ({mine} of {} sets)",
        path.display(),
        part.run.sets
    );
    Ok(())
}

/// Every OUTPUT.shard-i-of-n.json beside `output`.
fn read_table_shards(output: &std::path::Path) -> anyhow::Result<Vec<TableShard>> {
    let folder = varspec::io::folder_of(output);
    let file = output
        .file_name()
        .context("--merge needs -o naming the table file")?;
    let prefix = format!("{}.shard-", file.to_string_lossy());
    Ok(read_shard_files(
        folder,
        &prefix,
        1 << 34,
        "a table shard",
        |s: &TableShard| (s.shard.index, s.shard.count),
    )?)
}
