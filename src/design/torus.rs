//! `optimize points` on the torus as a library call: a [`TorusPlan`] fixes
//! the target, the descent's options, the start and the memory it needs
//! (checked before anything runs); [`TorusPlan::run`] designs the sets and
//! scores them against the classic samplers ([`TorusDesign`], the JSON
//! report). The loss is the in-box spectral loss Σ_(0<|k|∞≤h) W(k)·P_S(k)
//! (docs/mathematics.md §6; Pilleboue et al. 2015, eq. 8 for an integrand
//! target, where it is the predicted variance within the box).

use rayon::prelude::*;
use serde::Serialize;
use serde_json::json;

use super::DesignRun;
use crate::baseline::{Baseline, CLASSIC, classic_baselines};
use crate::integrands::Integrand;
use crate::optimize::adapted::{CheckpointPlan, Kept, design_sets};
use crate::optimize::lattice::{LatticeDesign, best_lattice};
use crate::optimize::{DescentOptions, OptimizeError, PointOptimizer, Stop, Target};
use crate::points::PointSet;
use crate::registry;
use crate::samplers::lattice::MAX_POINTS as LATTICE_MAX_POINTS;
use crate::samplers::{Sampler, SamplerError};
use crate::spectrum::Upsampling;
use crate::spectrum::nufft::nufft_memory_bytes;
use crate::sum::mean;
use crate::variance::spatial::{estimated_seconds, pair_evaluations};
use crate::variance::spatial_variance;

/// What to design (the options of `optimize points` on the torus).
#[derive(Debug, Clone)]
pub struct TorusRequest {
    /// Points per set.
    pub n: usize,
    /// Dimension.
    pub dim: usize,
    /// The target spec ([`Target::parse`]).
    pub target: String,
    /// Independent sets, designed in parallel.
    pub sets: usize,
    /// Iteration cap (default 1000).
    pub iters: Option<usize>,
    /// Seed of the starting sets.
    pub seed: u64,
    /// Starting sampler (default: see [`TorusPlan::new`]).
    pub init: Option<String>,
    /// Parameters of the starting sampler (`--param`), over its
    /// shorthand's.
    pub init_params: Vec<(String, String)>,
    /// NUFFT tolerance (default from the target).
    pub tol: Option<f64>,
    /// Relative-improvement stopping rule (default from the target).
    pub rel_tol: Option<f64>,
    /// The NUFFT's upsampling (default chosen for N).
    pub upsampling: Option<Upsampling>,
    /// Box resolution K (|k| < K/2).
    pub res: Option<usize>,
    /// Descend on a quarter box first (2D blue-noise targets): `None` as
    /// [`DescentOptions::for_target`] decides (from
    /// [`crate::optimize::descent::COARSE_FROM`] points on).
    pub coarse: Option<bool>,
}

/// A checked plan: everything decided, nothing run.
pub struct TorusPlan {
    request: TorusRequest,
    optimizer: PointOptimizer,
    init: Box<dyn Sampler>,
    init_name: String,
    exact_form: Option<Box<dyn Integrand>>,
    lattice: Option<LatticeDesign>,
    iters: usize,
    tolerance: f64,
    rel_tol: f64,
    coarse_half: Option<usize>,
    memory_bytes: f64,
    /// Time to plan and find the start (the best lattice), counted in the
    /// design's wall time.
    prepare_seconds: f64,
}

/// The designed sets and their report.
#[derive(Debug, Clone, Serialize)]
pub struct TorusDesign {
    /// The designed sets.
    #[serde(skip)]
    pub points: Vec<PointSet>,
    /// Domain, target, sizes, seed, start and wall time.
    #[serde(flatten)]
    pub run: DesignRun,
    /// The box half-width h.
    pub half: usize,
    /// The box resolution 2h + 1.
    pub res: usize,
    /// NUFFT tolerance.
    pub tolerance: f64,
    /// NUFFT upsampling factor.
    pub upsampling: f64,
    /// Per set: entries of its loss curve (the start's loss and each
    /// step's).
    pub iterations: Vec<usize>,
    /// The iteration cap (`--iters`).
    pub max_iterations: usize,
    /// The stopping rule's relative improvement over 50 iterations
    /// (`--rel-tol`; 0: never stop early).
    pub rel_tol: f64,
    /// Iterations on the coarse box per set.
    pub coarse_iterations: Vec<usize>,
    /// Why each set's descent stopped (converged, accuracy floor or cap).
    pub stopped: Vec<Stop>,
    /// What the loss is.
    pub loss: &'static str,
    /// Set 0's loss per iteration.
    pub loss_curve: Vec<f64>,
    /// Set 0's wall time per iteration.
    pub loss_curve_seconds: Vec<f64>,
    /// Mean best loss of the designs and of each classic sampler
    /// (`{"optimized": {"n", "loss"}, "jitter": {...}, ...}`).
    pub comparison: serde_json::Map<String, serde_json::Value>,
    /// Wall time of that comparison (after the design's `seconds`).
    pub comparison_seconds: f64,
    /// Mean exact variance (spatial form, no box) where the target is an
    /// integrand with a closed-form autocovariance.
    pub exact_variance: Option<f64>,
    /// Per set: the exact variances the returned set was chosen on.
    pub exact: Vec<Option<serde_json::Value>>,
    /// The integration lattice started from, if any.
    pub lattice: Option<LatticeDesign>,
    /// The classic samplers' mean losses.
    #[serde(skip)]
    pub baselines: Vec<Baseline<f64>>,
    /// Mean best loss of the designs.
    #[serde(skip)]
    pub mean_loss: f64,
    /// Sets whose start was returned unchanged.
    #[serde(skip)]
    pub kept_start: usize,
    /// Largest rounding bound of the exact variances.
    #[serde(skip)]
    pub rounding: f64,
}

impl TorusDesign {
    /// The classic sampler at the same N whose exact variance on the target
    /// is lowest, where the design's exceeds it by more than a quarter (the
    /// classic samplers' means are over 8 or more sets) and the rounding
    /// bound: a start the descent could not leave (every N-point lattice
    /// holds N·Z² in its dual, so `cos:kx=64` at N = 16 is aliased by all
    /// of them: 0.5 against Sobol's 0.017, returned without a word).
    #[must_use]
    pub fn beaten_by(&self) -> Option<(&str, f64)> {
        let design = self.exact_variance?;
        self.comparison
            .iter()
            .filter(|(name, row)| {
                *name != "optimized" && row["n"].as_u64() == Some(self.run.n as u64)
            })
            .filter_map(|(name, row)| Some((name.as_str(), row["exact_variance"].as_f64()?)))
            .filter(|&(_, v)| 1.25 * v + self.rounding < design)
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }
}

impl TorusPlan {
    /// Parses the target, picks the start (the best integration lattice for
    /// 2D integrands with a closed-form autocovariance, measured 0.14× CMJ
    /// on a half-plane at N = 256 against 0.29× from CMJ,
    /// results/optimize-adapted; CMJ for other 2D integrands; random
    /// otherwise) and checks the memory the run needs.
    ///
    /// # Errors
    /// [`OptimizeError`] for a bad target or option, a start that cannot be
    /// built, or a run larger than the memory budget.
    pub fn new(request: TorusRequest) -> Result<Self, OptimizeError> {
        let prepared = std::time::Instant::now();
        let r = &request;
        if r.sets == 0 {
            return Err(OptimizeError::Option("--sets must be at least 1".into()));
        }
        crate::memory::check(
            &format!("the results of {} designed sets of {} points", r.sets, r.n),
            Some(results_bytes(r.sets, r.n, r.dim, r.iters)),
            "lower --sets",
        )?;
        let target = Target::parse(&r.target)?;
        let integrand = match &target {
            Target::Integrand(spec) => Some(crate::integrands::parse(spec)?),
            _ => None,
        };
        let has_integrand = integrand.is_some();
        let exact_form = integrand.filter(|f| f.has_autocov());
        let init_spec = r.init.clone().unwrap_or_else(|| {
            match &exact_form {
                // The lattice search holds up to MAX_POINTS points; beyond,
                // the default is the next best start.
                Some(f) if r.dim == 2 && f.dim() == 2 && r.n <= LATTICE_MAX_POINTS => "lattice",
                _ if has_integrand && r.dim == 2 => "cmj",
                _ => "random",
            }
            .into()
        });
        let init_name = registry::label(&init_spec, &r.init_params)?;
        let iters = r.iters.unwrap_or(1000);
        let mut options = DescentOptions::for_target(r.n, r.dim, &target);
        options.iters = iters;
        if let Some(t) = r.tol {
            options.tolerance = t;
        }
        if let Some(t) = r.rel_tol {
            options.rel_tol = crate::optimize::adam::AdamOptions::checked_rel_tol(t)?;
        }
        if let Some(u) = r.upsampling {
            options.upsampling = u;
        }
        if let Some(res) = r.res {
            if res < 3 {
                return Err(OptimizeError::Option(
                    "--res must be at least 3 (the box |k| < K/2 must hold a frequency besides 0)"
                        .into(),
                ));
            }
            options.half = (res - 1) / 2;
        }
        match r.coarse {
            Some(true) if !DescentOptions::takes_coarse(r.dim, &target) => {
                return Err(OptimizeError::Option(
                    "--coarse applies to 2D blue-noise targets (family:, power:, radial:), not to integrand targets or other dimensions".into(),
                ));
            }
            Some(true) => options.coarse_half = Some(options.half / 4),
            Some(false) => options.coarse_half = None,
            // A box given by --res: the coarse phase is a quarter of it.
            None => options.coarse_half = options.coarse_half.map(|_| options.half / 4),
        }
        let (tolerance, rel_tol, coarse_half) =
            (options.tolerance, options.rel_tol, options.coarse_half);
        let optimizer = PointOptimizer::new(r.dim, &target, options)?;
        let (init, lattice): (Box<dyn Sampler>, _) = if init_name == "lattice" {
            let Some(f) = exact_form.as_ref().filter(|f| f.dim() == 2 && r.dim == 2) else {
                return Err(OptimizeError::Option(
                    "--init lattice (the search for the best integration lattice) needs a 2D \
                     integrand target with a closed-form autocovariance (cos, disk, box, gaussian, \
                     halfplane); to start from one given rank-1 lattice, name it: --init \
                     lattice:g=G"
                        .into(),
                ));
            };
            let found = best_lattice(r.n, f.as_ref())?;
            (Box::new(found.lattice), Some(found))
        } else {
            (
                registry::build(&init_spec, r.n, Some(r.dim), &r.init_params)?,
                None,
            )
        };
        let plan_bytes = nufft_memory_bytes(optimizer.frequencies()).unwrap_or(f64::INFINITY);
        // An upper bound: the plans (the coarse phase's too, about a
        // sixteenth of the box), each running descent, the kept results, and
        // the classic samplers' sets of the comparison (measured at
        // N = 1,048,576 with --coarse: peak 525 MiB against 661 MiB stated).
        let coarse_bytes = if coarse_half.is_some() {
            plan_bytes / 16.0
        } else {
            0.0
        };
        let baseline_bytes = r.sets.max(8) as f64 * r.n as f64 * r.dim as f64 * 8.0;
        let memory_bytes = plan_bytes
            + coarse_bytes
            + rayon::current_num_threads().min(r.sets) as f64 * optimizer.descent_bytes(r.n)
            + results_bytes(r.sets, r.n, r.dim, r.iters)
            + baseline_bytes;
        crate::memory::check(
            &format!(
                "{} descent(s) of {} points on a box |k| <= {}",
                r.sets,
                r.n,
                optimizer.frequencies().half
            ),
            Some(memory_bytes),
            "lower --sets, -n or --res",
        )?;
        Ok(Self {
            request,
            optimizer,
            init,
            init_name,
            exact_form,
            lattice,
            iters,
            tolerance,
            rel_tol,
            coarse_half,
            memory_bytes,
            prepare_seconds: prepared.elapsed().as_secs_f64(),
        })
    }

    /// The memory the run was checked for, in bytes.
    pub fn memory_bytes(&self) -> f64 {
        self.memory_bytes
    }

    /// The integration lattice the sets start from, if any.
    pub fn lattice(&self) -> Option<&LatticeDesign> {
        self.lattice.as_ref()
    }

    /// The optimizer (its box, loss and upsampling).
    pub fn optimizer(&self) -> &PointOptimizer {
        &self.optimizer
    }

    /// Seconds the classic samplers' exact variances would take (the
    /// spatial form on 8 or more sets of each of [`CLASSIC`] at N), when
    /// the target has an exact form and the pairs exceed 2^30 (below, a few
    /// seconds at most: `None`).
    pub fn comparison_estimate(&self) -> Option<f64> {
        let r = &self.request;
        let f = self.exact_form.as_deref().filter(|f| f.dim() == r.dim)?;
        let sets = r.sets.max(8) * CLASSIC.len();
        if pair_evaluations(f, r.n) * sets as f64 <= (1u64 << 30) as f64 {
            return None;
        }
        // The exact form has c_f, so the probe cannot fail.
        estimated_seconds(f, &[(r.n, sets)]).ok()
    }

    /// Iterations per set at most.
    pub fn iters(&self) -> usize {
        self.iters
    }

    /// Everything that decides the result, as one line: a checkpoint
    /// continues only a run with the same line.
    pub fn run_line(&self) -> String {
        let r = &self.request;
        format!(
            "optimize points -n {} -d {} --target {} --init {} --seed {} --iters {} --res {} --tol {:e} --rel-tol {:e} --upsampling {} --coarse {}",
            r.n,
            r.dim,
            r.target,
            self.init_name,
            r.seed,
            self.iters,
            2 * self.optimizer.frequencies().half + 1,
            self.tolerance,
            self.rel_tol,
            self.optimizer.upsampling(),
            self.coarse_half.is_some(),
        )
    }

    /// Designs the sets (`on_iteration(set, loss)` after every step), calls
    /// `on_designed`, and scores them and 8 or more sets of each classic
    /// sampler by the loss (and by the exact variance where the target has
    /// one: O(N²) per set, [`TorusPlan::comparison_estimate`]).
    ///
    /// # Errors
    /// [`OptimizeError`] from a start, a checkpoint or a baseline.
    pub fn run(
        &self,
        on_iteration: &(dyn Fn(usize, f64) + Sync),
        checkpoint: Option<&CheckpointPlan>,
        on_designed: &dyn Fn(),
    ) -> Result<TorusDesign, OptimizeError> {
        let r = &self.request;
        let start = std::time::Instant::now();
        let results = design_sets(
            &self.optimizer,
            self.init.as_ref(),
            self.exact_form.as_deref(),
            r.seed,
            r.sets,
            on_iteration,
            checkpoint,
        )?;
        let seconds = self.prepare_seconds + start.elapsed().as_secs_f64();
        on_designed();
        let comparing = std::time::Instant::now();
        let final_losses: Vec<f64> = results
            .iter()
            .map(|k| {
                k.descent
                    .losses
                    .iter()
                    .copied()
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        let mean_loss = mean(&final_losses);
        let mut comparison = serde_json::Map::new();
        comparison.insert("optimized".into(), json!({"n": r.n, "loss": mean_loss}));
        let baselines = classic_baselines(r.n, r.dim, r.sets.max(8), r.seed, |sets| {
            let losses: Vec<f64> = sets.par_iter().map(|p| self.optimizer.loss(p)).collect();
            Ok::<_, SamplerError>(mean(&losses))
        })?;
        for b in &baselines {
            comparison.insert(b.name.into(), json!({"n": b.n, "loss": b.score}));
        }
        // Beside the in-box losses, the classic samplers' exact variances
        // (spatial form, no box) where the design has its own: an in-box
        // loss leaves out what lies beyond the box, which the descent does
        // not see, so its ratio overstates the design's gain.
        if let Some(f) = self.exact_form.as_deref().filter(|f| f.dim() == r.dim) {
            let exact = classic_baselines(r.n, r.dim, r.sets.max(8), r.seed, |sets| {
                let variances: Vec<f64> = sets
                    .par_iter()
                    .map(|p| spatial_variance(p, f).map(|v| v.0))
                    .collect::<Result<_, _>>()?;
                Ok::<_, OptimizeError>(mean(&variances))
            })?;
            for b in exact {
                if let Some(entry) = comparison.get_mut(b.name).and_then(|v| v.as_object_mut()) {
                    entry.insert("exact_variance".into(), json!(b.score));
                }
            }
        }
        let exact: Option<Vec<f64>> = results.iter().map(Kept::variance).collect();
        if let (Some(v), Some(entry)) = (
            exact.as_deref(),
            comparison
                .get_mut("optimized")
                .and_then(|e| e.as_object_mut()),
        ) {
            entry.insert("exact_variance".into(), json!(mean(v)));
        }
        let comparison_seconds = comparing.elapsed().as_secs_f64();
        let half = self.optimizer.frequencies().half;
        Ok(TorusDesign {
            points: results.iter().map(|k| k.points.clone()).collect(),
            run: DesignRun {
                domain: "torus",
                target: r.target.clone(),
                n: r.n,
                dim: r.dim,
                sets: r.sets,
                seed: r.seed,
                init: self.init_name.clone(),
                seconds,
            },
            half,
            res: 2 * half + 1,
            tolerance: self.tolerance,
            upsampling: self.optimizer.upsampling(),
            iterations: results.iter().map(|k| k.descent.losses.len()).collect(),
            max_iterations: self.iters,
            rel_tol: self.rel_tol,
            coarse_iterations: results.iter().map(|k| k.descent.coarse_iterations).collect(),
            stopped: results.iter().map(|k| k.descent.stop).collect(),
            loss: "sum over 0 < |k|inf <= half of W(k) P_S(k)  (for an integrand target: its predicted variance within the box)",
            loss_curve: results[0].descent.losses.clone(),
            loss_curve_seconds: results[0].descent.seconds.clone(),
            comparison,
            comparison_seconds,
            exact_variance: exact.as_deref().map(mean),
            exact: results
                .iter()
                .map(|k| {
                    k.exact.map(|e| {
                        json!({"start": e.start, "descended": e.descended, "rounding_bound": e.rounding, "kept_start": e.kept_start})
                    })
                })
                .collect(),
            lattice: self.lattice.clone(),
            baselines,
            mean_loss,
            kept_start: results.iter().filter(|k| k.start_returned()).count(),
            rounding: results
                .iter()
                .filter_map(|k| k.exact.map(|e| e.rounding))
                .fold(0.0, f64::max),
        })
    }

    /// The coarse phase's box half-width, when there is one.
    pub fn coarse_half(&self) -> Option<usize> {
        self.coarse_half
    }
}

/// Bytes of the designed sets kept until all are written: each set's points
/// and its loss curve (loss and time per iteration, at most 2000).
pub fn results_bytes(sets: usize, n: usize, dim: usize, iters: Option<usize>) -> f64 {
    let iters = iters.unwrap_or(2000) as f64;
    sets as f64 * (n as f64 * dim as f64 * 8.0 + iters * 16.0)
}
