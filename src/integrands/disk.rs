//! The indicator of a disk of radius r ≤ ½ centred at c, periodized.
//!
//! F(k) = r·J1(2πr|k|)/|k|·e^(−2πik·c) (the Fourier transform of a disk,
//! e.g. Bracewell 2000, "The Fourier Transform and its Applications", Ch. 12);
//! the autocorrelation is the lens area of two disks at the pair's distance,
//! summed over the periodic images that overlap.

use rustfft::num_complex::Complex64;

use super::{Integrand, IntegrandClass, IntegrandError, nearest_image, sum_over_images};
use crate::spec_params::SpecValue;
use crate::spectrum::phase::exp_neg_2pi_i;

/// Periodized disk indicator.
#[derive(Debug, Clone)]
pub struct Disk {
    r: f64,
    centre: [f64; 2],
}

impl Disk {
    /// Radius r in (0, ½], centre c (finite).
    ///
    /// # Errors
    /// [`IntegrandError::Value`] for a radius outside (0, ½] (a larger
    /// disk overlaps its own periodic images and the closed forms no
    /// longer hold) or a centre that is not finite.
    pub fn new(r: f64, centre: [f64; 2]) -> Result<Self, IntegrandError> {
        if !(r > 0.0 && r <= 0.5) {
            return Err(IntegrandError::Value {
                integrand: "disk",
                key: "r",
                value: r.to_string(),
                expected: "a radius in (0, 0.5]".into(),
            });
        }
        if !centre.iter().all(|c| c.is_finite()) {
            return Err(IntegrandError::Value {
                integrand: "disk",
                key: "cx/cy",
                value: format!("{centre:?}"),
                expected: "a finite centre".into(),
            });
        }
        Ok(Disk { r, centre })
    }

    fn area(&self) -> f64 {
        std::f64::consts::PI * self.r * self.r
    }

    /// Area of the intersection of two disks of radius r at distance d:
    /// 2r²·acos(d/2r) − (d/2)·√(4r² − d²).
    fn lens(&self, d: f64) -> f64 {
        let r = self.r;
        if d >= 2.0 * r {
            return 0.0;
        }
        2.0 * r * r * (d / (2.0 * r)).acos() - 0.5 * d * ((2.0 * r - d) * (2.0 * r + d)).sqrt()
    }
}

impl Integrand for Disk {
    fn dim(&self) -> usize {
        2
    }

    fn integral(&self) -> f64 {
        self.area()
    }

    fn variance(&self) -> f64 {
        self.area() * (1.0 - self.area())
    }

    fn eval(&self, x: &[f64]) -> f64 {
        let dx = nearest_image(x[0] - self.centre[0]);
        let dy = nearest_image(x[1] - self.centre[1]);
        if dx * dx + dy * dy <= self.r * self.r {
            1.0
        } else {
            0.0
        }
    }

    fn fourier(&self, k: &[i64]) -> Complex64 {
        if k[0] == 0 && k[1] == 0 {
            return Complex64::new(self.area(), 0.0);
        }
        let kn = ((k[0] as f64).powi(2) + (k[1] as f64).powi(2)).sqrt();
        let amplitude = self.r * libm::j1(std::f64::consts::TAU * self.r * kn) / kn;
        exp_neg_2pi_i(k, &self.centre) * amplitude
    }

    fn autocov(&self, h: &[f64]) -> Option<f64> {
        // With r ≤ ½ only images within one period can overlap.
        let reach2 = 4.0 * self.r * self.r;
        let overlap = sum_over_images(h, |t| {
            let d2 = t[0] * t[0] + t[1] * t[1];
            if d2 < reach2 {
                self.lens(d2.sqrt())
            } else {
                0.0
            }
        });
        Some(overlap - self.area() * self.area())
    }

    fn autocov_support(&self) -> Option<f64> {
        Some(2.0 * self.r)
    }

    fn class(&self) -> IntegrandClass {
        IntegrandClass {
            smooth: false,
            one_axis: false,
        }
    }

    fn spec(&self) -> String {
        format!(
            "disk:r={},cx={},cy={}",
            SpecValue(self.r),
            SpecValue(self.centre[0]),
            SpecValue(self.centre[1])
        )
    }
}
