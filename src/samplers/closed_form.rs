//! A sampler's expected power E[N·P_S(k)] in closed form, where it has one:
//! 2D samplers with independent strata through their expected pair sums
//! ([`PairSpectrum`]: E[N·P_S(k)] = 1 + C(k, k)/N), and padded 4D samplers
//! whose (x, y) and (u, v) halves both have one.
//!
//! A padded set pairs point l of the (x, y) set with point π(l) of the
//! (u, v) set, π a uniformly random permutation independent of both
//! halves (Cook 1986; Singh & Jarosz 2017, §5). For l ≠ m, (π(l), π(m)) is
//! a uniformly random ordered pair of distinct indices, so the (u, v)
//! factor of E[e^(2πi k·(q_l − q_m))] is the mean over distinct pairs,
//! C_uv(k_uv, k_uv)/(N(N − 1)), whatever l and m are:
//!
//!   E[N·P_S(k)] = 1 + C_xy(k_xy, k_xy)·C_uv(k_uv, k_uv) / (N²(N − 1)),
//!
//! which at k_uv = 0 (C_uv = N(N − 1)) is the (x, y) half's own power.

use super::Sampler;
use crate::spectrum::pair::PairSpectrum;

/// The closed-form expected power of a sampler.
#[derive(Clone, Copy)]
pub enum ClosedFormSpectrum<'a> {
    /// A 2D sampler's expected pair sums.
    Planar(&'a dyn PairSpectrum),
    /// A padded 4D sampler's two halves (see the module doc).
    Padded {
        /// The (x, y) half.
        xy: &'a dyn PairSpectrum,
        /// The (u, v) half.
        uv: &'a dyn PairSpectrum,
    },
}

impl<'a> ClosedFormSpectrum<'a> {
    /// The closed form of `sampler`, if it has one.
    pub fn of(sampler: &'a dyn Sampler) -> Option<Self> {
        if let Some(pairs) = sampler.pair_spectrum() {
            return Some(ClosedFormSpectrum::Planar(pairs));
        }
        let [xy, uv] = sampler.halves()?;
        Some(ClosedFormSpectrum::Padded {
            xy: xy.pair_spectrum()?,
            uv: uv.pair_spectrum()?,
        })
    }

    /// Points per realization, N.
    pub fn points(&self) -> usize {
        match self {
            ClosedFormSpectrum::Planar(p) => p.points(),
            ClosedFormSpectrum::Padded { xy, .. } => xy.points(),
        }
    }

    /// The dimension of the points: 2, or 4 for a padded sampler.
    pub fn dim(&self) -> usize {
        match self {
            ClosedFormSpectrum::Planar(_) => 2,
            ClosedFormSpectrum::Padded { .. } => 4,
        }
    }

    /// E[N·P_S] of a 2D closed form at every (x, y) of `xs` × `ys`,
    /// row-major by x ([`PairSpectrum::power_grid`]); `None` in 4D.
    pub fn power_grid(&self, xs: &[f64], ys: &[f64]) -> Option<Vec<f64>> {
        match self {
            ClosedFormSpectrum::Planar(p) => Some(p.power_grid(xs, ys)),
            ClosedFormSpectrum::Padded { .. } => None,
        }
    }

    /// E[N·P_S(k)] at the integer frequency `k` (of [`Self::dim`] entries).
    pub fn power(&self, k: &[i64]) -> f64 {
        let w = |i: usize| [k[i] as f64, k[i + 1] as f64];
        match self {
            ClosedFormSpectrum::Planar(p) => p.power(w(0)),
            ClosedFormSpectrum::Padded { xy, uv } => {
                let n = xy.points() as f64;
                if n < 2.0 {
                    // One point: no pairs, the power is 1.
                    return 1.0;
                }
                let c_xy = xy.pair_sum(w(0), w(0)).re;
                let c_uv = uv.pair_sum(w(2), w(2)).re;
                1.0 + c_xy * c_uv / (n * n * (n - 1.0))
            }
        }
    }
}
