//! `optimize points -d 4` with targets per projection as a library call:
//! one 4D descent per set on the weighted sum of the planes' spectral
//! losses ([`crate::optimize::projections`]; the seed's design principle, Singh &
//! Jarosz 2017), from umj by default, reported per term before and after
//! with the closest pair of the XY and UV projections.

use rayon::prelude::*;
use serde::Serialize;

use super::DesignRun;
use crate::neighbours::closest_pair_ratio;
use crate::optimize::projections::{ProjectionObjective, parse_projections};
use crate::optimize::{AdamOptions, Domain, OptimizeError, Stop, adam};
use crate::points::PointSet;
use crate::registry;
use crate::rng::set_rng;

/// What to design.
#[derive(Debug, Clone)]
pub struct ProjectionRequest {
    /// Points per set.
    pub n: usize,
    /// The projection target (`xy:SPEC;uv:SPEC;…`).
    pub target: String,
    /// Independent sets, designed in parallel.
    pub sets: usize,
    /// Iteration cap (default 1000).
    pub iters: Option<usize>,
    /// Relative-improvement stopping rule (default 1e-4).
    pub rel_tol: Option<f64>,
    /// Seed of the starting sets.
    pub seed: u64,
    /// Starting 4D sampler (default umj).
    pub init: Option<String>,
    /// Parameters of the starting sampler (`--param`), over its
    /// shorthand's.
    pub init_params: Vec<(String, String)>,
}

/// One projection term's loss before and after the descent (means over
/// the sets).
#[derive(Debug, Clone, Serialize)]
pub struct TermLoss {
    /// The term's label.
    pub term: String,
    /// Its weight.
    pub weight: f64,
    /// The 2×4 projection.
    pub rows: [[f64; 4]; 2],
    /// Half-width h of the term's frequency box |k|∞ ≤ h on its plane (its
    /// 2D target's default box at N): the loss sees no frequency beyond.
    pub half: usize,
    /// Mean loss of the starts.
    pub loss_before: f64,
    /// Mean loss of the designs.
    pub loss_after: f64,
}

/// Closest pair over the hexagonal spacing, worst over the sets.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ClosestPairs {
    /// In the XY projection.
    pub xy: f64,
    /// In the UV projection.
    pub uv: f64,
}

/// The designed sets and their report.
#[derive(Debug, Clone, Serialize)]
pub struct ProjectionDesign {
    /// The designed sets.
    #[serde(skip)]
    pub points: Vec<PointSet>,
    /// Domain, target, sizes, seed, start and wall time.
    #[serde(flatten)]
    pub run: DesignRun,
    /// Per set: entries of its loss curve (what the descent ran before
    /// it stopped).
    pub iterations: Vec<usize>,
    /// The iteration cap (`--iters`).
    pub max_iterations: usize,
    /// The stopping rule's relative improvement over 50 iterations
    /// (`--rel-tol`; 0: never stop early).
    pub rel_tol: f64,
    /// Why each set's descent stopped (converged, accuracy floor or cap).
    pub stopped: Vec<Stop>,
    /// Per term, before and after.
    pub terms: Vec<TermLoss>,
    /// XY and UV closest pairs of the designs.
    pub closest_pair_over_hexagonal: ClosestPairs,
    /// What the loss is.
    pub loss: &'static str,
    /// Set 0's loss per iteration.
    pub loss_curve: Vec<f64>,
    /// Set 0's wall time per iteration.
    pub loss_curve_seconds: Vec<f64>,
}

/// Designs `request.sets` 4D sets (`on_iteration(set, loss)` after every
/// step).
///
/// # Errors
/// [`OptimizeError`] for a bad target, start or point set.
pub fn design_projections(
    request: &ProjectionRequest,
    on_iteration: &(dyn Fn(usize, f64) + Sync),
) -> Result<ProjectionDesign, OptimizeError> {
    let r = request;
    if r.sets == 0 {
        return Err(OptimizeError::Option("--sets must be at least 1".into()));
    }
    let terms = parse_projections(&r.target, r.n)?;
    let init_spec = r.init.clone().unwrap_or_else(|| "umj".into());
    let init_name = registry::label(&init_spec, &r.init_params)?;
    let init = registry::build(&init_spec, r.n, Some(4), &r.init_params)?;
    let options = AdamOptions {
        iters: r.iters.unwrap_or(1000),
        rel_tol: AdamOptions::checked_rel_tol(r.rel_tol.unwrap_or(1e-4))?,
        step: 0.05,
        final_step: 0.002,
        score_every: 1,
        floor: 0.0,
    };
    let start = std::time::Instant::now();
    let results = (0..r.sets)
        .into_par_iter()
        .map(|set| -> Result<_, OptimizeError> {
            let first = init.sample(&mut set_rng(r.seed, set as u64))?;
            let objective = ProjectionObjective::new(&terms, &first);
            let before: Vec<f64> = terms.iter().map(|t| t.loss(&first)).collect();
            let result = adam(first, &objective, &options, Domain::Torus, on_iteration);
            Ok((before, result))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let seconds = start.elapsed().as_secs_f64();
    let points: Vec<PointSet> = results.iter().map(|x| x.1.points.clone()).collect();
    let mean = |v: Vec<f64>| crate::sum::mean(&v);
    let terms_out = terms
        .iter()
        .enumerate()
        .map(|(t, term)| TermLoss {
            term: term.label.clone(),
            weight: term.weight,
            rows: term.rows,
            half: term.half(),
            loss_before: mean(results.iter().map(|x| x.0[t]).collect()),
            loss_after: mean(points.iter().map(|s| term.loss(s)).collect()),
        })
        .collect();
    let closest = |dims: [usize; 2]| -> Result<f64, OptimizeError> {
        let mut worst = f64::INFINITY;
        for s in &points {
            worst = worst.min(closest_pair_ratio(&s.projected(&dims)?));
        }
        Ok(worst)
    };
    let closest_pairs = ClosestPairs {
        xy: closest([0, 1])?,
        uv: closest([2, 3])?,
    };
    Ok(ProjectionDesign {
        run: DesignRun {
            domain: "torus",
            target: r.target.clone(),
            n: r.n,
            dim: 4,
            sets: r.sets,
            seed: r.seed,
            init: init_name,
            seconds,
        },
        iterations: results.iter().map(|x| x.1.losses.len()).collect(),
        max_iterations: options.iters,
        rel_tol: options.rel_tol,
        stopped: results.iter().map(|x| x.1.stop).collect(),
        terms: terms_out,
        closest_pair_over_hexagonal: closest_pairs,
        loss: "sum of w_t L_t(M_t X) / L_t(M_t X0) over the projection terms",
        loss_curve: results[0].1.losses.clone(),
        loss_curve_seconds: results[0].1.seconds.clone(),
        points,
    })
}
