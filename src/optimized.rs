//! Optimized point sets as a sampler (registered as `blue-noise` by
//! [`crate::registry`]): each realization starts from a
//! classic sampler's draw (from the realization's own stream) and descends
//! toward a target. On the torus (the default) the target is a spectral
//! loss of [`crate::optimize::descent`], by default the disk family, i.e.
//! CCVT-like blue noise, starting from uniform random points; on the square
//! (`domain=square`) it is a sum of family MSEs of the unshifted estimator
//! ([`crate::square::design`]), by default half-planes + Gaussians + blue
//! repulsion, starting from jitter (CMJ where N is not a square).
//! Deterministic for a seed like every
//! sampler.

use crate::optimize::{AdamOptions, DescentOptions, PointOptimizer, Target};
use crate::points::PointSet;
use crate::rng::SetRng;
use crate::samplers::config::Config;
use crate::samplers::{Random, Sampler, SamplerError};
use crate::square::design::{SquareTerm, default_options, default_start, design, parse_target};

/// The square's default target.
pub const SQUARE_TARGET: &str = "halfplanes+gaussians+16*blue";

/// Blue noise (or any target) by descent.
pub struct Optimized {
    dim: usize,
    n: usize,
    how: How,
}

enum How {
    Torus {
        start: Random,
        optimizer: Box<PointOptimizer>,
    },
    Square {
        start: Box<dyn Sampler>,
        terms: Vec<SquareTerm>,
        options: AdamOptions,
    },
}

pub(crate) fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let iters: Option<usize> = match c.given("iters") {
        None => None,
        Some(text) => Some(
            text.parse()
                .ok()
                .filter(|&i: &usize| i >= 1)
                .ok_or_else(|| c.bad_param("iters", "a positive integer"))?,
        ),
    };
    let how = match c.param("domain") {
        "torus" => {
            let spec = c.param("target");
            let target = Target::parse(spec).map_err(|e| {
                c.bad_param(
                    "target",
                    format!("a target (family:disks, power:A, radial:FILE, an integrand): {e}"),
                )
            })?;
            let mut options = DescentOptions::for_target(c.n, c.dim, &target);
            options.iters = iters.unwrap_or(1000);
            let optimizer = PointOptimizer::new(c.dim, &target, options)
                .map_err(|e| c.bad_param("target", e.to_string()))?;
            // The transform plans and, per thread, one running descent.
            let plans = crate::spectrum::nufft::nufft_memory_bytes(optimizer.frequencies())
                .unwrap_or(f64::INFINITY);
            let threads = rayon::current_num_threads() as f64;
            crate::memory::check(
                &format!("blue-noise descents of {} points in {}D", c.n, c.dim),
                Some(plans + threads * optimizer.descent_bytes(c.n)),
                "lower -n",
            )?;
            How::Torus {
                start: Random::new(c.n, c.dim)?,
                optimizer: Box::new(optimizer),
            }
        }
        "square" => {
            if c.dim != 2 {
                return Err(c.bad_param("domain", "torus, or square with d = 2"));
            }
            let spec = c.given("target").unwrap_or(SQUARE_TARGET);
            let terms = parse_target(spec).map_err(|e| c.bad_param("target", e.to_string()))?;
            let mut options = default_options();
            if let Some(i) = iters {
                options.iters = i;
            }
            How::Square {
                start: c.build_other(default_start(c.n), c.n, Some(2), &[])?,
                terms,
                options,
            }
        }
        _ => return Err(c.bad_param("domain", "torus or square")),
    };
    Ok(Box::new(Optimized {
        dim: c.dim,
        n: c.n,
        how,
    }))
}

impl Sampler for Optimized {
    fn dim(&self) -> usize {
        self.dim
    }

    fn points_per_set(&self) -> usize {
        self.n
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        match &self.how {
            How::Torus { start, optimizer } => {
                let start = start.sample(rng)?;
                Ok(optimizer.optimize(start, &|_, _| {}).points)
            }
            How::Square {
                start,
                terms,
                options,
            } => {
                let first = start.sample(rng)?;
                let seed = crate::rng::below(rng, u64::MAX);
                Ok(design(terms, first, seed, options, &|_, _| {}).points)
            }
        }
    }
}
