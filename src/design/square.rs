//! `optimize points --domain square` as a library call: descend on family
//! MSEs of the unshifted estimator ([`crate::square::design`]), then score the
//! designs and the classic samplers on family members the descent never
//! saw (the peer's half-planes and Gaussians, and the target's own
//! families; UTK's integration tests, Ahmed et al. 2016).

use rayon::prelude::*;
use serde::Serialize;
use serde_json::{Map, Value, json};

use super::DesignRun;
use crate::baseline::classic_baselines;
use crate::neighbours::closest_pair_ratio;
use crate::optimize::Stop;
use crate::points::PointSet;
use crate::registry;
use crate::rng::set_rng;
use crate::samplers::SamplerError;
use crate::square::design::{TermKind, default_options, design, parse_target};
use crate::square::{Family, FamilyError, family_mse};

/// What stops a design on the square.
#[derive(Debug, thiserror::Error)]
pub enum SquareDesignError {
    /// A bad target.
    #[error(transparent)]
    Family(#[from] FamilyError),
    /// A start that cannot be built.
    #[error(transparent)]
    Sampler(#[from] SamplerError),
    /// Scores larger than the memory budget.
    #[error(transparent)]
    Memory(#[from] crate::memory::TooMuchMemory),
    /// A request that cannot be met.
    #[error("{0}")]
    Request(String),
}

/// What to design.
#[derive(Debug, Clone)]
pub struct SquareRequest {
    /// Points per set.
    pub n: usize,
    /// The target terms (`halfplanes+gaussians+16*blue`, …).
    pub target: String,
    /// Independent sets, designed in parallel.
    pub sets: usize,
    /// Iteration cap (default from [`default_options`]).
    pub iters: Option<usize>,
    /// Seed of the starts and of the descent's members.
    pub seed: u64,
    /// Starting sampler (default: [`crate::square::design::default_start`]).
    pub init: Option<String>,
    /// Parameters of the starting sampler (`--param`), over its
    /// shorthand's.
    pub init_params: Vec<(String, String)>,
    /// Family members each score averages over.
    pub members: usize,
    /// Seed of the scoring members.
    pub score_seed: u64,
}

/// The designed sets and their report.
#[derive(Debug, Clone, Serialize)]
pub struct SquareDesign {
    /// The designed sets.
    #[serde(skip)]
    pub points: Vec<PointSet>,
    /// Domain, target, sizes, seed, start and wall time of the descents.
    #[serde(flatten)]
    pub run: DesignRun,
    /// The estimator scored.
    pub estimator: &'static str,
    /// Per set: entries of its loss curve (what the descent ran before
    /// it stopped).
    pub iterations: Vec<usize>,
    /// The iteration cap (`--iters`).
    pub max_iterations: usize,
    /// Why each set's descent stopped (converged, accuracy floor or cap).
    pub stopped: Vec<Stop>,
    /// What the loss is.
    pub loss: &'static str,
    /// Per set: the loss's score at the start.
    pub score_start: Vec<f64>,
    /// Per set: the best score reached.
    pub score_best: Vec<f64>,
    /// Set 0's loss per iteration.
    pub loss_curve: Vec<f64>,
    /// Set 0's wall time per iteration.
    pub loss_curve_seconds: Vec<f64>,
    /// Family MSEs (mse, stderr, members) and the closest pair of the
    /// designs ("optimized") and of each classic sampler.
    pub comparison: Map<String, Value>,
    /// Members per score.
    pub score_members: usize,
    /// Seed of the scoring members.
    pub score_seed: u64,
    /// The families scored, in order.
    #[serde(skip)]
    pub families: Vec<String>,
}

/// Designs `request.sets` sets on the square (`on_iteration(set, loss)`
/// after every step) and scores them beside the classic samplers.
///
/// # Errors
/// [`SquareDesignError`] for a bad target, a start that cannot give N
/// points, or scores beyond the memory budget.
pub fn design_on_square(
    request: &SquareRequest,
    on_iteration: &(dyn Fn(usize, f64) + Sync),
) -> Result<SquareDesign, SquareDesignError> {
    let r = request;
    if r.sets == 0 {
        return Err(SquareDesignError::Request(
            "--sets must be at least 1".into(),
        ));
    }
    let terms = parse_target(&r.target)?;
    // Scores: the designed sets and 8 or more sets of each classic sampler.
    crate::square::mse::check_family_memory(r.members, r.sets.max(8))?;
    let mut options = default_options();
    if let Some(i) = r.iters {
        options.iters = i;
    }
    let init_spec = r
        .init
        .clone()
        .unwrap_or_else(|| crate::square::design::default_start(r.n).into());
    let init_name = registry::label(&init_spec, &r.init_params)?;
    let (init, n) = registry::build_nearest(&init_spec, r.n, Some(2), &r.init_params)?;
    if n != r.n {
        return Err(SquareDesignError::Request(format!(
            "--init {init_name} cannot start from N = {} (nearest: {n}); pick another --init or N",
            r.n
        )));
    }
    let start = std::time::Instant::now();
    let results = (0..r.sets)
        .into_par_iter()
        .map(|set| -> Result<_, SquareDesignError> {
            let first = init.sample(&mut set_rng(r.seed, set as u64))?;
            let seed = crate::rng::mix64(r.seed ^ (set as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
            Ok(design(&terms, first, seed, &options, on_iteration))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let seconds = start.elapsed().as_secs_f64();
    let points: Vec<PointSet> = results.iter().map(|x| x.points.clone()).collect();
    // The peer's two families, and the target's own.
    let mut families = vec![Family::parse("halfplanes")?, Family::parse("gaussians")?];
    for term in &terms {
        if let TermKind::Family(f) = &term.kind
            && !families.iter().any(|g| g.spec() == f.spec())
        {
            families.push(f.clone());
        }
    }
    let score = |sets: &[PointSet]| {
        let mut m = Map::new();
        for f in &families {
            let s = family_mse(sets, f, r.members, r.score_seed);
            m.insert(
                f.spec(),
                json!({"mse": s.mse, "stderr": s.stderr, "stderr_members": s.stderr_members,
                       "stderr_sets": s.stderr_sets, "members": s.members, "sets": sets.len()}),
            );
        }
        let closest = sets
            .iter()
            .map(closest_pair_ratio)
            .fold(f64::INFINITY, f64::min);
        m.insert("closest_pair_over_hexagonal".into(), json!(closest));
        m
    };
    let mut comparison = Map::new();
    comparison.insert("optimized".into(), json!(score(&points)));
    for b in classic_baselines(r.n, 2, r.sets.max(8), r.seed, |sets| {
        Ok::<_, SamplerError>(score(sets))
    })? {
        let mut m = b.score;
        m.insert("n".into(), json!(b.n));
        comparison.insert(b.name.into(), json!(m));
    }
    Ok(SquareDesign {
        run: DesignRun {
            domain: "square",
            target: r.target.clone(),
            n: r.n,
            dim: 2,
            sets: r.sets,
            seed: r.seed,
            init: init_name,
            seconds,
        },
        estimator: "unshifted: mean of f over the set on [0,1)^2",
        iterations: results.iter().map(|x| x.losses.len()).collect(),
        max_iterations: options.iters,
        stopped: results.iter().map(|x| x.stop).collect(),
        loss: "sum of w_t MSE_t / MSE_t(start) (blue: repulsion / its value for uniform points); stochastic per iteration",
        score_start: results.iter().map(|x| x.start_score).collect(),
        score_best: results.iter().map(|x| x.best_score).collect(),
        loss_curve: results[0].losses.clone(),
        loss_curve_seconds: results[0].seconds.clone(),
        comparison,
        score_members: r.members,
        score_seed: r.score_seed,
        families: families.iter().map(Family::spec).collect(),
        points,
    })
}
