//! A sampler's expected variance without drawing a set, in the most exact
//! closed form it has:
//!
//! - **a lattice sum** when every realization is a shifted integration
//!   lattice (the regular grid, uniform jitter, the lattice rule) and the
//!   integrand has a closed-form autocovariance: (1/N) Σ_(x∈L) c_f(x), exact
//!   with no truncation ([`super::lattice`]);
//! - otherwise **the expected power** E[N·P_S] of samplers with independent
//!   strata, summed with P_f over a frequency box and completed by the
//!   Parseval tail ([`fourier_expected`]; Pilleboue et al. 2015, Eq. (9)).
//!
//! The lattice sum replaces the Fourier form for lattices because a
//! lattice's power is N at its dual points and 0 elsewhere: whatever the
//! box, the tail beyond it is not white, and the Fourier form's bound on it
//! is the worst case (15× the value for uniform jitter of 256 points on a
//! disk, whose true error there is 0.24%).

use super::lattice::lattice_variance;
use super::{FourierEstimate, VarianceError, fourier_expected};
use crate::integrands::Integrand;
use crate::samplers::{ClosedFormSpectrum, Lattice, Sampler};

/// Which closed form a (sampler, integrand) pair has.
#[derive(Clone, Copy)]
pub enum ClosedForm<'a> {
    /// Every realization is this lattice under a uniform shift, and the
    /// integrand has c_f.
    Lattice(Lattice),
    /// The sampler's expected power, and the integrand has Fourier
    /// coefficients.
    Spectrum(ClosedFormSpectrum<'a>),
}

/// A sampler's expected variance from its closed form.
#[derive(Debug, Clone, PartialEq)]
pub struct ExpectedVariance {
    /// The expected variance of the shift-randomized estimator.
    pub variance: f64,
    /// Bound on the error of the Fourier form's tail (0 for a lattice sum).
    pub truncation_bound: f64,
    /// Bound on what floating point puts into `variance`.
    pub rounding_bound: f64,
    /// The Fourier form's parts (box, tail, strips); `None` for a lattice
    /// sum.
    pub fourier: Option<FourierEstimate>,
}

impl<'a> ClosedForm<'a> {
    /// The closed form of `sampler` for `f`, if they have one.
    pub fn of(sampler: &'a dyn Sampler, f: &dyn Integrand) -> Option<Self> {
        if let Some(lattice) = sampler.lattice()
            && f.dim() == 2
            && f.has_autocov()
        {
            return Some(ClosedForm::Lattice(lattice));
        }
        ClosedFormSpectrum::of(sampler)
            .filter(|c| c.dim() == f.dim() && f.has_fourier())
            .map(ClosedForm::Spectrum)
    }

    /// What the form is, for tables and JSON: `lattice sum` or `fourier`.
    pub fn name(&self) -> &'static str {
        match self {
            ClosedForm::Lattice(_) => "lattice sum",
            ClosedForm::Spectrum(_) => "fourier",
        }
    }

    /// The expected variance for `f`; `half` is the Fourier form's box
    /// half-width (unused by a lattice sum, which has no box).
    ///
    /// # Errors
    /// [`VarianceError`] from the form ([`lattice_variance`],
    /// [`fourier_expected`]).
    pub fn variance(
        &self,
        f: &dyn Integrand,
        half: usize,
    ) -> Result<ExpectedVariance, VarianceError> {
        Ok(match self {
            ClosedForm::Lattice(lattice) => {
                let v = lattice_variance(lattice, f)?;
                ExpectedVariance {
                    variance: v.variance,
                    truncation_bound: 0.0,
                    rounding_bound: v.rounding_bound,
                    fourier: None,
                }
            }
            ClosedForm::Spectrum(closed) => {
                let e = fourier_expected(f, half, closed)?.estimate;
                ExpectedVariance {
                    variance: e.variance,
                    truncation_bound: e.truncation_bound,
                    rounding_bound: e.rounding_bound,
                    fourier: Some(e),
                }
            }
        })
    }
}
