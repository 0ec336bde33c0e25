//! Three independent predictors of Var[Î] for the shift-randomized
//! estimator Î(s) = (1/N) Σ_j f(x_j + s mod 1) (docs/mathematics.md), which must
//! agree: [`spatial`] (exact, to rounding), [`fourier`] (within its reported
//! truncation bound) and [`empirical`] (within its confidence interval);
//! and the convergence-rate fit ([`convergence`]).
//!
//! Realizations are handed in as a function r ↦ point set (sets of a file,
//! or fresh draws of a sampler with stream (seed, r)), so sampler-level
//! predictions average the same realizations in every method.

pub mod closed_form;
pub mod convergence;
pub mod empirical;
pub mod fourier;
pub mod lattice;
pub mod measure;
pub mod paired;
pub mod radial;
pub mod sets;
pub mod spatial;
pub mod strips;

pub use closed_form::{ClosedForm, ExpectedVariance};
pub use convergence::{SlopeError, SlopeFit, fit_slope, theoretical_rate};
pub use empirical::{
    DEFAULT_SHIFT_SEED, EmpiricalEstimate, NORMAL_95, empirical, empirical_shifting,
    shifted_estimates,
};
pub use fourier::{FourierEstimate, FourierParts, fourier, fourier_expected, fourier_parts};
pub use lattice::{LatticeVariance, lattice_variance};
pub use measure::{
    SamplerVariance, VarianceForm, expected_min_half, fourier_half, sampler_variance,
    zero_to_rounding,
};
pub use paired::{VarianceRatio, paired_ratio};
pub use radial::{RadialEstimate, radial_from};
pub use sets::{
    MAX_AUTO_SETS, SetCount, TARGET_RELATIVE_STDERR, auto_set_cap, sets_for_relative_stderr,
};
pub use spatial::{
    SpatialEstimate, estimated_seconds, pair_evaluations, spatial, spatial_variance,
};

use crate::samplers::SamplerError;
use crate::spectrum::SpectrumError;

/// What stops a prediction.
#[derive(Debug, thiserror::Error)]
pub enum VarianceError {
    /// Points and integrand differ in dimension.
    #[error("the integrand is {integrand}-dimensional, the points are {points}-dimensional")]
    Dimension {
        /// Integrand dimension.
        integrand: usize,
        /// Point dimension.
        points: usize,
    },
    /// The spatial form needs a closed-form autocovariance.
    #[error(
        "the spatial predictor needs the integrand's autocovariance c_f, which {spec} does not have in closed form"
    )]
    NoAutocovariance {
        /// The integrand.
        spec: String,
    },
    /// The Fourier forms need the integrand's Fourier coefficients.
    #[error(
        "the Fourier predictor needs the integrand's Fourier coefficients, which {spec} does not have in closed form (use the empirical predictor)"
    )]
    NoFourier {
        /// The integrand.
        spec: String,
    },
    /// Realizations of different sizes in a Fourier prediction.
    #[error(
        "the Fourier predictor needs every set to have the same N (found {first} and {other}), \
         or to come from one random-count process of known density (point files: --density); \
         the spatial and empirical forms take sets of any N (--method spatial,empirical)"
    )]
    MixedSizes {
        /// One size.
        first: usize,
        /// Another.
        other: usize,
    },
    /// Realizations of random-count processes of different densities, or
    /// mixed with fixed-N sets, in a Fourier prediction.
    #[error(
        "the Fourier predictor needs every set from one process: found density {} and {} \
         (point files: give --density once for all sets)",
        density_text(*first), density_text(*other)
    )]
    MixedDensity {
        /// One set's density (`None`: a fixed-N set).
        first: Option<f64>,
        /// Another's.
        other: Option<f64>,
    },
    /// A realization could not be produced (a file's set, a projection).
    #[error("realization {index}: {message}")]
    Realization {
        /// Which realization.
        index: usize,
        /// What went wrong.
        message: String,
    },
    /// A set without points: Î = (1/N) Σ f(x_i) is undefined for N = 0.
    #[error(
        "{what} needs at least one point per set (the estimator (1/N) Σ f(x_i) is undefined for N = 0)"
    )]
    NoPoints {
        /// The predictor.
        what: &'static str,
    },
    /// Too few realizations for a variance.
    #[error("{what} needs at least {needed} realizations, got {got}")]
    TooFew {
        /// The estimate.
        what: &'static str,
        /// Required.
        needed: usize,
        /// Given.
        got: usize,
    },
    /// A sampler failed to produce a realization.
    #[error(transparent)]
    Sampler(#[from] SamplerError),
    /// The spectrum could not be computed.
    #[error(transparent)]
    Spectrum(#[from] SpectrumError),
    /// The results would not fit in memory.
    #[error(transparent)]
    Memory(#[from] crate::memory::TooMuchMemory),
}

fn density_text(d: Option<f64>) -> String {
    d.map_or("none (a fixed-N set)".into(), |v| v.to_string())
}

/// The variance a random count adds to one set's squared error,
/// (N/λ − 1)²·I² for N points drawn by a process of density λ (exactly 0
/// when the intensity is N itself; docs/mathematics.md §2, "A random number
/// of points"). The spatial and Fourier forms both add it.
fn count_term(points: usize, intensity: f64, integral: f64) -> f64 {
    (points as f64 / intensity - 1.0).powi(2) * integral * integral
}
