//! `varspec sample`: generate point sets.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use clap::ValueEnum;

use super::{args, progress};
use varspec::io::npy::write_point_sets_npy;
use varspec::io::{PointFormat, write_atomic, write_point_sets};
use varspec::points::PointSet;
use varspec::registry;
use varspec::registry::SAMPLERS;
use varspec::samplers;

/// Point-set file formats.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// CSV with a `[set,]x0,x1,...` header.
    Csv,
    /// UTK whitespace text, `#` between sets.
    Utk,
    /// NumPy float64 array of shape [sets, N, d] (`numpy.load`).
    Npy,
}

impl Format {
    /// The format asked for, else the one the output's extension names
    /// (`.npy`), else CSV.
    ///
    /// # Errors
    /// A format asked for against the output's name (UTK text in `u.npy`,
    /// or .npy bytes in `u.csv`, would misstate the file; a name without
    /// an extension says nothing).
    fn resolve(asked: Option<Format>, output: Option<&Path>) -> anyhow::Result<Format> {
        let ext = output.and_then(Path::extension);
        let npy_name = ext.is_some_and(|e| e.eq_ignore_ascii_case("npy"));
        match asked {
            None if npy_name => Ok(Format::Npy),
            None => Ok(Format::Csv),
            Some(f) if ext.is_none() || npy_name == (f == Format::Npy) => Ok(f),
            Some(f) => bail!(
                "--format {} with -o {}: the name says another format; name the file .npy for \
                 npy, anything else (.csv, .txt) for csv and utk",
                f.to_possible_value()
                    .map_or("?".into(), |v| v.get_name().to_string()),
                output.map_or(String::new(), |p| p.display().to_string())
            ),
        }
    }

    fn write(self, out: &mut dyn Write, sets: &[PointSet]) -> std::io::Result<()> {
        match self {
            Format::Csv => write_point_sets(out, sets, PointFormat::Csv),
            Format::Utk => write_point_sets(out, sets, PointFormat::Utk),
            Format::Npy => write_point_sets_npy(out, sets),
        }
    }
}

#[derive(clap::Args)]
pub struct Args {
    /// Sampler name (see --list), with `name:key=value,...` parameters if any.
    #[arg(required_unless_present_any = ["list", "sampler_flag"], conflicts_with = "sampler_flag")]
    sampler: Option<String>,
    /// The same as the positional sampler name (as in the other commands).
    #[arg(long = "sampler", value_name = "SAMPLER")]
    sampler_flag: Option<String>,
    /// Points per set.
    #[arg(short = 'n', long = "n", value_parser = super::args::count, allow_negative_numbers = true, required_unless_present = "list")]
    n: Option<usize>,
    /// Dimension (default: the sampler's own, 2 for most, 4 for umj).
    #[arg(value_parser = super::args::whole::<usize>, allow_negative_numbers = true, short = 'd', long = "dim")]
    dim: Option<usize>,
    /// Seed: the same seed gives bit-identical output for any thread count.
    #[arg(value_parser = super::args::whole::<u64>, allow_negative_numbers = true, long, default_value_t = 0)]
    seed: u64,
    /// Number of independent realizations.
    #[arg(value_parser = args::whole_at_least::<1, usize>, allow_negative_numbers = true, long, default_value_t = args::DEFAULT_SETS)]
    sets: usize,
    /// Sampler parameter key=value (repeatable; see --list; wins over the
    /// same key in the NAME:key=value shorthand).
    #[arg(long = "param", value_parser = args::key_value)]
    params: Vec<(String, String)>,
    /// Output file (default: standard output).
    #[arg(value_parser = args::point_file_path, short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Output format (default: npy for an `-o` ending in .npy, else csv).
    #[arg(long, value_enum)]
    format: Option<Format>,
    /// List every sampler with its dimensions, constraint on N and parameters.
    #[arg(long)]
    list: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    if a.list {
        return list();
    }
    let (name, n) = (
        a.sampler.or(a.sampler_flag).expect("clap requires one"),
        a.n.expect("clap requires it"),
    );
    args::check_outputs([a.output.as_deref()])?;
    let sampler = registry::build(&name, n, a.dim, &a.params)?;
    let name = registry::label(&name, &a.params)?;
    args::note_caveat(sampler.as_ref());
    let format = Format::resolve(a.format, a.output.as_deref())?;
    note_large_output(format, sampler.points_per_set(), sampler.dim(), a.sets);
    let bar = progress::bar(a.sets as u64, &format!("{name} N={n}"));
    let sets = samplers::generate_sets(sampler.as_ref(), a.seed, a.sets, &|_| bar.inc(1))?;
    bar.finish_and_clear();
    if let Some(density) = sampler.density() {
        // The files hold points only: the weight 1/λ has to be given back.
        eprintln!(
            "note: {name} draws a random number of points per set (density {density}); \
             analyse the sets with --density {density} so the estimator weighs points by 1/{density}"
        );
    }
    match &a.output {
        Some(path) => {
            write_atomic(path, |w| format.write(w, &sets))?;
            let dim = sets.first().map_or(0, |s| s.dim());
            announce!(
                "wrote {}: {} of {name} N={n} in {dim}D",
                path.display(),
                super::stdout::counted(sets.len(), "set")
            );
        }
        None => {
            let mut out = std::io::BufWriter::new(std::io::stdout().lock());
            format
                .write(&mut out, &sets)
                .context("writing to standard output")?;
            out.flush().context("writing to standard output")?;
        }
    }
    Ok(())
}

/// Output size above which [`note_large_output`] speaks (1 GB).
const LARGE_OUTPUT: f64 = 1e9;

/// A note before drawing when the output will be large: its estimated size
/// (text: ~20 characters per coordinate; npy: 8 bytes), so a request for
/// 10⁹ points is seen for what it is before the disk fills.
fn note_large_output(format: Format, n: usize, dim: usize, sets: usize) {
    let values = n as f64 * dim as f64 * sets as f64;
    let bytes = match format {
        Format::Npy => 8.0 * values,
        Format::Csv | Format::Utk => 20.0 * values,
    };
    if bytes > LARGE_OUTPUT {
        eprintln!(
            "note: the output will be about {:.0} GB ({values:.1e} coordinates{})",
            bytes / 1e9,
            if matches!(format, Format::Npy) {
                ""
            } else {
                "; as .npy it would be 8 bytes each"
            }
        );
    }
}

fn list() -> anyhow::Result<()> {
    let mut out = String::new();
    for s in SAMPLERS {
        let aliases = if s.aliases.is_empty() {
            String::new()
        } else {
            format!(" (alias {})", s.aliases.join(", "))
        };
        let dims = if s.dims.min == s.dims.max {
            format!("d = {}", s.dims.min)
        } else {
            format!(
                "d = {}..{} (default {})",
                s.dims.min, s.dims.max, s.dims.default
            )
        };
        out += &format!(
            "{}{aliases}\n    {}\n    {dims}; {}\n",
            s.name, s.summary, s.count
        );
        for p in s.params {
            out += &format!(
                "    --param {}=<value>  (default {}) {}\n",
                p.key, p.default, p.help
            );
        }
    }
    super::stdout::bytes(out.as_bytes());
    Ok(())
}
