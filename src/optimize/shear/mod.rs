//! Shear search for structured 4D sets (Singh & Jarosz 2017, "Convergence
//! analysis for anisotropic Monte Carlo sampling spectra", ACM TOG 36(4)):
//! shear x' = x + a·u, y' = y + b·v (mod 1) and choose (a, b) to minimize
//! the variance of the unshifted estimator on a 4D integrand.
//!
//! The objective is the mean squared error of Î over R fixed realizations
//! (common random numbers, so it is a smooth function of (a, b)), written in
//! Fourier form and restricted to the integrand's spectral support Ω — the
//! smallest set of frequencies in the box |k|∞ ≤ h holding 99% of its
//! in-box energy (model only what the scene needs):
//! e_r(a,b) = Σ_(k∈Ω) F_f(k)·conj(S_r(k; a,b))/N, J(a,b) = mean_r |e_r|²,
//! with S_r(k; a,b) = Σ_j e^(−2πi(kx(x_j + a u_j) + ky(y_j + b v_j) + ku u_j + kv v_j)).
//! The mod-1 wrap of x' does not change e^(−2πi kx x') for integer kx, so J
//! is smooth. A coarse scan of a (b = 0) refined by Brent's method, then the
//! same for b, seeds Nelder–Mead (both from argmin).
//! For `defocus` with shear c the analytic optimum is a = b = −c: then
//! x' + c(u − ½) = x − c/2 and the (x, y) stratification integrates g
//! directly.

use argmin::core::{CostFunction, Error as ArgminError, Executor, State};
use argmin::solver::neldermead::NelderMead;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;

use super::OptimizeError;
use crate::integrands::Integrand;
use crate::points::{PointSet, wrap01};
use crate::spectrum::FrequencyBox;
use crate::spectrum::phase::{phasor, reduced_phase};

/// Share of the in-box energy the support keeps.
const ENERGY: f64 = 0.99;
/// Largest support (frequencies).
const MAX_SUPPORT: usize = 4000;

/// The smooth CRN objective J(a, b).
pub struct ShearObjective {
    sets: Vec<PointSet>,
    /// Support frequencies and F_f there.
    support: Vec<([i64; 4], Complex64)>,
    half: i64,
    evaluations: std::sync::atomic::AtomicU64,
}

impl ShearObjective {
    /// The objective over `sets` (fixed realizations, 4D) for integrand `f`,
    /// with its support taken from the box |k|∞ ≤ `half`.
    ///
    /// # Errors
    /// [`OptimizeError::Option`] for non-4D points or integrand, or no sets.
    pub fn new(f: &dyn Integrand, sets: Vec<PointSet>, half: usize) -> Result<Self, OptimizeError> {
        if f.dim() != 4 || sets.is_empty() || sets.iter().any(|s| s.dim() != 4) {
            return Err(OptimizeError::Option(
                "the shear search needs 4D points, a 4D integrand and at least one set".into(),
            ));
        }
        let freqs = FrequencyBox { dim: 4, half };
        let zero = freqs.zero_index();
        let mut all: Vec<([i64; 4], Complex64, f64)> = (0..freqs.len())
            .into_par_iter()
            .filter(|&i| i != zero)
            .map(|i| {
                let mut k = [0i64; 4];
                freqs.frequency(i, &mut k);
                let c = f.fourier(&k);
                (k, c, c.norm_sqr())
            })
            .collect();
        // Largest energy first; ties broken by index order for determinism.
        all.sort_by(|a, b| b.2.total_cmp(&a.2));
        let total: f64 = all.iter().map(|t| t.2).sum();
        let mut kept = 0.0;
        let support: Vec<([i64; 4], Complex64)> = all
            .iter()
            .take_while(|t| {
                let keep = kept < ENERGY * total;
                kept += t.2;
                keep
            })
            .take(MAX_SUPPORT)
            .map(|t| (t.0, t.1))
            .collect();
        Ok(ShearObjective {
            sets,
            support,
            half: half as i64,
            evaluations: 0.into(),
        })
    }

    /// Frequencies in the support.
    pub fn support_len(&self) -> usize {
        self.support.len()
    }

    /// Evaluations of J so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// J(a, b).
    pub fn value(&self, a: f64, b: f64) -> f64 {
        self.evaluations
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let h = self.half;
        let side = (2 * h + 1) as usize;
        let per_set: Vec<f64> = self
            .sets
            .par_iter()
            .map(|set| {
                let n = set.len() as f64;
                let mut err = vec![Complex64::new(0.0, 0.0); self.support.len()];
                // Per point: e^(−2πi k x) for every k in −h..=h and each
                // coordinate, and the shear factors e^(−2πi a kx u), e^(−2πi b ky v).
                let mut table = vec![Complex64::new(0.0, 0.0); 6 * side];
                for p in set.points() {
                    for (slot, k) in (-h..=h).enumerate() {
                        for c in 0..4 {
                            table[c * side + slot] = phasor(reduced_phase(k, p[c]));
                        }
                        table[4 * side + slot] = phasor(a * k as f64 * p[2]);
                        table[5 * side + slot] = phasor(b * k as f64 * p[3]);
                    }
                    let at = |c: usize, k: i64| table[c * side + (k + h) as usize];
                    for (e, (k, _)) in err.iter_mut().zip(&self.support) {
                        *e += at(0, k[0])
                            * at(1, k[1])
                            * at(2, k[2])
                            * at(3, k[3])
                            * at(4, k[0])
                            * at(5, k[1]);
                    }
                }
                let total: Complex64 = err
                    .iter()
                    .zip(&self.support)
                    .map(|(s, (_, fk))| fk * s.conj())
                    .sum();
                (total / n).norm_sqr()
            })
            .collect();
        per_set.iter().sum::<f64>() / per_set.len() as f64
    }
}

impl CostFunction for ShearObjective {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, p: &Vec<f64>) -> Result<f64, ArgminError> {
        Ok(self.value(p[0], p[1]))
    }
}

/// The search result.
#[derive(Debug, Clone)]
pub struct ShearResult {
    /// (a, b).
    pub shear: [f64; 2],
    /// J at the optimum.
    pub objective: f64,
    /// J at (0, 0).
    pub objective_unsheared: f64,
    /// Objective evaluations.
    pub evaluations: u64,
}

/// J along one coordinate, the other held fixed, for Brent's method.
struct Line<'a> {
    objective: &'a ShearObjective,
    fixed: f64,
    along_a: bool,
}

impl CostFunction for Line<'_> {
    type Param = f64;
    type Output = f64;

    fn cost(&self, t: &f64) -> Result<f64, ArgminError> {
        Ok(if self.along_a {
            self.objective.value(*t, self.fixed)
        } else {
            self.objective.value(self.fixed, *t)
        })
    }
}

/// Scans a on [−range, range] (b = 0) in `steps`, refines it by Brent's
/// method within one step of the best grid point, does the same for b (a
/// fixed) — the exact search when the objective separates in a and b — and
/// polishes (a, b) jointly with Nelder–Mead.
///
/// # Errors
/// [`OptimizeError::Search`] if argmin fails.
pub fn search_shear(
    objective: ShearObjective,
    range: f64,
    steps: usize,
) -> Result<ShearResult, OptimizeError> {
    let grid: Vec<f64> = (0..=steps)
        .map(|i| -range + 2.0 * range * i as f64 / steps as f64)
        .collect();
    let d = 2.0 * range / steps as f64;
    let line_minimum = |fixed: f64, along_a: bool| -> Result<f64, OptimizeError> {
        let at = |t: f64| {
            if along_a {
                objective.value(t, fixed)
            } else {
                objective.value(fixed, t)
            }
        };
        let (t0, _) = grid
            .iter()
            .map(|&t| (t, at(t)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .expect("grid is not empty");
        let line = Line {
            objective: &objective,
            fixed,
            along_a,
        };
        let brent = argmin::solver::brent::BrentOpt::new(t0 - d, t0 + d).set_tolerance(1e-6, 1e-9);
        let result = Executor::new(line, brent)
            .configure(|s| s.max_iters(60))
            .run()
            .map_err(|e| OptimizeError::Search(e.to_string()))?;
        Ok(result.state().get_best_param().copied().unwrap_or(t0))
    };
    let a0 = line_minimum(0.0, true)?;
    let b0 = line_minimum(a0, false)?;
    let unsheared = objective.value(0.0, 0.0);
    let simplex = vec![
        vec![a0, b0],
        vec![a0 + 0.25 * d, b0],
        vec![a0, b0 + 0.25 * d],
    ];
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(1e-12)
        .map_err(|e| OptimizeError::Search(e.to_string()))?;
    let result = Executor::new(objective, solver)
        .configure(|s| s.max_iters(200))
        .run()
        .map_err(|e| OptimizeError::Search(e.to_string()))?;
    let evaluations = result
        .problem
        .problem
        .as_ref()
        .map_or(0, ShearObjective::evaluations);
    let state = result.state();
    let best = state
        .get_best_param()
        .cloned()
        .unwrap_or_else(|| vec![a0, b0]);
    Ok(ShearResult {
        shear: [best[0], best[1]],
        objective: state.get_best_cost(),
        objective_unsheared: unsheared,
        evaluations,
    })
}

/// The set sheared by (a, b): x' = x + a·u, y' = y + b·v (mod 1).
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
    let coords = set
        .points()
        .flat_map(|p| [wrap01(p[0] + a * p[2]), wrap01(p[1] + b * p[3]), p[2], p[3]])
        .collect();
    Ok(PointSet::new(4, coords)?)
}
