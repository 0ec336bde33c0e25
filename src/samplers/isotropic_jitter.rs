//! Isotropic jitter (Öztireli 2016, "Integration with stochastic point
//! processes", ACM TOG 35(5), §6): the jittered grid of spacing h = 1/m,
//! rotated by a uniformly random angle and translated by a uniformly random
//! offset, then clipped to the unit square.
//!
//! The rotation and translation make the process stationary and isotropic
//! in the plane, with density λ = m² points per unit area; the clipped set
//! holds a random number of points (mean λ). The unbiased estimator weighs
//! every point by 1/λ, Î = (1/λ) Σ f(x_j); the sets carry λ
//! ([`PointSet::density`]) so every predictor uses that weight, and the
//! random count adds E[(N/λ − 1)²]·I² to the variance (docs/mathematics.md
//! §2, "A random number of points").

use super::config::{Config, integer_root};
use super::{Sampler, SamplerError};
use crate::points::PointSet;
use crate::rng::{SetRng, uniform};

/// The randomly rotated and shifted m×m-per-unit-area jittered grid,
/// clipped to [0,1)².
#[derive(Debug, Clone)]
pub struct IsotropicJitter {
    m: usize,
}

impl IsotropicJitter {
    /// Spacing 1/m: density λ = m².
    ///
    /// # Errors
    /// [`SamplerError::ZeroPoints`] for m = 0.
    pub fn new(m: usize) -> Result<Self, SamplerError> {
        if m == 0 {
            return Err(SamplerError::ZeroPoints {
                sampler: "isotropic-jitter",
            });
        }
        Ok(IsotropicJitter { m })
    }
}

pub(crate) fn from_config(c: &Config) -> Result<Box<dyn Sampler>, SamplerError> {
    let m = integer_root(c.n, 2);
    if m * m != c.n {
        return Err(c.bad_count(
            "N = m^2 (the expected count)",
            Some(m * m),
            Some((m + 1) * (m + 1)),
        ));
    }
    Ok(Box::new(IsotropicJitter::new(m)?))
}

impl Sampler for IsotropicJitter {
    fn dim(&self) -> usize {
        2
    }

    /// The expected count λ = m²; each set's own count is random.
    fn points_per_set(&self) -> usize {
        self.m * self.m
    }

    fn density(&self) -> Option<f64> {
        Some((self.m * self.m) as f64)
    }

    fn sample(&self, rng: &mut SetRng) -> Result<PointSet, SamplerError> {
        let m = self.m as f64;
        // The grid is symmetric under quarter turns: θ ∈ [0, π/2) covers
        // every orientation.
        let theta = uniform(rng) * std::f64::consts::FRAC_PI_2;
        let (s, c) = theta.sin_cos();
        let offset = [uniform(rng), uniform(rng)];
        // Grid coordinates q = m·R(−θ)·x of the unit square's corners span
        // q₀ ∈ [0, m(c + s)], q₁ ∈ [−m·s, m·c]; one cell of margin each side.
        let q0 = -1..(m * (c + s)).ceil() as i64 + 1;
        let q1 = (-(m * s).ceil()) as i64 - 1..(m * c).ceil() as i64 + 1;
        let mut coords = Vec::with_capacity(2 * (self.m + 2) * (self.m + 2));
        for j in q1 {
            for i in q0.clone() {
                let a = (i as f64 + offset[0] + uniform(rng)) / m;
                let b = (j as f64 + offset[1] + uniform(rng)) / m;
                let x = c * a - s * b;
                let y = s * a + c * b;
                if (0.0..1.0).contains(&x) && (0.0..1.0).contains(&y) {
                    coords.extend([x, y]);
                }
            }
        }
        Ok(PointSet::new(2, coords)
            .and_then(|p| p.with_density(m * m))
            .expect("clipped coordinates lie in [0,1) and m ≥ 1"))
    }
}
