//! Point-set samplers: one file per family behind the [`Sampler`] trait.
//! The registry that names them for the command line is
//! [`crate::registry`].
//!
//! A sampler is an immutable configuration (N, d, parameters); randomness is
//! handed in as a [`SetRng`] (docs/architecture.md, "Conventions"). [`generate_sets`] draws many
//! realizations in parallel, realization r from stream (seed, r), so the
//! output is identical for any number of threads.

pub mod closed_form;
pub mod config;
pub(crate) mod halton;
pub(crate) mod isotropic_jitter;
pub(crate) mod jitter;
pub mod lattice;
pub(crate) mod multijitter;
pub(crate) mod nrooks;
pub(crate) mod padded;
pub(crate) mod poisson_disk;
pub(crate) mod random;
pub(crate) mod sobol;
mod sobol_table;

pub use closed_form::ClosedFormSpectrum;
pub use halton::Halton;
pub use isotropic_jitter::IsotropicJitter;
pub use jitter::{Jitter, StratumOffset};
pub use lattice::Lattice;
pub use multijitter::MultiJitter;
pub use nrooks::NRooks;
pub use padded::Padded;
pub use poisson_disk::PoissonDisk;
pub use random::Random;
pub use sobol::Sobol;

use rayon::prelude::*;

use crate::points::PointSet;
use crate::rng::{SetRng, set_rng};
use crate::spectrum::pair::PairSpectrum;

/// A point-set generator: N points in d dimensions per call.
pub trait Sampler: Send + Sync {
    /// Dimension d of every set.
    fn dim(&self) -> usize;
    /// Number of points N of every set (the expected number for a sampler
    /// with a [`density`](Sampler::density)).
    fn points_per_set(&self) -> usize;
    /// The density λ of a sampler whose number of points is random
    /// (isotropic jitter): its sets carry it and their estimator weight is
    /// 1/λ. `None` for a fixed N.
    fn density(&self) -> Option<f64> {
        None
    }
    /// Draws one realization from `rng`.
    ///
    /// # Errors
    /// Only samplers that can fail to place N points (Poisson disk) do.
    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError>;
    /// The expected pair sums C(ω, ω′) in closed form, for 2D samplers that
    /// have one ([`PairSpectrum`]); `None` otherwise.
    fn pair_spectrum(&self) -> Option<&dyn PairSpectrum> {
        None
    }
    /// The (x, y) and (u, v) samplers of a padded 4D sampler (independent
    /// 2D halves paired by a uniformly random permutation); `None` for
    /// every other sampler.
    fn halves(&self) -> Option<[&dyn Sampler; 2]> {
        None
    }
    /// The 2D integration lattice every realization is a uniformly shifted
    /// copy of (the regular grid, uniform jitter, the lattice rule), whose
    /// expected variance is an exact N-term sum
    /// ([`crate::variance::lattice`]); `None` for every other sampler.
    fn lattice(&self) -> Option<Lattice> {
        None
    }
    /// True when every realization is a shift of one set (the regular grid
    /// and uniform jitter in any dimension, the lattice rule): the
    /// shift-randomized estimator then has the same variance on every set,
    /// so a spread of zero between sets is exact, not a sign of too few.
    fn shifts_of_one_set(&self) -> bool {
        self.lattice().is_some()
    }
    /// What a user should know about this instance that its name does not
    /// say (a multi-jittered set of N with no divisor near √N is a thin
    /// grid that stratifies like N-rooks); `None` when nothing. A padded
    /// sampler says its halves'.
    fn caveat(&self) -> Option<String> {
        let halves = self.halves()?;
        let mut said: Vec<String> = halves.iter().filter_map(|h| h.caveat()).collect();
        said.dedup();
        (!said.is_empty()).then(|| said.join("; "))
    }
}

/// What is wrong with a sampler request.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SamplerError {
    /// No sampler has this name.
    #[error("unknown sampler `{name}`{suggestion}; known samplers: {known}")]
    Unknown {
        /// The name given.
        name: String,
        /// " (did you mean `…`?)" or empty ([`crate::suggest`]).
        suggestion: String,
        /// Every known name.
        known: String,
    },
    /// N = 0.
    #[error("{sampler}: the number of points must be at least 1")]
    ZeroPoints {
        /// Sampler name.
        sampler: &'static str,
    },
    /// A dimension the sampler does not support.
    #[error("{sampler}: dimension {dim} is not supported ({})", supported(*min, *max))]
    Dimension {
        /// Sampler name.
        sampler: &'static str,
        /// Requested dimension.
        dim: usize,
        /// Smallest supported.
        min: usize,
        /// Largest supported.
        max: usize,
    },
    /// N does not fit the sampler's structure.
    #[error("{sampler} in {dim}D: N = {n} does not fit ({rule}); nearest valid N: {}", nearest(*below, *above))]
    Count {
        /// Sampler name (for a padded set's half, which half of what).
        sampler: String,
        /// The dimension the set was asked in (the rule often depends on it).
        dim: usize,
        /// Requested N.
        n: usize,
        /// The constraint.
        rule: &'static str,
        /// Largest valid N below, if any.
        below: Option<usize>,
        /// Smallest valid N above, if any.
        above: Option<usize>,
    },
    /// The realizations asked for do not fit in memory.
    #[error(transparent)]
    Memory(#[from] crate::memory::TooMuchMemory),
    /// N·d is too large to hold.
    #[error(
        "{sampler}: {n} points in {dim}D is more than this tool holds (fewer than 2^32 coordinates)"
    )]
    TooLarge {
        /// Sampler name.
        sampler: &'static str,
        /// Requested N.
        n: usize,
        /// Requested d.
        dim: usize,
    },
    /// A malformed `name:key=value,...` list.
    #[error("sampler `{spec}`: {reason}")]
    Syntax {
        /// The whole spec.
        spec: String,
        /// What is wrong with its list.
        reason: crate::spec_params::ParamListError,
    },
    /// The same parameter given twice in one place (the spec's shorthand,
    /// or the --param list).
    #[error("sampler `{spec}`: parameter `{key}` is given twice (each once)")]
    RepeatedParam {
        /// The sampler spec.
        spec: String,
        /// The repeated key.
        key: String,
    },
    /// A parameter the sampler does not have.
    #[error("{sampler}: unknown parameter `{key}`{suggestion}; its parameters: {known}{hint}")]
    UnknownParam {
        /// Sampler name.
        sampler: &'static str,
        /// The key given.
        key: String,
        /// " (did you mean `…`?)" or empty ([`crate::suggest`]).
        suggestion: String,
        /// The sampler's keys.
        known: String,
        /// Where the key may have come from (empty if nowhere likely).
        hint: String,
    },
    /// A parameter value out of its domain.
    #[error("{sampler}: parameter {key}={value} is invalid: expected {expected}")]
    Param {
        /// Sampler name.
        sampler: &'static str,
        /// The key.
        key: &'static str,
        /// The value given.
        value: String,
        /// What is accepted.
        expected: String,
    },
    /// Dart throwing could not place N points.
    #[error(
        "poisson-disk: placed only {placed} of {n} points after {trials} dart throws at relative radius {rho} \
         (random sequential dart throwing jams near 0.78 in 2D, 0.80 in 3D and 4D): lower --param radius=... \
         or raise --param max-trials=..."
    )]
    Jammed {
        /// Points placed.
        placed: usize,
        /// Points requested.
        n: usize,
        /// Throws made.
        trials: u64,
        /// Relative radius ρ.
        rho: f64,
    },
    /// Dart throwing filled the torus before N points: every position lies
    /// within r of a placed point (the set is maximal), shown by covering
    /// the torus with cubes each inside one disk.
    #[error(
        "poisson-disk: no room for point {next} of {n} at relative radius {rho}: the {placed} placed leave no \
         position at least r from all of them (random sequential dart throwing jams near 0.78 in 2D, 0.80 in \
         3D and 4D, sooner in some sets): lower --param radius=... or try another --seed"
    )]
    Saturated {
        /// Points placed.
        placed: usize,
        /// The point that found no room: `placed + 1`.
        next: usize,
        /// Points requested.
        n: usize,
        /// Relative radius ρ.
        rho: f64,
    },
}

fn supported(min: usize, max: usize) -> String {
    if min == max {
        format!("it is {min}D only")
    } else {
        format!("supported: {min} to {max}")
    }
}

fn nearest(below: Option<usize>, above: Option<usize>) -> String {
    match (below, above) {
        (Some(b), Some(a)) => format!("{b} or {a}"),
        (Some(b), None) => b.to_string(),
        (None, Some(a)) => a.to_string(),
        (None, None) => "none".to_string(),
    }
}

/// Checks what every sampler needs of its size: N ≥ 1, d in `dims`, and
/// fewer than 2^32 coordinates (point indices then fit a u32: the
/// permutations of N-rooks and multi-jitter hold u32).
///
/// # Errors
/// [`SamplerError::ZeroPoints`], [`SamplerError::Dimension`] or
/// [`SamplerError::TooLarge`] naming `sampler`.
pub fn check_size(
    sampler: &'static str,
    n: usize,
    dim: usize,
    dims: std::ops::RangeInclusive<usize>,
) -> Result<(), SamplerError> {
    if !dims.contains(&dim) {
        return Err(SamplerError::Dimension {
            sampler,
            dim,
            min: *dims.start(),
            max: *dims.end(),
        });
    }
    if n == 0 {
        return Err(SamplerError::ZeroPoints { sampler });
    }
    if n.checked_mul(dim).is_none_or(|c| c >= 1 << 32) {
        return Err(SamplerError::TooLarge { sampler, n, dim });
    }
    Ok(())
}

/// Bytes `sets` realizations of `sampler` hold (coordinates and the set's
/// own fields), the estimate [`generate_sets`] checks before drawing.
pub fn sets_bytes(sampler: &dyn Sampler, sets: usize) -> f64 {
    sets as f64 * (sampler.points_per_set() as f64 * sampler.dim() as f64 * 8.0 + 64.0)
}

/// Draws `sets` realizations of `sampler` in parallel; realization r uses
/// the stream [`set_rng`]`(seed, r)`. `on_set_done` is called once per
/// finished set with the time that set took to draw on its thread (for
/// progress display and per-set timings).
///
/// # Errors
/// [`SamplerError::Memory`] before anything is drawn when the sets would
/// not fit in memory; else the first failing realization's error, in
/// realization order.
pub fn generate_sets(
    sampler: &dyn Sampler,
    seed: u64,
    sets: usize,
    on_set_done: &(dyn Fn(std::time::Duration) + Sync),
) -> Result<Vec<PointSet>, SamplerError> {
    crate::memory::check(
        &format!(
            "{sets} realizations of {} points in {}D",
            sampler.points_per_set(),
            sampler.dim()
        ),
        Some(sets_bytes(sampler, sets)),
        "lower --sets",
    )?;
    (0..sets as u64)
        .into_par_iter()
        .map(|r| {
            let start = std::time::Instant::now();
            let set = sampler.sample(&mut set_rng(seed, r));
            on_set_done(start.elapsed());
            set
        })
        .collect()
}
