//! The spatial form (docs/mathematics.md; the torus version of Öztireli 2016,
//! "Integration with stochastic point processes", ACM TOG 35(5), Eq. (9)):
//!
//! Var_s[Î] = (1/N²) Σ_(i,j) c_f(x_i − x_j)
//!          = (1/N²) [N·c_f(0) + 2 Σ_(i<j) c_f(x_i − x_j)],
//!
//! exact with no truncation. For a set with a density λ (a random number of
//! points, weight w = 1/λ) the mean squared error of Î = w Σ f(x_j + s) is
//! w² Σ_(i,j) c_f(x_i − x_j) + (wN − 1)² I², whose mean over realizations is
//! the variance (docs/mathematics.md §2, "A random number of points"); with
//! w = 1/N the second term is exactly 0. Terms are autocovariances (never
//! autocorrelations minus I²), summed with Neumaier compensation in fixed
//! row blocks reduced in order, so the result is identical for any thread
//! count. For integrands whose autocorrelation has compact support of
//! radius ρ (disks, boxes), pairs farther apart contribute exactly −I² each:
//! only close pairs are visited (cell grid) and the rest are counted.

use rayon::prelude::*;

use super::VarianceError;
use crate::integrands::Integrand;
use crate::neighbours::CellGrid;
use crate::points::PointSet;
use crate::sum::NeumaierSum;

/// Rows per parallel task (fixed: the reduction order must not depend on
/// the thread count).
const ROWS: usize = 32;

/// The autocovariance support radius below which [`spatial_variance`]
/// visits only close pairs (with more than [`GRID_MIN_POINTS`] points).
const GRID_MAX_SUPPORT: f64 = 0.25;

/// Points above which a small support is worth the cell grid.
const GRID_MIN_POINTS: usize = 64;

/// The support radius [`spatial_variance`] restricts its pairs to, if any.
fn grid_support(f: &dyn Integrand, n: usize) -> Option<f64> {
    f.autocov_support()
        .filter(|&r| r < GRID_MAX_SUPPORT && n > GRID_MIN_POINTS)
}

/// Pair evaluations [`spatial_variance`] makes on one set of `n` points:
/// the n(n−1)/2 distinct pairs, or the expected number within the
/// autocovariance's support (a ball of its radius on the unit torus) when
/// only close pairs are visited.
pub fn pair_evaluations(f: &dyn Integrand, n: usize) -> f64 {
    let pairs = n as f64 * (n as f64 - 1.0) / 2.0;
    let Some(r) = grid_support(f, n) else {
        return pairs;
    };
    let pi = std::f64::consts::PI;
    let ball = match f.dim() {
        1 => 2.0 * r,
        2 => pi * r * r,
        3 => 4.0 / 3.0 * pi * r.powi(3),
        _ => pi * pi / 2.0 * r.powi(4),
    };
    pairs * ball.min(1.0)
}

/// Timings of the probe set [`estimated_seconds`] takes the fastest of.
const PROBE_TIMINGS: usize = 3;

/// Seconds [`spatial`] would take here on every (N, sets) of `runs`, sets
/// of `f`'s dimension: one set of min(largest N, 2048) random points is
/// timed ([`PROBE_TIMINGS`] times, the fastest kept) and the time scaled
/// by [`pair_evaluations`] (the cost is O(N²) per set, so a request can
/// run for days; commands say so before they start).
///
/// # Errors
/// As [`spatial_variance`] (an integrand without c_f).
pub fn estimated_seconds(f: &dyn Integrand, runs: &[(usize, usize)]) -> Result<f64, VarianceError> {
    let largest = runs.iter().map(|&(n, _)| n).max().unwrap_or(0);
    let probe = largest.clamp(2, 2048);
    let mut rng = crate::rng::set_rng(0, 0);
    let coords = (0..probe * f.dim())
        .map(|_| crate::rng::uniform(&mut rng))
        .collect();
    let set = PointSet::new(f.dim(), coords).expect("uniform values lie in [0, 1)");
    // The fastest of three timings: the first call also pays for starting
    // the thread pool, and a busy moment slows any one (single timings
    // varied 3× between runs).
    let mut fastest = f64::INFINITY;
    for _ in 0..PROBE_TIMINGS {
        let start = std::time::Instant::now();
        spatial_variance(&set, f)?;
        fastest = fastest.min(start.elapsed().as_secs_f64());
    }
    let per_pair = fastest / pair_evaluations(f, probe).max(1.0);
    Ok(runs
        .iter()
        .map(|&(n, sets)| per_pair * sets as f64 * pair_evaluations(f, n))
        .sum())
}

/// The spatial prediction, averaged over realizations.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialEstimate {
    /// Mean over realizations of Var_s[Î | X].
    pub variance: f64,
    /// Bound on the rounding error of the compensated sums, 4ε·Σ|terms|/N²
    /// (largest over realizations): the spatial form sums N² terms of size
    /// up to c_f(0), so a variance far below c_f(0)/N² is resolved only to
    /// this level.
    pub rounding_bound: f64,
    /// Standard error of that mean (0 for one realization).
    pub stderr: f64,
    /// Realizations averaged.
    pub sets: usize,
}

/// Var_s[Î] for one point set under uniform random shifts (its mean squared
/// error E_s[(Î − I)²] for a set with a density), with the bound on its
/// rounding error (see [`SpatialEstimate::rounding_bound`]).
///
/// # Errors
/// [`VarianceError::Dimension`], or [`VarianceError::NoAutocovariance`] for
/// integrands without closed-form c_f.
pub fn spatial_variance(points: &PointSet, f: &dyn Integrand) -> Result<(f64, f64), VarianceError> {
    let (n, d) = (points.len(), points.dim());
    if d != f.dim() || d > 4 {
        return Err(VarianceError::Dimension {
            integrand: f.dim(),
            points: d,
        });
    }
    let zero = vec![0.0; d];
    let c0 = f
        .autocov(&zero)
        .ok_or_else(|| VarianceError::NoAutocovariance { spec: f.spec() })?;
    if n == 0 && points.density().is_none() {
        // Î = (1/N) Σ f(x_i) is undefined: no variance to report (with a
        // density, Î = 0 and the loops below are empty).
        return Err(VarianceError::NoPoints {
            what: "the spatial predictor",
        });
    }
    let pair = |i: usize, j: usize| {
        f.autocov_between(points.point(i), points.point(j))
            .expect("checked above")
    };
    let support = grid_support(f, n);
    let off_diagonal = match support {
        Some(radius) => {
            // Close pairs exactly; each of the remaining pairs adds exactly −I².
            let grid = CellGrid::new(points);
            let i2 = f.integral() * f.integral();
            let blocks: Vec<(NeumaierSum, f64, u64)> = (0..n.div_ceil(ROWS))
                .into_par_iter()
                .map(|b| {
                    let (mut s, mut abs, mut close) = (NeumaierSum::default(), 0.0, 0u64);
                    for i in b * ROWS..((b + 1) * ROWS).min(n) {
                        grid.for_each_within(i, radius, |j, _| {
                            if j > i {
                                let c = pair(i, j);
                                s.add(c);
                                abs += c.abs();
                                close += 1;
                            }
                        });
                    }
                    (s, abs, close)
                })
                .collect();
            let (mut total, mut abs, mut close) = (NeumaierSum::default(), 0.0, 0u64);
            for (s, a, c) in blocks {
                total.merge(s);
                abs += a;
                close += c;
            }
            let far = (n as u64 * (n as u64 - 1)) / 2 - close;
            total.add(-(far as f64) * i2);
            (total.value(), abs + far as f64 * i2)
        }
        None => {
            let blocks: Vec<(NeumaierSum, f64)> = (0..n.div_ceil(ROWS))
                .into_par_iter()
                .map(|b| {
                    let (mut s, mut abs) = (NeumaierSum::default(), 0.0);
                    for i in b * ROWS..((b + 1) * ROWS).min(n) {
                        for j in i + 1..n {
                            let c = pair(i, j);
                            s.add(c);
                            abs += c.abs();
                        }
                    }
                    (s, abs)
                })
                .collect();
            let (mut total, mut abs) = (NeumaierSum::default(), 0.0);
            for (s, a) in blocks {
                total.merge(s);
                abs += a;
            }
            (total.value(), abs)
        }
    };
    let (off_diagonal, off_abs) = off_diagonal;
    let mut v = NeumaierSum::default();
    v.add(n as f64 * c0);
    v.add(2.0 * off_diagonal);
    let intensity = points.intensity();
    let n2 = intensity * intensity;
    let rounding = 4.0 * f64::EPSILON * (n as f64 * c0.abs() + 2.0 * off_abs) / n2;
    // w² Σ c_f is a variance, non-negative; a negative total is rounding
    // noise, within `rounding` of 0. Then (wN − 1)² I²: exactly 0 for
    // w = 1/N, the random count's cost otherwise.
    let pairs = (v.value() / n2).max(0.0);
    Ok((
        pairs + super::count_term(n, intensity, f.integral()),
        rounding,
    ))
}

/// The spatial prediction averaged over `sets` realizations.
///
/// # Errors
/// As [`spatial_variance`], plus a failing realization.
pub fn spatial<E>(
    f: &dyn Integrand,
    sets: usize,
    realization: impl Fn(usize) -> Result<crate::points::PointSet, E> + Sync,
) -> Result<SpatialEstimate, VarianceError>
where
    VarianceError: From<E>,
{
    if sets == 0 {
        return Err(VarianceError::TooFew {
            what: "the spatial predictor",
            needed: 1,
            got: 0,
        });
    }
    let mut per_set = Vec::with_capacity(sets);
    let mut rounding_bound: f64 = 0.0;
    for r in 0..sets {
        let (v, rounding) = spatial_variance(&realization(r)?, f)?;
        per_set.push(v);
        rounding_bound = rounding_bound.max(rounding);
    }
    let (mean, stderr) = crate::sum::mean_and_stderr(&per_set);
    Ok(SpatialEstimate {
        variance: mean,
        rounding_bound,
        stderr,
        sets,
    })
}

#[cfg(test)]
mod tests {
    use super::pair_evaluations;
    use crate::integrands;

    #[test]
    fn pair_evaluations_count_the_pairs_the_form_visits() {
        // Support 0.6 (disk r = 0.3): every distinct pair.
        let wide = integrands::parse("disk:r=0.3").unwrap();
        assert_eq!(pair_evaluations(wide.as_ref(), 1000), 499_500.0);
        // Support 0.2 (< 0.25): the pairs within a disk of radius 0.2.
        let small = integrands::parse("disk:r=0.1").unwrap();
        let expected = 499_500.0 * std::f64::consts::PI * 0.04;
        assert!((pair_evaluations(small.as_ref(), 1000) - expected).abs() < 1e-6 * expected);
        // 64 points or fewer: no cell grid, every pair.
        assert_eq!(pair_evaluations(small.as_ref(), 64), 2016.0);
    }
}
