//! Integration lattices searched for one integrand: the structure a
//! discontinuous or smooth 2D target asks for, found exactly.
//!
//! Every 2D integration lattice of N points ([`lattices`]) is a candidate,
//! ranked by its exact shift-randomized variance, an N-term sum
//! ([`lattice_variance`]; Cranley & Patterson 1976; Sloan & Joe 1994, §2):
//! all of them, or, when that costs more than [`EXACT_BUDGET`] evaluations
//! of c_f, the best [`FINALISTS`] of a screen by the dual sum over
//! |k|∞ ≤ 4√N ([`lattice::dual_sum`]).

use rayon::prelude::*;

use super::OptimizeError;
use crate::integrands::Integrand;
use crate::samplers::lattice::{Lattice, MAX_POINTS, lattices};
use crate::variance::lattice::{self, lattice_variance};

/// Evaluations of c_f the exhaustive exact ranking may spend (σ(N)·N).
pub const EXACT_BUDGET: u64 = 1 << 26;
/// Lattices ranked exactly after the dual-sum screen.
pub const FINALISTS: usize = 32;

/// The best lattice found for an integrand.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LatticeDesign {
    /// The lattice.
    pub lattice: Lattice,
    /// Its exact shift-randomized variance (spatial form).
    pub variance: f64,
    /// Bound on the rounding error of `variance`.
    pub rounding_bound: f64,
    /// Where `variance` is at its rounding floor: Σ P_f over the dual
    /// lattice in 0 < |k|∞ ≤ K, with K, which ranked the lattices instead.
    pub dual_sum: Option<(f64, i64)>,
    /// Lattices of N points (σ(N)).
    pub candidates: usize,
    /// Lattices ranked by the exact form (all, or the screen's finalists).
    pub ranked_exactly: usize,
}

/// The integration lattice of `n` points with the smallest shift-randomized
/// variance for `f`. Ties (a smooth f, e.g. a cosine, is integrated exactly
/// by most lattices) go to the lattice with the longest shortest dual
/// vector ([`Lattice::shortest_dual`]: the one best for integrands in
/// general, not N points on one line), then to the first in [`lattices`]
/// order.
///
/// # Errors
/// [`OptimizeError::Option`] for N = 0 or above [`MAX_POINTS`], or a
/// target that is not 2D or has no closed-form autocovariance.
pub fn best_lattice(n: usize, f: &dyn Integrand) -> Result<LatticeDesign, OptimizeError> {
    if n == 0 || n > MAX_POINTS {
        return Err(OptimizeError::Option(format!(
            "a lattice search needs 1 <= N <= {MAX_POINTS}, got N = {n}"
        )));
    }
    if f.dim() != 2 || !f.has_autocov() {
        return Err(OptimizeError::Target {
            spec: f.spec(),
            reason: "a lattice search needs a 2D integrand with a closed-form autocovariance \
                     (cos, disk, box, gaussian, halfplane)"
                .into(),
        });
    }
    let all = lattices(n);
    let exact_cost = all.len() as u64 * n as u64;
    let finalists: Vec<Lattice> = if exact_cost <= EXACT_BUDGET {
        all.clone()
    } else {
        let half = (4.0 * (n as f64).sqrt()).ceil() as i64;
        let mut screened: Vec<(f64, usize)> = all
            .par_iter()
            .enumerate()
            .map(|(i, l)| (lattice::dual_sum(l, f, half), i))
            .collect();
        screened.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let mut keep: Vec<usize> = screened.iter().take(FINALISTS).map(|s| s.1).collect();
        keep.sort_unstable();
        keep.into_iter().map(|i| all[i]).collect()
    };
    let ranked: Vec<(f64, f64)> = finalists
        .par_iter()
        .map(|l| lattice_variance(l, f).map(|v| (v.variance, v.rounding_bound)))
        .collect::<Result<_, _>>()?;
    let spread = |i: usize| finalists[i].spectral_test();
    let first_min = |scores: &[(usize, f64)]| {
        scores
            .iter()
            .min_by(|x, y| {
                x.1.total_cmp(&y.1)
                    .then(spread(y.0).cmp(&spread(x.0)))
                    .then(x.0.cmp(&y.0))
            })
            .map(|s| s.0)
            .expect("at least the N x 1 lattice")
    };
    let exact: Vec<(usize, f64)> = ranked.iter().map(|r| r.0).enumerate().collect();
    let mut best = first_min(&exact);
    let mut dual_sum = None;
    // A smooth f can leave several lattices at the spatial form's rounding
    // floor; the dual sum (nonnegative terms, P_f decaying fast) ranks them.
    let at_floor: Vec<usize> = (0..ranked.len())
        .filter(|&i| ranked[i].0 <= ranked[i].1)
        .collect();
    if at_floor.len() > 1 && at_floor.contains(&best) {
        let half = (8.0 * (n as f64).sqrt()).ceil() as i64;
        let sums: Vec<(usize, f64)> = at_floor
            .par_iter()
            .map(|&i| (i, lattice::dual_sum(&finalists[i], f, half)))
            .collect();
        best = first_min(&sums);
        dual_sum = sums.iter().find(|s| s.0 == best).map(|s| (s.1, half));
    }
    Ok(LatticeDesign {
        lattice: finalists[best],
        variance: ranked[best].0,
        rounding_bound: ranked[best].1,
        dual_sum,
        candidates: all.len(),
        ranked_exactly: finalists.len(),
    })
}
