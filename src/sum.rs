//! Compensated summation (Neumaier 1974, "Rundungsfehleranalyse einiger
//! Verfahren zur Summation endlicher Summen", ZAMM 54): the error of a long
//! sum stays O(ε·Σ|x|) independent of its length, which the spatial
//! predictor's N² terms of both signs need; and the statistics built on
//! such sums (mean, sample variance, standard error).

/// A running Neumaier sum.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NeumaierSum {
    sum: f64,
    compensation: f64,
}

impl NeumaierSum {
    /// Adds `x`.
    #[inline]
    pub fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.compensation += (self.sum - t) + x;
        } else {
            self.compensation += (x - t) + self.sum;
        }
        self.sum = t;
    }

    /// Adds another compensated sum.
    pub fn merge(&mut self, other: NeumaierSum) {
        self.add(other.sum);
        self.add(other.compensation);
    }

    /// The compensated total.
    pub fn value(&self) -> f64 {
        self.sum + self.compensation
    }
}

/// The compensated sum of `values`.
pub fn sum(values: impl IntoIterator<Item = f64>) -> f64 {
    let mut s = NeumaierSum::default();
    for v in values {
        s.add(v);
    }
    s.value()
}

/// The mean of `values` by a compensated sum (NaN for none).
pub fn mean(values: &[f64]) -> f64 {
    sum(values.iter().copied()) / values.len() as f64
}

/// The unbiased sample variance of `values` by two compensated passes (the
/// mean, then centred squares: no E[X²] − E[X]² cancellation); 0 below two
/// values.
pub fn sample_variance(values: &[f64]) -> f64 {
    variance_about(values, mean(values))
}

/// Σ(v − m)²/(R − 1), 0 below two values.
fn variance_about(values: &[f64], m: f64) -> f64 {
    if values.len() < 2 {
        return 0.0;
    }
    sum(values.iter().map(|v| (v - m) * (v - m))) / (values.len() - 1) as f64
}

/// The mean of `values` and its standard error √(s²/R) (0 below two
/// values).
pub fn mean_and_stderr(values: &[f64]) -> (f64, f64) {
    let m = mean(values);
    (m, (variance_about(values, m) / values.len() as f64).sqrt())
}

/// The variance of the unbiased sample variance s² of R independent
/// values, estimated from s² and the fourth central moment m₄ = Σ(v − v̄)⁴/R:
/// Var(s²) ≈ (m₄ − s⁴(R − 3)/(R − 1))/R, clamped at 0: the exact
/// Var(s²) = (μ₄ − σ⁴(R − 3)/(R − 1))/R of independent values (Cramér
/// 1946, Mathematical Methods of Statistics, ch. 27) with the sample
/// moments in place of μ₄ and σ⁴. It keeps the kurtosis that the χ²
/// interval of normal values would drop (indicator integrands are far from
/// normal), but it is biased low for small R: for the mean of many such
/// estimates use [`unbiased_variance_of_sample_variance`].
pub fn variance_of_sample_variance(m4: f64, s2: f64, r: usize) -> f64 {
    let r = r as f64;
    ((m4 - s2 * s2 * (r - 3.0) / (r - 1.0)) / r).max(0.0)
}

/// An unbiased estimate of Var(s²) from R ≥ 4 independent values with
/// central sums S₂ = Σ(v − v̄)² and S₄ = Σ(v − v̄)⁴ (None below 4 values):
/// (s²)² minus the unbiased estimate of σ⁴, the U-statistic of
/// (x₁ − x₂)²(x₃ − x₄)²/4 over distinct quadruples, which in central sums
/// is (R² − 3R + 3)·S₂²/(R(R − 1)(R − 2)(R − 3)) − S₄/((R − 2)(R − 3))
/// (Kendall's polykay k₂₂; the coefficients were checked against the
/// U-statistic by exact rational arithmetic for R = 4 … 8). One estimate
/// can be negative; a sum of many independent ones, as over the pixels of
/// an image, is unbiased where the plug-in [`variance_of_sample_variance`]
/// is not (2.5× low at R = 4 on a rendered image's pixels).
pub fn unbiased_variance_of_sample_variance(s2_sum: f64, s4_sum: f64, r: usize) -> Option<f64> {
    if r < 4 {
        return None;
    }
    let r = r as f64;
    let s2 = s2_sum / (r - 1.0);
    let sigma4 = (r * r - 3.0 * r + 3.0) * s2_sum * s2_sum
        / (r * (r - 1.0) * (r - 2.0) * (r - 3.0))
        - s4_sum / ((r - 2.0) * (r - 3.0));
    Some(s2 * s2 - sigma4)
}

/// Mean and second to fourth central sums of a stream of values, updated
/// one value at a time without differences of large sums (Pébay 2008,
/// "Formulas for robust, one-pass parallel computation of covariances and
/// arbitrary-order statistical moments", SAND2008-6212: its pairwise
/// update with one value on one side; Welford's update is its second-order
/// part).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RunningMoments {
    count: usize,
    mean: f64,
    m2: f64,
    m3: f64,
    m4: f64,
}

impl RunningMoments {
    /// Adds `x`.
    pub fn add(&mut self, x: f64) {
        self.count += 1;
        let n = self.count as f64;
        let delta = x - self.mean;
        let delta_n = delta / n;
        let term = delta * delta_n * (n - 1.0);
        self.mean += delta_n;
        self.m4 += term * delta_n * delta_n * (n * n - 3.0 * n + 3.0)
            + 6.0 * delta_n * delta_n * self.m2
            - 4.0 * delta_n * self.m3;
        self.m3 += term * delta_n * (n - 2.0) - 3.0 * delta_n * self.m2;
        self.m2 += term;
    }

    /// The mean (0 before any value).
    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// The unbiased sample variance, Σ(v − v̄)²/(R − 1) (0 below two values).
    pub fn variance(&self) -> f64 {
        if self.count < 2 {
            0.0
        } else {
            self.m2 / (self.count - 1) as f64
        }
    }

    /// [`unbiased_variance_of_sample_variance`] of these values (None
    /// below four).
    pub fn variance_of_variance(&self) -> Option<f64> {
        unbiased_variance_of_sample_variance(self.m2, self.m4, self.count)
    }
}

/// The ratio a/b of two independent estimates given as (value, standard
/// error), and its standard error to first order (the delta method):
/// (a/b)·√((σ_a/a)² + (σ_b/b)²).
pub fn ratio_and_stderr(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let ratio = a.0 / b.0;
    (ratio, ratio.abs() * (a.1 / a.0).hypot(b.1 / b.0))
}

/// Terms of one compensated partial sum in [`par_sum`].
const TERMS_PER_TASK: usize = 1 << 14;

/// The compensated sum of `term(i)` for i < `len`, in parallel: fixed runs
/// of [`TERMS_PER_TASK`] terms summed apart and merged in order, so the
/// result is the same for any thread count.
pub fn par_sum(len: usize, term: impl Fn(usize) -> f64 + Sync) -> f64 {
    use rayon::prelude::*;
    let partial: Vec<NeumaierSum> = (0..len.div_ceil(TERMS_PER_TASK))
        .into_par_iter()
        .map(|task| {
            let mut s = NeumaierSum::default();
            for i in task * TERMS_PER_TASK..len.min((task + 1) * TERMS_PER_TASK) {
                s.add(term(i));
            }
            s
        })
        .collect();
    let mut total = NeumaierSum::default();
    for s in partial {
        total.merge(s);
    }
    total.value()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_what_naive_summation_loses() {
        // 1 + 1e-16 (×10⁴) − 1: naive gives 0, the exact answer is 1e-12.
        let values = std::iter::once(1.0)
            .chain(std::iter::repeat_n(1e-16, 10_000))
            .chain(std::iter::once(-1.0));
        let naive: f64 = values.clone().sum();
        assert_eq!(naive, 0.0);
        let s = sum(values);
        assert!((s - 1e-12).abs() < 1e-24, "{s}");
    }

    #[test]
    fn parallel_sum_is_compensated_and_thread_count_independent() {
        // 1 + 1e-16 (×50,000, across four tasks) − 1 = 5e-12 exactly in
        // real arithmetic; a naive sum of the same terms gives 0.
        let len = 50_002;
        let term = |i: usize| match i {
            0 => 1.0,
            i if i == len - 1 => -1.0,
            _ => 1e-16,
        };
        let s = par_sum(len, term);
        assert!((s - 5e-12).abs() < 1e-24, "{s}");
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| par_sum(len, term));
        assert_eq!(one.to_bits(), s.to_bits());
    }

    #[test]
    fn running_moments_survive_a_large_offset() {
        // 10⁹ + k, k = 0 … 9: deviations ±0.5, ±1.5, …, ±4.5 from the mean,
        // so Σd² = 82.5 and Σd⁴ = 1208.625 by hand; E[X²] − E[X]² would
        // lose them all in the 10¹⁸ of the squares.
        let mut m = RunningMoments::default();
        for k in 0..10 {
            m.add(1e9 + f64::from(k));
        }
        let s2 = 82.5 / 9.0;
        // Var(s²) unbiased: (s²)² minus the mean of (dᵢ − dⱼ)²(dₖ − dₗ)²/4
        // over the 5040 ordered quadruples of distinct values, enumerated.
        let mut quadruples = (0.0, 0.0);
        for i in 0..10 {
            for j in (0..10).filter(|&j| j != i) {
                for k in (0..10).filter(|&k| k != i && k != j) {
                    for l in (0..10).filter(|&l| l != i && l != j && l != k) {
                        let d = |a: i32, b: i32| f64::from(a - b).powi(2);
                        quadruples.0 += d(i, j) * d(k, l) / 4.0;
                        quadruples.1 += 1.0;
                    }
                }
            }
        }
        let var_of_var = s2 * s2 - quadruples.0 / quadruples.1;
        assert_eq!(m.mean(), 1e9 + 4.5);
        assert!((m.variance() - s2).abs() < 1e-12 * s2, "{}", m.variance());
        let unbiased = m.variance_of_variance().unwrap();
        assert!(
            (unbiased - var_of_var).abs() < 1e-9 * var_of_var,
            "{unbiased} vs {var_of_var}"
        );
    }

    #[test]
    fn a_ratio_carries_both_relative_errors() {
        // 6 ± 3% over 2 ± 4%: 3 ± 5%.
        let (r, se) = ratio_and_stderr((6.0, 0.18), (2.0, 0.08));
        assert!(
            (r - 3.0).abs() < 1e-15 && (se - 0.15).abs() < 1e-15,
            "{r} ± {se}"
        );
    }
}
