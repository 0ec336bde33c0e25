//! Integration lattices searched for one integrand: the structure a
//! discontinuous or smooth 2D target asks for, found exactly.
//!
//! A lattice point set L ⊃ Z² of N points, moved by a uniform random shift,
//! is the randomly shifted lattice rule (Cranley & Patterson 1976; Sloan &
//! Joe, "Lattice Methods for Multiple Integration", 1994, §2). Differences of
//! its points are points of L, so the spatial form of the variance
//! (docs/mathematics.md §2; Öztireli 2016, Eq. 9) collapses from N² terms
//! to N:
//!
//!   Var[Î] = (1/N²) Σ_i Σ_j c_f(x_i − x_j) = (1/N) Σ_(x ∈ L ∩ [0,1)²) c_f(x),
//!
//! exact with no frequency truncation, or in Fourier terms the sum of P_f
//! over the dual lattice L* = {k ∈ Z² : k·x ∈ Z for all x ∈ L} without 0.
//! Every 2D integration lattice of N points is listed once by the Hermite
//! normal form of its dual, rows (a, 0) and (b, c) with a·c = N and
//! 0 ≤ b < a: σ(N) lattices (σ the divisor sum), rank-1 lattices
//! (Korobov's (1, g)/N) among them. The search ranks them all by the exact
//! form, or, when that costs more than [`EXACT_BUDGET`] evaluations of
//! c_f, screens them by the dual sum over |k|∞ ≤ 4√N and ranks the best
//! [`FINALISTS`] exactly.

use rayon::prelude::*;

use super::OptimizeError;
use crate::integrands::Integrand;
use crate::points::PointSet;
use crate::rng::{SetRng, uniform};
use crate::samplers::config::Config;
use crate::samplers::{Sampler, SamplerError};
use crate::sum::NeumaierSum;

/// Evaluations of c_f the exhaustive exact ranking may spend (σ(N)·N).
pub const EXACT_BUDGET: u64 = 1 << 26;
/// Lattices ranked exactly after the dual-sum screen.
pub const FINALISTS: usize = 32;
/// Largest N searched (σ(N) candidates of (4√N)²·4/N dual points each).
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
    fn point(&self, j: usize) -> [f64; 2] {
        let n = self.len();
        let (i, m) = (j % self.a, j / self.a);
        // (m·a − b·i) mod N without overflow or negative values.
        let y = ((m * self.a) % n + n - (self.b * i) % n) % n;
        [i as f64 / self.a as f64, y as f64 / n as f64]
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

    /// The exact variance of the shifted rule for `f` and the bound on its
    /// rounding error, 4ε·Σ|c_f(x)|/N: (1/N) Σ_x c_f(x) summed with Neumaier
    /// compensation in point order (thread-count independent). Clamped at
    /// 0 (a smooth f can cancel to below the bound).
    fn variance(&self, f: &dyn Integrand) -> (f64, f64) {
        let n = self.len();
        let (mut sum, mut abs) = (NeumaierSum::default(), 0.0);
        for j in 0..n {
            let c = f.autocov(&self.point(j)).expect("checked by the search");
            sum.add(c);
            abs += c.abs();
        }
        (
            (sum.value() / n as f64).max(0.0),
            4.0 * f64::EPSILON * abs / n as f64,
        )
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

    /// Σ P_f(k) over the dual lattice in 0 < |k|∞ ≤ `half` (a lower bound of
    /// the variance, used to screen).
    fn dual_sum(&self, f: &dyn Integrand, half: i64) -> f64 {
        let (a, b, c) = (self.a as i64, self.b as i64, self.c as i64);
        let mut sum = NeumaierSum::default();
        // Dual points k = m1·(a, 0) + m2·(b, c); count k and −k once each
        // by taking k2 > 0, or k2 = 0 and k1 > 0, and doubling.
        for m2 in 0..=half / c {
            let k2 = c * m2;
            let base = b * m2;
            // k1 = a·m1 + base within [−half, half].
            let lo = (-half - base).div_euclid(a) + i64::from((-half - base).rem_euclid(a) != 0);
            let hi = (half - base).div_euclid(a);
            for m1 in lo..=hi {
                let k1 = a * m1 + base;
                if k2 == 0 && k1 <= 0 {
                    continue;
                }
                sum.add(f.fourier(&[k1, k2]).norm_sqr());
            }
        }
        2.0 * sum.value()
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
}

/// The best lattice found for an integrand.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LatticeDesign {
    /// The lattice.
    pub lattice: Lattice,
    /// Its exact shift-randomized variance (spatial form).
    pub variance: f64,
    /// Bound on the rounding error of `variance`.
    pub rounding_bound: f64,
    /// Where `variance` is at its rounding floor: Σ P_f over the dual
    /// lattice in 0 < |k|∞ ≤ K, with K, which ranked the lattices instead.
    pub dual_sum: Option<(f64, i64)>,
    /// Lattices of N points (σ(N)).
    pub candidates: usize,
    /// Lattices ranked by the exact form (all, or the screen's finalists).
    pub ranked_exactly: usize,
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

/// The integration lattice of `n` points with the smallest shift-randomized
/// variance for `f`. Ties (a smooth f, e.g. a cosine, is integrated exactly
/// by most lattices) go to the lattice with the longest shortest dual
/// vector ([`Lattice::shortest_dual`]: the one best for integrands in
/// general, not N points on one line), then to the first in [`lattices`]
/// order.
///
/// # Errors
/// [`OptimizeError::Option`] for N = 0 or above [`MAX_POINTS`], or a
/// target that is not 2D or has no closed-form autocovariance.
pub fn best_lattice(n: usize, f: &dyn Integrand) -> Result<LatticeDesign, OptimizeError> {
    if n == 0 || n > MAX_POINTS {
        return Err(OptimizeError::Option(format!(
            "a lattice search needs 1 <= N <= {MAX_POINTS}, got N = {n}"
        )));
    }
    if f.dim() != 2 || !f.has_autocov() {
        return Err(OptimizeError::Target {
            spec: f.spec(),
            reason: "a lattice search needs a 2D integrand with a closed-form autocovariance \
                     (cos, disk, box, gaussian, halfplane)"
                .into(),
        });
    }
    let all = lattices(n);
    let exact_cost = all.len() as u64 * n as u64;
    let finalists: Vec<Lattice> = if exact_cost <= EXACT_BUDGET {
        all.clone()
    } else {
        let half = (4.0 * (n as f64).sqrt()).ceil() as i64;
        let mut screened: Vec<(f64, usize)> = all
            .par_iter()
            .enumerate()
            .map(|(i, l)| (l.dual_sum(f, half), i))
            .collect();
        screened.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let mut keep: Vec<usize> = screened.iter().take(FINALISTS).map(|s| s.1).collect();
        keep.sort_unstable();
        keep.into_iter().map(|i| all[i]).collect()
    };
    let ranked: Vec<(f64, f64)> = finalists.par_iter().map(|l| l.variance(f)).collect();
    let spread = |i: usize| finalists[i].spectral_test();
    let first_min = |scores: &[(usize, f64)]| {
        scores
            .iter()
            .min_by(|x, y| {
                x.1.total_cmp(&y.1)
                    .then(spread(y.0).cmp(&spread(x.0)))
                    .then(x.0.cmp(&y.0))
            })
            .map(|s| s.0)
            .expect("at least the N x 1 lattice")
    };
    let exact: Vec<(usize, f64)> = ranked.iter().map(|r| r.0).enumerate().collect();
    let mut best = first_min(&exact);
    let mut dual_sum = None;
    // A smooth f can leave several lattices at the spatial form's rounding
    // floor; the dual sum (nonnegative terms, P_f decaying fast) ranks them.
    let at_floor: Vec<usize> = (0..ranked.len())
        .filter(|&i| ranked[i].0 <= ranked[i].1)
        .collect();
    if at_floor.len() > 1 && at_floor.contains(&best) {
        let half = (8.0 * (n as f64).sqrt()).ceil() as i64;
        let sums: Vec<(usize, f64)> = at_floor
            .par_iter()
            .map(|&i| (i, finalists[i].dual_sum(f, half)))
            .collect();
        best = first_min(&sums);
        dual_sum = sums.iter().find(|s| s.0 == best).map(|s| (s.1, half));
    }
    Ok(LatticeDesign {
        lattice: finalists[best],
        variance: ranked[best].0,
        rounding_bound: ranked[best].1,
        dual_sum,
        candidates: all.len(),
        ranked_exactly: finalists.len(),
    })
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
