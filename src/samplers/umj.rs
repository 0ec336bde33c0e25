//! 4D uncorrelated multi-jitter: (x, y) and (u, v) are two independent
//! multi-jittered (or CMJ) 2D sets, paired by a uniformly random permutation,
//! so each 2D pair keeps its stratification while the pairing decorrelates
//! the dimensions (the "uncorrelated multi-jitter" of Singh & Jarosz 2017,
//! "Convergence analysis for anisotropic Monte Carlo sampling spectra",
//! ACM TOG 36(4)).

use super::multijitter::MultiJitter;
use super::registry::Config;
use super::{Sampler, SamplerError};
use crate::points::PointSet;
use crate::rng::{SetRng, permutation};

/// Paired multi-jittered 4D points (x, y, u, v).
#[derive(Debug, Clone)]
pub struct Umj {
    pairs: MultiJitter,
    n: usize,
}

impl Umj {
    /// N = m·n points whose (x,y) and (u,v) are each `pairs` sets.
    pub fn new(pairs: MultiJitter) -> Self {
        let n = pairs.points_per_set();
        Umj { pairs, n }
    }
}

pub(super) fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let correlated = match c.param("pairs") {
        "mj" | "multijitter" => false,
        "cmj" => true,
        _ => return Err(c.bad_param("pairs", "mj or cmj")),
    };
    let (m, n) = MultiJitter::grid(c)?;
    Ok(Box::new(Umj::new(MultiJitter::new(m, n, correlated))))
}

impl Sampler for Umj {
    fn dim(&self) -> usize {
        4
    }

    fn points_per_set(&self) -> usize {
        self.n
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let n = self.n;
        let mut xy = vec![0.0; 2 * n];
        let mut uv = vec![0.0; 2 * n];
        self.pairs.fill(rng, &mut xy);
        self.pairs.fill(rng, &mut uv);
        let pairing = permutation(rng, n);
        let mut coords = Vec::with_capacity(4 * n);
        for (i, &p) in pairing.iter().enumerate() {
            let p = p as usize;
            coords.extend_from_slice(&[xy[2 * i], xy[2 * i + 1], uv[2 * p], uv[2 * p + 1]]);
        }
        Ok(PointSet::new(4, coords).expect("stratum coordinates lie in [0,1)"))
    }
}
