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

    /// k₀·x mod 1 with exact phase reduction (k₀ may be 4000 or more).
    fn phase(&self, x: &[f64]) -> f64 {
        reduced_phase(self.k0[0], x[0]) + reduced_phase(self.k0[1], x[1])
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
        1.0 + cos_turns(self.phase(x))
    }

    fn eval_shifted(&self, x: &[f64], s: &[f64]) -> f64 {
        // k₀·(x + s) = k₀·x + k₀·s mod 1, each reduced exactly: no
        // rounding of x + s enters the phase.
        1.0 + cos_turns(self.phase(x) + self.phase(s))
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
            0.5 * cos_turns(self.phase(h))
        })
    }

    fn autocov_between(&self, x: &[f64], y: &[f64]) -> Option<f64> {
        // Each point's phase k₀·x mod 1 is exact to rounding; their
        // difference is the phase of x − y without the rounding of x − y.
        Some(if self.constant() {
            0.0
        } else {
            0.5 * cos_turns(self.phase(x) - self.phase(y))
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

/// cos(2π t) for a phase t in turns, reduced to [−½, ½] first.
fn cos_turns(t: f64) -> f64 {
    (std::f64::consts::TAU * (t - t.round())).cos()
}
