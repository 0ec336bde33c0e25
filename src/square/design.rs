//! Designing point sets for the square: a weighted sum of family MSEs,
//!
//!   L(X) = Σ_t w_t · MSE_t(X) / MSE_t(X₀),
//!
//! each term scaled by its value at the start X₀ so the weights compare
//! relative gains (a `blue` repulsion term by its value for uniform random
//! points instead). A `halfplanes` term is the Cramér–von Mises form of
//! [`super::halfplanes`] over q directions with a random offset per
//! iteration (an unbiased estimate of the θ average: the set cannot fit a
//! fixed set of directions); another family's term is the sample form of
//! [`super::sampled`] on fresh members each iteration (disks, boxes and
//! listed integrands through their gradients smoothed over half a spacing;
//! a stochastic
//! gradient on the family MSE itself). The best set is kept by a
//! deterministic score: 512 directions for half-planes, a fixed validation
//! sample for smooth families, both drawn apart from the members the final
//! scores use.

use rayon::prelude::*;

use super::family::{Family, FamilyError};
use super::halfplanes::{Projection, directional_loss, directions, halfplane_mse};
use super::sampled::{Members, sampled_loss};
use crate::optimize::repulsion::repulsion;
use crate::optimize::{AdamOptions, DescentResult, Domain, PointObjective, adam};
use crate::points::PointSet;
use crate::rng::{set_rng, uniform};

/// Directions per iteration for half-plane terms.
const DIRECTIONS: usize = 64;
/// Directions of the deterministic score.
const SCORE_DIRECTIONS: usize = 512;
/// Members per iteration for smooth families.
const BATCH: usize = 128;
/// Half-width of the ramp that smooths an indicator member's edge for its
/// gradient, in mean spacings 1/√N ([`super::integrands::SquareIntegrand::edge_gradient`]).
const EDGE_SPACINGS: f64 = 0.5;
/// Members of the validation sample.
const VALIDATION: usize = 1024;
/// Streams of the descent's own draws (never the scoring seeds).
const DIRECTION_STREAM: u64 = 0x4450_4952_4543_5431;
const TRAIN_STREAM: u64 = 0x5452_4149_4e5f_5351;
const VALIDATION_STREAM: u64 = 0x5641_4c49_445f_5351;

/// What one term of a square target measures.
#[derive(Debug, Clone, PartialEq)]
pub enum TermKind {
    /// A family's MSE.
    Family(Family),
    /// Gaussian repulsion on the torus ([`crate::optimize::repulsion`]):
    /// keeps the design blue.
    Blue,
}

/// One term of a square target.
#[derive(Debug, Clone, PartialEq)]
pub struct SquareTerm {
    /// What it measures.
    pub kind: TermKind,
    /// Its weight w_t.
    pub weight: f64,
}

/// Parses `TERM[+W*TERM...]` with TERM a family or `blue`, e.g.
/// `halfplanes+0.5*gaussians+0.1*blue`.
///
/// # Errors
/// [`FamilyError`] for a bad family or weight.
pub fn parse_target(spec: &str) -> Result<Vec<SquareTerm>, FamilyError> {
    let fail = |reason: String| FamilyError {
        spec: spec.to_string(),
        reason,
    };
    let mut terms = Vec::new();
    for (i, part) in spec.split('+').enumerate() {
        let (weight, family) = match part.split_once('*') {
            Some((w, f)) => (crate::spec_params::term_weight(w).map_err(fail)?, f),
            None => (1.0, part),
        };
        if family.trim().is_empty() {
            return Err(fail(format!(
                "term {} is empty (a `+` with nothing on one side): terms are families or `blue`, \
                 e.g. `halfplanes+gaussians+16*blue`",
                i + 1
            )));
        }
        let kind = if family.trim() == "blue" {
            TermKind::Blue
        } else {
            TermKind::Family(Family::parse(family.trim())?)
        };
        // Twice the same term is one term of twice the weight: say so
        // rather than read a slip silently.
        if terms.iter().any(|t: &SquareTerm| t.kind == kind) {
            return Err(fail(format!(
                "`{}` is given twice: write one term with a weight (2*TERM) instead",
                family.trim()
            )));
        }
        terms.push(SquareTerm { kind, weight });
    }
    Ok(terms)
}

/// The weighted family MSEs as a point objective.
pub struct SquareObjective {
    terms: Vec<SquareTerm>,
    scale: Vec<f64>,
    seed: u64,
}

impl SquareObjective {
    /// The objective for `terms`, scaled at the start `start`; the
    /// descent's random draws come from `seed`.
    pub fn new(terms: Vec<SquareTerm>, start: &PointSet, seed: u64) -> Self {
        let mut objective = SquareObjective {
            scale: vec![1.0; terms.len()],
            terms,
            seed,
        };
        objective.scale = objective
            .term_scores(start)
            .into_iter()
            .zip(&objective.terms)
            .map(|(s, term)| match term.kind {
                // Repulsion is scaled by its value for uniform random
                // points, not by the start's, so its weight means the
                // same whatever the start.
                TermKind::Blue => crate::optimize::repulsion::uniform_energy(start.len()),
                TermKind::Family(_) => s.max(f64::MIN_POSITIVE),
            })
            .collect();
        objective
    }

    /// Each term's deterministic score (its family MSE estimate).
    pub fn term_scores(&self, points: &PointSet) -> Vec<f64> {
        self.terms
            .iter()
            .map(|term| match &term.kind {
                TermKind::Blue => repulsion(points, 0.0, None),
                TermKind::Family(Family::HalfPlanes) => halfplane_mse(points, SCORE_DIRECTIONS),
                TermKind::Family(family) => sampled_loss(
                    points,
                    family,
                    Members {
                        seed: self.seed ^ VALIDATION_STREAM,
                        first: 0,
                        count: VALIDATION,
                    },
                    0.0,
                    0.0,
                    None,
                )
                .expect("values need no gradient"),
            })
            .collect()
    }
}

impl PointObjective for SquareObjective {
    fn loss_and_gradient(&self, points: &PointSet, t: usize, gradient: &mut [f64]) -> f64 {
        let mut total = 0.0;
        for (term, scale) in self.terms.iter().zip(&self.scale) {
            let w = term.weight / scale;
            total += w * match &term.kind {
                TermKind::Blue => repulsion(points, w, Some(gradient)),
                TermKind::Family(Family::HalfPlanes) => {
                    let offset = uniform(&mut set_rng(self.seed ^ DIRECTION_STREAM, t as u64));
                    let thetas: Vec<f64> = directions(DIRECTIONS, offset).collect();
                    let parts: Vec<(f64, Vec<f64>)> = thetas
                        .par_chunks(8)
                        .map(|chunk| {
                            let mut g = vec![0.0; gradient.len()];
                            let mut order = Vec::with_capacity(points.len());
                            let loss: f64 = chunk
                                .iter()
                                .map(|&theta| {
                                    directional_loss(
                                        points,
                                        &Projection::new(theta),
                                        1.0 / DIRECTIONS as f64,
                                        Some(&mut g),
                                        &mut order,
                                    )
                                })
                                .sum();
                            (loss, g)
                        })
                        .collect();
                    let mut loss = 0.0;
                    for (l, g) in parts {
                        loss += l;
                        for (o, v) in gradient.iter_mut().zip(&g) {
                            *o += w * v;
                        }
                    }
                    loss / DIRECTIONS as f64
                }
                TermKind::Family(family) => sampled_loss(
                    points,
                    family,
                    Members {
                        seed: self.seed ^ TRAIN_STREAM,
                        first: (t * BATCH) as u64,
                        count: BATCH,
                    },
                    w,
                    EDGE_SPACINGS / (points.len() as f64).sqrt(),
                    Some(gradient),
                )
                .expect("targets have gradients"),
            };
        }
        total
    }

    fn score(&self, points: &PointSet) -> Option<f64> {
        Some(
            self.term_scores(points)
                .iter()
                .zip(&self.terms)
                .zip(&self.scale)
                .map(|((s, term), scale)| term.weight * s / scale)
                .sum(),
        )
    }
}

/// The sampler a design on the square starts from by default: jitter
/// where N is a square m², else CMJ, which stratifies any N the same way.
pub fn default_start(n: usize) -> &'static str {
    let m = (n as f64).sqrt().round() as usize;
    if m * m == n { "jitter" } else { "cmj" }
}

/// Descent defaults for the square: 2000 Adam steps from 0.1 to 0.004 of
/// the spacing, scored every 20 (measured in results/square: the
/// half-plane MSE is within 2% of its 4000-step value at N = 1024 and 4096).
pub fn default_options() -> AdamOptions {
    AdamOptions {
        iters: 2000,
        rel_tol: 0.0,
        step: 0.1,
        final_step: 0.004,
        score_every: 20,
        floor: 0.0,
    }
}

/// Designs one set for `terms` from `start`; the descent's draws come from
/// `seed`. The result is never worse than the start by the score: the
/// start is kept when nothing better was found.
pub fn design(
    terms: &[SquareTerm],
    start: PointSet,
    seed: u64,
    options: &AdamOptions,
    on_iteration: &dyn Fn(usize, f64),
) -> DescentResult {
    let objective = SquareObjective::new(terms.to_vec(), &start, seed);
    adam(start, &objective, options, Domain::Square, on_iteration)
}
