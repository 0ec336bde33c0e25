//! The closed-form expectation beyond the Fourier box, along the axes.
//!
//! The Parseval tail of the Fourier form (see [`super::fourier`]) weighs
//! every frequency outside the box B by the white-noise level, E[N·P_S] = 1.
//! N-rooks samplers (multi-jitter, correlated multi-jitter) break that
//! where it matters most: their x and y projections hold one point per
//! 1/N stratum, so near the axes δ(k) = E[N·P_S(k)] − 1 ≈ −sinc²(πk_x/N)
//! stays near −1 out to |k_x| ≈ N, far beyond a box of half-width ~4√N —
//! and an axis-aligned edge (the default `box`, a square's border) puts
//! its energy there, P_f falling only as |k_x|⁻². The white tail then
//! counts as variance what the strata integrate away: CMJ at N = 1024 on
//! `box:w=0.5,h=0.25` predicted 7.04e-7 against the spatial form's
//! 3.50e-7.
//!
//! With a closed form the deviation is known at every frequency, so the
//! tail is summed exactly over the four axis strips S = {h < |k_a| ≤ M,
//! |k_b| ≤ w} (a, b the two axes): Σ_(k∈S) P_f(k)·δ(k) corrects the white
//! tail there, and only the rest is left to the shell's estimate (the
//! bound adds the strips' continuation beyond M: [`super::fourier`]). The
//! strips' reach is M = 2N (past the N-rooks strata's scale N, where δ on
//! the axis has its first zero) and their half-width w = ⌈√N/2⌉ (half the
//! jitter cells' frequency, where the cells still couple the rows to the
//! axis), within a budget of [`STRIP_BUDGET`] evaluations: w within the
//! box's own half-width, M shortened to fit (to ≈ N at N = 65,536).
//! Measured (CMJ, N = 4096, `box:w=0.5,h=0.5`; spatial form over 256 sets
//! 2.6520e-8 ± 0.0065e-8): w = 16 gives 2.6845e-8, w = 32 2.6526e-8,
//! reach 4N instead of N changes the fifth digit; the white tail gave
//! 1.0365e-7. At N = 65,536 on the default `box` (empirical over 256 sets
//! 8.37e-11, 95% CI [8.07e-11, 8.70e-11]): reach N 8.45e-11, reach N/4
//! 1.08e-10, the white tail 1.16e-9.
//!
//! 2D closed forms only: a padded 4D sampler's light fields carry their
//! energy on sheared planes, not on the axes.

use rayon::prelude::*;

use crate::integrands::Integrand;
use crate::samplers::ClosedFormSpectrum;
use crate::sum::NeumaierSum;

/// Most (P_f, E[N·P_S]) evaluations the strips may take: reach 2N up to
/// N = 16,384, ≈ N at 65,536 (where `predict --method expected` on the
/// default box takes 3.1 s on 2 cores, 1.5 s without the strips).
pub const STRIP_BUDGET: usize = 1 << 25;

/// The strips' sums and shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisStrips {
    /// Σ_(k∈S) P_f(k)·(E[N·P_S(k)] − 1): what the white tail gets wrong
    /// on the strips.
    pub correction: f64,
    /// Σ_(k∈S) P_f(k): the part of the tail mass the strips hold.
    pub mass: f64,
    /// The half-width w: |k_b| ≤ w across the strip.
    pub width: usize,
    /// The reach M: h < |k_a| ≤ M along it.
    pub reach: usize,
    /// The P_f-weighted mean deviation E[N·P_S] − 1 over the strips' outer
    /// half ((h + M)/2 < |k_a| ≤ M): what the strips beyond M are taken to
    /// continue, for the bound.
    pub outer_deviation: f64,
}

/// The strips' half-width and reach for N points beyond a box of
/// half-width `half`, within [`STRIP_BUDGET`]; `None` when 2N ≤ `half` (the
/// box already reaches past the strata's scale).
pub fn strip_shape(points: usize, half: usize) -> Option<(usize, usize)> {
    // The reach aims at 2N: past the strata's scale N, where δ has fallen
    // to its first zero on the axis and decays as (N/πk)² after it.
    let aim = 2 * points;
    if aim <= half {
        return None;
    }
    let width = ((points as f64).sqrt() / 2.0).ceil() as usize;
    let width = width.clamp(1, half.max(1));
    // Two strips (their mirror images give the same sums) of (M − h) rows
    // of 2w + 1 frequencies.
    let per_row = 2 * (2 * width + 1);
    let rows = (aim - half).min(STRIP_BUDGET / per_row).max(1);
    Some((width, half + rows))
}

/// Rows of a strip per parallel task.
const ROWS_PER_TASK: usize = 64;

/// The strips' sums for a 2D closed form beyond the box of half-width
/// `half` (`None` for 4D, or when the box already reaches N).
///
/// P_f(−k) = P_f(k) for a real f and E[P_S(−k)] = E[P_S(k)] for real
/// points, so the strips at k_a < −h are the mirror images of those at
/// k_a > h: two are summed and doubled. Deterministic for any thread
/// count: fixed runs of rows are summed apart and merged in order.
pub fn axis_strips(
    f: &dyn Integrand,
    closed: &ClosedFormSpectrum,
    half: usize,
) -> Option<AxisStrips> {
    if closed.dim() != 2 || f.dim() != 2 {
        return None;
    }
    let (width, reach) = strip_shape(closed.points(), half)?;
    let w = width as i64;
    let across: Vec<f64> = (-w..=w).map(|b| b as f64).collect();
    let along: Vec<i64> = (half as i64 + 1..=reach as i64).collect();
    let outer_from = (half as i64 + reach as i64) / 2;
    let runs: Vec<[NeumaierSum; 4]> = along
        .par_chunks(ROWS_PER_TASK)
        .map(|rows| {
            let xs: Vec<f64> = rows.iter().map(|&a| a as f64).collect();
            // Along x (rows × across) and along y (across × rows).
            let horizontal = closed.power_grid(&xs, &across)?;
            let vertical = closed.power_grid(&across, &xs)?;
            // Σ P_f·δ and Σ P_f over all rows, then over the outer half.
            let mut sums = [NeumaierSum::default(); 4];
            for (i, &a) in rows.iter().enumerate() {
                for (j, b) in (-w..=w).enumerate() {
                    for (k, power) in [
                        ([a, b], horizontal[i * across.len() + j]),
                        ([b, a], vertical[j * rows.len() + i]),
                    ] {
                        let pf = f.fourier(&k).norm_sqr();
                        let terms = [pf * (power - 1.0), pf];
                        let parts = if a > outer_from { 0..4 } else { 0..2 };
                        for p in parts {
                            sums[p].add(terms[p % 2]);
                        }
                    }
                }
            }
            Some(sums)
        })
        .collect::<Option<_>>()?;
    let mut total = [NeumaierSum::default(); 4];
    for run in runs {
        for (t, s) in total.iter_mut().zip(run) {
            t.merge(s);
        }
    }
    let [correction, mass, outer, outer_mass] = total.map(|t| t.value());
    Some(AxisStrips {
        correction: 2.0 * correction,
        mass: 2.0 * mass,
        width,
        reach,
        outer_deviation: if outer_mass > 0.0 {
            outer / outer_mass
        } else {
            0.0
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_follows_the_rule_and_the_budget() {
        // N = 4096 beyond h = 256: w = 32, M = 2N (2·7936·65 evaluations).
        assert_eq!(strip_shape(4096, 256), Some((32, 8192)));
        // The box already reaches 2N: nothing beyond it to correct.
        assert_eq!(strip_shape(128, 256), None);
        // N = 65,536, h = 1024: w = 128, the budget shortens the reach to
        // h + ⌊2^25 / (2·257)⌋ rows.
        assert_eq!(strip_shape(65536, 1024), Some((128, 1024 + 65280)));
        // A narrow box caps the width at its own half-width.
        assert_eq!(strip_shape(4096, 8), Some((8, 8192)));
    }
}
