//! Optimizers (docs/mathematics.md §6): gradient descent on point positions to
//! minimize a weighted spectral loss ([`descent`], weights from
//! [`target`]), and the shear search for structured 4D sets ([`shear`]).

pub mod adam;
pub mod adapted;
pub mod checkpoint;
pub mod descent;
pub mod lattice;
pub mod projections;
pub mod repulsion;
pub mod shear;
pub mod target;

pub use adam::{
    AdamOptions, AdamState, Checkpointing, DescentResult, Domain, PointObjective, Stop, adam,
    adam_from,
};
pub use descent::{DescentOptions, PointOptimizer};
pub use target::Target;

/// What stops an optimization.
#[derive(Debug, thiserror::Error)]
pub enum OptimizeError {
    /// A target spec that cannot be used.
    #[error("target `{spec}`: {reason}")]
    Target {
        /// The spec.
        spec: String,
        /// What is wrong.
        reason: String,
    },
    /// A bad option value.
    #[error("{0}")]
    Option(String),
    /// The spectrum plan could not be made.
    #[error(transparent)]
    Spectrum(#[from] crate::spectrum::SpectrumError),
    /// A sampler failed.
    #[error(transparent)]
    Sampler(#[from] crate::samplers::SamplerError),
    /// The integrand spec is invalid.
    #[error(transparent)]
    Integrand(#[from] crate::integrands::IntegrandError),
    /// A point-set problem.
    #[error(transparent)]
    PointSet(#[from] crate::points::PointSetError),
    /// A variance predictor failed.
    #[error(transparent)]
    Variance(#[from] crate::variance::VarianceError),
    /// A checkpoint could not be resumed.
    #[error(transparent)]
    Checkpoint(#[from] checkpoint::CheckpointError),
    /// The run needs more memory than the budget.
    #[error(transparent)]
    Memory(#[from] crate::memory::TooMuchMemory),
    /// argmin reported an error.
    #[error("shear search failed: {0}")]
    Search(String),
}
