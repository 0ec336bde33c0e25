//! Compensated summation (Neumaier 1974, "Rundungsfehleranalyse einiger
//! Verfahren zur Summation endlicher Summen", ZAMM 54): the error of a long
//! sum stays O(ε·Σ|x|) independent of its length, which the spatial
//! predictor's N² terms of both signs need.

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
}
