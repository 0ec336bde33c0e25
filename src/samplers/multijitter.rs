//! Multi-jittered sampling (Chiu, Shirley & Wang 1994, "Multi-jittered
//! sampling", Graphics Gems IV) and correlated multi-jittered sampling
//! (Kensler 2013, "Correlated multi-jittered sampling", Pixar Tech. Memo
//! 13-01), one sampler with the shuffle correlation as a parameter.
//!
//! N = m·n points on m columns and n rows. Point (i, j) — column i, row j —
//! has x in fine interval i·n + σ_i(j) and y in fine interval j·m + τ_j(i)
//! of the N intervals of each axis, with a uniform offset inside it. Any
//! permutations σ_i, τ_j keep both properties: one point per m×n cell
//! (jitter) and one per 1/N interval of each axis (N-rooks). Multi-jitter
//! shuffles every column and row independently; CMJ uses one σ for all
//! columns and one τ for all rows.

use super::registry::Config;
use super::{Sampler, SamplerError};
use crate::points::{PointSet, stratum_coord};
use crate::rng::{SetRng, permutation, uniform};

/// Multi-jittered N = m·n points in 2D.
#[derive(Debug, Clone)]
pub struct MultiJitter {
    columns: usize,
    rows: usize,
    correlated: bool,
}

impl MultiJitter {
    /// `columns` × `rows` strata; `correlated` selects Kensler's CMJ.
    pub fn new(columns: usize, rows: usize, correlated: bool) -> Self {
        MultiJitter {
            columns,
            rows,
            correlated,
        }
    }

    /// The grid (m, n) used for N points: m = `columns` if given, else the
    /// largest divisor of N not above √N.
    pub(super) fn grid(c: &Config) -> Result<(usize, usize), SamplerError> {
        let n = c.n;
        let m = match c.param("m") {
            "auto" => (1..=n)
                .take_while(|m| m * m <= n)
                .filter(|m| n % m == 0)
                .last()
                .unwrap_or(1),
            text => match text.parse::<usize>() {
                Ok(m) if m >= 1 && n % m == 0 => m,
                _ => return Err(c.bad_param("m", format!("`auto` or a divisor of N = {n}"))),
            },
        };
        Ok((m, n / m))
    }

    /// Writes the set's (x, y) pairs into `out` (length 2N), point (i, j)
    /// at index j·m + i.
    pub(super) fn fill(&self, rng: &mut SetRng, out: &mut [f64]) {
        let (m, n) = (self.columns, self.rows);
        let total = m * n;
        let shared_sigma = self.correlated.then(|| permutation(rng, n));
        let shared_tau = self.correlated.then(|| permutation(rng, m));
        for i in 0..m {
            let own;
            let sigma = match &shared_sigma {
                Some(s) => s,
                None => {
                    own = permutation(rng, n);
                    &own
                }
            };
            for (j, &s) in sigma.iter().enumerate() {
                out[2 * (j * m + i)] = stratum_coord(i * n + s as usize, uniform(rng), total);
            }
        }
        for j in 0..n {
            let own;
            let tau = match &shared_tau {
                Some(t) => t,
                None => {
                    own = permutation(rng, m);
                    &own
                }
            };
            for (i, &t) in tau.iter().enumerate() {
                out[2 * (j * m + i) + 1] = stratum_coord(j * m + t as usize, uniform(rng), total);
            }
        }
    }
}

pub(super) fn multijitter_from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let (m, n) = MultiJitter::grid(c)?;
    Ok(Box::new(MultiJitter::new(m, n, false)))
}

pub(super) fn cmj_from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let (m, n) = MultiJitter::grid(c)?;
    Ok(Box::new(MultiJitter::new(m, n, true)))
}

impl Sampler for MultiJitter {
    fn dim(&self) -> usize {
        2
    }

    fn points_per_set(&self) -> usize {
        self.columns * self.rows
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let mut coords = vec![0.0; 2 * self.points_per_set()];
        self.fill(rng, &mut coords);
        Ok(PointSet::new(2, coords).expect("stratum coordinates lie in [0,1)"))
    }
}
