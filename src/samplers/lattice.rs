//! Integration lattices: the randomly shifted lattice rule as a sampler
//! (Cranley & Patterson 1976; Sloan & Joe, "Lattice Methods for Multiple
//! Integration", 1994, §2).
//!
//! A lattice point set L ⊃ Z² of N points, moved by a uniform random shift,
//! is the randomly shifted lattice rule. Every 2D integration lattice of N
//! points is listed once by the Hermite normal form of its dual, rows
//! (a, 0) and (b, c) with a·c = N and 0 ≤ b < a: σ(N) lattices (σ the
//! divisor sum), rank-1 lattices (Korobov's (1, g)/N) among them. The
//! regular m × m grid is the lattice (a, b, c) = (m, 0, m). Differences of a
//! lattice's points are its points, so its variance for an integrand is an
//! N-term sum ([`crate::variance::lattice`]).

use crate::points::PointSet;
use crate::rng::{SetRng, uniform};
use crate::samplers::config::Config;
use crate::samplers::{Sampler, SamplerError};

/// Largest N listed (σ(N) candidates of (4√N)²·4/N dual points each in the
/// search of [`crate::optimize::lattice`]).
pub const MAX_POINTS: usize = 1 << 20;

/// A 2D integration lattice of `a·c` points: the points
/// (i/a, ((m·a − b·i) mod N)/N) for i < a, m < c, whose dual lattice has
/// the basis rows (a, 0), (b, c).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Lattice {
    /// First diagonal entry of the dual's Hermite normal form.
    pub a: usize,
    /// Off-diagonal entry, 0 ≤ b < a.
    pub b: usize,
    /// Second diagonal entry, a·c = N.
    pub c: usize,
}

impl Lattice {
    /// Points in the lattice.
    pub fn len(&self) -> usize {
        self.a * self.c
    }

    /// Never empty (a, c ≥ 1).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Point `j` (j < N), exact in binary fractions of N.
    pub fn point(&self, j: usize) -> [f64; 2] {
        let ([x, y], [p, q]) = self.fractions(j);
        [x as f64 / p as f64, y as f64 / q as f64]
    }

    /// Point `j` as the rounded coordinates of [`Lattice::point`] and their
    /// rounding remainders: p/q = hi + lo to about 2⁻¹⁰⁶ (the remainder
    /// p − hi·q is exact by one fused multiply-add, Dekker 1971).
    pub fn point_split(&self, j: usize) -> ([f64; 2], [f64; 2]) {
        let (num, den) = self.fractions(j);
        let hi = [0, 1].map(|k| num[k] as f64 / den[k] as f64);
        let lo = [0, 1].map(|k| (-hi[k]).mul_add(den[k] as f64, num[k] as f64) / den[k] as f64);
        (hi, lo)
    }

    /// Point `j`'s coordinates as fractions: numerators and denominators.
    fn fractions(&self, j: usize) -> ([usize; 2], [usize; 2]) {
        let n = self.len();
        let (i, m) = (j % self.a, j / self.a);
        // (m·a − b·i) mod N without overflow or negative values.
        let y = ((m * self.a) % n + n - (self.b * i) % n) % n;
        ([i, y], [self.a, n])
    }

    /// Its points moved by `shift` (mod 1): one realization of the randomly
    /// shifted lattice rule.
    pub fn points(&self, shift: [f64; 2]) -> PointSet {
        let coords = (0..self.len())
            .flat_map(|j| {
                let p = self.point(j);
                [
                    crate::points::wrap01(p[0] + shift[0]),
                    crate::points::wrap01(p[1] + shift[1]),
                ]
            })
            .collect();
        PointSet::new(2, coords).expect("points in [0,1)")
    }

    /// The shortest nonzero vector h of the dual lattice (Lagrange–Gauss
    /// reduction of the basis (a, 0), (b, c); Nguyen & Stehlé 2009, Alg. 1):
    /// the points lie on parallel lines h·x ∈ Z + s, 1/|h| apart, so |h| is
    /// the lattice's figure of merit for integrands in general — the
    /// spectral test (Knuth, TAOCP vol. 2, §3.3.4), √(2N/√3) at best (the
    /// hexagonal lattice), 1 for N points on one line.
    pub fn shortest_dual(&self) -> [i64; 2] {
        let norm = |v: [i64; 2]| v[0] * v[0] + v[1] * v[1];
        let (mut u, mut v) = ([self.a as i64, 0], [self.b as i64, self.c as i64]);
        if norm(u) > norm(v) {
            std::mem::swap(&mut u, &mut v);
        }
        loop {
            // v − round(⟨u, v⟩/|u|²)·u, then swap while it got shorter.
            let dot = u[0] * v[0] + u[1] * v[1];
            let q = (dot as f64 / norm(u) as f64).round() as i64;
            v = [v[0] - q * u[0], v[1] - q * u[1]];
            if norm(v) >= norm(u) {
                return u;
            }
            std::mem::swap(&mut u, &mut v);
        }
    }

    /// |h|² of [`Self::shortest_dual`]: the spectral test's figure, larger
    /// is better.
    pub fn spectral_test(&self) -> i64 {
        let h = self.shortest_dual();
        h[0] * h[0] + h[1] * h[1]
    }
}

/// The randomly shifted lattice rule as a sampler: each realization is the
/// lattice moved by a uniform shift drawn from the set's stream.
impl Sampler for Lattice {
    fn dim(&self) -> usize {
        2
    }

    fn points_per_set(&self) -> usize {
        self.len()
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        Ok(self.points([uniform(rng), uniform(rng)]))
    }

    fn lattice(&self) -> Option<Lattice> {
        Some(*self)
    }
}
/// The rank-1 (Korobov) lattice of `n` points with generator `g`:
/// (i/N, (g·i mod N)/N), i < N, whose dual is {k : k₁ + g·k₂ ≡ 0 mod N}
/// (Korobov 1959; Sloan & Joe 1994, §2.5).
pub fn korobov(n: usize, g: usize) -> Lattice {
    Lattice {
        a: n,
        b: (n - g % n) % n,
        c: 1,
    }
}

/// The integration lattice of `n` points that passes the spectral test
/// best: the longest shortest dual vector ([`Lattice::shortest_dual`]; the
/// points' parallel lines lie furthest apart), the first in [`lattices`]
/// order among equals. Every lattice is tried, rank-1 or not: O(σ(N)·log N).
pub fn best_spectral_lattice(n: usize) -> Lattice {
    // max_by_key keeps the last of equals: reversed, the first in order.
    lattices(n)
        .into_iter()
        .rev()
        .max_by_key(Lattice::spectral_test)
        .expect("N >= 1 has the lattice Z²/N")
}

/// The `lattice` sampler of the registry: [`best_spectral_lattice`], or the
/// Korobov lattice of the `g` given, under a fresh uniform shift per set
/// (the randomly shifted lattice rule).
///
/// # Errors
/// [`SamplerError::Count`] above [`MAX_POINTS`]; [`SamplerError::Param`]
/// for a `g` that is not a whole number in 1 ≤ g < N.
pub fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    if c.n == 0 || c.n > MAX_POINTS {
        return Err(c.bad_count(
            "1 <= N <= 2^20: the spectral-test search lists every lattice of N points",
            (c.n > MAX_POINTS).then_some(MAX_POINTS),
            (c.n == 0).then_some(1),
        ));
    }
    let lattice = match c.param("g") {
        "auto" => best_spectral_lattice(c.n),
        text => match text.parse::<usize>() {
            Ok(g) if (1..c.n).contains(&g) => korobov(c.n, g),
            _ => {
                return Err(
                    c.bad_param("g", format!("auto or a whole number 1 <= g < N = {}", c.n))
                );
            }
        },
    };
    Ok(Box::new(lattice))
}

/// Every 2D integration lattice of `n` points, in a fixed order.
pub fn lattices(n: usize) -> Vec<Lattice> {
    (1..=n)
        .filter(|a| n % a == 0)
        .flat_map(|a| (0..a).map(move |b| Lattice { a, b, c: n / a }))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lattices_are_counted_by_the_divisor_sum_and_are_closed_under_differences() {
        // σ(12) = 1 + 2 + 3 + 4 + 6 + 12 = 28.
        assert_eq!(lattices(12).len(), 28);
        for l in lattices(12) {
            let pts: Vec<[f64; 2]> = (0..12).map(|j| l.point(j)).collect();
            let key = |p: [f64; 2]| {
                (
                    (p[0] * 12.0).round() as i64 % 12,
                    (p[1] * 12.0).round() as i64 % 12,
                )
            };
            let set: std::collections::BTreeSet<_> = pts.iter().map(|&p| key(p)).collect();
            assert_eq!(set.len(), 12, "{l:?} repeats a point");
            for p in &pts {
                for q in &pts {
                    let d = [(p[0] - q[0]).rem_euclid(1.0), (p[1] - q[1]).rem_euclid(1.0)];
                    assert!(set.contains(&key(d)), "{l:?}: difference {d:?} not a point");
                }
            }
        }
    }
}
