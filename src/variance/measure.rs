//! The sampler-level variance one number per (sampler, integrand, N) stands
//! for, as `converge` and `experiment` tabulate it: the mean over the
//! realizations of the exact spatial form where the integrand has a
//! closed-form autocovariance, else the Fourier form with its Parseval tail
//! on a box sized for the dimension (|k|∞ ≤ 127 in 2D, 31 in 3D, 10 in 4D:
//! 21⁴ ≈ 190,000 frequencies, not the 255⁴ a 2D box would ask for in 4D).

use super::{VarianceError, fourier, spatial};
use crate::integrands::Integrand;
use crate::points::PointSet;

/// Which form of the variance to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarianceForm {
    /// The spatial form where the integrand has a closed-form
    /// autocovariance, else the Fourier form on [`fourier_half`]'s box.
    Auto,
    /// The exact spatial form (refused without a closed-form
    /// autocovariance).
    Spatial,
    /// The Fourier form on the box |k|∞ ≤ `half`.
    Fourier {
        /// Box half-width.
        half: usize,
    },
}

/// A sampler-level variance.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SamplerVariance {
    /// Mean over realizations.
    pub variance: f64,
    /// Standard error of that mean over the realizations.
    pub stderr: f64,
    /// The Fourier form's truncation bound (0 for the spatial form).
    pub truncation_bound: f64,
    /// The form's bound on its rounding (the spatial form's compensated
    /// sums, largest over the realizations; the Fourier form's transform
    /// tolerance and Parseval tail): a variance at or below it is zero to
    /// rounding (a lattice integrating a cosine exactly).
    pub rounding_bound: f64,
    /// `spatial` or `fourier`.
    pub method: &'static str,
}

/// Whether `value` (a variance, or its standard error) is zero to
/// rounding: at or below a positive rounding bound (0 means no bound).
pub fn zero_to_rounding(value: f64, rounding_bound: f64) -> bool {
    rounding_bound > 0.0 && value <= rounding_bound
}

/// The Fourier box half-width used for `dim`-dimensional integrands.
pub fn fourier_half(dim: usize) -> usize {
    match dim {
        1 => 1023,
        2 => 127,
        3 => 31,
        _ => 10,
    }
}

/// The smallest box half-width a closed-form expected spectrum
/// ([`super::fourier_expected`]) is evaluated on for N points by default:
/// ⌈4√N⌉ in 2D, where a stratified set's spectrum rises to white noise near
/// k ≈ √N and a fixed box would leave that rise to the tail estimate (CMJ at
/// N = 65,536 on a 255² box: truncation bound 2× the value; on 2049²: 5%);
/// 0 (no minimum) in other dimensions, where the box grows as K^d.
pub fn expected_min_half(dim: usize, n: usize) -> usize {
    if dim == 2 {
        (4.0 * (n as f64).sqrt()).ceil() as usize
    } else {
        0
    }
}

/// The variance of the shift-randomized estimator averaged over `sets`
/// realizations, by the form `form` says (`converge --method`; `Auto` for
/// `experiment`).
///
/// # Errors
/// As [`spatial`] and [`fourier`].
pub fn sampler_variance<E>(
    f: &dyn Integrand,
    sets: usize,
    form: VarianceForm,
    realization: impl Fn(usize) -> Result<PointSet, E> + Sync,
) -> Result<SamplerVariance, VarianceError>
where
    VarianceError: From<E>,
    E: Send,
{
    let by_fourier = |half: usize| -> Result<SamplerVariance, VarianceError> {
        let p = fourier(f, half, 1e-10, sets, &realization)?;
        Ok(SamplerVariance {
            variance: p.variance,
            stderr: p.stderr,
            truncation_bound: p.truncation_bound,
            rounding_bound: p.rounding_bound,
            method: "fourier",
        })
    };
    if let VarianceForm::Fourier { half } = form {
        return by_fourier(half);
    }
    match spatial(f, sets, &realization) {
        Ok(p) => Ok(SamplerVariance {
            variance: p.variance,
            stderr: p.stderr,
            truncation_bound: 0.0,
            rounding_bound: p.rounding_bound,
            method: "spatial",
        }),
        Err(VarianceError::NoAutocovariance { .. }) if form == VarianceForm::Auto => {
            by_fourier(fourier_half(f.dim()))
        }
        Err(e) => Err(e),
    }
}
