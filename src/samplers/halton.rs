//! Randomized Halton points (Halton 1960): coordinate j of point i is the
//! radical inverse of i in the j-th prime base p, Σ_k d_k(i) p^−(k+1), with
//! random digit scrambling (Matoušek 1998, "On the L2-discrepancy for
//! anchored boxes", J. Complexity 14): digit position k of dimension j is
//! mapped through its own uniformly random permutation π_(j,k) of 0..p−1.
//!
//! Every digit position down to p^−K < 2⁻⁵³ is permuted, including the
//! leading zeros of i, so each coordinate is uniform on [0,1) to double
//! precision while the stratification of the Halton sequence is kept.
//! Positions where every i < N has the digit 0 enter only through π(0),
//! uniform on 0..p−1, which is all that is drawn for them: the same
//! distribution without a permutation per position (at N = 16 in 4D a set
//! drew 456 permutation entries for its 64 coordinates).

use super::config::Config;
use super::{Sampler, SamplerError};
use crate::points::PointSet;
use crate::rng::{PREV_ONE, SetRng, below, permutation};

/// The first primes: the bases of dimensions 0, 1, ….
const PRIMES: [u32; 32] = [
    2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97,
    101, 103, 107, 109, 113, 127, 131,
];

/// Dimensions supported (one prime base each).
pub const MAX_DIM: usize = PRIMES.len();

/// Scrambled Halton points: N points in d ≤ [`MAX_DIM`] dimensions.
#[derive(Debug, Clone)]
pub struct Halton {
    n: usize,
    dim: usize,
}

impl Halton {
    /// The first N ≥ 1 points in 1 ≤ d ≤ [`MAX_DIM`] dimensions.
    ///
    /// # Errors
    /// [`SamplerError::ZeroPoints`] or [`SamplerError::Dimension`].
    pub fn new(n: usize, dim: usize) -> Result<Self, SamplerError> {
        if n == 0 {
            return Err(SamplerError::ZeroPoints { sampler: "halton" });
        }
        if !(1..=MAX_DIM).contains(&dim) {
            return Err(SamplerError::Dimension {
                sampler: "halton",
                dim,
                min: 1,
                max: MAX_DIM,
            });
        }
        Ok(Halton { n, dim })
    }
}

pub(crate) fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    Ok(Box::new(Halton::new(c.n, c.dim)?))
}

/// One dimension's scrambled radical inverse, precomputed for a set.
struct ScrambledBase {
    base: u64,
    /// π_k for each digit position k that some i < N uses, flattened.
    perms: Vec<u32>,
    /// p^−(k+1).
    weights: Vec<f64>,
    /// tails[L] = Σ_(k ≥ L) π_k(0)·p^−(k+1): the permuted leading zeros.
    tails: Vec<f64>,
}

impl ScrambledBase {
    /// The scramble of base `base` for the points i < `n`.
    fn new(base: u32, n: usize, rng: &mut SetRng) -> Self {
        let p = base as usize;
        let digits = (53.0 * 2f64.ln() / (p as f64).ln()).ceil() as usize;
        // Digit positions some i < n has (n − 1 written in base p).
        let used = std::iter::successors(Some(n as u64 - 1), |&m| Some(m / base as u64))
            .take_while(|&m| m > 0)
            .count()
            .min(digits);
        let perms: Vec<u32> = (0..used).flat_map(|_| permutation(rng, p)).collect();
        let zeros: Vec<u32> = (0..digits)
            .map(|k| {
                if k < used {
                    perms[k * p]
                } else {
                    below(rng, p as u64) as u32
                }
            })
            .collect();
        let weights: Vec<f64> = (1..=digits as i32).map(|k| (p as f64).powi(-k)).collect();
        let mut tails = vec![0.0; digits + 1];
        for k in (0..digits).rev() {
            tails[k] = tails[k + 1] + zeros[k] as f64 * weights[k];
        }
        ScrambledBase {
            base: base as u64,
            perms,
            weights,
            tails,
        }
    }

    fn radical_inverse(&self, mut i: u64) -> f64 {
        let p = self.base as usize;
        let mut k = 0;
        let mut digits = [0u32; 64];
        while i != 0 {
            let digit = (i % self.base) as usize;
            digits[k] = self.perms[k * p + digit];
            i /= self.base;
            k += 1;
        }
        // Smallest terms first: the permuted leading zeros, then digits upward.
        let mut v = self.tails[k];
        for j in (0..k).rev() {
            v += digits[j] as f64 * self.weights[j];
        }
        v.min(PREV_ONE)
    }
}

impl Sampler for Halton {
    fn dim(&self) -> usize {
        self.dim
    }

    fn points_per_set(&self) -> usize {
        self.n
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let bases: Vec<ScrambledBase> = PRIMES[..self.dim]
            .iter()
            .map(|&p| ScrambledBase::new(p, self.n, rng))
            .collect();
        let coords = (0..self.n as u64)
            .flat_map(|i| bases.iter().map(move |b| b.radical_inverse(i)))
            .collect();
        Ok(PointSet::new(self.dim, coords).expect("radical inverses lie in [0,1)"))
    }
}
