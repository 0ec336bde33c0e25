//! The sum of the periodic images of a Gaussian of peak 1 (its own peak
//! exceeds 1 once the images overlap): f(x) = Σ_m g(x − c + m),
//! g(u) = exp(−½(a²/sx² + b²/sy²)) with a = u·e₁, b = u·e₂ in the frame
//! rotated by θ.
//!
//! I = 2π·sx·sy; F(k) = I·exp(−2π²(sx²(k·e₁)² + sy²(k·e₂)²))·e^(−2πik·c);
//! the autocorrelation of g is π·sx·sy·exp(−¼(a²/sx² + b²/sy²)), summed
//! over periodic images. When the bump is so wide that I² approaches
//! ∫f² (4π·sx·sy > ½), the autocovariance is summed as the Fourier series
//! Σ_(k≠0) P_f(k) cos(2πk·h) instead, which converges fast there and does
//! not subtract nearly equal numbers.

use rustfft::num_complex::Complex64;

use super::{Integrand, IntegrandClass, nearest_image};
use crate::spec_params::SpecValue;
use crate::spectrum::phase::{exp_neg_2pi_i, reduced_phase};

/// Exponents beyond this contribute below 1e-17 relative.
const CUTOFF: f64 = 40.0;

/// Periodized rotated Gaussian bump.
#[derive(Debug, Clone)]
pub struct Gaussian {
    sx: f64,
    sy: f64,
    angle: f64,
    centre: [f64; 2],
    e1: [f64; 2],
    e2: [f64; 2],
    /// Image offsets m to sum for f (|m|∞ ≤ images).
    images: i64,
    /// Autocovariance by Fourier series (wide bumps) rather than images.
    fourier_autocov: bool,
}

impl Gaussian {
    /// Standard deviations sx, sy in (0, ½], angle in degrees, centre c.
    ///
    /// # Errors
    /// [`super::IntegrandError::Value`] for a deviation outside (0, ½] (a
    /// wider bump overlaps its periodic images beyond what the image sums
    /// hold; a negative one has no meaning) or a non-finite angle or centre.
    pub fn new(
        sx: f64,
        sy: f64,
        angle: f64,
        centre: [f64; 2],
    ) -> Result<Self, super::IntegrandError> {
        let deviation = |s: f64| s > 0.0 && s <= 0.5;
        let name = "gaussian";
        super::require(
            deviation(sx),
            name,
            "sx",
            sx,
            "a standard deviation in (0, 0.5]",
        )?;
        super::require(
            deviation(sy),
            name,
            "sy",
            sy,
            "a standard deviation in (0, 0.5]",
        )?;
        super::require(
            angle.is_finite(),
            name,
            "angle",
            angle,
            "an angle in degrees",
        )?;
        super::require(
            centre.iter().all(|c| c.is_finite()),
            name,
            "cx/cy",
            centre,
            "a finite centre",
        )?;
        let (s, c) = angle.to_radians().sin_cos();
        let smax = sx.max(sy);
        // Autocorrelation images reach √2·s·√(4·CUTOFF)… beyond which terms vanish.
        let images = ((2.0 * CUTOFF).sqrt() * std::f64::consts::SQRT_2 * smax).ceil() as i64 + 1;
        let fourier_autocov = 4.0 * std::f64::consts::PI * sx * sy > 0.5;
        Ok(Gaussian {
            sx,
            sy,
            angle,
            centre,
            e1: [c, s],
            e2: [-s, c],
            images,
            fourier_autocov,
        })
    }

    /// The quadratic form a²/sx² + b²/sy² of offset u.
    #[inline]
    fn form(&self, u: [f64; 2]) -> f64 {
        let a = u[0] * self.e1[0] + u[1] * self.e1[1];
        let b = u[0] * self.e2[0] + u[1] * self.e2[1];
        a * a / (self.sx * self.sx) + b * b / (self.sy * self.sy)
    }

    /// Σ_m exp(−scale·form(u + m)) over images, skipping negligible ones:
    /// form(v) ≥ |v|²/s_max², so only |u_j + m_j| ≤ s_max·√(CUTOFF/scale)
    /// along each axis can contribute.
    fn image_sum(&self, u: [f64; 2], scale: f64) -> f64 {
        let (ux, uy) = (nearest_image(u[0]), nearest_image(u[1]));
        let reach = self.sx.max(self.sy) * (CUTOFF / scale).sqrt();
        let range = |v: f64| {
            ((-reach - v).ceil() as i64).max(-self.images)
                ..=((reach - v).floor() as i64).min(self.images)
        };
        let mut sum = 0.0;
        for mx in range(ux) {
            for my in range(uy) {
                let q = scale * self.form([ux + mx as f64, uy + my as f64]);
                if q < CUTOFF {
                    sum += (-q).exp();
                }
            }
        }
        sum
    }

    fn power(&self, k: [i64; 2]) -> f64 {
        let (kx, ky) = (k[0] as f64, k[1] as f64);
        let a = kx * self.e1[0] + ky * self.e1[1];
        let b = kx * self.e2[0] + ky * self.e2[1];
        let i = self.integral();
        let q = 4.0
            * std::f64::consts::PI.powi(2)
            * (self.sx * self.sx * a * a + self.sy * self.sy * b * b);
        i * i * (-q).exp()
    }

    /// Σ_(k≠0) P_f(k) cos(2πk·h) over the box where P_f is not negligible.
    fn fourier_autocov(&self, h: [f64; 2]) -> f64 {
        let kmax =
            ((CUTOFF + 2.0).sqrt() / (std::f64::consts::TAU * self.sx.min(self.sy))).ceil() as i64;
        let mut sum = 0.0;
        for kx in -kmax..=kmax {
            for ky in -kmax..=kmax {
                if (kx, ky) != (0, 0) {
                    let t = reduced_phase(kx, h[0]) + reduced_phase(ky, h[1]);
                    sum += self.power([kx, ky]) * (std::f64::consts::TAU * (t - t.round())).cos();
                }
            }
        }
        sum
    }
}

impl Integrand for Gaussian {
    fn dim(&self) -> usize {
        2
    }

    fn integral(&self) -> f64 {
        std::f64::consts::TAU * self.sx * self.sy
    }

    fn variance(&self) -> f64 {
        self.autocov(&[0.0, 0.0]).expect("2D closed form")
    }

    fn eval(&self, x: &[f64]) -> f64 {
        self.image_sum([x[0] - self.centre[0], x[1] - self.centre[1]], 0.5)
    }

    fn fourier(&self, k: &[i64]) -> Complex64 {
        exp_neg_2pi_i(k, &self.centre) * self.power([k[0], k[1]]).sqrt()
    }

    fn autocov(&self, h: &[f64]) -> Option<f64> {
        Some(if self.fourier_autocov {
            self.fourier_autocov([h[0], h[1]])
        } else {
            let i = self.integral();
            std::f64::consts::PI * self.sx * self.sy * self.image_sum([h[0], h[1]], 0.25) - i * i
        })
    }

    fn class(&self) -> IntegrandClass {
        IntegrandClass {
            smooth: true,
            one_axis: false,
        }
    }

    fn spec(&self) -> String {
        format!(
            "gaussian:sx={},sy={},angle={},cx={},cy={}",
            SpecValue(self.sx),
            SpecValue(self.sy),
            SpecValue(self.angle),
            SpecValue(self.centre[0]),
            SpecValue(self.centre[1])
        )
    }
}
