//! The ratio of two variances measured on the same realizations: a design
//! against its baseline (a shear against none) where realization r of both
//! is the same sampler draw and shift, changed only deterministically
//! (common random numbers). The two estimates then err together, and the
//! ratio is known far better than two separate intervals say: where the
//! separate 95% intervals of Var before and after overlap (a 4% gain at
//! R = 4000), the paired interval can still exclude 1.
//!
//! With A_r = (a_r − ā)² and B_r = (b_r − b̄)² (after and before), the
//! ratio is ρ̂ = ΣA/ΣB and, by the delta method on the log scale,
//! Var(ln ρ̂) ≈ (s_A²/Ā² + s_B²/B̄² − 2·s_AB/(Ā·B̄))/R with the sample
//! (co)variances of A and B, i.e. the sample variance of A_r/Ā − B_r/B̄
//! over R; the interval is ρ̂·exp(±z·√Var(ln ρ̂)). Like
//! the single-variance interval it is asymptotic; tests/standard_errors.rs
//! measures its coverage on a defocus pixel where few realizations carry
//! the variance. Below 8 pairs, where it has no width to speak of (at
//! R = 2 the two A_r are equal, and so are the B_r: a zero-width interval
//! that declared a shear 4× worse than none), the interval is Pitman and
//! Morgan's for bivariate normal estimates: ρ̂/(K + √(K² − 1)) to
//! ρ̂·(K + √(K² − 1)), K = 1 + 2(1 − r²)·t²/(R − 2), r the sample
//! correlation of a and b and t Student's 97.5% quantile with R − 2 degrees
//! of freedom: the ratios ρ for which a − √ρ·b and a + √ρ·b are not
//! correlated at that level (Pitman 1939, Morgan 1939); none, [0, ∞), at
//! R = 2.

use super::convergence::t975;
use super::empirical::{KURTOSIS_REALIZATIONS, NORMAL_95};
use crate::sum::sum;

/// Var(after) / Var(before) from paired realizations, with its 95%
/// interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VarianceRatio {
    /// Sample variance after over sample variance before.
    pub ratio: f64,
    /// 95% interval, lower end.
    pub ci_low: f64,
    /// 95% interval, upper end.
    pub ci_high: f64,
}

/// The paired ratio of the variances of `after` and `before` (realization
/// r of each from the same draw); `None` for fewer than 2 pairs, lengths
/// that differ, or a variance of 0 on either side (nothing to divide).
#[must_use]
pub fn paired_ratio(before: &[f64], after: &[f64]) -> Option<VarianceRatio> {
    let n = before.len();
    if n < 2 || after.len() != n {
        return None;
    }
    let r = n as f64;
    let centred = |v: &[f64]| {
        let mean = sum(v.iter().copied()) / r;
        v.iter().map(|x| x - mean).collect::<Vec<f64>>()
    };
    let (ca, cb) = (centred(after), centred(before));
    let squares = |v: &[f64]| v.iter().map(|x| x * x).collect::<Vec<f64>>();
    let (a, b) = (squares(&ca), squares(&cb));
    let (ma, mb) = (sum(a.iter().copied()) / r, sum(b.iter().copied()) / r);
    if !(ma > 0.0 && mb > 0.0) {
        return None;
    }
    let ratio = ma / mb;
    if n < KURTOSIS_REALIZATIONS {
        // 1 − r² = (S_aa·S_bb − S_ab²)/(S_aa·S_bb), the numerator by
        // Lagrange's identity Σ_(i<j) (a_i·b_j − a_j·b_i)²: no cancellation,
        // and exactly 0 for proportional samples (the difference of squares
        // left 1e-16, which the square root below widened to 1e-8).
        let minors = sum((0..n).flat_map(|i| {
            let (ca, cb) = (&ca, &cb);
            (i + 1..n).map(move |j| (ca[i] * cb[j] - ca[j] * cb[i]).powi(2))
        }));
        let uncorrelated = (minors / (r * ma * r * mb)).min(1.0);
        let (ci_low, ci_high) = match n.checked_sub(2).filter(|&dof| dof > 0) {
            Some(dof) => {
                let t = t975(dof);
                let k = 1.0 + 2.0 * uncorrelated * t * t / dof as f64;
                let root = (k * k - 1.0).sqrt();
                // K − √(K² − 1) = 1/(K + √(K² − 1)), without cancellation.
                (ratio / (k + root), ratio * (k + root))
            }
            None => (0.0, f64::INFINITY),
        };
        return Some(VarianceRatio {
            ratio,
            ci_low,
            ci_high,
        });
    }
    // s_A²/Ā² + s_B²/B̄² − 2·s_AB/(Ā·B̄) is the sample variance of
    // A_r/Ā − B_r/B̄, whose mean is 0: one sum of squares.
    let var_log = sum(a.iter().zip(&b).map(|(x, y)| (x / ma - y / mb).powi(2))) / ((r - 1.0) * r);
    let spread = (NORMAL_95 * var_log.sqrt()).exp();
    Some(VarianceRatio {
        ratio,
        ci_low: ratio / spread,
        ci_high: ratio * spread,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_samples_have_ratio_one_and_no_width() {
        let v = [0.1, 0.4, 0.2, 0.9, 0.3];
        let r = paired_ratio(&v, &v).unwrap();
        assert!(
            (r.ratio - 1.0).abs() < 1e-15 && (r.ci_high - r.ci_low).abs() < 1e-12,
            "{r:?}"
        );
    }

    #[test]
    fn a_scaled_copy_has_the_squared_scale_exactly() {
        let before = [0.1, 0.4, 0.2, 0.9, 0.3, 0.7];
        let after: Vec<f64> = before.iter().map(|x| 0.5 * x).collect();
        let r = paired_ratio(&before, &after).unwrap();
        assert!(
            (r.ratio - 0.25).abs() < 1e-15 && (r.ci_high / r.ci_low - 1.0).abs() < 1e-9,
            "{r:?}"
        );
    }

    /// Below 8 pairs: Pitman and Morgan's interval, 95% coverage for
    /// bivariate normal estimates at every R = 3 … 7 (the delta method's
    /// had zero width at R = 2 and missed 8 of 30 seeds at R = 5 on a
    /// layers pixel: stress probe), none at R = 2. Before and after
    /// correlated 0.9, true ratio 0.5; 4000 trials per R (fixed seed): a
    /// true 95% keeps the coverage within ±0.0134 (3.89 standard errors).
    #[test]
    fn few_pairs_get_the_pitman_morgan_interval() {
        use crate::rng::{set_rng, uniform};
        let two = paired_ratio(&[0.1, 0.3], &[0.2, 0.9]).unwrap();
        assert_eq!((two.ci_low, two.ci_high), (0.0, f64::INFINITY));
        let mut rng = set_rng(0x0a1e_d5e7, 0);
        let mut normal = || {
            let (u, v) = (uniform(&mut rng), uniform(&mut rng));
            (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        let (rho, scale) = (0.9_f64, 0.5_f64.sqrt());
        for r in 3..8 {
            let trials = 4000_u32;
            let mut covered = 0_u32;
            for _ in 0..trials {
                let mut before = Vec::new();
                let mut after = Vec::new();
                for _ in 0..r {
                    let (z1, z2) = (normal(), normal());
                    before.push(z1);
                    after.push(scale * (rho * z1 + (1.0 - rho * rho).sqrt() * z2));
                }
                let ratio = paired_ratio(&before, &after).unwrap();
                covered += u32::from(ratio.ci_low <= 0.5 && 0.5 <= ratio.ci_high);
            }
            let coverage = f64::from(covered) / f64::from(trials);
            assert!(
                (coverage - 0.95).abs() <= 0.0134,
                "R = {r}: coverage {coverage} of the nominal 95% (99.99% band 0.9366-0.9634)"
            );
        }
    }

    /// From 8 pairs the delta method: identical samples give ratio 1 and
    /// no width, a scaled copy the squared scale exactly.
    #[test]
    fn the_delta_method_is_exact_on_identities() {
        let before = [0.1, 0.4, 0.2, 0.9, 0.3, 0.7, 0.55, 0.05];
        let same = paired_ratio(&before, &before).unwrap();
        assert!(
            (same.ratio - 1.0).abs() < 1e-15 && (same.ci_high - same.ci_low).abs() < 1e-12,
            "{same:?}"
        );
        let after: Vec<f64> = before.iter().map(|x| 0.5 * x).collect();
        let scaled = paired_ratio(&before, &after).unwrap();
        assert!(
            (scaled.ratio - 0.25).abs() < 1e-15
                && (scaled.ci_high / scaled.ci_low - 1.0).abs() < 1e-9,
            "{scaled:?}"
        );
        // Not an identity: the interval has width.
        let other = [0.3, 0.1, 0.8, 0.2, 0.6, 0.4, 0.9, 0.15];
        let r = paired_ratio(&before, &other).unwrap();
        assert!(
            r.ci_low < r.ratio && r.ratio < r.ci_high && r.ci_high / r.ci_low > 1.5,
            "{r:?}"
        );
    }

    #[test]
    fn degenerate_inputs_have_no_ratio() {
        assert_eq!(paired_ratio(&[1.0], &[1.0]), None);
        assert_eq!(paired_ratio(&[1.0, 2.0], &[1.0]), None);
        assert_eq!(paired_ratio(&[1.0, 1.0], &[1.0, 2.0]), None);
    }
}
