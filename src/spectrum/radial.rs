//! Radially averaged power and anisotropy (Lagae & Dutré 2008, "A comparison
//! of methods for generating Poisson disk distributions", CGF 27(1), §4):
//! on rings of width 1 around DC, the mean power and the anisotropy
//! var/mean² of the power over the ring (an isotropic spectrum has about the
//! periodogram noise 1/R for R realizations; in decibels, 10·log10 of it).

use super::{FrequencyBox, Spectrum};
use crate::sum::NeumaierSum;

/// One ring of a radial profile.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialBin {
    /// Ring radius: frequencies with round(|k|) = k.
    pub k: usize,
    /// Mean power over the ring.
    pub power: f64,
    /// Sample variance of the power over the ring / mean²; 0 on a ring of
    /// zero power (powers are ≥ 0, so a zero mean is a constant ring), and
    /// on one every power of which is at or below the spectrum's floor
    /// (`within_error`).
    pub anisotropy: f64,
    /// Every power of the ring is at or below the floor: what an exact 0
    /// can read after the method's error, so the ring may hold nothing (a
    /// lattice's empty rings) and its spread is the transform's error, not
    /// anisotropy.
    pub within_error: bool,
    /// Frequencies in the ring.
    pub count: usize,
}

/// The values of one ring round(|k|) = r of a frequency box.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RingMoments {
    /// Frequencies in the ring.
    pub count: usize,
    /// Their mean.
    pub mean: f64,
    /// Σ (value − mean)² over the ring.
    pub centred_squares: f64,
    /// The largest value.
    pub max: f64,
}

/// The ring round(|k|) of every frequency of `freqs`, in box order.
pub fn rings_of(freqs: &FrequencyBox) -> Vec<usize> {
    let mut k = vec![0i64; freqs.dim];
    (0..freqs.len())
        .map(|idx| {
            freqs.frequency(idx, &mut k);
            let r2: i64 = k.iter().map(|v| v * v).sum();
            (r2 as f64).sqrt().round() as usize
        })
        .collect()
}

/// The moments of `values` (one per frequency, box order, in the rings
/// `ring` of [`rings_of`]) on every ring r = 0 …, from two compensated
/// passes: means, then centred squares (no E[X²] − E[X]² cancellation).
/// Shared by the radial profile and the radial variance form.
pub fn ring_moments(ring: &[usize], values: &[f64]) -> Vec<RingMoments> {
    let rings = ring.iter().copied().max().map_or(0, |r| r + 1);
    let mut count = vec![0usize; rings];
    let mut sums = vec![NeumaierSum::default(); rings];
    let mut max = vec![f64::NEG_INFINITY; rings];
    for (&r, &v) in ring.iter().zip(values) {
        count[r] += 1;
        sums[r].add(v);
        max[r] = max[r].max(v);
    }
    let mean: Vec<f64> = sums
        .iter()
        .zip(&count)
        .map(|(s, &c)| if c > 0 { s.value() / c as f64 } else { 0.0 })
        .collect();
    let mut centred = vec![NeumaierSum::default(); rings];
    for (&r, &v) in ring.iter().zip(values) {
        centred[r].add((v - mean[r]).powi(2));
    }
    (0..rings)
        .map(|r| RingMoments {
            count: count[r],
            mean: mean[r],
            centred_squares: centred[r].value(),
            max: max[r],
        })
        .collect()
}

/// The radial profile of a spectrum for rings 1..=h (only rings that lie
/// wholly in the box) with at least two frequencies. `floor` is the power
/// an exact zero can show after the method's error
/// ([`Method::power_floor`](super::Method::power_floor); 0 for a closed
/// form): rings whose every power is at or below it have anisotropy 0.
pub fn radial_profile(spectrum: &Spectrum, floor: f64) -> Vec<RadialBin> {
    let h = spectrum.freqs.half;
    ring_moments(&rings_of(&spectrum.freqs), &spectrum.power)
        .into_iter()
        .enumerate()
        .filter(|&(r, m)| (1..=h).contains(&r) && m.count > 1)
        .map(|(r, m)| {
            let var = m.centred_squares / (m.count - 1) as f64;
            let within_error = m.max <= floor;
            let anisotropy = if m.mean > 0.0 && !within_error {
                var / (m.mean * m.mean)
            } else {
                0.0
            };
            RadialBin {
                k: r,
                power: m.mean,
                anisotropy,
                within_error,
                count: m.count,
            }
        })
        .collect()
}
