//! Stratified sampling on the m^d grid: regular (cell centres), jittered (an
//! independent uniform offset per stratum) and uniform jitter (one offset
//! shared by all strata) are one sampler with the offset as a parameter
//! (docs/architecture.md, "Conventions").
//!
//! Jitter's expected power spectrum is E[N·P_S(k)] = 1 − Π_j sinc²(π k_j/m)
//! (Pilleboue et al. 2015, "Variance analysis for Monte Carlo integration",
//! ACM TOG 34(4), §5), zero at every nonzero multiple of m.

use rustfft::num_complex::Complex64;

use super::Lattice;
use super::config::{Config, integer_root, pow_saturating};
use super::{Sampler, SamplerError};
use crate::points::{PointSet, stratum_coord};
use crate::rng::{SetRng, uniform};
use crate::spectrum::pair::{PairSpectrum, geometric, uniform_char};
use crate::spectrum::phase::turn;

/// Where in its stratum each point lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StratumOffset {
    /// The cell centre: the regular grid.
    Centre,
    /// An independent uniform offset per stratum: jittered sampling.
    Independent,
    /// One uniform offset shared by every stratum: uniform jitter
    /// (Ramamoorthi, Anderson, Meyer & Nowrouzezahrai 2012, "A theory of
    /// Monte Carlo visibility sampling", ACM TOG 31(5)).
    Shared,
}

/// One point in each cell of the m^d grid, N = m^d.
#[derive(Debug, Clone)]
pub struct Jitter {
    m: usize,
    dim: usize,
    offset: StratumOffset,
}

impl Jitter {
    /// The m^d grid in d dimensions (1 to 4) with the given offset rule.
    ///
    /// # Errors
    /// As [`super::check_size`] for N = m^d.
    pub fn new(m: usize, dim: usize, offset: StratumOffset) -> Result<Self, SamplerError> {
        let n = u32::try_from(dim)
            .ok()
            .and_then(|d| m.checked_pow(d))
            .unwrap_or(usize::MAX);
        super::check_size("jitter", n, dim, 1..=4)?;
        Ok(Jitter { m, dim, offset })
    }
}

fn from_config(c: &Config, offset: StratumOffset) -> Result<Box<dyn Sampler>, SamplerError> {
    let m = integer_root(c.n, c.dim);
    if pow_saturating(m, c.dim) != c.n {
        let below = (m >= 1).then(|| pow_saturating(m, c.dim));
        let above = Some(pow_saturating(m + 1, c.dim)).filter(|&a| a != usize::MAX);
        return Err(c.bad_count("N = m^d", below, above));
    }
    Ok(Box::new(Jitter::new(m, c.dim, offset)?))
}

pub(crate) fn regular_from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    from_config(c, StratumOffset::Centre)
}

pub(crate) fn jitter_from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    from_config(c, StratumOffset::Independent)
}

pub(crate) fn uniform_jitter_from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    from_config(c, StratumOffset::Shared)
}

impl Sampler for Jitter {
    fn dim(&self) -> usize {
        self.dim
    }

    fn points_per_set(&self) -> usize {
        pow_saturating(self.m, self.dim)
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let (m, d) = (self.m, self.dim);
        let shared: Vec<f64> = match self.offset {
            StratumOffset::Shared => (0..d).map(|_| uniform(rng)).collect(),
            _ => vec![0.5; d],
        };
        let n = self.points_per_set();
        let mut coords = Vec::with_capacity(n * d);
        // Point i sits in the stratum whose base-m digits are i's: digit j
        // (least significant first) is its cell index along axis j.
        for i in 0..n {
            let mut rest = i;
            for &s in &shared {
                let cell = rest % m;
                rest /= m;
                let xi = if self.offset == StratumOffset::Independent {
                    uniform(rng)
                } else {
                    s
                };
                coords.push(stratum_coord(cell, xi, m));
            }
        }
        Ok(PointSet::new(d, coords).expect("stratum coordinates lie in [0,1)"))
    }

    fn pair_spectrum(&self) -> Option<&dyn PairSpectrum> {
        (self.dim == 2).then_some(self as &dyn PairSpectrum)
    }

    /// The regular grid and uniform jitter in 2D are the m × m lattice
    /// (m, 0, m) under a shift (none for cell centres: the estimator's own
    /// shift randomizes them).
    fn lattice(&self) -> Option<Lattice> {
        (self.dim == 2 && self.offset != StratumOffset::Independent).then_some(Lattice {
            a: self.m,
            b: 0,
            c: self.m,
        })
    }

    /// The regular grid and uniform jitter in any dimension.
    fn shifts_of_one_set(&self) -> bool {
        self.offset != StratumOffset::Independent
    }
}

/// One point per cell of the m×m grid (2D): with μ_s(ω) = E[e^(2πiω·q_s)]
/// the mean phasor of stratum s,
/// C(ω, ω′) = Σ_(s≠s′) E[e^(2πi(ω·q_s − ω′·q_s′))]
///          = o(ω, ω′)·(A(ω)·conj(A(ω′)) − A(ω − ω′)),
/// A(ω) = Σ_cells e^(2πiω·c/m) (a product of two geometric sums) and o the
/// offsets' factor: χ(ω/m)·conj(χ(ω′/m)) for independent offsets,
/// e^(πi(ω−ω′)/m) per axis for cell centres, χ((ω − ω′)/m) for one shared
/// offset (uniform jitter). The diagonal A(ω − ω′) is subtracted in the
/// same factored form, so no pair is visited: O(1) per frequency pair.
impl PairSpectrum for Jitter {
    fn points(&self) -> usize {
        self.points_per_set()
    }

    fn pair_sum(&self, w1: [f64; 2], w2: [f64; 2]) -> Complex64 {
        let m = self.m;
        let mf = m as f64;
        let cells = |w: [f64; 2]| geometric(w[0] / mf, m) * geometric(w[1] / mf, m);
        let delta = [w1[0] - w2[0], w1[1] - w2[1]];
        let offsets = match self.offset {
            StratumOffset::Independent => {
                let chi = |w: [f64; 2]| uniform_char(w[0] / mf) * uniform_char(w[1] / mf);
                chi(w1) * chi(w2).conj()
            }
            StratumOffset::Centre => turn(0.5 * (delta[0] + delta[1]) / mf),
            StratumOffset::Shared => uniform_char(delta[0] / mf) * uniform_char(delta[1] / mf),
        };
        offsets * (cells(w1) * cells(w2).conj() - cells(delta))
    }
}
