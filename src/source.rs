//! Where analysed point sets come from: the sets of a point-set file, or
//! fresh realizations of a sampler (realization r from stream (seed, r)),
//! optionally projected onto chosen dimensions. The command line resolves
//! its options into a [`Source`]; library users build one directly.

use crate::points::{PointSet, PointSetError};
use crate::rng::set_rng;
use crate::samplers::{Sampler, SamplerError};

/// A realization that could not be produced.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    /// The sampler failed (e.g. Poisson disk jammed).
    #[error(transparent)]
    Sampler(#[from] SamplerError),
    /// The projection does not fit the points.
    #[error("{source_name}: {error}")]
    Projection {
        /// The source's label.
        source_name: String,
        /// What is wrong.
        error: PointSetError,
    },
}

/// Resolved point sets, realization by realization.
pub enum Source {
    /// Sets read from a file.
    File {
        /// Every set of the file.
        sets: Vec<PointSet>,
        /// The projection, if any.
        dims: Option<Vec<usize>>,
        /// A label for titles and messages.
        name: String,
    },
    /// A sampler and its seed.
    Sampler {
        /// The sampler.
        sampler: Box<dyn Sampler>,
        /// Realization r is drawn from stream (seed, r).
        seed: u64,
        /// Realizations to draw.
        sets: usize,
        /// The projection, if any.
        dims: Option<Vec<usize>>,
        /// A label for titles and messages.
        name: String,
    },
}

impl Source {
    /// Points per realization.
    pub fn points_per_set(&self) -> usize {
        match self {
            Source::File { sets, .. } => sets[0].len(),
            Source::Sampler { sampler, .. } => sampler.points_per_set(),
        }
    }

    /// The density λ of a random-count source (`--density` for a file),
    /// `None` for a fixed N.
    pub fn density(&self) -> Option<f64> {
        match self {
            Source::File { sets, .. } => sets[0].density(),
            Source::Sampler { sampler, .. } => sampler.density(),
        }
    }

    /// "N = 256", "N = 243 to 268, each set weighed by 1/N" for a file of
    /// sets of different sizes, or "random N, density 256" for a
    /// random-count source.
    pub fn count_label(&self) -> String {
        let sizes = match self {
            Source::File { sets, .. } => sets
                .iter()
                .map(PointSet::len)
                .fold((usize::MAX, 0), |(lo, hi), n| (lo.min(n), hi.max(n))),
            Source::Sampler { sampler, .. } => (sampler.points_per_set(), sampler.points_per_set()),
        };
        match (self.density(), sizes) {
            (Some(density), _) => format!("random N, density {density}"),
            (None, (lo, hi)) if lo != hi => format!(
                "N = {lo} to {hi}, each set weighed by 1/N; --density gives a random-count process's 1/λ"
            ),
            (None, (n, _)) => format!("N = {n}"),
        }
    }

    /// Every realization, projected: a file's sets, or the sampler's
    /// `count()` draws made once (in parallel, each from its own stream) for
    /// commands that pass over them several times.
    pub fn realizations(&self) -> Result<Vec<PointSet>, SourceError> {
        use rayon::prelude::*;
        (0..self.count())
            .into_par_iter()
            .map(|r| self.get(r))
            .collect()
    }

    /// Number of realizations.
    pub fn count(&self) -> usize {
        match self {
            Source::File { sets, .. } => sets.len(),
            Source::Sampler { sets, .. } => *sets,
        }
    }

    /// A label for titles and messages.
    pub fn name(&self) -> &str {
        match self {
            Source::File { name, .. } | Source::Sampler { name, .. } => name,
        }
    }

    /// Realization r for estimators that need more realizations than the
    /// source holds: a file's sets are reused cyclically, a sampler draws
    /// fresh ones.
    pub fn get_cyclic(&self, r: usize) -> Result<PointSet, SourceError> {
        match self {
            Source::File { sets, .. } => self.get(r % sets.len()),
            Source::Sampler { .. } => self.get(r),
        }
    }

    /// Realization r, projected.
    pub fn get(&self, r: usize) -> Result<PointSet, SourceError> {
        let (set, dims) = match self {
            Source::File { sets, dims, .. } => (sets[r].clone(), dims),
            Source::Sampler {
                sampler,
                seed,
                dims,
                ..
            } => (sampler.sample(&mut set_rng(*seed, r as u64))?, dims),
        };
        match dims {
            Some(d) => set.projected(d).map_err(|error| SourceError::Projection {
                source_name: self.name().to_string(),
                error,
            }),
            None => Ok(set),
        }
    }
}
