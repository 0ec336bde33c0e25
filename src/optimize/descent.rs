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
//! The step is Adam's (Kingma & Ba 2015, "Adam: a method for stochastic
//! optimization", ICLR, Alg. 1) with a learning rate in units of the mean
//! spacing N^(−1/d), decaying geometrically; a step that raises the loss
//! above 1.5× the best so far is undone and the rate halved, so the descent
//! cannot blow up. It stops when the loss improves by less than a relative
//! `rel_tol` over 50 iterations, or after `iters`. Positions wrap modulo 1.

use rustfft::num_complex::Complex64;

use super::{OptimizeError, Target};
use crate::points::{PointSet, wrap01};
use crate::spectrum::nufft::NufftScratch;
use crate::spectrum::{FrequencyBox, NufftPlan, Sign};

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
}

impl DescentOptions {
    /// Defaults for N points in d dimensions and `target`. The box must hold
    /// the spectrum the target weighs: blue-noise families need a few times
    /// the Nyquist radius N^(1/d), K = max(16, ⌈2.5·N^(1/d)⌉) but at most 400
    /// (1.56·√N at N = 65,536: still past the peak at ≈ 1.07·√N, and a
    /// fourth of the FFT work of 2.5·√N); an integrand's
    /// P_f reaches further (what lies beyond the box is variance the descent
    /// cannot see), K = clamp(⌈8·N^(1/d)⌉, 32, 128).
    pub fn for_target(n: usize, dim: usize, target: &Target) -> Self {
        let root = (n as f64).powf(1.0 / dim as f64);
        let half = match target {
            Target::Integrand(_) => ((8.0 * root).ceil() as usize).clamp(32, 128),
            _ => ((2.5 * root).ceil() as usize).clamp(16, 400),
        };
        DescentOptions {
            half,
            tolerance: 1e-6,
            iters: 2000,
            rel_tol: 1e-4,
            step: 0.05,
            final_step: 0.002,
        }
    }
}

/// The optimized set and how it got there.
#[derive(Debug, Clone)]
pub struct DescentResult {
    /// The best set found.
    pub points: PointSet,
    /// Loss after each iteration (the first entry is the start's).
    pub losses: Vec<f64>,
    /// Wall time since the start at each entry of `losses`, in seconds.
    pub seconds: Vec<f64>,
}

/// A designed descent: box, weights and NUFFT plan, reused for every
/// realization (`Sync`, one scratch per call).
pub struct PointOptimizer {
    freqs: FrequencyBox,
    weights: Vec<f64>,
    plan: NufftPlan,
    options: DescentOptions,
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
        if options.iters == 0
            || !(options.step > 0.0 && options.final_step > 0.0)
            || options.half == 0
        {
            return Err(OptimizeError::Option(
                "iterations, steps and the box must be positive".into(),
            ));
        }
        let freqs = FrequencyBox {
            dim,
            half: options.half,
        };
        let weights = target.weights(&freqs)?;
        let plan = NufftPlan::new(freqs, options.tolerance)?;
        Ok(PointOptimizer {
            freqs,
            weights,
            plan,
            options,
        })
    }

    /// The weights W(k) in box order.
    pub fn weights(&self) -> &[f64] {
        &self.weights
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
        crate::variance::sum::sum(s.iter().zip(&self.weights).map(|(v, w)| w * v.norm_sqr())) / n2
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
        let mut k = vec![0i64; d];
        for pair in (0..d).step_by(2) {
            for (idx, c) in work.coeffs.iter_mut().enumerate() {
                self.freqs.frequency(idx, &mut k);
                let base = work.spectrum[idx].conj() * self.weights[idx];
                // −2πi·k_d: the first dimension of the pair in the real part,
                // the second (if any) in the imaginary part.
                let first = base * Complex64::new(0.0, -tau * k[pair] as f64);
                let second = if pair + 1 < d {
                    base * Complex64::new(0.0, -tau * k[pair + 1] as f64)
                } else {
                    Complex64::new(0.0, 0.0)
                };
                *c = first + Complex64::new(0.0, 1.0) * second;
            }
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

    /// Descends from `start`; `on_iteration(t, loss)` is called every step.
    pub fn optimize(&self, start: PointSet, on_iteration: &dyn Fn(usize, f64)) -> DescentResult {
        let (n, d) = (start.len(), start.dim());
        let o = &self.options;
        let spacing = (1.0 / n.max(1) as f64).powf(1.0 / d as f64);
        let (beta1, beta2, eps) = (0.9f64, 0.999f64, 1e-300f64);
        let mut work = self.work(n);
        let mut x = start.coords().to_vec();
        let (mut m, mut v) = (vec![0.0; n * d], vec![0.0; n * d]);
        let mut best = (f64::INFINITY, x.clone());
        let mut losses = Vec::with_capacity(o.iters + 1);
        let mut seconds = Vec::with_capacity(o.iters + 1);
        let clock = std::time::Instant::now();
        let mut damping = 1.0;
        for t in 0..o.iters {
            let points = PointSet::new(d, x.clone()).expect("wrapped coordinates lie in [0,1)");
            let (loss, grad) = self.loss_and_gradient(&points, &mut work);
            losses.push(loss);
            seconds.push(clock.elapsed().as_secs_f64());
            on_iteration(t, loss);
            if loss < best.0 {
                best = (loss, x.clone());
            } else if loss > 1.5 * best.0 {
                // Undo a step that blew up and take smaller ones from the best set.
                x.clone_from(&best.1);
                m.fill(0.0);
                v.fill(0.0);
                damping *= 0.5;
                continue;
            }
            if t >= 50 && losses[t - 50] - loss < o.rel_tol * loss {
                break;
            }
            let progress = t as f64 / o.iters as f64;
            let lr = damping * spacing * o.step * (o.final_step / o.step).powf(progress);
            let (c1, c2) = (
                1.0 - beta1.powi(t as i32 + 1),
                1.0 - beta2.powi(t as i32 + 1),
            );
            for i in 0..n * d {
                m[i] = beta1 * m[i] + (1.0 - beta1) * grad[i];
                v[i] = beta2 * v[i] + (1.0 - beta2) * grad[i] * grad[i];
                let step = lr * (m[i] / c1) / ((v[i] / c2).sqrt() + eps);
                x[i] = wrap01(x[i] - step);
            }
        }
        let points = PointSet::new(d, best.1).expect("wrapped coordinates lie in [0,1)");
        DescentResult {
            points,
            losses,
            seconds,
        }
    }
}

/// Buffers for one descent.
pub struct Work {
    spectrum: Vec<Complex64>,
    coeffs: Vec<Complex64>,
    values: Vec<Complex64>,
    scratch: NufftScratch,
}
