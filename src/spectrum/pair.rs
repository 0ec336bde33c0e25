//! Expected pair sums of a 2D point process at real frequencies:
//!
//!   C(ω, ω′) = E[ Σ_(l≠m) e^(2πi(ω·q_l − ω′·q_m)) ],  ω, ω′ ∈ R²,
//!
//! the off-diagonal part of the expected cross-spectrum. At an integer
//! frequency k it gives the expected power, E[N·P_S(k)] = 1 + C(k, k)/N
//! (the diagonal l = m contributes exactly N). At real frequencies it is
//! what a shear needs: shearing x′ = x + a·u moves an integrand's frequency
//! k_x onto the real frequency a·k_x of the u coordinates (Singh & Jarosz
//! 2017, §5), and a padded 4D sampler pairs its halves at random, so the
//! expected variance of a sheared set factors through C of each half
//! (docs/mathematics.md §6.2).
//!
//! Samplers with independent strata have C in closed form (random, jitter,
//! multi-jitter, CMJ: each implements [`PairSpectrum`] beside its
//! generator); [`EmpiricalPairs`] estimates C from realizations of any
//! sampler, with a standard error.

use rustfft::num_complex::Complex64;

use crate::points::PointSet;
use crate::spectrum::phase::{reduced_product, sinc_pi, turn};

/// One term A·e^(2πi ω·q) of a superposition of plane waves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneWave {
    /// The amplitude A.
    pub amplitude: Complex64,
    /// The real frequency ω.
    pub frequency: [f64; 2],
}

/// The expected off-diagonal pair sum C(ω, ω′) of a 2D point process.
pub trait PairSpectrum: Send + Sync {
    /// Points per realization, N.
    fn points(&self) -> usize;
    /// C(ω, ω′) = E[Σ_(l≠m) e^(2πi(ω·q_l − ω′·q_m))].
    fn pair_sum(&self, w1: [f64; 2], w2: [f64; 2]) -> Complex64;
    /// For ψ(q) = Σ_t A_t e^(2πi(ω_t + σ)·q), the expected pair sum
    /// E[Σ_(l≠m) ψ(q_l)·conj(ψ(q_m))] = Σ_(t,t′) A_t conj(A_t′) C(ω_t + σ, ω_t′ + σ)
    /// (real: the double sum is Hermitian).
    fn wave_pair_sum(&self, waves: &[PlaneWave], shift: [f64; 2]) -> f64 {
        let mut acc = Complex64::new(0.0, 0.0);
        for a in waves {
            let w1 = [a.frequency[0] + shift[0], a.frequency[1] + shift[1]];
            for b in waves {
                let w2 = [b.frequency[0] + shift[0], b.frequency[1] + shift[1]];
                acc += a.amplitude * b.amplitude.conj() * self.pair_sum(w1, w2);
            }
        }
        acc.re
    }
    /// The expected power E[N·P_S(k)] = 1 + C(k, k)/N at frequency `k`.
    fn power(&self, k: [f64; 2]) -> f64 {
        1.0 + self.pair_sum(k, k).re / self.points() as f64
    }
    /// [`Self::power`] at every (x, y) of `xs` × `ys`, row-major by x (one
    /// row per x). Samplers whose pair sums factor by axis override it to
    /// compute each axis's part once.
    fn power_grid(&self, xs: &[f64], ys: &[f64]) -> Vec<f64> {
        xs.iter()
            .flat_map(|&x| ys.iter().map(move |&y| self.power([x, y])))
            .collect()
    }
}

/// χ(w) = ∫₀¹ e^(2πiwt) dt = e^(πiw)·sinc(πw): the characteristic function
/// of a uniform offset in [0, 1).
#[inline]
pub fn uniform_char(w: f64) -> Complex64 {
    turn(0.5 * w) * sinc_pi(w)
}

/// The geometric sum Σ_(t=0)^(L−1) e^(2πizt) (a Dirichlet kernel with its
/// phase), periodic in z with period 1: with δ = z − round(z) it is
/// e^(πiδ(L−1))·sin(πLδ)/sin(πδ), evaluated as L·sinc(πLδ)/sinc(πδ) so
/// it stays exact near integer z.
#[inline]
pub fn geometric(z: f64, len: usize) -> Complex64 {
    if len == 0 {
        return Complex64::new(0.0, 0.0);
    }
    let l = len as f64;
    let delta = z - z.round();
    turn(0.5 * delta * (l - 1.0)) * (l * sinc_pi(l * delta) / sinc_pi(delta))
}

/// The mean of e^(2πi(z·t − z′·t′)) over ordered pairs t ≠ t′ drawn without
/// replacement from 0..L (zero when L < 2: there are no such pairs).
#[inline]
pub fn distinct_pair_mean(z: f64, z2: f64, len: usize) -> Complex64 {
    if len < 2 {
        return Complex64::new(0.0, 0.0);
    }
    let l = len as f64;
    (geometric(z, len) * geometric(z2, len).conj() - geometric(z - z2, len)) / (l * (l - 1.0))
}

/// C(ω, ω′) estimated from realizations of a sampler, with per-set values
/// for standard errors (direct sums: O(N) per set and frequency pair).
#[derive(Debug, Clone)]
pub struct EmpiricalPairs {
    sets: Vec<PointSet>,
    n: usize,
}

impl EmpiricalPairs {
    /// The estimator over `sets` (2D, all of N points).
    ///
    /// # Panics
    /// If `sets` is empty, not 2D or of different sizes (callers draw them
    /// from one sampler).
    pub fn new(sets: Vec<PointSet>) -> Self {
        let n = sets.first().map_or(0, PointSet::len);
        assert!(
            !sets.is_empty() && sets.iter().all(|s| s.dim() == 2 && s.len() == n),
            "empirical pair sums need 2D sets of one size"
        );
        EmpiricalPairs { sets, n }
    }

    /// Σ_(l≠m) e^(2πi(ω·q_l − ω′·q_m)) on set `r` alone, computed as
    /// (Σ_l e^(2πiω·q_l))·conj(Σ_m e^(2πiω′·q_m)) − Σ_l e^(2πi(ω−ω′)·q_l).
    pub fn pair_sum_of(&self, r: usize, w1: [f64; 2], w2: [f64; 2]) -> Complex64 {
        let mut a = Complex64::new(0.0, 0.0);
        let mut b = Complex64::new(0.0, 0.0);
        let mut diagonal = Complex64::new(0.0, 0.0);
        for q in self.sets[r].points() {
            let e1 = turn(reduced_product(w1[0], q[0]) + reduced_product(w1[1], q[1]));
            let e2 = turn(reduced_product(w2[0], q[0]) + reduced_product(w2[1], q[1]));
            a += e1;
            b += e2;
            diagonal += e1 * e2.conj();
        }
        a * b.conj() - diagonal
    }

    /// [`PairSpectrum::wave_pair_sum`] on set `r` alone, as
    /// |Σ_l ψ(q_l)|² − Σ_l |ψ(q_l)|²: one phasor per point and wave.
    pub fn wave_pair_sum_of(&self, r: usize, waves: &[PlaneWave], shift: [f64; 2]) -> f64 {
        let mut total = Complex64::new(0.0, 0.0);
        let mut diagonal = 0.0;
        for q in self.sets[r].points() {
            let psi: Complex64 = waves
                .iter()
                .map(|w| {
                    w.amplitude
                        * turn(
                            reduced_product(w.frequency[0] + shift[0], q[0])
                                + reduced_product(w.frequency[1] + shift[1], q[1]),
                        )
                })
                .sum();
            total += psi;
            diagonal += psi.norm_sqr();
        }
        total.norm_sqr() - diagonal
    }
}

impl PairSpectrum for EmpiricalPairs {
    fn points(&self) -> usize {
        self.n
    }

    fn pair_sum(&self, w1: [f64; 2], w2: [f64; 2]) -> Complex64 {
        let total: Complex64 = (0..self.sets.len())
            .map(|r| self.pair_sum_of(r, w1, w2))
            .sum();
        total / self.sets.len() as f64
    }

    fn wave_pair_sum(&self, waves: &[PlaneWave], shift: [f64; 2]) -> f64 {
        let total: f64 = (0..self.sets.len())
            .map(|r| self.wave_pair_sum_of(r, waves, shift))
            .sum();
        total / self.sets.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geometric_sums_match_direct_sums() {
        for &(z, len) in &[
            (0.0, 7usize),
            (0.3, 7),
            (1.0 - 1e-12, 16),
            (3.0 + 1e-9, 16),
            (-2.75, 5),
            (123.456, 64),
            (0.5, 1),
        ] {
            let direct: Complex64 = (0..len)
                .map(|t| Complex64::from_polar(1.0, std::f64::consts::TAU * z * t as f64))
                .sum();
            let ours = geometric(z, len);
            assert!(
                (ours - direct).norm() <= 1e-9 * len as f64,
                "z = {z}, L = {len}: {ours} vs {direct}"
            );
        }
    }

    #[test]
    fn uniform_char_is_the_integral() {
        // ∫₀¹ e^(2πiwt) dt = (e^(2πiw) − 1)/(2πiw), written out.
        for &w in &[0.25, -1.5, 3.7, 1e-7, 40.2] {
            let exact = (Complex64::from_polar(1.0, std::f64::consts::TAU * w) - 1.0)
                / Complex64::new(0.0, std::f64::consts::TAU * w);
            assert!((uniform_char(w) - exact).norm() < 1e-9, "w = {w}");
        }
        assert_eq!(uniform_char(0.0), Complex64::new(1.0, 0.0));
        assert!(uniform_char(2.0).norm() < 1e-15);
    }

    #[test]
    fn distinct_pairs_average_over_all_ordered_pairs() {
        let (z, z2, len) = (0.37, -1.21, 6usize);
        let mut total = Complex64::new(0.0, 0.0);
        for t in 0..len {
            for u in 0..len {
                if t != u {
                    total += Complex64::from_polar(
                        1.0,
                        std::f64::consts::TAU * (z * t as f64 - z2 * u as f64),
                    );
                }
            }
        }
        let mean = total / (len * (len - 1)) as f64;
        assert!((distinct_pair_mean(z, z2, len) - mean).norm() < 1e-12);
        assert_eq!(distinct_pair_mean(z, z2, 1), Complex64::new(0.0, 0.0));
    }
}
