//! `varspec experiment FILE`: run a declarative experiment (JSON) — whole,
//! or one shard of it — and `varspec merge`: combine shards into exactly
//! the files a single run writes. The work is the library's
//! (`varspec::experiment`); this file parses, calls and prints.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use super::progress;
use varspec::experiment::{
    ExperimentFile, SHARD_PREFIX, Shard, ShardFile, merge_shards, run_items, write_results,
};
use varspec::io::shards::{read_shard_files, shard_file_name};
use varspec::io::write_atomic;

#[derive(clap::Args)]
#[command(after_help = "\
The experiment file is one JSON object (docs/formats.md, \"Experiment file\"):
  name         string, required: a plain file name (no / or ..); the report's
               title and the default output folder out/experiments/<name>
  description  string: a paragraph under the title (default \"\")
  samplers     array of sampler names, required, non-empty
  integrands   array of integrand specs of one dimension, required, non-empty
  n            array of requested N, required; each sampler uses its nearest valid N
  sets         realizations per (sampler, N), default 16
  seed         seed of the realizations, default 0
  radial       {\"half\": H}: also the radial predictor and the Fourier form on
               the box |k|inf <= H, from the same realizations (radial.csv)
Unknown fields are an error. Examples: experiments/rates.json,
experiments/radial-failure.json.
With \"kind\": \"figures\" the file lists figures instead (name, description,
seed, figures: radial-spectra, spectrum, projections, ingredients,
designed-projections, scene-variance, scene-samplers, scene-pixels,
shear-convergence; docs/formats.md,
\"Figure experiments\"), e.g. experiments/seed-figures.json")]
pub struct Args {
    /// Experiment file (JSON; fields in docs/formats.md): name, description,
    /// samplers, integrands, n, sets, seed, radial.
    file: PathBuf,
    /// Output folder (default out/experiments/<name>; results/ only when
    /// asked for, so tracked files are not overwritten by accident).
    #[arg(short = 'o', long = "output", visible_alias = "out")]
    output: Option<PathBuf>,
    /// Run only shard i of n (0-based, e.g. 3/8 or $SLURM_ARRAY_TASK_ID/8)
    /// and write OUTPUT/shard-i-of-n.json; `varspec merge OUTPUT` combines them.
    #[arg(long, value_parser = Shard::parse)]
    shard: Option<Shard>,
}

#[derive(clap::Args)]
pub struct MergeArgs {
    /// Folder holding shard-i-of-n.json files of one experiment.
    folder: PathBuf,
    /// Where to write the merged tables (default: the same folder).
    #[arg(short = 'o', long = "output", visible_alias = "out")]
    output: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let file = a.file.display().to_string();
    let text = varspec::io::read_text_bounded(&a.file, 16 << 20, "an experiment file")
        .with_context(|| format!("cannot read {file}"))?;
    let parsed = ExperimentFile::parse(&text, &file)?;
    let out = a
        .output
        .clone()
        .unwrap_or_else(|| Path::new("out/experiments").join(parsed.name()));
    super::args::check_folder(&out, "-o")?;
    let e = match parsed {
        ExperimentFile::Variance(e) => e,
        ExperimentFile::Figures(e) => {
            if a.shard.is_some() {
                bail!(
                    "{file}: a figure experiment runs whole; --shard splits variance experiments"
                );
            }
            let bar = progress::bar(e.figures.len() as u64, &e.name);
            super::args::create_folder(&out, "-o")?;
            varspec::experiment::remove_variance_runs(&out)?;
            let md = e.run(&file, &out, &|i, seconds| {
                bar.inc(1);
                bar.suspend(|| eprintln!("figures[{i}]: {seconds:.1} s"));
            })?;
            bar.finish_and_clear();
            super::stdout::bytes(md.as_bytes());
            announce!("wrote {}", out.display());
            return Ok(());
        }
    };
    let shard = a.shard.unwrap_or(Shard::ALL);
    let total = e.items().len() * e.integrands.len();
    let bar = progress::bar((total / shard.count).max(1) as u64, &e.name);
    let cells = run_items(&e, &file, shard, &|| bar.inc(1))?;
    bar.finish_and_clear();
    // The folder is made only once there is something to write.
    super::args::create_folder(&out, "-o")?;
    varspec::experiment::remove_other_runs(&out, a.shard)?;
    if a.shard.is_some() {
        let name = shard_file_name(SHARD_PREFIX, shard.index, shard.count);
        let shard_file = ShardFile {
            experiment: e,
            file,
            shard,
            cells,
        };
        let json = serde_json::to_string_pretty(&shard_file)?;
        write_atomic(&out.join(&name), |w| w.write_all(json.as_bytes()))?;
        announce!("wrote {}", out.join(name).display());
        return Ok(());
    }
    let md = write_results(&e, &file, &cells, &out)?;
    super::stdout::bytes(md.as_bytes());
    announce!("wrote {}", out.display());
    Ok(())
}

pub fn merge(a: MergeArgs) -> anyhow::Result<()> {
    let shards: Vec<ShardFile> = read_shard_files(
        &a.folder,
        SHARD_PREFIX,
        1 << 30,
        "an experiment shard of this varspec version (re-run shards an older one wrote)",
        |s: &ShardFile| (s.shard.index, s.shard.count),
    )?;
    let (e, file, cells) = merge_shards(&shards)?;
    let out = a.output.unwrap_or(a.folder);
    super::args::create_folder(&out, "-o")?;
    write_results(&e, &file, &cells, &out)?;
    outln!(
        "merged {} shards of {} into {}",
        shards.len(),
        e.name,
        out.display()
    );
    Ok(())
}
