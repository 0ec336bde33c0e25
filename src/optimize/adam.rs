//! Adam descent on point positions (Kingma & Ba 2015, "Adam: a method for
//! stochastic optimization", ICLR, Alg. 1), shared by every point
//! objective: the torus's spectral loss and the square's family MSEs.
//!
//! The learning rate is in units of the mean spacing N^(−1/d) and decays
//! geometrically from `step` to `final_step`. After each step positions
//! return to the domain: modulo 1 on the torus, clamped into [0, 1) on the
//! square (a projected gradient step). The best set by the objective's
//! score is kept; a loss above 1.5× the best undoes the step, restarts the
//! moments *and their bias correction* (the step count since the restart,
//! so the steps after a recovery are the cautious first steps of a fresh
//! Adam, not large ones) and halves the rate. The descent stops when the
//! score improves by less than a relative `rel_tol` over 50 scored
//! iterations (0 disables the test), or after `iters`.

use crate::points::{PointSet, wrap01};
use crate::rng::PREV_ONE;

/// Where the points live.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Domain {
    /// The unit torus: positions wrap modulo 1.
    Torus,
    /// The unit square: positions are clamped into [0, 1).
    Square,
}

impl Domain {
    /// `v` brought back into the domain.
    #[inline]
    pub fn confine(self, v: f64) -> f64 {
        match self {
            Domain::Torus => wrap01(v),
            Domain::Square => v.clamp(0.0, PREV_ONE),
        }
    }
}

/// A loss of point positions.
pub trait PointObjective: Sync {
    /// The loss at iteration `t` (possibly a stochastic estimate) with its
    /// gradient written into `gradient` (point-major).
    fn loss_and_gradient(&self, points: &PointSet, t: usize, gradient: &mut [f64]) -> f64;
    /// A deterministic score to keep the best set by, if the loss is
    /// stochastic; `None` when the loss itself is deterministic.
    fn score(&self, _points: &PointSet) -> Option<f64> {
        None
    }
}

/// Knobs of the descent.
#[derive(Debug, Clone, PartialEq)]
pub struct AdamOptions {
    /// Maximum iterations.
    pub iters: usize,
    /// Relative improvement over 50 scored iterations below which to stop
    /// (0: never stop early).
    pub rel_tol: f64,
    /// Initial step in units of the mean spacing N^(−1/d).
    pub step: f64,
    /// Final step (after `iters`) in the same units.
    pub final_step: f64,
    /// Score a stochastic objective every this many iterations.
    pub score_every: usize,
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
    /// The best score (the best loss for deterministic objectives).
    pub best_score: f64,
    /// The start's score.
    pub start_score: f64,
}

/// Descends from `start`; `on_iteration(t, loss)` is called every step.
pub fn adam(
    start: PointSet,
    objective: &dyn PointObjective,
    options: &AdamOptions,
    domain: Domain,
    on_iteration: &dyn Fn(usize, f64),
) -> DescentResult {
    let (n, d) = (start.len(), start.dim());
    let o = options;
    let spacing = (1.0 / n.max(1) as f64).powf(1.0 / d as f64);
    let (beta1, beta2, eps) = (0.9f64, 0.999f64, 1e-300f64);
    let mut x = start.coords().to_vec();
    let (mut m, mut v) = (vec![0.0; n * d], vec![0.0; n * d]);
    let mut grad = vec![0.0; n * d];
    let mut best = (f64::INFINITY, x.clone());
    let mut start_score = f64::NAN;
    let mut losses = Vec::with_capacity(o.iters + 1);
    let mut seconds = Vec::with_capacity(o.iters + 1);
    let mut scores: Vec<f64> = Vec::new();
    let clock = std::time::Instant::now();
    let mut damping = 1.0;
    let mut since_reset = 0i32;
    for t in 0..o.iters {
        let points = PointSet::new(d, x.clone()).expect("confined coordinates lie in [0,1)");
        grad.fill(0.0);
        let loss = objective.loss_and_gradient(&points, t, &mut grad);
        losses.push(loss);
        seconds.push(clock.elapsed().as_secs_f64());
        on_iteration(t, loss);
        let scored = if o.score_every <= 1 {
            Some(loss)
        } else if t % o.score_every == 0 {
            Some(objective.score(&points).unwrap_or(loss))
        } else {
            None
        };
        if let Some(score) = scored {
            if t == 0 {
                start_score = score;
            }
            scores.push(score);
            if score < best.0 {
                best = (score, x.clone());
            } else if score > 1.5 * best.0 {
                // Undo steps that blew up; take smaller ones from the best set.
                x.clone_from(&best.1);
                m.fill(0.0);
                v.fill(0.0);
                since_reset = 0;
                damping *= 0.5;
                continue;
            }
            let s = scores.len();
            if o.rel_tol > 0.0 && s > 50 && scores[s - 51] - score < o.rel_tol * score {
                break;
            }
        }
        let progress = t as f64 / o.iters as f64;
        let lr = damping * spacing * o.step * (o.final_step / o.step).powf(progress);
        since_reset += 1;
        let (c1, c2) = (1.0 - beta1.powi(since_reset), 1.0 - beta2.powi(since_reset));
        for i in 0..n * d {
            m[i] = beta1 * m[i] + (1.0 - beta1) * grad[i];
            v[i] = beta2 * v[i] + (1.0 - beta2) * grad[i] * grad[i];
            let step = lr * (m[i] / c1) / ((v[i] / c2).sqrt() + eps);
            x[i] = domain.confine(x[i] - step);
        }
    }
    // A stochastic objective's last iterate is scored too.
    if o.score_every > 1 {
        let points = PointSet::new(d, x.clone()).expect("confined coordinates lie in [0,1)");
        if let Some(score) = objective.score(&points)
            && score < best.0
        {
            best = (score, x);
        }
    }
    let points = PointSet::new(d, best.1).expect("confined coordinates lie in [0,1)");
    DescentResult {
        points,
        losses,
        seconds,
        best_score: best.0,
        start_score,
    }
}
