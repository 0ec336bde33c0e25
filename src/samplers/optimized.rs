//! Optimized point sets as a sampler: each realization starts from uniform
//! random points (drawn from the realization's own stream) and descends on
//! the spectral loss of [`crate::optimize::descent`] toward a target — by
//! default the disk family, i.e. CCVT-like blue noise. Deterministic for a
//! seed like every sampler.

use super::registry::Config;
use super::{Random, Sampler, SamplerError};
use crate::optimize::{DescentOptions, PointOptimizer, Target};
use crate::points::PointSet;
use crate::rng::SetRng;

/// Blue noise (or any target) by spectral descent.
pub struct Optimized {
    start: Random,
    optimizer: PointOptimizer,
}

pub(super) fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let spec = c.param("target");
    let target = Target::parse(spec).map_err(|e| {
        c.bad_param(
            "target",
            format!("a target (family:disks, power:A, radial:FILE, an integrand): {e}"),
        )
    })?;
    let mut options = DescentOptions::for_target(c.n, c.dim, &target);
    options.iters = c
        .param("iters")
        .parse()
        .ok()
        .filter(|&i: &usize| i >= 1)
        .ok_or_else(|| c.bad_param("iters", "a positive integer"))?;
    let optimizer = PointOptimizer::new(c.dim, &target, options)
        .map_err(|e| c.bad_param("target", e.to_string()))?;
    Ok(Box::new(Optimized {
        start: Random::new(c.n, c.dim),
        optimizer,
    }))
}

impl Sampler for Optimized {
    fn dim(&self) -> usize {
        self.start.dim()
    }

    fn points_per_set(&self) -> usize {
        self.start.points_per_set()
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let start = self.start.sample(rng)?;
        Ok(self.optimizer.optimize(start, &|_, _| {}).points)
    }
}
