//! Gradient descent on point positions (docs/mathematics.md §6): minimize
//! L(X) = Σ_(0<|k|∞≤K) W(k)·P_S(k), P_S = |S|²/N², S(k) = Σ_j e^(−2πik·x_j),
//! on the torus, with the gradient
//! ∂L/∂x_j = (2/N²) Σ_k W(k) Re[conj(S(k))·(−2πik)·e^(−2πik·x_j)].
//!
//! One type-1 NUFFT gives S; one type-2 NUFFT per pair of dimensions gives
//! the gradient at every point: with W real and even, the coefficients
//! c_d(k) = W(k)·conj(S(k))·(−2πi k_d) are Hermitian, so each G_d(x) =
//! Σ_k c_d(k) e^(−2πik·x) is real and two of them travel as the real and
//! imaginary parts of one transform. Cost O(N·w^d + K^d log K) per step.
//!
//! The step is the shared Adam descent of [`super::adam`].

use rayon::prelude::*;
use rustfft::num_complex::Complex64;

use super::adam::{
    AdamOptions, AdamState, Checkpointing, DescentResult, Domain, PointObjective, Stop, adam_from,
};
use super::{OptimizeError, Target};
use crate::points::PointSet;
use crate::spectrum::nufft::NufftScratch;
use crate::spectrum::{FrequencyBox, NufftPlan, Sign, Upsampling};

/// Knobs of the descent.
#[derive(Debug, Clone)]
pub struct DescentOptions {
    /// Box half-width K of the loss.
    pub half: usize,
    /// NUFFT tolerance (accuracy knob of the gradient).
    pub tolerance: f64,
    /// Maximum iterations.
    pub iters: usize,
    /// Stop when the loss improves by less than this, relatively, over 50
    /// iterations.
    pub rel_tol: f64,
    /// Initial step in units of the mean spacing N^(−1/d).
    pub step: f64,
    /// Final step (after `iters`) in the same units.
    pub final_step: f64,
    /// Coarse-to-fine: a first phase on the box of this half-width (at most
    /// [`COARSE_ITERS`] iterations, same stopping rule) before the full box,
    /// whose descent then starts at a fifth of `step` (the points are
    /// already spaced). The small box fixes the start's large-scale density
    /// fluctuations at a fraction of the cost per step (21 ms against 72 ms
    /// at N = 65,536). `None`: one phase. The default from
    /// [`DescentOptions::for_target`]: a quarter of the box for 2D
    /// blue-noise targets from [`COARSE_FROM`] points on.
    pub coarse_half: Option<usize>,
    /// The NUFFT's upsampling factor: [`Upsampling::Auto`] for the set's
    /// size by default (σ = 5/4 below about 200,000 points in 2D, where it
    /// makes a step at N = 65,536 1.4–1.5× faster; spectrum/nufft.rs).
    pub upsampling: Upsampling,
}

/// Iteration cap of the coarse phase.
pub const COARSE_ITERS: usize = 300;

/// The stopping rule's default for blue-noise targets (`family:`, `power:`,
/// `radial:`): stop when the loss improves by less than 0.1% over 50
/// iterations. Against 1e-4 from random starts toward `family:disks`
/// (seed 5), scored on 24 disks + 24 boxes nobody tuned for
/// (examples/torus_scores.rs): 0.978× against 0.976× CMJ at N = 1024 (16
/// sets, 15.1 s against 22.8 s), 0.959× against 0.963× at 4096 (4 sets,
/// 11.7 s against 27.1 s); at 65,536 points it stops converged in 30 s,
/// 0.3% above the loss 1e-4 reaches at its iteration cap (38 s). Integrand
/// targets keep 1e-4 (not measured).
pub const BLUE_NOISE_REL_TOL: f64 = 1e-3;

/// Fewest points at which 2D blue-noise descents go coarse-to-fine by
/// default. From random starts toward `family:disks`, scored on 24 disks
/// and 24 boxes nobody tuned for (examples/torus_scores.rs,
/// results/optimize-blue-noise): coarse-to-fine against one phase, mean
/// variance relative to CMJ, 0.965× against 0.972× at N = 4096, 0.972×
/// against 0.994× at 16,384, 1.057× against 1.110× at 65,536; at N = 1024
/// it scored worse (0.992× against 0.973×), so smaller sets keep one phase.
pub const COARSE_FROM: usize = 4096;

impl DescentOptions {
    /// Defaults for N points in d dimensions and `target`. The box must hold
    /// the spectrum the target weighs: blue-noise families need a few times
    /// the Nyquist radius N^(1/d), K = max(16, ⌈2.5·N^(1/d)⌉) but at most 400
    /// (1.56·√N at N = 65,536: still past the peak at ≈ 1.07·√N, and a
    /// fourth of the FFT work of 2.5·√N); an integrand's
    /// P_f reaches further (what lies beyond the box is variance the descent
    /// cannot see), K = clamp(⌈8·N^(1/d)⌉, 32, 256): measured on a
    /// half-plane at N = 1024, the cap 128 left 87% of the variance beyond
    /// the box and reached 0.30× CMJ, 256 reaches 0.21× (results/optimize-adapted).
    /// In 3D and 4D the box holds (2K+1)^d frequencies and the transform
    /// (4K)^d cells per thread, so K is capped at 40 and 12 (4D, K = 12:
    /// about 0.4 GB on 2 threads; K = 32 asked for 9 GB). 2D blue-noise
    /// targets of [`COARSE_FROM`] points or more descend coarse-to-fine.
    /// The stopping rule: [`BLUE_NOISE_REL_TOL`] for blue-noise targets,
    /// 1e-4 for integrand targets.
    pub fn for_target(n: usize, dim: usize, target: &Target) -> Self {
        let root = (n as f64).powf(1.0 / dim as f64);
        let half = match target {
            Target::Integrand(_) => ((8.0 * root).ceil() as usize).clamp(32, 256),
            _ => ((2.5 * root).ceil() as usize).clamp(16, 400),
        };
        let half = match dim {
            3 => half.min(40),
            4 => half.min(12),
            _ => half,
        };
        DescentOptions {
            half,
            tolerance: 1e-6,
            iters: 2000,
            rel_tol: match target {
                Target::Integrand(_) => 1e-4,
                _ => BLUE_NOISE_REL_TOL,
            },
            step: 0.05,
            final_step: 0.002,
            coarse_half: (Self::takes_coarse(dim, target) && n >= COARSE_FROM).then_some(half / 4),
            upsampling: Upsampling::Auto { points: n },
        }
    }

    /// Whether a descent toward `target` in `dim` dimensions can run the
    /// coarse phase ([`DescentOptions::coarse_half`]): 2D blue-noise
    /// targets (`family:`, `power:`, `radial:`).
    pub fn takes_coarse(dim: usize, target: &Target) -> bool {
        dim == 2 && !matches!(target, Target::Integrand(_))
    }
}

/// A designed descent: box, weights and NUFFT plan, reused for every
/// realization (`Sync`, one scratch per call).
pub struct PointOptimizer {
    freqs: FrequencyBox,
    weights: Vec<f64>,
    plan: NufftPlan,
    options: DescentOptions,
    /// The coarse phase's descent, if any.
    coarse: Option<Box<PointOptimizer>>,
}

impl PointOptimizer {
    /// Plans the descent for d-dimensional points with `target`'s weights.
    ///
    /// # Errors
    /// A target that does not fit the dimension, or a bad tolerance or box.
    pub fn new(
        dim: usize,
        target: &Target,
        options: DescentOptions,
    ) -> Result<Self, OptimizeError> {
        if !(1..=4).contains(&dim) {
            return Err(OptimizeError::Option(format!(
                "point optimization works in 1 to 4 dimensions, not {dim}"
            )));
        }
        let bad = [
            (
                options.iters == 0,
                "the number of iterations (--iters) is 0",
            ),
            (
                !(options.step > 0.0 && options.step.is_finite()),
                "the initial step is not a positive number",
            ),
            (
                !(options.final_step > 0.0 && options.final_step.is_finite()),
                "the final step is not a positive number",
            ),
            (
                options.half == 0,
                "the frequency box (--res) holds only k = 0",
            ),
        ];
        if let Some((_, what)) = bad.iter().find(|(is_bad, _)| *is_bad) {
            return Err(OptimizeError::Option(format!(
                "{what}: iterations, steps and the box must be positive"
            )));
        }
        let freqs = FrequencyBox {
            dim,
            half: options.half,
        };
        crate::spectrum::nufft::check_nufft_memory(&freqs)?;
        let weights = target.weights(&freqs)?;
        let coarse = match options.coarse_half {
            Some(half) if half > 0 && half < options.half => {
                let coarse_options = DescentOptions {
                    half,
                    iters: COARSE_ITERS.min(options.iters),
                    coarse_half: None,
                    ..options.clone()
                };
                Some(Box::new(Self::new(dim, target, coarse_options)?))
            }
            _ => None,
        };
        let mut optimizer = Self::with_weights(freqs, weights, options)?;
        optimizer.coarse = coarse;
        Ok(optimizer)
    }

    /// Plans the descent for given weights W(k) on `freqs` (box order).
    ///
    /// # Errors
    /// A bad tolerance, or weights of another length than the box.
    pub fn with_weights(
        freqs: FrequencyBox,
        weights: Vec<f64>,
        options: DescentOptions,
    ) -> Result<Self, OptimizeError> {
        if weights.len() != freqs.len() {
            return Err(OptimizeError::Option(format!(
                "{} weights for a box of {} frequencies",
                weights.len(),
                freqs.len()
            )));
        }
        let plan = NufftPlan::with_upsampling(freqs, options.tolerance, options.upsampling)?;
        Ok(PointOptimizer {
            freqs,
            weights,
            plan,
            options,
            coarse: None,
        })
    }

    /// The NUFFT's upsampling factor σ in use (2 or 5/4).
    pub fn upsampling(&self) -> f64 {
        self.plan.upsampling()
    }

    /// Bytes one descent of `n` points holds, besides the plan's shared
    /// grids ([`crate::spectrum::nufft::nufft_memory_bytes`]): spectrum,
    /// coefficients and weights on the box, values at the points, and
    /// Adam's positions, moments, best set and gradient (eight copies of
    /// N·d coordinates with the point sets built from them), and the
    /// transform's per-point scratch
    /// ([`crate::spectrum::nufft::nufft_point_bytes`]).
    pub fn descent_bytes(&self, n: usize) -> f64 {
        let len = self.freqs.len() as f64;
        let d = self.freqs.dim;
        len * 40.0
            + n as f64
                * (16.0 + 8.0 * 8.0 * d as f64 + crate::spectrum::nufft::nufft_point_bytes(d))
    }

    /// The loss a set with P_S = 0 in the box shows through transforms of
    /// tolerance ε: each S(k) is off by about ε·Σ_j|c_j| = ε·N (sets of
    /// many points stay within 1.4·ε·N, measured; single points reach
    /// 7–23·ε·N: [`crate::variance::fourier`]), so the computed loss is
    /// about ε²·ΣW there. Below this level the loss cannot be told from
    /// zero and the descent stops (converged).
    pub fn loss_floor(&self) -> f64 {
        self.options.tolerance
            * self.options.tolerance
            * crate::sum::sum(self.weights.iter().copied())
    }

    /// The box.
    pub fn frequencies(&self) -> &FrequencyBox {
        &self.freqs
    }

    /// L(X) = Σ W(k)·|S(k)|²/N².
    pub fn loss(&self, points: &PointSet) -> f64 {
        let mut s = vec![Complex64::new(0.0, 0.0); self.freqs.len()];
        let mut scratch = self.plan.make_scratch();
        self.plan
            .type1(points, None, Sign::Negative, &mut s, &mut scratch);
        self.loss_of(&s, points.len())
    }

    fn loss_of(&self, s: &[Complex64], n: usize) -> f64 {
        let n2 = (n * n) as f64;
        crate::sum::par_sum(s.len(), |i| self.weights[i] * s[i].norm_sqr()) / n2
    }

    /// Loss and gradient (point-major, d per point) at `points`.
    pub fn loss_and_gradient(&self, points: &PointSet, work: &mut Work) -> (f64, Vec<f64>) {
        let (n, d) = (points.len(), points.dim());
        self.plan.type1(
            points,
            None,
            Sign::Negative,
            &mut work.spectrum,
            &mut work.scratch,
        );
        let loss = self.loss_of(&work.spectrum, n);
        let mut grad = vec![0.0; n * d];
        let scale = 2.0 / (n * n) as f64;
        let tau = std::f64::consts::TAU;
        let spectrum = &work.spectrum;
        for pair in (0..d).step_by(2) {
            work.coeffs
                .par_iter_mut()
                .enumerate()
                .with_min_len(1 << 12)
                .for_each_init(
                    || vec![0i64; d],
                    |k, (idx, c)| {
                        self.freqs.frequency(idx, k);
                        let base = spectrum[idx].conj() * self.weights[idx];
                        // −2πi·k_d: the first dimension of the pair in the
                        // real part, the second (if any) in the imaginary.
                        let first = base * Complex64::new(0.0, -tau * k[pair] as f64);
                        let second = if pair + 1 < d {
                            base * Complex64::new(0.0, -tau * k[pair + 1] as f64)
                        } else {
                            Complex64::new(0.0, 0.0)
                        };
                        *c = first + Complex64::new(0.0, 1.0) * second;
                    },
                );
            self.plan.type2(
                points,
                &work.coeffs,
                Sign::Negative,
                &mut work.values,
                &mut work.scratch,
            );
            for (j, g) in work.values.iter().enumerate() {
                grad[j * d + pair] = scale * g.re;
                if pair + 1 < d {
                    grad[j * d + pair + 1] = scale * g.im;
                }
            }
        }
        (loss, grad)
    }

    /// Working memory for [`Self::loss_and_gradient`].
    pub fn work(&self, n: usize) -> Work {
        let zero = Complex64::new(0.0, 0.0);
        Work {
            spectrum: vec![zero; self.freqs.len()],
            coeffs: vec![zero; self.freqs.len()],
            values: vec![zero; n],
            scratch: self.plan.make_scratch(),
        }
    }

    /// Descends from `start` by [`adam`] on the torus; `on_iteration(t,
    /// loss)` is called every step.
    pub fn optimize(&self, start: PointSet, on_iteration: &dyn Fn(usize, f64)) -> DescentResult {
        self.optimize_from(AdamState::start(&start), on_iteration, None)
    }

    /// Descends from a fresh or saved `state` (see [`adam_from`]), saving it
    /// as `checkpointing` says. A fresh state goes through the coarse phase
    /// first, if there is one; it is not saved (at most [`COARSE_ITERS`]
    /// iterations, 136 s at N = 1,048,576): a run killed in it starts again
    /// and reaches the same bits.
    pub fn optimize_from(
        &self,
        state: AdamState,
        on_iteration: &dyn Fn(usize, f64),
        checkpointing: Option<&Checkpointing>,
    ) -> DescentResult {
        if state.len() == 1 && state.t == 0 {
            return self.one_point(state, on_iteration);
        }
        let o = &self.options;
        let state = match &self.coarse {
            Some(coarse) if state.t == 0 => {
                let clock = std::time::Instant::now();
                let start =
                    PointSet::new(state.dim, state.x).expect("a fresh state holds its start");
                let first = coarse.optimize(start, &|_, _| {});
                let mut fine = AdamState::start(&first.points);
                fine.seconds_offset = clock.elapsed().as_secs_f64();
                fine.coarse_iterations = first.losses.len();
                fine
            }
            _ => state,
        };
        let step = if self.coarse.is_some() {
            o.step / 5.0
        } else {
            o.step
        };
        let adam_options = AdamOptions {
            iters: o.iters,
            rel_tol: o.rel_tol,
            step,
            final_step: o.final_step,
            score_every: 1,
            floor: self.loss_floor(),
        };
        let objective = TorusObjective {
            optimizer: self,
            work: std::sync::Mutex::new(self.work(state.len())),
        };
        adam_from(
            state,
            &objective,
            &adam_options,
            Domain::Torus,
            on_iteration,
            checkpointing,
        )
    }
}

impl PointOptimizer {
    /// One point: S(k) = e^(−2πik·x) has |S(k)|² = 1 at every k, so the
    /// loss Σ W(k)·P_S(k) is the same wherever the point lies and no step
    /// changes it (in 4D a descent spent 51 evaluations of 25^4 terms, 5 s,
    /// to learn that). The start, its loss evaluated once.
    fn one_point(&self, state: AdamState, on_iteration: &dyn Fn(usize, f64)) -> DescentResult {
        let clock = std::time::Instant::now();
        let start = PointSet::new(state.dim, state.x).expect("a fresh state holds its start");
        let (loss, _) = self.loss_and_gradient(&start, &mut self.work(1));
        on_iteration(0, loss);
        DescentResult {
            points: start,
            losses: vec![loss],
            seconds: vec![state.seconds_offset + clock.elapsed().as_secs_f64()],
            best_score: loss,
            start_score: loss,
            coarse_iterations: 0,
            stop: Stop::Stationary,
        }
    }
}

/// The spectral loss as a [`PointObjective`].
struct TorusObjective<'a> {
    optimizer: &'a PointOptimizer,
    work: std::sync::Mutex<Work>,
}

impl PointObjective for TorusObjective<'_> {
    fn loss_and_gradient(&self, points: &PointSet, _t: usize, gradient: &mut [f64]) -> f64 {
        let mut work = self.work.lock().expect("one descent at a time");
        let (loss, grad) = self.optimizer.loss_and_gradient(points, &mut work);
        gradient.copy_from_slice(&grad);
        loss
    }
}

/// Buffers for one descent.
pub struct Work {
    spectrum: Vec<Complex64>,
    coeffs: Vec<Complex64>,
    values: Vec<Complex64>,
    scratch: NufftScratch,
}
