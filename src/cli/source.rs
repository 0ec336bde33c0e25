//! The command-line options that choose where analysed point sets come
//! from (a point-set file, or fresh realizations of a sampler, optionally
//! projected), resolved into the library's [`Source`].

use std::path::PathBuf;

use anyhow::{Context, bail};

use super::args;
use varspec::PointSet;
use varspec::io::read_point_sets;
use varspec::registry;
use varspec::source::{Source, SourceError};
use varspec::variance::VarianceError;

#[derive(clap::Args)]
pub struct SourceArgs {
    /// Point-set file (CSV, UTK text, .npy, or a table of `varspec tables`); every set in it is used.
    #[arg(conflicts_with_all = ["sampler", "points_flag"])]
    points: Option<PathBuf>,
    /// The same as the positional point-set file.
    #[arg(long = "points", conflicts_with = "sampler", value_name = "FILE")]
    points_flag: Option<PathBuf>,
    /// Instead of a file: draw fresh realizations of this sampler.
    #[arg(long, requires = "n")]
    sampler: Option<String>,
    /// Points per realization (with --sampler).
    #[arg(short = 'n', long = "n", value_parser = super::args::count, allow_negative_numbers = true)]
    n: Option<usize>,
    /// Sampler dimension (with --sampler; default: the dimension the
    /// analysis needs where the sampler has it, 4 for a --dims plane with an
    /// index of 2 or 3, else the sampler's own).
    #[arg(value_parser = super::args::whole::<usize>, allow_negative_numbers = true, short = 'd', long = "dim")]
    dim: Option<usize>,
    #[command(flatten)]
    draw: args::DrawArgs,
    /// Analyse the projection onto these dimensions, e.g. 0,2 (XU) or 1,3 (YV).
    #[arg(long)]
    dims: Option<String>,
    /// With a file of a random-count process (isotropic jitter): its
    /// density λ, the expected points per unit volume; estimators weigh
    /// points by 1/λ instead of 1/N.
    #[arg(allow_negative_numbers = true, long, value_name = "LAMBDA")]
    density: Option<f64>,
}

impl SourceArgs {
    /// The seed given with --seed.
    pub fn seed(&self) -> u64 {
        self.draw.seed()
    }

    /// Whether --sets was given.
    pub fn sets_were_given(&self) -> bool {
        self.draw.sets_were_given()
    }

    /// True when a point-set file or a sampler was given.
    pub fn given(&self) -> bool {
        self.points.is_some() || self.points_flag.is_some() || self.sampler.is_some()
    }

    /// The point-set file given, if any (an input no output may replace).
    pub fn file(&self) -> Option<&std::path::Path> {
        self.points.as_deref().or(self.points_flag.as_deref())
    }

    /// The plane given with --dims, checked to be two distinct indices
    /// (what the spectrum of a 4D integrand is drawn on).
    pub fn plane(&self) -> anyhow::Result<Option<[usize; 2]>> {
        self.dims
            .as_deref()
            .map(|d| args::dims(d, 2).map(|v| [v[0], v[1]]))
            .transpose()
    }

    /// Reads the file or builds the sampler; checks that the (projected)
    /// points are `dim`-dimensional (any dimension for `None`).
    pub fn resolve(&self, dim: Option<usize>) -> anyhow::Result<Source> {
        self.resolve_with(dim, false)
    }

    /// As [`SourceArgs::resolve`] for a command that also draws from --seed
    /// with a file (a family's members): --seed is then not refused.
    pub fn resolve_seeded(&self, dim: Option<usize>) -> anyhow::Result<Source> {
        self.resolve_with(dim, true)
    }

    fn resolve_with(&self, dim: Option<usize>, seed_used: bool) -> anyhow::Result<Source> {
        let dims = self
            .dims
            .as_deref()
            .map(|d| args::dims(d, dim.unwrap_or_else(|| d.split(',').count())))
            .transpose()?;
        let source = match (
            self.points.as_ref().or(self.points_flag.as_ref()),
            &self.sampler,
        ) {
            (Some(path), _) => {
                self.draw.refuse_with_file(path, seed_used)?;
                if self.n.is_some() || self.dim.is_some() {
                    bail!(
                        "-n and --dim apply to --sampler; {} fixes N and d itself",
                        path.display()
                    );
                }
                let mut sets = read_point_sets(path)?;
                if let Some(density) = self.density {
                    sets =
                        varspec::PointSet::all_with_density(sets, density).context("--density")?;
                }
                Source::File {
                    sets,
                    dims: dims.clone(),
                    name: path.display().to_string(),
                }
            }
            (None, Some(name)) => {
                if self.density.is_some() {
                    bail!(
                        "--density applies to a point-set file; a sampler's sets carry their own density"
                    );
                }
                self.draw.check_results_memory()?;
                let n = self.n.context("--sampler needs -n")?;
                // Without -d, draw in the dimension the analysis needs
                // where the sampler has it (as `converge` does): jitter for
                // a 4D integrand is 4D jitter; with --dims, enough for its
                // largest index (--dims 0,2 is the XU plane of 4D sets, the
                // dimension the projections are named in). A sampler
                // without it keeps its own, and the check below says what
                // to do.
                let for_plane = dims
                    .as_ref()
                    .and_then(|d| d.iter().max())
                    .map(|&top| if top < 2 { 2 } else { 4.max(top + 1) });
                let wanted = self.dim.or(for_plane).or(dim);
                let sampler = match registry::build(name, n, wanted, &self.draw.params) {
                    Err(varspec::samplers::SamplerError::Dimension { .. })
                        if self.dim.is_none() =>
                    {
                        registry::build(name, n, None, &self.draw.params)?
                    }
                    built => built?,
                };
                super::args::note_caveat(sampler.as_ref());
                Source::Sampler {
                    sampler,
                    seed: self.draw.seed(),
                    sets: self.draw.sets(),
                    dims: dims.clone(),
                    name: format!("{} N={n}", registry::label(name, &self.draw.params)?),
                }
            }
            (None, None) => {
                bail!(
                    "no points given: name a point-set file (or --points FILE), or draw them with --sampler NAME -n N"
                )
            }
        };
        // Check the projection against the points' dimension without drawing
        // a realization (an optimized sampler's draw is a whole descent).
        let own = match &source {
            Source::File { sets, .. } => sets[0].dim(),
            Source::Sampler { sampler, .. } => sampler.dim(),
        };
        let found = match &dims {
            Some(d) => PointSet::new(own, Vec::new())?
                .projected(d)
                .with_context(|| source.name().to_string())?
                .dim(),
            None => own,
        };
        if let Some(dim) = dim.filter(|&d| d != found) {
            if matches!(source, Source::Sampler { .. }) && dims.is_none() && found < dim {
                bail!(
                    "{}: points are {found}-dimensional where {dim} dimensions are needed; \
                     draw them in {dim}D with -d {dim} (a sampler that has it, e.g. jitter, \
                     random, sobol) or use a 4D sampler (umj, padded:xy=...,uv=...)",
                    source.name()
                );
            }
            if found < dim {
                bail!(
                    "{}: points are {found}-dimensional where {dim} dimensions are needed: a projection \
                     cannot add dimensions; give points of {dim} or more dimensions, or an integrand of {found}",
                    source.name()
                );
            }
            let example = if found == 4 && dim == 2 {
                " (0,1 is XY, 2,3 is UV, 0,2 is XU, 1,3 is YV)".to_string()
            } else {
                let first: Vec<String> = (0..dim).map(|i| i.to_string()).collect();
                format!(", e.g. --dims {}", first.join(","))
            };
            bail!(
                "{}: points are {found}-dimensional where {dim} dimensions are needed; choose a \
                 projection with --dims{example}",
                source.name()
            );
        }
        Ok(source)
    }
}

/// A realization's failure as a predictor's error: a sampler failure
/// stays one, anything else names the realization.
pub fn realization_error(index: usize, e: SourceError) -> VarianceError {
    match e {
        SourceError::Sampler(s) => VarianceError::Sampler(s),
        other => VarianceError::Realization {
            index,
            message: other.to_string(),
        },
    }
}
