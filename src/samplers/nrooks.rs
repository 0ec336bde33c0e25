//! N-rooks (Shirley 1991) / Latin hypercube sampling (McKay, Beckman &
//! Conover 1979, Technometrics 21(2)): along every axis the N points fall one
//! in each interval [i/N, (i+1)/N), the intervals of different axes paired by
//! independent random permutations.

use super::config::Config;
use super::{Sampler, SamplerError};
use crate::points::{PointSet, stratum_coord};
use crate::rng::{SetRng, permutation, uniform};

/// Latin hypercube of N points in d dimensions.
#[derive(Debug, Clone)]
pub struct NRooks {
    n: usize,
    dim: usize,
}

impl NRooks {
    /// N points in d dimensions.
    ///
    /// # Errors
    /// As [`super::check_size`].
    pub fn new(n: usize, dim: usize) -> Result<Self, SamplerError> {
        super::check_size("nrooks", n, dim, 1..=usize::MAX)?;
        Ok(NRooks { n, dim })
    }
}

pub(crate) fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    Ok(Box::new(NRooks::new(c.n, c.dim)?))
}

impl Sampler for NRooks {
    fn dim(&self) -> usize {
        self.dim
    }

    fn points_per_set(&self) -> usize {
        self.n
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let (n, d) = (self.n, self.dim);
        let mut coords = vec![0.0; n * d];
        for j in 0..d {
            let perm = permutation(rng, n);
            for (i, &cell) in perm.iter().enumerate() {
                coords[i * d + j] = stratum_coord(cell as usize, uniform(rng), n);
            }
        }
        Ok(PointSet::new(d, coords).expect("stratum coordinates lie in [0,1)"))
    }
}
