//! The exact variance of a randomly shifted lattice rule (Cranley &
//! Patterson 1976; Sloan & Joe, "Lattice Methods for Multiple Integration",
//! 1994, §2): differences of a lattice's points are its points, so the
//! spatial form (docs/mathematics.md §2; Öztireli 2016, Eq. 9) collapses
//! from N² terms to N,
//!
//!   Var[Î] = (1/N²) Σ_i Σ_j c_f(x_i − x_j) = (1/N) Σ_(x ∈ L ∩ [0,1)²) c_f(x),
//!
//! exact with no frequency truncation; in Fourier terms (Poisson summation)
//! it is the sum of P_f over the dual lattice L* = {k ∈ Z² : k·x ∈ Z for
//! all x ∈ L} without 0, which [`dual_sum`] truncates to a box. The regular
//! grid and uniform jitter (one offset shared by every stratum) are the
//! lattice (m, 0, m) under a random shift, so this is their expected
//! variance in closed form.

use super::VarianceError;
use crate::integrands::Integrand;
use crate::samplers::lattice::Lattice;
use crate::sum::NeumaierSum;

/// The exact variance of a shifted lattice rule for one integrand.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LatticeVariance {
    /// (1/N) Σ_(x∈L) c_f(x), clamped at 0 (a smooth f can cancel to below
    /// the rounding bound).
    pub variance: f64,
    /// Bound on its rounding error, 4ε·Σ|c_f(x)|/N: a variance at or below
    /// it is zero to rounding (the lattice integrates f exactly).
    pub rounding_bound: f64,
}

/// The exact shift-randomized variance of `lattice` for `f`: c_f at the N
/// lattice points summed with Neumaier compensation in point order (the
/// same bits for any thread count). Serial: N evaluations are ~30 ms at
/// N = 2^20, and the lattice search runs many of them in parallel.
///
/// # Errors
/// [`VarianceError::Dimension`] for an integrand that is not 2D and
/// [`VarianceError::NoAutocovariance`] for one without a closed-form c_f.
pub fn lattice_variance(
    lattice: &Lattice,
    f: &dyn Integrand,
) -> Result<LatticeVariance, VarianceError> {
    if f.dim() != 2 {
        return Err(VarianceError::Dimension {
            integrand: f.dim(),
            points: 2,
        });
    }
    if !f.has_autocov() {
        return Err(VarianceError::NoAutocovariance { spec: f.spec() });
    }
    let n = lattice.len();
    let (mut sum, mut abs) = (NeumaierSum::default(), NeumaierSum::default());
    for j in 0..n {
        // c_f at the lattice point itself, p/q, not at its rounding: the
        // remainder matters to a cosine of large frequency (a variance of
        // 1e-12 where the lattice integrates it exactly).
        let (hi, lo) = lattice.point_split(j);
        let c = f.autocov_between(&hi, &lo.map(|v| -v)).unwrap_or(f64::NAN);
        sum.add(c);
        abs.add(c.abs());
    }
    Ok(LatticeVariance {
        variance: (sum.value() / n as f64).max(0.0),
        rounding_bound: 4.0 * f64::EPSILON * abs.value() / n as f64,
    })
}

/// Σ P_f(k) over the dual lattice in 0 < |k|∞ ≤ `half`: a lower bound of
/// the variance (every term is nonnegative), used to screen lattices and to
/// rank those a smooth f leaves at the exact form's rounding floor.
pub fn dual_sum(lattice: &Lattice, f: &dyn Integrand, half: i64) -> f64 {
    let (a, b, c) = (lattice.a as i64, lattice.b as i64, lattice.c as i64);
    let mut sum = NeumaierSum::default();
    // Dual points k = m1·(a, 0) + m2·(b, c); count k and −k once each by
    // taking k2 > 0, or k2 = 0 and k1 > 0, and doubling.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrands::Cosine;
    use crate::points::PointSet;
    use crate::variance::spatial::spatial_variance;

    /// The Fibonacci lattice (i/233, −144i/233 mod 1), whose dual is
    /// {k : k₁ − 144·k₂ ≡ 0 (mod 233)}.
    const FIBONACCI: Lattice = Lattice {
        a: 233,
        b: 144,
        c: 1,
    };

    #[test]
    fn a_cosine_of_large_frequency_is_integrated_exactly_off_the_dual() {
        // k = (1000003, 7) is not in the dual (1000003 − 144·7 ≡ 124 mod
        // 233): the lattice integrates it exactly. Evaluated at the rounded
        // points, the phases k·fl(p/q) drift by up to k·2⁻⁵⁴ and the sum
        // read 3.5e-12, 12,000× its rounding bound.
        let off = Cosine::new([1_000_003, 7]).unwrap();
        let v = lattice_variance(&FIBONACCI, &off).unwrap();
        assert!(
            v.variance <= v.rounding_bound && v.rounding_bound < 1e-15,
            "{v:?}"
        );
        // On the dual every term is ½·cos(2π·integer) = ½.
        let on = Cosine::new([932_000 + 144 * 3, 3]).unwrap();
        let v = lattice_variance(&FIBONACCI, &on).unwrap();
        assert!((v.variance - 0.5).abs() <= 1e-15, "{v:?}");
    }

    #[test]
    fn the_spatial_form_of_the_rounded_lattice_resolves_a_large_frequency() {
        // The lattice's points as a file holds them (rounded doubles): the
        // variance of that set, 4.746e-24 by a 50-digit sum over the exact
        // doubles (mpmath, outside the project), is far below rounding.
        // Differences x_i − x_j round below 0.5 (finer bits than 2⁻⁵³),
        // which read 2.1e-13 before each point's phase was reduced apart.
        let coords = (0..FIBONACCI.len())
            .flat_map(|j| FIBONACCI.point(j))
            .collect();
        let set = PointSet::new(2, coords).unwrap();
        let (variance, bound) =
            spatial_variance(&set, &Cosine::new([932_001, 0]).unwrap()).unwrap();
        assert!(
            variance.abs() <= bound && bound < 1e-15,
            "{variance} (bound {bound})"
        );
    }
}
