//! Radially averaged power and anisotropy (Lagae & Dutré 2008, "A comparison
//! of methods for generating Poisson disk distributions", CGF 27(1), §4):
//! on rings of width 1 around DC, the mean power and the anisotropy
//! var/mean² of the power over the ring (an isotropic spectrum has about the
//! periodogram noise 1/R for R realizations; in decibels, 10·log10 of it).

use super::Spectrum;

/// One ring of a radial profile.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialBin {
    /// Ring radius: frequencies with round(|k|) = k.
    pub k: usize,
    /// Mean power over the ring.
    pub power: f64,
    /// Sample variance of the power over the ring / mean².
    pub anisotropy: f64,
    /// Frequencies in the ring.
    pub count: usize,
}

/// The radial profile of a spectrum for rings 1..=h (only rings that lie
/// wholly in the box), from two passes over the box: means, then centred
/// squares (no E[X²] − E[X]² cancellation).
pub fn radial_profile(spectrum: &Spectrum) -> Vec<RadialBin> {
    let freqs = spectrum.freqs;
    let h = freqs.half;
    let ring_of = |idx: usize, k: &mut [i64]| {
        freqs.frequency(idx, k);
        let r2: i64 = k.iter().map(|v| v * v).sum();
        (r2 as f64).sqrt().round() as usize
    };
    let mut k = vec![0i64; freqs.dim];
    let mut sum = vec![0.0; h + 1];
    let mut count = vec![0usize; h + 1];
    for (idx, &p) in spectrum.power.iter().enumerate() {
        let r = ring_of(idx, &mut k);
        if (1..=h).contains(&r) {
            sum[r] += p;
            count[r] += 1;
        }
    }
    let mean: Vec<f64> = sum
        .iter()
        .zip(&count)
        .map(|(s, &c)| if c > 0 { s / c as f64 } else { 0.0 })
        .collect();
    let mut centred = vec![0.0; h + 1];
    for (idx, &p) in spectrum.power.iter().enumerate() {
        let r = ring_of(idx, &mut k);
        if (1..=h).contains(&r) {
            centred[r] += (p - mean[r]).powi(2);
        }
    }
    (1..=h)
        .filter(|&r| count[r] > 1)
        .map(|r| {
            let var = centred[r] / (count[r] - 1) as f64;
            let anisotropy = if mean[r] > 0.0 {
                var / (mean[r] * mean[r])
            } else {
                0.0
            };
            RadialBin {
                k: r,
                power: mean[r],
                anisotropy,
                count: count[r],
            }
        })
        .collect()
}
