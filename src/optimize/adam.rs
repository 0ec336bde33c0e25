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
//! iterations (0 disables the test), once it reaches the objective's
//! accuracy floor, or after `iters` steps (whose curve holds `iters` + 1
//! losses: the start's and every step's).

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
    /// Stop once the score is at or below this (0: never): the level below
    /// which the objective cannot resolve a loss from zero.
    pub floor: f64,
}

impl AdamOptions {
    /// `rel_tol` checked: a finite relative improvement in [0, 1) (0: never
    /// stop early; NaN or a negative value would silently never stop, 1 or
    /// more would stop at the first check).
    ///
    /// # Errors
    /// [`OptimizeError::Option`] naming the value.
    pub fn checked_rel_tol(rel_tol: f64) -> Result<f64, super::OptimizeError> {
        if (0.0..1.0).contains(&rel_tol) {
            Ok(rel_tol)
        } else {
            Err(super::OptimizeError::Option(format!(
                "--rel-tol {}: the relative improvement over 50 iterations below which the descent stops must be in [0, 1) (0: never stop early)",
                crate::spec_params::SpecValue(rel_tol)
            )))
        }
    }
}

/// Why a descent stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// The score improved by less than `rel_tol` over 50 scored iterations.
    Converged,
    /// The score reached the objective's accuracy floor.
    Floor,
    /// The iteration cap came first: not converged by the rule.
    Cap,
    /// No step can change the loss: one point on the torus, whose
    /// spectrum |S(k)|² = 1 at every k wherever it lies.
    Stationary,
}

impl Stop {
    /// A phrase for a summary line.
    pub fn describe(self) -> &'static str {
        match self {
            Stop::Converged => "converged",
            Stop::Floor => "at the transform's accuracy floor",
            Stop::Cap => "iteration cap, not converged",
            Stop::Stationary => "one point: its loss is the same wherever it lies",
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
    /// The best score (the best loss for deterministic objectives).
    pub best_score: f64,
    /// The start's score.
    pub start_score: f64,
    /// Iterations of a coarse first phase run before `losses` began (0:
    /// none; see [`super::descent::DescentOptions::coarse_half`]).
    pub coarse_iterations: usize,
    /// Why the descent stopped.
    pub stop: Stop,
}

/// Everything the descent needs to go on from iteration `t`: positions,
/// Adam's moments, the best set so far and the history. A run continued
/// from a saved state takes the same steps, bit for bit, as one never
/// stopped (the objectives depend on the positions and on `t` only).
#[derive(Debug, Clone, PartialEq)]
pub struct AdamState {
    /// Dimension of the points.
    pub dim: usize,
    /// The next iteration.
    pub t: usize,
    /// Positions, point-major.
    pub x: Vec<f64>,
    /// First moment.
    pub m: Vec<f64>,
    /// Second moment.
    pub v: Vec<f64>,
    /// Best score so far (infinite before the first).
    pub best_score: f64,
    /// Positions of the best score.
    pub best_x: Vec<f64>,
    /// The start's score (NaN before the first).
    pub start_score: f64,
    /// Factor on the rate, halved by each recovery.
    pub damping: f64,
    /// Steps since the moments were last reset (Adam's bias correction).
    pub since_reset: i32,
    /// Scores so far (the stopping test looks 50 back).
    pub scores: Vec<f64>,
    /// Loss of every iteration so far.
    pub losses: Vec<f64>,
    /// Wall time at every entry of `losses`, in seconds since the run began
    /// (across restarts).
    pub seconds: Vec<f64>,
    /// Wall time spent before the first entry (a coarse phase), in seconds.
    pub seconds_offset: f64,
    /// Iterations of the coarse phase run before this state's first step
    /// (0: none), kept across restarts for the report.
    pub coarse_iterations: usize,
}

impl AdamState {
    /// The state before the first step from `start`.
    pub fn start(start: &PointSet) -> Self {
        let x = start.coords().to_vec();
        let zeros = vec![0.0; x.len()];
        AdamState {
            dim: start.dim(),
            t: 0,
            m: zeros.clone(),
            v: zeros,
            best_score: f64::INFINITY,
            best_x: x.clone(),
            x,
            start_score: f64::NAN,
            damping: 1.0,
            since_reset: 0,
            scores: Vec::new(),
            losses: Vec::new(),
            seconds: Vec::new(),
            seconds_offset: 0.0,
            coarse_iterations: 0,
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.x.len() / self.dim.max(1)
    }

    /// Whether the state holds no point.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
}

/// Saving the state while the descent runs: `save` receives it at the top
/// of an iteration once `every` has passed since the last save (the run
/// itself does not change: saving only reads the state).
pub struct Checkpointing<'a> {
    /// Least wall time between two saves.
    pub every: std::time::Duration,
    /// Called with the state to save.
    pub save: &'a (dyn Fn(&AdamState) + Sync),
}

/// Descends from `start`; `on_iteration(t, loss)` is called every step.
pub fn adam(
    start: PointSet,
    objective: &dyn PointObjective,
    options: &AdamOptions,
    domain: Domain,
    on_iteration: &dyn Fn(usize, f64),
) -> DescentResult {
    adam_from(
        AdamState::start(&start),
        objective,
        options,
        domain,
        on_iteration,
        None,
    )
}

/// Descends from a saved (or fresh) `state`, saving it as `checkpointing`
/// says; `on_iteration(t, loss)` is called every step.
pub fn adam_from(
    mut s: AdamState,
    objective: &dyn PointObjective,
    options: &AdamOptions,
    domain: Domain,
    on_iteration: &dyn Fn(usize, f64),
    checkpointing: Option<&Checkpointing>,
) -> DescentResult {
    let (n, d) = (s.len(), s.dim);
    let o = options;
    let spacing = (1.0 / n.max(1) as f64).powf(1.0 / d as f64);
    let (beta1, beta2, eps) = (0.9f64, 0.999f64, 1e-300f64);
    let mut grad = vec![0.0; n * d];
    let offset = s.seconds.last().copied().unwrap_or(s.seconds_offset);
    let clock = std::time::Instant::now();
    let mut last_save = clock;
    let mut stop = Stop::Cap;
    // `iters` steps: the start and every step's set are evaluated, the
    // last step's too (it ends the curve and competes for the best; it was
    // never evaluated, so `--iters 1` returned the start unchanged).
    let evaluations = if o.iters == 0 { 0 } else { o.iters + 1 };
    while s.t < evaluations {
        let t = s.t;
        let last = t == o.iters;
        if let Some(c) = checkpointing
            && t > 0
            && last_save.elapsed() >= c.every
        {
            (c.save)(&s);
            last_save = std::time::Instant::now();
        }
        s.t += 1;
        let points = PointSet::new(d, s.x.clone()).expect("confined coordinates lie in [0,1)");
        grad.fill(0.0);
        let loss = objective.loss_and_gradient(&points, t, &mut grad);
        s.losses.push(loss);
        s.seconds.push(offset + clock.elapsed().as_secs_f64());
        on_iteration(t, loss);
        let scored = if o.score_every <= 1 {
            Some(loss)
        } else if last || t % o.score_every == 0 {
            Some(objective.score(&points).unwrap_or(loss))
        } else {
            None
        };
        if let Some(score) = scored {
            if t == 0 {
                s.start_score = score;
            }
            s.scores.push(score);
            if score < s.best_score {
                s.best_score = score;
                s.best_x.clone_from(&s.x);
            } else if score > 1.5 * s.best_score {
                // Undo steps that blew up; take smaller ones from the best set.
                s.x.clone_from(&s.best_x);
                s.m.fill(0.0);
                s.v.fill(0.0);
                s.since_reset = 0;
                s.damping *= 0.5;
                continue;
            }
            // No step follows the last set (it is always scored).
            if last {
                break;
            }
            let k = s.scores.len();
            if score <= o.floor {
                stop = Stop::Floor;
                break;
            }
            if o.rel_tol > 0.0 && k > 50 && s.scores[k - 51] - score < o.rel_tol * score {
                stop = Stop::Converged;
                break;
            }
        }
        let progress = t as f64 / o.iters as f64;
        let lr = s.damping * spacing * o.step * (o.final_step / o.step).powf(progress);
        s.since_reset += 1;
        let (c1, c2) = (
            1.0 - beta1.powi(s.since_reset),
            1.0 - beta2.powi(s.since_reset),
        );
        for (((x, m), v), g) in s.x.iter_mut().zip(&mut s.m).zip(&mut s.v).zip(&grad) {
            *m = beta1 * *m + (1.0 - beta1) * g;
            *v = beta2 * *v + (1.0 - beta2) * g * g;
            let step = lr * (*m / c1) / ((*v / c2).sqrt() + eps);
            *x = domain.confine(*x - step);
        }
    }
    let points = PointSet::new(d, s.best_x).expect("confined coordinates lie in [0,1)");
    DescentResult {
        points,
        losses: s.losses,
        seconds: s.seconds,
        best_score: s.best_score,
        start_score: s.start_score,
        coarse_iterations: s.coarse_iterations,
        stop,
    }
}
