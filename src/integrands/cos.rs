//! f(x) = 1 + cos(2π k₀·x): the simplest integrand with a finite spectrum,
//! F(0) = 1, F(±k₀) = ½, so Var[Î] = ½·P_S(k₀) exactly for a fixed set.

use rustfft::num_complex::Complex64;

use super::{Integrand, IntegrandClass};
use crate::spectrum::phase::reduced_phase;

/// 1 + cos(2π k₀·x) with integer k₀ (k₀ = 0 gives the constant 2).
#[derive(Debug, Clone)]
pub struct Cosine {
    k0: [i64; 2],
}

impl Cosine {
    /// The cosine of integer frequency k₀, |k₀ components| ≤ 2^40.
    ///
    /// # Errors
    /// [`super::IntegrandError::Value`] beyond 2^40 (the phase reduction
    /// of `k·h` needs the product exact).
    pub fn new(k0: [i64; 2]) -> Result<Self, super::IntegrandError> {
        for (key, k) in [("kx", k0[0]), ("ky", k0[1])] {
            super::require(
                k.unsigned_abs() <= 1 << 40,
                "cos",
                key,
                k,
                "an integer in [-2^40, 2^40]",
            )?;
        }
        Ok(Cosine { k0 })
    }

    /// cos(2π k₀·h) with exact phase reduction (k₀ may be 4000 or more).
    fn cos_phase(&self, h: &[f64]) -> f64 {
        let t = reduced_phase(self.k0[0], h[0]) + reduced_phase(self.k0[1], h[1]);
        (std::f64::consts::TAU * (t - t.round())).cos()
    }

    fn constant(&self) -> bool {
        self.k0 == [0, 0]
    }
}

impl Integrand for Cosine {
    fn dim(&self) -> usize {
        2
    }

    fn integral(&self) -> f64 {
        if self.constant() { 2.0 } else { 1.0 }
    }

    fn variance(&self) -> f64 {
        if self.constant() { 0.0 } else { 0.5 }
    }

    fn eval(&self, x: &[f64]) -> f64 {
        1.0 + self.cos_phase(x)
    }

    fn fourier(&self, k: &[i64]) -> Complex64 {
        let re = match (k[0], k[1]) {
            (0, 0) => self.integral(),
            (a, b) if !self.constant() && ([a, b] == self.k0 || [-a, -b] == self.k0) => 0.5,
            _ => 0.0,
        };
        Complex64::new(re, 0.0)
    }

    fn autocov(&self, h: &[f64]) -> Option<f64> {
        Some(if self.constant() {
            0.0
        } else {
            0.5 * self.cos_phase(h)
        })
    }

    fn autocov_between(&self, x: &[f64], y: &[f64]) -> Option<f64> {
        // Each point's phase k₀·x mod 1 is exact to rounding; their
        // difference is the phase of x − y without the rounding of x − y.
        let phase = |p: &[f64]| reduced_phase(self.k0[0], p[0]) + reduced_phase(self.k0[1], p[1]);
        let t = phase(x) - phase(y);
        Some(if self.constant() {
            0.0
        } else {
            0.5 * (std::f64::consts::TAU * (t - t.round())).cos()
        })
    }

    fn class(&self) -> IntegrandClass {
        IntegrandClass {
            smooth: true,
            one_axis: self.k0[0] == 0 || self.k0[1] == 0,
        }
    }

    fn spec(&self) -> String {
        format!("cos:kx={},ky={}", self.k0[0], self.k0[1])
    }
}
