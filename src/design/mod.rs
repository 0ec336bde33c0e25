//! Design runs as library calls, one per domain: the optimizers of
//! [`crate::optimize`] and [`crate::square`] applied to a request, started
//! from the registry's samplers and scored against the classic samplers
//! ([`crate::baseline`]), with the report `optimize points` writes. They sit
//! above the registry (which registers the optimizer as a sampler), so the
//! optimizers themselves never name it.

pub mod projections;
pub mod square;
pub mod torus;

use serde::Serialize;

/// What every design report starts with (flattened into it).
#[derive(Debug, Clone, Serialize)]
pub struct DesignRun {
    /// "torus" or "square".
    pub domain: &'static str,
    /// The target spec.
    pub target: String,
    /// Points per set.
    pub n: usize,
    /// Dimension.
    pub dim: usize,
    /// Number of sets.
    pub sets: usize,
    /// Seed of the starts.
    pub seed: u64,
    /// The starting sampler.
    pub init: String,
    /// Wall time of the design, seconds.
    pub seconds: f64,
}
