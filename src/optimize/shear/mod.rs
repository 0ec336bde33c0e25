//! Shear search for padded 4D sets (Singh & Jarosz 2017, "Convergence
//! analysis for anisotropic Monte Carlo sampling spectra", ACM TOG 36(4)):
//! shear x′ = x + a·u, y′ = y + b·v (mod 1) and choose (a, b) to minimize
//! the expected variance of the (x, y)-shifted estimator over the
//! sampler's own randomness ([`objective`]), starting from the direction of
//! the integrand's spectrum ([`start`]).
//!
//! The search: evaluate J at the spectral candidates and at (0, 0); refine
//! a, then b, by scans at shrinking scales: 0.1 over the whole range on a
//! coarse J (the low frequencies, whose basins are wide; J itself then
//! ranks its deepest local minima), 0.01 around the best on J (a hairline
//! spectrum has a basin narrower than a coarse grid step), and Brent's
//! method in the last interval; polish (a, b)
//! jointly with Nelder–Mead (both from argmin). Where the spectrum lies on
//! one line and J cannot tell that line's shear from the result (within
//! two standard errors), the line's shear is returned. The result is never worse than no shear: if
//! J(found) > J(0, 0), the search returns (0, 0).

pub mod checked;
pub mod layer_sums;
pub mod objective;
pub mod start;

use argmin::core::{CostFunction, Error as ArgminError, Executor, State};
use argmin::solver::brent::BrentOpt;
use argmin::solver::neldermead::NelderMead;

pub use layer_sums::{LayerSums, SumMethod};
pub use objective::{Evaluation, ObjectiveOptions, ShearObjective};
pub use start::{PlaneDirections, SpectralStart, spectral_start};

use super::OptimizeError;
use crate::points::{PointSet, wrap01};
use crate::rng::SetRng;
use crate::samplers::{Sampler, SamplerError};

/// The relative change of J the search resolves: the polish stops when its
/// simplex's J agree to this, and a shear must lower J by more than this
/// to be kept over no shear.
const J_RESOLUTION: f64 = 1e-8;

/// Shear offset at which `sensitivity` reports J.
pub const SENSITIVITY_STEP: f64 = 0.01;
/// Step of the scan over the whole range.
const COARSE_STEP: f64 = 0.1;
/// Points on each side of the current value in one refinement scan.
const SCAN_POINTS: i32 = 10;
/// Local minima of the coarse scan that J compares (a double wedge has
/// two, one per layer; the coarse J may rank them differently from J).
const BASINS: usize = 3;

/// The search result.
#[derive(Debug, Clone)]
pub struct ShearResult {
    /// (a, b).
    pub shear: [f64; 2],
    /// J at the optimum, with its standard error.
    pub optimum: Evaluation,
    /// J at (0, 0).
    pub unsheared: Evaluation,
    /// The spectral start's shear and J there.
    pub initial: ([f64; 2], f64),
    /// J at (a ∓ 0.01, b) and (a, b ∓ 0.01): how sharp the optimum is.
    pub sensitivity: [f64; 4],
    /// Whether the result is no shear: what the search found was (0, 0)
    /// itself or had J above the unsheared one (off the spectrum's line:
    /// not below it by more than the search resolves, 1e-8 of J).
    pub kept_unsheared: bool,
    /// Objective evaluations.
    pub evaluations: u64,
    /// Evaluations of the coarse objective (the scans that locate basins).
    pub coarse_evaluations: u64,
}

impl ShearResult {
    /// The result for an integrand constant in (x, y): no shear, variance
    /// 0 everywhere, nothing evaluated.
    #[must_use]
    pub fn constant() -> Self {
        let zero = Evaluation {
            value: 0.0,
            stderr: 0.0,
        };
        ShearResult {
            shear: [0.0, 0.0],
            optimum: zero,
            unsheared: zero,
            initial: ([0.0, 0.0], 0.0),
            sensitivity: [0.0; 4],
            kept_unsheared: true,
            evaluations: 0,
            coarse_evaluations: 0,
        }
    }
}

/// What the search is doing, for a progress display.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchStage {
    /// J at the spectral candidates and at (0, 0).
    Candidates,
    /// The scans and Brent's method along one axis (0: a, 1: b).
    Line(usize),
    /// Nelder–Mead on (a, b) jointly.
    Polish,
    /// J at the optimum ± [`SENSITIVITY_STEP`].
    Sensitivity,
}

impl std::fmt::Display for SearchStage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SearchStage::Candidates => write!(f, "J at the spectral candidates"),
            SearchStage::Line(0) => write!(f, "scanning a (coarse J, then J)"),
            SearchStage::Line(_) => write!(f, "scanning b (coarse J, then J)"),
            SearchStage::Polish => write!(f, "polishing (a, b) jointly"),
            SearchStage::Sensitivity => write!(f, "J at the optimum ± {SENSITIVITY_STEP}"),
        }
    }
}

/// J along one coordinate, the other held fixed, for Brent's method.
struct Line<'o, 'a> {
    objective: &'o ShearObjective<'a>,
    fixed: f64,
    along_a: bool,
}

impl Line<'_, '_> {
    fn shear(&self, t: f64) -> [f64; 2] {
        if self.along_a {
            [t, self.fixed]
        } else {
            [self.fixed, t]
        }
    }

    fn at(&self, t: f64) -> f64 {
        let [a, b] = self.shear(t);
        self.objective.value(a, b)
    }

    fn coarse_at(&self, t: f64) -> f64 {
        let [a, b] = self.shear(t);
        self.objective.coarse_value(a, b)
    }
}

impl CostFunction for Line<'_, '_> {
    type Param = f64;
    type Output = f64;

    fn cost(&self, t: &f64) -> Result<f64, ArgminError> {
        Ok(self.at(*t))
    }
}

/// J(a, b) as an argmin problem.
struct Joint<'o, 'a>(&'o ShearObjective<'a>);

impl CostFunction for Joint<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, p: &Vec<f64>) -> Result<f64, ArgminError> {
        Ok(self.0.value(p[0], p[1]))
    }
}

/// The widest shear range searched: a shear of 64 moves x by 64 periods
/// across the lens, far beyond any light field's slope; the line scans cost
/// O(range) evaluations.
pub const MAX_SHEAR_RANGE: f64 = 64.0;

/// Searches (a, b) in [−`range`, `range`]² from the spectral `start`,
/// telling `stage` what it does next.
///
/// # Errors
/// [`OptimizeError::Option`] for a range that is not finite and positive;
/// [`OptimizeError::Search`] if argmin fails.
pub fn search_shear(
    objective: &ShearObjective,
    start: &SpectralStart,
    range: f64,
    stage: &dyn Fn(SearchStage),
) -> Result<ShearResult, OptimizeError> {
    if !(range.is_finite() && range > 0.0 && range <= MAX_SHEAR_RANGE) {
        return Err(OptimizeError::Option(format!(
            "the shear range must be a positive number up to {MAX_SHEAR_RANGE}, not {range}"
        )));
    }
    let clamp = |s: [f64; 2]| [s[0].clamp(-range, range), s[1].clamp(-range, range)];
    stage(SearchStage::Candidates);
    let unsheared = objective.evaluate([0.0, 0.0])?;
    let initial = clamp(start.shear);
    let initial_value = objective.value(initial[0], initial[1]);
    let mut best = ([0.0, 0.0], unsheared.value);
    if initial_value < best.1 {
        best = (initial, initial_value);
    }
    // The first candidate is the spectral start itself, J known above.
    for c in start.candidates().into_iter().skip(1).map(clamp) {
        let v = objective.value(c[0], c[1]);
        if v < best.1 {
            best = (c, v);
        }
    }
    // J at `shear` is carried along (the lines return it): no evaluation
    // repeats one already made.
    let (mut shear, mut lined) = best;
    for along_a in [true, false] {
        let axis = usize::from(!along_a);
        stage(SearchStage::Line(axis));
        let line = Line {
            objective,
            fixed: shear[1 - axis],
            along_a,
        };
        let (t, value) = refine_line(&line, (shear[axis], lined), range)?;
        shear[axis] = t;
        lined = value;
    }
    stage(SearchStage::Polish);
    let step = 0.05 * SENSITIVITY_STEP;
    let simplex = vec![
        shear.to_vec(),
        vec![shear[0] + step, shear[1]],
        vec![shear[0], shear[1] + step],
    ];
    let solver = NelderMead::new(simplex)
        // J to J_RESOLUTION of itself (|J|: an estimated J may come out
        // ≤ 0, and argmin refuses a negative tolerance): far below its
        // truncation bound and stderr.
        .with_sd_tolerance(J_RESOLUTION * lined.abs())
        .map_err(|e| OptimizeError::Search(e.to_string()))?;
    let result = Executor::new(Joint(objective), solver)
        .configure(|s| s.max_iters(100))
        .run()
        .map_err(|e| OptimizeError::Search(e.to_string()))?;
    if let Some(p) = result.state().get_best_param() {
        let polished = clamp([p[0], p[1]]);
        if objective.value(polished[0], polished[1]) < lined {
            shear = polished;
        }
    }
    let mut optimum = objective.evaluate(shear)?;
    // Where J cannot tell the spectrum's line from what the scans found (a
    // flat objective: a tiny aperture, or an estimated half's noise), the
    // line decides: within two standard errors combined as if the two
    // estimates were independent (they share their realizations, so this
    // is wider than the difference's own). Only for a spectrum on one line
    // (a single layer's, whose shear −c is its slope): a double wedge has
    // no one line.
    let line = clamp(start.line_shear());
    if shear != line && !start.double_wedge {
        let at_line = objective.evaluate(line)?;
        if at_line.value <= optimum.value + 2.0 * optimum.stderr.hypot(at_line.stderr) {
            shear = line;
            optimum = at_line;
        }
    }
    // Off the spectrum's line, a gain below the polish's resolution is no
    // gain: no shear is kept exactly (a symmetric double wedge's optimum is
    // (0, 0), which the polish otherwise returned as a shear of 1e-9). On
    // the line, a tie keeps the line, which the spectrum chose where J
    // cannot tell shears apart (a hairline aperture).
    let on_line = !start.double_wedge && shear == line;
    let resolution = if on_line {
        0.0
    } else {
        J_RESOLUTION * unsheared.value.abs()
    };
    let kept_unsheared = optimum.value > unsheared.value - resolution || shear == [0.0, 0.0];
    if kept_unsheared {
        shear = [0.0, 0.0];
        optimum = unsheared;
    }
    stage(SearchStage::Sensitivity);
    let d = SENSITIVITY_STEP;
    let sensitivity = [
        objective.value(shear[0] - d, shear[1]),
        objective.value(shear[0] + d, shear[1]),
        objective.value(shear[0], shear[1] - d),
        objective.value(shear[0], shear[1] + d),
    ];
    Ok(ShearResult {
        shear,
        optimum,
        unsheared,
        initial: (initial, initial_value),
        sensitivity,
        kept_unsheared,
        evaluations: objective.evaluations(),
        coarse_evaluations: objective.coarse_evaluations(),
    })
}

/// Minimizes J along a line from `t0`, where J is `value0`: a scan of the whole range at step
/// [`COARSE_STEP`] on the coarse J ([`ShearObjective::coarse_value`]), J
/// at its [`BASINS`] deepest local minima, a scan of ±10 points around the
/// best at step 0.01, then Brent's method within one step of the best.
fn refine_line(
    line: &Line,
    (t0, value0): (f64, f64),
    range: f64,
) -> Result<(f64, f64), OptimizeError> {
    let mut best = (t0, value0);
    let coarse = (range / COARSE_STEP).ceil() as i32;
    let scan: Vec<(f64, f64)> = (-coarse..=coarse)
        .map(|i| {
            let t = (COARSE_STEP * i as f64).clamp(-range, range);
            (t, line.coarse_at(t))
        })
        .collect();
    for t in deepest_minima(&scan, BASINS) {
        let v = line.at(t);
        if v < best.1 {
            best = (t, v);
        }
    }
    let step = 0.1 * COARSE_STEP;
    let centre = best.0;
    for i in -SCAN_POINTS..=SCAN_POINTS {
        let t = (centre + step * i as f64).clamp(-range, range);
        let v = line.at(t);
        if v < best.1 {
            best = (t, v);
        }
    }
    let (lo, hi) = ((best.0 - step).max(-range), (best.0 + step).min(range));
    if hi > lo {
        let brent = BrentOpt::new(lo, hi).set_tolerance(1e-8, 1e-12);
        let result = Executor::new(
            Line {
                objective: line.objective,
                fixed: line.fixed,
                along_a: line.along_a,
            },
            brent,
        )
        .configure(|s| s.max_iters(60))
        .run()
        .map_err(|e| OptimizeError::Search(e.to_string()))?;
        if let Some(&t) = result.state().get_best_param() {
            let v = line.at(t);
            if v < best.1 {
                best = (t, v);
            }
        }
    }
    Ok(best)
}

/// The arguments of the `count` deepest local minima of the scan
/// `(t, value)` (ends compared with their one neighbour), deepest first.
fn deepest_minima(scan: &[(f64, f64)], count: usize) -> Vec<f64> {
    let mut minima: Vec<(f64, f64)> = (0..scan.len())
        .filter(|&i| {
            let v = scan[i].1;
            (i == 0 || v <= scan[i - 1].1) && (i + 1 == scan.len() || v <= scan[i + 1].1)
        })
        .map(|i| scan[i])
        .collect();
    minima.sort_by(|x, y| x.1.total_cmp(&y.1).then(x.0.total_cmp(&y.0)));
    minima.into_iter().take(count).map(|(t, _)| t).collect()
}

/// A 4D sampler whose sets come out sheared by (a, b).
pub struct Sheared<'a> {
    inner: &'a dyn Sampler,
    shear: [f64; 2],
}

impl<'a> Sheared<'a> {
    /// `inner`'s sets sheared by `shear`.
    ///
    /// # Errors
    /// [`OptimizeError::Option`] for a sampler that is not 4D.
    pub fn new(inner: &'a dyn Sampler, shear: [f64; 2]) -> Result<Self, OptimizeError> {
        if inner.dim() != 4 {
            return Err(OptimizeError::Option(format!(
                "shearing needs 4D points, not {}D",
                inner.dim()
            )));
        }
        Ok(Sheared { inner, shear })
    }
}

impl Sampler for Sheared<'_> {
    fn dim(&self) -> usize {
        4
    }

    fn points_per_set(&self) -> usize {
        self.inner.points_per_set()
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let set = self.inner.sample(rng)?;
        Ok(shear_coords(&set, self.shear))
    }
}

fn shear_coords(set: &PointSet, [a, b]: [f64; 2]) -> PointSet {
    let coords = set
        .points()
        .flat_map(|p| [wrap01(p[0] + a * p[2]), wrap01(p[1] + b * p[3]), p[2], p[3]])
        .collect();
    PointSet::new(4, coords).expect("wrapped coordinates lie in [0,1)")
}

/// The set sheared by (a, b): x′ = x + a·u, y′ = y + b·v (mod 1).
///
/// # Errors
/// [`OptimizeError::Option`] for a set that is not 4D.
pub fn shear_set(set: &PointSet, [a, b]: [f64; 2]) -> Result<PointSet, OptimizeError> {
    if set.dim() != 4 {
        return Err(OptimizeError::Option(format!(
            "shearing needs 4D points, not {}D",
            set.dim()
        )));
    }
    Ok(shear_coords(set, [a, b]))
}

#[cfg(test)]
mod tests {
    use super::deepest_minima;

    #[test]
    fn local_minima_come_deepest_first_with_the_ends() {
        let scan: Vec<(f64, f64)> = [1.0, 3.0, 2.0, 5.0, 0.5, 0.7, 4.0, 4.0, 6.0, 2.5]
            .iter()
            .enumerate()
            .map(|(i, &v)| (i as f64, v))
            .collect();
        assert_eq!(deepest_minima(&scan, 3), vec![4.0, 0.0, 2.0]);
        // The shoulder at 7 (level with its left neighbour) counts.
        assert_eq!(deepest_minima(&scan, 10), vec![4.0, 0.0, 2.0, 9.0, 7.0]);
        // A plateau offers each of its points; ties go to the smaller t.
        let flat = [(0.0, 1.0), (1.0, 1.0), (2.0, 1.0)];
        assert_eq!(deepest_minima(&flat, 2), vec![0.0, 1.0]);
        assert!(deepest_minima(&[], 3).is_empty());
    }
}
