//! Independent uniform points: the white-noise baseline, E[N·P_S(k)] = 1 for
//! every k ≠ 0.

use super::registry::Config;
use super::{Sampler, SamplerError};
use crate::points::PointSet;
use crate::rng::{SetRng, uniform};

/// N independent uniform points in [0,1)^d.
#[derive(Debug, Clone)]
pub struct Random {
    n: usize,
    dim: usize,
}

impl Random {
    /// N uniform points in d dimensions.
    pub fn new(n: usize, dim: usize) -> Self {
        Random { n, dim }
    }
}

pub(super) fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    Ok(Box::new(Random::new(c.n, c.dim)))
}

impl Sampler for Random {
    fn dim(&self) -> usize {
        self.dim
    }

    fn points_per_set(&self) -> usize {
        self.n
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let coords = (0..self.n * self.dim).map(|_| uniform(rng)).collect();
        Ok(PointSet::new(self.dim, coords).expect("uniform draws lie in [0,1)"))
    }
}
