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
}
