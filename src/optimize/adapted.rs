//! Which set a design adapted to one integrand returns (torus,
//! shift-randomized estimator).
//!
//! The spectral descent ([`super::descent`]) minimizes the variance inside
//! its frequency box; an integrand's P_f reaches beyond it (a half-plane's
//! |k|⁻² ridge runs out to k ≈ N), so a step that lowers the in-box loss can
//! raise the variance. Where the integrand has a closed-form
//! autocovariance, the exact spatial form (Öztireli 2016, Eq. 9; no
//! truncation) decides between the descent's set and its start, and the
//! result says which was kept: a start is never passed off as optimized.

use std::path::{Path, PathBuf};
use std::time::Duration;

use rayon::prelude::*;

use super::adam::{AdamState, Checkpointing};
use super::checkpoint;
use super::{DescentResult, OptimizeError, PointOptimizer};
use crate::integrands::Integrand;
use crate::io::WriteError;
use crate::points::PointSet;
use crate::rng::set_rng;
use crate::samplers::Sampler;
use crate::variance::{VarianceError, spatial_variance};

/// The set a design returns, with the evidence for it.
#[derive(Debug, Clone)]
pub struct Kept {
    /// The returned set.
    pub points: PointSet,
    /// The descent that was run (its curve and scores).
    pub descent: DescentResult,
    /// Exact variance of the start and of the descent's best set, where
    /// the integrand has a closed-form autocovariance.
    pub exact: Option<ExactComparison>,
}

/// The exact variances the choice was made on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExactComparison {
    /// Exact variance of the start (spatial form; its rounding bound is
    /// 4ε·Σ|c_f|/N², see [`crate::variance::spatial::SpatialEstimate`]).
    pub start: f64,
    /// Exact variance of the descent's best set.
    pub descended: f64,
    /// Bound on the rounding error of either value.
    pub rounding: f64,
    /// True when the start's variance was not above the descent's and the
    /// start was returned.
    pub kept_start: bool,
}

impl Kept {
    /// The descent's set, without an exact check.
    pub fn descended(descent: DescentResult) -> Self {
        Kept {
            points: descent.points.clone(),
            descent,
            exact: None,
        }
    }

    /// True when a descent ran and returned its start: the exact form kept
    /// it, or (without one) the descent's best score is the start's. False
    /// for one point on the torus, where no descent runs
    /// ([`super::adam::Stop::Stationary`]).
    pub fn start_returned(&self) -> bool {
        if self.descent.stop == super::adam::Stop::Stationary {
            return false;
        }
        match self.exact {
            Some(e) => e.kept_start,
            None => self.descent.best_score >= self.descent.start_score,
        }
    }

    /// Exact variance of the returned set, if known.
    pub fn variance(&self) -> Option<f64> {
        self.exact
            .map(|e| if e.kept_start { e.start } else { e.descended })
    }
}

/// The lower-variance set of `start` and the descent's result, by the exact
/// spatial form for `f`. When the two differ by less than the form's
/// rounding bounds the descent's own scores decide, and a descent that
/// found nothing lower (its best set is the start) keeps the start.
///
/// # Errors
/// [`VarianceError`] if the spatial form cannot be evaluated (dimension,
/// no closed-form autocovariance).
pub fn keep_lower_variance(
    start: PointSet,
    descent: DescentResult,
    f: &dyn Integrand,
) -> Result<Kept, VarianceError> {
    let (before, before_rounding) = spatial_variance(&start, f)?;
    // A descent that found nothing lower returns its start itself: one
    // O(N²) evaluation, not two.
    let (after, after_rounding) = if descent.points == start {
        (before, before_rounding)
    } else {
        spatial_variance(&descent.points, f)?
    };
    let kept_start = if (before - after).abs() <= before_rounding + after_rounding {
        // Both at the spatial form's rounding floor (a smooth f on a good
        // set): the descent's own loss, a sum of nonnegative terms, decides.
        descent.best_score >= descent.start_score
    } else {
        before < after
    };
    Ok(Kept {
        points: if kept_start {
            start
        } else {
            descent.points.clone()
        },
        descent,
        exact: Some(ExactComparison {
            start: before,
            descended: after,
            rounding: before_rounding.max(after_rounding),
            kept_start,
        }),
    })
}

/// Checkpoints of [`design_sets`]: set r of several is saved to `PATH.r`,
/// a single set to `PATH` ([`checkpoint_path`]); `on_event` hears of every
/// resume, save and failed save (a failed save does not stop the descent).
pub struct CheckpointPlan<'a> {
    /// Where set 0 (of one) is saved.
    pub path: &'a Path,
    /// The run's description; a checkpoint of another run is refused.
    pub run: &'a str,
    /// Least wall time between saves.
    pub every: Duration,
    /// Told of each resume, save and failure.
    pub on_event: &'a (dyn Fn(CheckpointEvent) + Sync),
}

/// What happened to a checkpoint.
#[derive(Debug)]
pub enum CheckpointEvent<'a> {
    /// Set `set` continues from iteration `iteration` saved at `path`.
    Resumed {
        /// The set.
        set: usize,
        /// Its next iteration.
        iteration: usize,
        /// The file.
        path: &'a Path,
    },
    /// Set `set` was saved at iteration `iteration`.
    Saved {
        /// The set.
        set: usize,
        /// Its next iteration.
        iteration: usize,
        /// The file.
        path: &'a Path,
    },
    /// Saving set `set` failed; the descent goes on.
    Failed {
        /// The set.
        set: usize,
        /// Why.
        error: &'a WriteError,
    },
}

/// The checkpoint file of set `set` of `sets` with base path `path`.
pub fn checkpoint_path(path: &Path, set: usize, sets: usize) -> PathBuf {
    if sets == 1 {
        return path.to_path_buf();
    }
    let mut name = path.as_os_str().to_owned();
    name.push(format!(".{set}"));
    PathBuf::from(name)
}

/// Checkpoint files beside `path` that a run with another set count wrote
/// (`PATH` of one set, `PATH.r` of several) and a run of `sets` sets does
/// not read, sorted: a run resumed with another `--sets` starts afresh, and
/// says so.
pub fn stray_checkpoints(path: &Path, sets: usize) -> Vec<PathBuf> {
    let ours: Vec<PathBuf> = (0..sets).map(|r| checkpoint_path(path, r, sets)).collect();
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return Vec::new();
    };
    let Ok(entries) = std::fs::read_dir(crate::io::folder_of(path)) else {
        return Vec::new();
    };
    let mut stray: Vec<PathBuf> = entries
        .flatten()
        .filter(|e| {
            let file = e.file_name().to_string_lossy().into_owned();
            file == name
                || file
                    .strip_prefix(&name)
                    .and_then(|r| r.strip_prefix('.'))
                    .is_some_and(|r| !r.is_empty() && r.bytes().all(|b| b.is_ascii_digit()))
        })
        .map(|e| path.with_file_name(e.file_name()))
        .filter(|p| !ours.contains(p))
        .collect();
    stray.sort();
    stray
}

/// Removes the checkpoint files of `sets` sets with base path `path` (once
/// the designs are written); returns those that could not be removed, with
/// why. Files already gone are not failures.
pub fn remove_checkpoints(path: &Path, sets: usize) -> Vec<(PathBuf, std::io::Error)> {
    (0..sets)
        .map(|r| checkpoint_path(path, r, sets))
        .filter_map(|file| match std::fs::remove_file(&file) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Some((file, e)),
            _ => None,
        })
        .collect()
}

/// `sets` designs: realization r of `start` (stream (seed, r)) descended by
/// `optimizer`, each kept by [`keep_lower_variance`] when `exact` is given.
/// Sets run in parallel; each is independent of the thread count. With a
/// `checkpoint` plan each set continues from its saved state when there is
/// one, and the result is the same, bit for bit, as a run never stopped.
///
/// # Errors
/// A failed realization of the start, the exact form, or a checkpoint that
/// is damaged or belongs to another run.
pub fn design_sets(
    optimizer: &PointOptimizer,
    start: &dyn Sampler,
    exact: Option<&dyn Integrand>,
    seed: u64,
    sets: usize,
    on_iteration: &(dyn Fn(usize, f64) + Sync),
    checkpoint: Option<&CheckpointPlan>,
) -> Result<Vec<Kept>, OptimizeError> {
    (0..sets)
        .into_par_iter()
        .map(|r| {
            let first = start.sample(&mut set_rng(seed, r as u64))?;
            let descended = match checkpoint {
                None => optimizer.optimize(first.clone(), on_iteration),
                Some(plan) => {
                    let path = checkpoint_path(plan.path, r, sets);
                    let state = match checkpoint::load(&path, plan.run)? {
                        Some(saved) => {
                            (plan.on_event)(CheckpointEvent::Resumed {
                                set: r,
                                iteration: saved.t,
                                path: &path,
                            });
                            saved
                        }
                        None => AdamState::start(&first),
                    };
                    let save = |s: &AdamState| match checkpoint::save(&path, plan.run, s) {
                        Ok(()) => (plan.on_event)(CheckpointEvent::Saved {
                            set: r,
                            iteration: s.t,
                            path: &path,
                        }),
                        Err(error) => (plan.on_event)(CheckpointEvent::Failed {
                            set: r,
                            error: &error,
                        }),
                    };
                    let checkpointing = Checkpointing {
                        every: plan.every,
                        save: &save,
                    };
                    optimizer.optimize_from(state, on_iteration, Some(&checkpointing))
                }
            };
            Ok(match exact {
                Some(f) => keep_lower_variance(first, descended, f)?,
                None => Kept::descended(descended),
            })
        })
        .collect()
}
