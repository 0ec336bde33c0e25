//! The radial (isotropic) form (Pilleboue et al. 2015, §5; the seed's
//! formula for isotropic sampling spectra): Var ≈ ∫ ρ^(d−1) P̃_S(ρ) P̃_f(ρ)
//! dρ from radially averaged spectra. On the integer frequencies of the box
//! the rings are round(|k|) = r, and the form is
//!
//!   Var_radial = (1/N) Σ_r n_r · P̄_S(r) · P̄_f(r) + tail/N,
//!
//! with n_r the frequencies of ring r (inside the box) and the same
//! Parseval tail as the Fourier form. It differs from the Fourier form's
//! in-box sum exactly by the rings' covariances,
//! (1/N) Σ_r Σ_(k∈r) (P_S(k) − P̄_S(r))·(P_f(k) − P̄_f(r)),
//! which vanish when either spectrum is isotropic and which the
//! Cauchy–Schwarz inequality bounds by (1/N) Σ_r n_r·σ_S(r)·σ_f(r): the
//! predictor's own error estimate, computed from the two radial profiles'
//! spreads alone. Where it fails: an axis-aligned integrand (a band) under
//! N-rooks or jitter, whose spectra both concentrate on the axes: the
//! radial average spreads the axes' zero power over the ring and predicts
//! the wrong rate.

use super::fourier::FourierParts;
use crate::spectrum::radial::{ring_moments, rings_of};
use crate::sum::NeumaierSum;

/// The radial prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialEstimate {
    /// (1/N) Σ_r n_r P̄_S(r) P̄_f(r) + tail/N (+ the Fourier form's count
    /// term for a random-count process).
    pub variance: f64,
    /// Cauchy–Schwarz bound on |radial − Fourier| inside the box:
    /// (1/N) Σ_r n_r σ_S(r) σ_f(r).
    pub anisotropy_bound: f64,
    /// The tail's error bound (shared with the Fourier form).
    pub truncation_bound: f64,
    /// Rings used.
    pub rings: usize,
}

/// The radial form from the Fourier form's spectra.
pub fn radial_from(parts: &FourierParts) -> RadialEstimate {
    let ring = rings_of(&parts.spectrum.freqs);
    let sampling = ring_moments(&ring, &parts.spectrum.power);
    let integrand = ring_moments(&ring, &parts.integrand_power);
    let rings = sampling.len();
    let (mut in_box, mut bound) = (NeumaierSum::default(), NeumaierSum::default());
    for (s, f) in sampling.iter().zip(&integrand).skip(1) {
        if s.count == 0 {
            continue;
        }
        in_box.add(s.count as f64 * s.mean * f.mean);
        // n·σ_S·σ_f with population standard deviations.
        bound.add((s.centred_squares * f.centred_squares).sqrt());
    }
    let nf = parts.intensity;
    RadialEstimate {
        variance: in_box.value() / nf + parts.estimate.tail + parts.estimate.count_term,
        anisotropy_bound: bound.value() / nf,
        truncation_bound: parts.estimate.truncation_bound,
        rings: rings.saturating_sub(1),
    }
}
