//! Independent uniform points: the white-noise baseline, E[N·P_S(k)] = 1 for
//! every k ≠ 0.

use rustfft::num_complex::Complex64;

use super::config::Config;
use super::{Sampler, SamplerError};
use crate::points::PointSet;
use crate::rng::{SetRng, uniform};
use crate::spectrum::pair::{PairSpectrum, uniform_char};

/// N independent uniform points in [0,1)^d.
#[derive(Debug, Clone)]
pub struct Random {
    n: usize,
    dim: usize,
}

impl Random {
    /// N uniform points in d dimensions.
    ///
    /// # Errors
    /// As [`super::check_size`].
    pub fn new(n: usize, dim: usize) -> Result<Self, SamplerError> {
        super::check_size("random", n, dim, 1..=usize::MAX)?;
        Ok(Random { n, dim })
    }
}

pub(crate) fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    Ok(Box::new(Random::new(c.n, c.dim)?))
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

    fn pair_spectrum(&self) -> Option<&dyn PairSpectrum> {
        (self.dim == 2).then_some(self as &dyn PairSpectrum)
    }
}

/// Independent points: C(ω, ω′) = N(N−1)·χ(ω)·conj(χ(ω′)), χ the
/// characteristic function of a uniform point.
impl PairSpectrum for Random {
    fn points(&self) -> usize {
        self.n
    }

    fn pair_sum(&self, w1: [f64; 2], w2: [f64; 2]) -> Complex64 {
        let n = self.n as f64;
        let chi = |w: [f64; 2]| uniform_char(w[0]) * uniform_char(w[1]);
        chi(w1) * chi(w2).conj() * (n * (n - 1.0))
    }
}
